"""Operating profiles: piecewise-linear fractions of rated speed or load over time."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def profile_value(t: float, times: np.ndarray, fractions: np.ndarray) -> float:
    """Piecewise-linear value at time t, held constant before the first and after the last point."""
    n = times.size
    if t <= times[0]:
        return fractions[0]
    if t >= times[n - 1]:
        return fractions[n - 1]
    m = np.searchsorted(times, t, side="right") - 1
    return fractions[m] + (fractions[m + 1] - fractions[m]) * (t - times[m]) / (times[m + 1] - times[m])


@njit(cache=True)
def profile_integral(t: float, times: np.ndarray, fractions: np.ndarray) -> float:
    """Integral of the profile from 0 to t (exact for the piecewise-linear profile), in fraction * s."""
    total = 0.0
    prev_t, prev_f = 0.0, profile_value(0.0, times, fractions)
    for m in range(times.size):
        tm = times[m]
        if tm <= 0.0:
            continue
        if tm >= t:
            break
        total += 0.5 * (prev_f + fractions[m]) * (tm - prev_t)
        prev_t, prev_f = tm, fractions[m]
    total += 0.5 * (prev_f + profile_value(t, times, fractions)) * (t - prev_t)
    return total


def profile_arrays(profile) -> tuple[np.ndarray, np.ndarray]:
    """(times, fractions) float arrays of a :class:`~gearbody.model.Profile`."""
    return np.asarray(profile.time_s, float), np.asarray(profile.fraction, float)
