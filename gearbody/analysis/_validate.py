"""Argument checks shared by the spectrum-labelling modules (ValueError naming the argument)."""

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
