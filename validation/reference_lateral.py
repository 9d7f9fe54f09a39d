"""Independent reference model for the lateral gear models: the public names of
:mod:`.reference.lateral` (which see), kept at this import path (``validation.reference_lateral``)."""

from __future__ import annotations

from .reference.lateral import initial_state_lateral, simulate_reference_lateral
from .reference.lateral_model import _ETA_F, _ETA_R, _Gear, _LatTrain
from .reference.lateral_scenario import (
    _AXES,
    _MESH_DEFAULTS,
    as_train,
    bearing_force,
    gear_names,
    mesh_geometry,
    resolve_lateral_defaults,
    static_displacement,
)

__all__ = [
    "simulate_reference_lateral",
    "resolve_lateral_defaults",
    "as_train",
    "gear_names",
    "mesh_geometry",
    "bearing_force",
    "static_displacement",
    "initial_state_lateral",
]
