"""Jump times of the mesh force law along a simulated run, for band-limited output sampling.

The force law is continuous in the state except where the mesh phase passes a breakpoint of
:func:`~gearbody.physics.mesh.mesh_breakpoint_phases` (tooth change, single/double contact switch,
pit edges) and where contact starts or ends (damping switches on with the deflection rate).
Both are located on the fine output grid by linear interpolation of smooth functions of time
(``u = z1 phi_p / 2 pi - p_break`` crossing an integer, ``d -+ l_u`` crossing zero).
"""

from __future__ import annotations

import math

import numpy as np

from ..analysis.antialias import level_crossings
from ..model.budget import OVERSAMPLING
from ..physics.mesh import I_LU, I_Z1, mesh_breakpoint_phases, mesh_gap_series

__all__ = ["OVERSAMPLING", "CubicHermite", "integer_crossings", "is_band_limited", "mesh_jump_times"]


BAND_LIMITED_SUFFIXES = (
    "_accel_rad_s2",
    "_accel_m_s2",
    "_bearing_force_x_N",
    "_bearing_force_y_N",
    "ring_sensor_N",
)
"""Signals replaced by their band-limited samples (accelerations, bearing, housing and ring-sensor
signals)."""


def integer_crossings(t_s: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Times where the smooth sampled ``u`` crosses an integer (at most one per interval), s."""
    n = np.floor(u)
    j = np.flatnonzero(n[1:] != n[:-1])
    level = np.maximum(n[j], n[j + 1])
    return t_s[j] + (t_s[j + 1] - t_s[j]) * (level - u[j]) / (u[j + 1] - u[j])


def mesh_jump_times(t_s: np.ndarray, pinion_angle_rad: np.ndarray, delta_m: np.ndarray, P: np.ndarray):
    """All times in the run where this mesh's force law jumps, s (sorted)."""
    u = pinion_angle_rad * P[I_Z1] / (2.0 * math.pi)
    times = [integer_crossings(t_s, u - b) for b in mesh_breakpoint_phases(P)]
    d = mesh_gap_series(np.ascontiguousarray(pinion_angle_rad), np.ascontiguousarray(delta_m), P)
    lu = P[I_LU]
    times += [level_crossings(t_s, d, lu), level_crossings(t_s, d, -lu)]
    return np.sort(np.concatenate(times))


def is_band_limited(name: str) -> bool:
    return name.endswith(BAND_LIMITED_SUFFIXES) or "_housing_accel_" in name


class CubicHermite:
    """Cubic Hermite interpolant of samples ``y`` (one row per signal) with slopes ``dydx`` at
    increasing times ``x``: the arithmetic of ``scipy.interpolate.CubicHermiteSpline(x, y, dydx,
    axis=1)`` operation for operation, so bitwise the same values (tests/test_engine.py compares), without
    importing scipy.interpolate (~0.45 s) on every run. Intervals are half-open ``[x_i, x_i+1)``, the last
    closed; outside, the end polynomials extrapolate."""

    def __init__(self, x: np.ndarray, y: np.ndarray, dydx: np.ndarray) -> None:
        x = np.asarray(x, float)
        y, dydx = np.asarray(y, float).T, np.asarray(dydx, float).T  # time first, like scipy
        dxr = np.diff(x).reshape(-1, *(1,) * (y.ndim - 1))
        slope = np.diff(y, axis=0) / dxr
        t = (dydx[:-1] + dydx[1:] - 2 * slope) / dxr
        self.x = x
        self.c = (t / dxr, (slope - dydx[:-1]) / dxr - t, dydx[:-1], y[:-1])

    def __call__(self, times: np.ndarray) -> np.ndarray:
        times = np.asarray(times, float)
        i = np.clip(np.searchsorted(self.x, times, side="right") - 1, 0, self.x.size - 2)
        s = (times - self.x[i]).reshape(-1, *(1,) * (self.c[0].ndim - 1))
        c0, c1, c2, c3 = (c[i] for c in self.c)
        # scipy's evaluate_poly1: res = 0; res += c[3-k] * s**k (powers by repeated products), k = 0..3
        s2 = s * s
        out = 0.0 + c3 + c2 * s + c1 * s2 + c0 * (s2 * s)
        return out.T
