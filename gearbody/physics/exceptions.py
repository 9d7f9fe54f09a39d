"""Errors of the physics layer (engine-free, imports nothing from the rest of gearbody).

The model layer turns them into :class:`~gearbody.model.params.ScenarioError` where it calls physics
(``gearbody.model.resolve``), with the same message, so users still see an input error (exit 2).
"""

from __future__ import annotations


class GearGeometryError(ValueError):
    """Impossible or unsound gear-pair geometry; the message names parameter, value and allowed range."""


def geometry_error(name: str, value, reason: str, allowed: str) -> GearGeometryError:
    """``GearGeometryError("name = value: reason; allowed: allowed")`` (floats shown to 6 digits)."""
    shown = f"{value:.6g}" if isinstance(value, float) else repr(value)
    return GearGeometryError(f"{name} = {shown}: {reason}; allowed: {allowed}")
