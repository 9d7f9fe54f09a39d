"""Engine-free physics: mesh force law, error modes, motor characteristic, operating profiles."""

from . import _numba_cache  # noqa: F401  (first: drops stale compiled kernels before any is loaded)
from .error_mode import tooth_error_depths_m, tooth_random_factors
from .mesh import (
    contact_force,
    error_shape,
    friction_force,
    mean_stiffness_N_per_m,
    mesh_contact,
    mesh_contact_series,
    mesh_phase_series,
    pack_mesh_parameters,
    stiffness_at_phase,
    torsional_mesh_forces,
)
from .motor import (
    kloss_torque_Nm,
    load_fraction_at,
    load_torque_at,
    motor_torque_at,
    steady_slip,
    synchronous_angle_at,
    synchronous_speed_at,
    viscous_equivalent_Nms,
)
from .profiles import profile_arrays, profile_integral, profile_value

__all__ = [
    "contact_force",
    "error_shape",
    "friction_force",
    "kloss_torque_Nm",
    "load_fraction_at",
    "load_torque_at",
    "motor_torque_at",
    "synchronous_angle_at",
    "synchronous_speed_at",
    "mean_stiffness_N_per_m",
    "mesh_contact",
    "mesh_contact_series",
    "mesh_phase_series",
    "pack_mesh_parameters",
    "profile_arrays",
    "profile_integral",
    "profile_value",
    "steady_slip",
    "stiffness_at_phase",
    "tooth_error_depths_m",
    "tooth_random_factors",
    "torsional_mesh_forces",
    "viscous_equivalent_Nms",
]
