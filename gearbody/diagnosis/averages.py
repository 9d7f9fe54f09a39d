"""Synchronous averages of every shaft from one order-tracked signal.

The channel is order-tracked once, on the input shaft's angle, with its anti-aliasing filter
(:func:`gearbody.analysis.orders.order_track`). The input shaft's average is that signal cut into whole
revolutions and averaged; another shaft turns at ``ratio`` times the input's angle, so its uniform angle
grid is a uniform grid of the input's angle too, read off the tracked signal by cubic-spline
interpolation (the tracked signal is oversampled: at least 2.5 points per period of its highest order).
"""

from __future__ import annotations

import numpy as np

from ..analysis import SynchronousAverage
from ..analysis.orders import OrderTrackedSignal
from ..errors import InputError

__all__ = ["shaft_average"]

_TWO_PI = 2.0 * np.pi


def _points_per_rev(samples_per_rev: int, ratio: float, teeth: int | None) -> int:
    """A power of two holding the tracked signal's resolution on this shaft, and >= 8 teeth."""
    need = max(samples_per_rev / ratio, 8 * (teeth or 1), 16)
    return int(2 ** np.ceil(np.log2(need)))


def shaft_average(tracked: OrderTrackedSignal, ratio: float, teeth: int | None) -> SynchronousAverage:
    """The synchronous average over the whole revolutions of a shaft turning at ``ratio`` (> 0) times the
    tracked shaft's angle, from ``tracked``; ``teeth``: of the gear on it."""
    if not ratio > 0:
        raise InputError(f"ratio = {ratio!r}: a shaft's speed over the tracked shaft's must be > 0")
    spr, step = tracked.samples_per_rev, tracked.step_rad
    values = tracked.values
    if ratio == 1.0:
        k_first = int(round(tracked.start_rad / step))
        i0 = (-k_first) % spr
        n_revs = (values.size - i0) // spr
        if n_revs < 1:
            raise InputError(f"the tracked signal holds {values.size / spr:.2f} revolutions: no whole one")
        average = values[i0 : i0 + n_revs * spr].reshape(n_revs, spr).mean(axis=0)
        return SynchronousAverage(np.arange(spr) * step, average, n_revs, teeth)
    from scipy.ndimage import map_coordinates, spline_filter1d

    points = _points_per_rev(spr, ratio, teeth)
    first = ratio * tracked.start_rad
    last = ratio * (tracked.start_rad + step * (values.size - 1))
    rev0 = int(np.ceil(first / _TWO_PI - 1e-9))
    n_revs = int(np.floor(last / _TWO_PI + 1e-9)) - rev0
    if n_revs < 1:
        raise InputError(f"the shaft turns {(last - first) / _TWO_PI:.2f} revolutions: no whole one")
    grid = np.arange(points) * (_TWO_PI / points)
    coefficients = spline_filter1d(values, order=3, mode="nearest")  # the cubic spline's, once
    total = np.zeros(points)
    for r in range(n_revs):  # one revolution at a time: memory bounded
        target = (_TWO_PI * (rev0 + r) + grid) / ratio  # the tracked shaft's angle there
        index = (target - tracked.start_rad) / step
        total += map_coordinates(coefficients, index[None, :], order=3, mode="nearest", prefilter=False)
    return SynchronousAverage(grid, total / n_revs, n_revs, teeth)
