"""Engine-free assembly: a scenario turned into solver inputs — the topology (inertias, shafts, meshes),
packed parameters for the compiled laws, the steady operating point and initial state, and the checks
that the drive can run at all (input errors, exit code 2). The Exudyn engine and the modal model both
build from this; nothing here imports Exudyn."""

from .operating_point import (
    initial_state,
    mesh_frequency_hz,
    static_deflection_m,
    static_lateral_displacements_m,
    steady_operating_point,
)
from .parameters import mesh_parameters_from_scenario, pack_drive_parameters
from .stiff_modes import check_resolved_modes, coordinate_frequencies
from .topology import (
    Inertia,
    LateralSupport,
    MeshLink,
    ShaftLink,
    TorsionalLayout,
    gear_names,
    reduced_mass_kg,
    torsional_layout,
)

__all__ = [
    "Inertia",
    "LateralSupport",
    "MeshLink",
    "ShaftLink",
    "TorsionalLayout",
    "check_resolved_modes",
    "coordinate_frequencies",
    "gear_names",
    "initial_state",
    "mesh_frequency_hz",
    "mesh_parameters_from_scenario",
    "pack_drive_parameters",
    "reduced_mass_kg",
    "static_deflection_m",
    "static_lateral_displacements_m",
    "steady_operating_point",
    "torsional_layout",
]
