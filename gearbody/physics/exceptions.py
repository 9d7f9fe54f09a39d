"""Errors of the physics layer (engine-free: of the rest of gearbody it imports only :mod:`gearbody.errors`,
which imports nothing).

Each is an :class:`~gearbody.errors.InputError` (so also a ``ValueError``): a user calling physics
directly meets a gearbody error (exit 2). The model layer turns them into
:class:`~gearbody.errors.ScenarioError` where it calls physics (``gearbody.model.resolve``), with the
scenario key in front of the same message.
"""

from __future__ import annotations

from ..errors import InputError


class GearGeometryError(InputError):
    """Impossible or unsound gear-pair geometry; the message names parameter, value and allowed range."""


def geometry_error(name: str, value, reason: str, allowed: str) -> GearGeometryError:
    """``GearGeometryError("name = value: reason; allowed: allowed")`` (floats shown to 6 digits)."""
    shown = f"{value:.6g}" if isinstance(value, float) else repr(value)
    return GearGeometryError(f"{name} = {shown}: {reason}; allowed: {allowed}")
