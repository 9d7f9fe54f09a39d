"""Argument checks shared by the analysis modules (InputError, a ValueError, naming the argument)."""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError


def is_real(value: object) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)


def positive_frequency(name: str, value: float) -> float:
    if not (is_real(value) and math.isfinite(value) and value > 0):
        raise InputError(f"{name} must be a positive frequency [Hz], got {value!r}")
    return float(value)


def integer_at_least(name: str, value: int, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise InputError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def finite_1d(name: str, values: object, min_size: int = 2) -> np.ndarray:
    """``values`` as a 1-D float64 array of at least ``min_size`` finite values."""
    array = np.asarray(values, dtype=float)
    if array.ndim != 1:
        raise InputError(f"{name} must be 1-D, got shape {array.shape}")
    if array.size < min_size:
        raise InputError(f"{name} must hold at least {min_size} values, got {array.size}")
    if not np.all(np.isfinite(array)):
        first = int(np.flatnonzero(~np.isfinite(array))[0])
        raise InputError(f"{name} must be finite, sample {first} is {array[first]!r}")
    return array


def strictly_increasing_angle(angle: np.ndarray) -> None:
    """InputError naming the first sample where the unwrapped shaft angle does not increase."""
    step = np.diff(angle)
    if np.any(step <= 0.0):
        i = int(np.flatnonzero(step <= 0.0)[0])
        raise InputError(
            "shaft_angle_rad must be strictly increasing (unwrapped, rotation in the positive sense): "
            f"sample {i + 1} is {angle[i + 1]!r} rad after {angle[i]!r} rad at sample {i}"
        )
