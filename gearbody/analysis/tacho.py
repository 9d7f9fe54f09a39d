"""Tacho processing: pulse instants from a sampled pulse train, and the shaft angle and speed they imply.

Engine-free: plain numpy arrays in, numpy arrays out. The shaft angle feeds computed order tracking
(:func:`gearbody.analysis.orders.order_track`) and the synchronous average (:mod:`gearbody.analysis.tsa`).

Pulse k (k = 0, 1, ...) marks the shaft angle 2 pi k / pulses_per_rev: the angle is 0 at the first pulse
and assumes equally spaced marks (a wheel with an uneven tooth spacing gives an angle error of the
size of its spacing error).
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ._validate import finite_1d, integer_at_least, is_real, positive_frequency

__all__ = ["pulse_times", "shaft_angle_from_pulses", "shaft_speed_from_pulses"]

_TWO_PI = 2.0 * np.pi
_LEVEL_PERCENTILES = (0.5, 99.5)
"""Robust low and high state of a pulse train [percent of samples] (a state held for < 0.5 % of the
record, e.g. a very narrow keyphasor pulse, needs an explicit ``level``)."""
_DEFAULT_HYSTERESIS = 0.1
"""Default hysteresis as a fraction of the robust range (high state - low state)."""


def _finite_real(name: str, value: float) -> float:
    if not (is_real(value) and math.isfinite(value)):
        raise InputError(f"{name} must be a finite number, got {value!r}")
    return float(value)


def _thresholds(x: NDArray[np.float64], level: float | None, hysteresis: float | None) -> tuple[float, float]:
    """Trigger level and hysteresis width, defaults from the robust low and high state."""
    low, high = np.percentile(x, _LEVEL_PERCENTILES)
    if level is None:
        level = 0.5 * (low + high)
    level = _finite_real("level", level)
    if hysteresis is None:
        hysteresis = _DEFAULT_HYSTERESIS * (high - low)
    hysteresis = _finite_real("hysteresis", hysteresis)
    if hysteresis < 0:
        raise InputError(f"hysteresis must be >= 0 [signal units], got {hysteresis!r}")
    if not np.any(x > level + 0.5 * hysteresis) or not np.any(x < level - 0.5 * hysteresis):
        raise InputError(
            f"tacho_signal never crosses level {level:.6g} +- hysteresis/2 ({hysteresis:.6g} / 2): its range "
            f"is {x.min():.6g} .. {x.max():.6g}"
        )
    return level, hysteresis


def pulse_times(
    tacho_signal: ArrayLike,
    sample_rate_hz: float,
    level: float | None = None,
    hysteresis: float | None = None,
    edge: Literal["rising", "falling"] = "rising",
    t0_s: float = 0.0,
) -> NDArray[np.float64]:
    """Instants [s] of the pulses of a sampled tacho pulse train (TTL square wave or keyphasor).

    A Schmitt trigger: a rising edge counts when the signal rises above ``level + hysteresis / 2`` after
    it was last below ``level - hysteresis / 2`` (falling edges mirror it), so noise chatter narrower
    than the hysteresis is ignored. The instant is the crossing of ``level`` itself, linearly
    interpolated between the two samples around it (sub-sample). An edge in progress at the first
    sample (no preceding opposite state) is not counted.

    Accuracy: on an edge whose rise takes a few samples the interpolation error is a small fraction of a
    sample; on an ideal square wave (a jump between two samples) it is up to half a sample, 0.5 /
    sample_rate_hz.

    Args:
        tacho_signal: the sampled pulse train [any unit].
        sample_rate_hz: sample rate [Hz].
        level: trigger level [signal units]; None: midway between the 0.5 and 99.5 percentiles.
        hysteresis: full width of the hysteresis band [signal units]; None: 10 % of that percentile range.
        edge: "rising" or "falling".
        t0_s: time of the first sample [s].
    """
    x = finite_1d("tacho_signal", tacho_signal, 2)
    fs = positive_frequency("sample_rate_hz", sample_rate_hz)
    t0_s = _finite_real("t0_s", t0_s)
    if edge not in ("rising", "falling"):
        raise InputError(f"edge must be 'rising' or 'falling', got {edge!r}")
    level, hysteresis = _thresholds(x, level, hysteresis)
    if edge == "falling":
        x, level = -x, -level
    above = x > level + 0.5 * hysteresis
    below = x < level - 0.5 * hysteresis
    index = np.arange(x.size)
    # state of the trigger at each sample: +1 high, -1 low, 0 not yet decided (carried forward)
    last = np.maximum.accumulate(np.where(above | below, index, -1))
    state = np.where(last >= 0, np.where(above[np.maximum(last, 0)], 1, -1), 0)
    edges = np.flatnonzero((state[1:] == 1) & (state[:-1] == -1)) + 1
    # the last sample at or below the level before each edge, and the crossing after it
    at_or_below = np.maximum.accumulate(np.where(x <= level, index, -1))
    k = at_or_below[edges]
    x0, x1 = x[k], x[k + 1]
    fraction = (level - x0) / (x1 - x0)
    return t0_s + (k + fraction) / fs


def _pulse_angles(pulse_times_s: ArrayLike, pulses_per_rev: int) -> tuple[NDArray, NDArray]:
    """Validated pulse instants [s] and the shaft angle of each [rad]."""
    pulses_per_rev = integer_at_least("pulses_per_rev", pulses_per_rev, 1)
    t = finite_1d("pulse_times_s", pulse_times_s, 3)
    step = np.diff(t)
    if np.any(step <= 0):
        i = int(np.flatnonzero(step <= 0)[0])
        raise InputError(
            f"pulse_times_s must be strictly increasing: pulse {i + 1} at {t[i + 1]!r} s is not after "
            f"pulse {i} at {t[i]!r} s"
        )
    return t, _TWO_PI / pulses_per_rev * np.arange(t.size)


def _interpolant(pulse_times_s: ArrayLike, pulses_per_rev: int, method: str):
    """(t, angle, piecewise cubic through the pulses)."""
    t, angle = _pulse_angles(pulse_times_s, pulses_per_rev)
    from scipy.interpolate import CubicSpline, PchipInterpolator

    if method == "cubic":
        return t, angle, CubicSpline(t, angle, bc_type="not-a-knot")
    if method == "pchip":
        return t, angle, PchipInterpolator(t, angle)
    raise InputError(f"method must be 'cubic' or 'pchip', got {method!r}")


def shaft_angle_from_pulses(
    pulse_times_s: ArrayLike,
    pulses_per_rev: int,
    time_s: ArrayLike,
    *,
    method: Literal["cubic", "pchip"] = "cubic",
) -> NDArray[np.float64]:
    """Unwrapped shaft angle [rad] at the instants ``time_s``, from tacho pulse instants.

    Pulse k is at angle 2 pi k / pulses_per_rev (0 at the first pulse). Between the first and the last
    pulse the angle is a piecewise cubic through the points (t_k, angle_k):

    - "cubic": a not-a-knot cubic spline, exact for an angle cubic in time (constant angular
      acceleration included) and fourth-order accurate otherwise; the best choice for a smooth speed.
    - "pchip": the monotone PCHIP interpolant (the angle never runs backwards, even across an abrupt
      speed change), less accurate on a smooth speed.

    Outside the pulse span the angle is extrapolated linearly with the interpolant's speed at the
    nearest end pulse (constant speed assumed before the first and after the last pulse).

    Args:
        pulse_times_s: strictly increasing pulse instants, at least 3 [s] (from :func:`pulse_times`).
        pulses_per_rev: pulses per shaft revolution (>= 1).
        time_s: instants at which the angle is wanted [s] (any shape, e.g. the signal's sample times).
        method: "cubic" or "pchip".
    """
    t, angle, spline = _interpolant(pulse_times_s, pulses_per_rev, method)
    query = np.asarray(time_s, dtype=float)
    result = spline(query)
    before, after = query < t[0], query > t[-1]
    if np.any(before):
        result[before] = angle[0] + spline(t[0], 1) * (query[before] - t[0])
    if np.any(after):
        result[after] = angle[-1] + spline(t[-1], 1) * (query[after] - t[-1])
    return result


def shaft_speed_from_pulses(
    pulse_times_s: ArrayLike,
    pulses_per_rev: int,
    time_s: ArrayLike,
    *,
    method: Literal["cubic", "pchip"] = "cubic",
) -> NDArray[np.float64]:
    """Shaft speed [rad/s] at the instants ``time_s``: the time derivative of the angle of
    :func:`shaft_angle_from_pulses` (same interpolant; constant outside the pulse span)."""
    t, _, spline = _interpolant(pulse_times_s, pulses_per_rev, method)
    query = np.clip(np.asarray(time_s, dtype=float), t[0], t[-1])
    return spline(query, 1)
