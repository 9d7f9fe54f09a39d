"""One coordinate's own rate from the diagonals of a drive's matrices (:class:`CoordinateFrequency`:
sqrt(K_ii / M_ii) and C_ii / (2 M_ii)), and the bookkeeping of K_ii and C_ii by the scenario key that
contributes them, shared by the parallel and the compound drive's estimates
(:mod:`gearbody.assembly.stiff_modes`, :mod:`gearbody.assembly.stiff_modes_compound`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["CoordinateFrequency", "add", "largest"]


@dataclass(frozen=True)
class CoordinateFrequency:
    """sqrt(K_ii / M_ii) / 2 pi of one coordinate, its damping C_ii, and the scenario key of its mass."""

    name: str
    frequency_hz: float
    key: str
    mass: float  # kg m^2 (rotation) or kg (translation)
    stiffness: float  # N m / rad or N / m
    damping: float = 0.0  # N m s / rad or N s / m
    damping_source: str = ""  # what contributes most of C_ii, for the message
    stiffness_source: str = ""  # what contributes most of K_ii, for the message

    @property
    def damping_rate_hz(self) -> float:
        """C_ii / (2 M_ii) / 2 pi: the coordinate's decay rate when overdamped, Hz."""
        return self.damping / (2.0 * self.mass) / (2 * math.pi)

    @property
    def rate_hz(self) -> float:
        """max(natural frequency, damping rate), Hz: the coordinate's own largest |root| / 2 pi is at
        least this."""
        return max(self.frequency_hz, self.damping_rate_hz)


def add(to: dict[str, float], key: str, value: float) -> None:
    """Add ``value`` to what ``key`` contributes to a diagonal entry."""
    to[key] = to.get(key, 0.0) + value


def largest(by_key: dict[str, float]) -> str:
    """The key contributing most (empty when nothing contributes)."""
    return max(by_key, key=by_key.get) if sum(by_key.values()) > 0 else ""
