"""A scenario's numbers packed for the compiled laws: one float64 array per mesh (the layout of
:func:`gearbody.physics.mesh.pack_mesh_parameters`) and one for motor, load and profiles."""

from __future__ import annotations

import math

import numpy as np

from ..model import Scenario
from ..physics.error_mode import tooth_error_depths_m
from ..physics.mesh import pack_mesh_parameters
from ..physics.mesh_stiffness import stage_pair_table


def mesh_parameters_from_scenario(scenario: Scenario, stage: int = 0, *, friction: bool = True) -> np.ndarray:
    """Packed mesh parameters of one stage (0-based) of a :class:`~gearbody.model.Scenario`."""
    st = scenario.stages[stage]
    mesh, em = st.mesh, st.error_mode
    z1, z2 = st.pinion.teeth, st.wheel.teeth
    f, g = np.ones(z1), np.ones(z2)
    for tooth in st.damaged_teeth:
        (f if tooth.gear == "pinion" else g)[tooth.tooth] *= tooth.stiffness_factor
    table = mesh.stiffness_profile == "table"
    pair_table = None
    if mesh.stiffness_profile == "potential-energy":
        pair_table = stage_pair_table(st)
    runout, runout_phase = [0.0, 0.0], [0.0, 0.0]
    for ecc in st.eccentricity:
        k = 0 if ecc.gear == "pinion" else 1
        runout[k], runout_phase[k] = ecc.amplitude_um * 1e-6, math.radians(ecc.phase_deg)
    pits = {"pinion": np.zeros((z1, 3)), "wheel": np.zeros((z2, 3))}
    for pit in st.pitted_teeth:
        pits[pit.gear][pit.tooth] = (pit.depth_um * 1e-6, pit.start_phase, pit.end_phase)
    return pack_mesh_parameters(
        r1_m=st.pinion.base_radius_m,
        r2_m=st.wheel.base_radius_m,
        z1=z1,
        z2=z2,
        stiffness_single_N_per_m=mesh.stiffness_single_N_per_m,
        stiffness_double_N_per_m=mesh.stiffness_double_N_per_m,
        contact_ratio=mesh.contact_ratio,
        damping_Ns_per_m=mesh.damping_Ns_per_m,
        backlash_m=mesh.backlash_um * 1e-6,
        friction_coefficient=scenario.condition.friction_coefficient if friction else 0.0,
        pitch_point_phase=mesh.pitch_point_phase,
        pressure_angle_rad=math.radians(mesh.pressure_angle_deg),
        error_a=em.a,
        error_depths_m=tooth_error_depths_m(em.e_um, em.r, z1, scenario.meta.seed, stage),
        pinion_factors=f,
        wheel_factors=g,
        table_phase=np.array(mesh.table_phase) if table else None,
        table_stiffness_N_per_m=np.array(mesh.table_stiffness_N_per_m) if table else None,
        runout_m=(runout[0], runout[1]),
        runout_phase_rad=(runout_phase[0], runout_phase[1]),
        pinion_pits=pits["pinion"],
        wheel_pits=pits["wheel"],
        transition_width=mesh.transition_width,
        pair_stiffness_N_per_m=None if pair_table is None else pair_table.stiffness_N_per_m,
        pair_ratios=None if pair_table is None else pair_table.ratios,
        friction_transition_speed_m_s=scenario.condition.friction_transition_speed_m_s,
    )


def pack_drive_parameters(scenario: Scenario) -> np.ndarray:
    """Motor and load parameters with the speed and load profiles, as one float64 array."""
    m, op = scenario.design.motor, scenario.operation
    st, sf = np.asarray(op.speed_profile.time_s, float), np.asarray(op.speed_profile.fraction, float)
    lt, lf = np.asarray(op.load_profile.time_s, float), np.asarray(op.load_profile.fraction, float)
    head = np.array(
        [
            m.synchronous_speed_rad_s,
            m.breakdown_torque_Nm,
            m.breakdown_slip,
            scenario.design.machine.rated_torque_Nm,
            st.size,
            lt.size,
        ]
    )
    return np.concatenate([head, st, sf, lt, lf])
