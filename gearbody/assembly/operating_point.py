"""The state a run starts from: steady operating point stage by stage (speeds, mesh forces), static mesh
deflections and bearing displacements, and the initial coordinates and velocities (docs/scenario.md,
"Initial state"). Whether the drive can run at all is checked here: the motor must carry the initial
load (an input error, exit code 2).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from ..model import Scenario
from ..model.kinds import register_stage_kind, stage_kind
from ..physics.lateral import mesh_directions, static_bearing_displacement_m
from ..physics.mesh import effective_stiffness_series, pair_in_mesh
from ..physics.motor import steady_slip
from ..signals import stage_prefix
from .parameters import mesh_parameters_from_scenario
from .topology import gear_names


def static_lateral_displacements_m(
    scenario: Scenario, load_fraction: float | None = None
) -> dict[str, np.ndarray]:
    """Centre displacement (x, y) of every lateral gear at static equilibrium (friction ignored).

    Default: the initial state (0 from rest; under the steady mesh forces for 'steady'). With
    ``load_fraction``: under that fraction of the rated mesh forces (modes use 1.0).
    """
    out: dict[str, np.ndarray] = {}
    forces = None
    if load_fraction is not None:
        forces = [load_fraction * scenario.stage_rated_force_N(k) for k in range(len(scenario.stages))]
    elif scenario.operation.initial_state == "steady":
        forces = steady_operating_point(scenario)["mesh_force_N"]
    for k, st in enumerate(scenario.stages):
        n, _, _ = mesh_directions(st.mesh.centre_line_deg, st.mesh.line_of_action_deg)
        for name, gear, sign in zip(gear_names(k), (st.pinion, st.wheel), (-1.0, 1.0), strict=True):
            if gear.lateral == "none":
                continue
            if forces is None:
                out[name] = np.zeros(2)
            else:
                try:
                    out[name] = static_bearing_displacement_m(
                        gear.bearing.law(), sign * forces[k] * n, gear.free_directions
                    )
                except ValueError as exc:  # the bearing law cannot carry the mesh force
                    raise InputError(f"cannot set the initial bearing displacements: {exc}") from None
    return out


def steady_operating_point(scenario: Scenario) -> dict[str, object]:
    """Steady running at t = 0 (friction ignored), stage by stage: speeds, mesh forces, deflections.

    Returns per-stage lists ``mesh_force_N``, ``pinion_torque_Nm``, ``pinion_speed_rad_s``,
    ``wheel_speed_rad_s``, plus ``load_torque_Nm``. Raises InputError when the motor cannot carry the
    initial load.
    """
    d, op = scenario.design, scenario.operation
    stages = scenario.stages
    load = d.machine.rated_torque_Nm * np.interp(0.0, op.load_profile.time_s, op.load_profile.fraction)
    fraction = load / d.machine.rated_torque_Nm
    forces = [fraction * scenario.stage_rated_force_N(k) for k in range(len(stages))]
    pinion_torques = [f * st.input_arm_m for f, st in zip(forces, stages, strict=True)]  # planetary: r_eq
    try:
        s = steady_slip(pinion_torques[0], d.motor.breakdown_torque_Nm, d.motor.breakdown_slip)
    except ValueError as exc:  # the physics' own refusal: load above the breakdown torque
        raise InputError(f"operation.initial_state = 'steady': {exc}") from None
    ws0 = d.motor.synchronous_speed_rad_s * np.interp(0.0, op.speed_profile.time_s, op.speed_profile.fraction)
    w = ws0 - s * d.motor.synchronous_speed_rad_s
    pinion_speeds, wheel_speeds = [], []
    for st in stages:
        pinion_speeds.append(w)
        w = w * st.input_arm_m / st.output_arm_m  # r_p w_p = r_w w_w: no deflection rate
        wheel_speeds.append(w)
    return {
        "load_torque_Nm": load,
        "mesh_force_N": forces,
        "pinion_torque_Nm": pinion_torques,
        "pinion_speed_rad_s": pinion_speeds,
        "wheel_speed_rad_s": wheel_speeds,
    }


def static_deflection_m(scenario: Scenario, stage: int, pinion_angle_rad: float, force_N: float) -> float:
    """Mesh deflection carrying ``force_N`` at the teeth and phase in mesh at ``pinion_angle_rad``:
    delta = F / k + l_u - E (0 without load)."""
    if force_N == 0.0:
        return 0.0
    P = mesh_parameters_from_scenario(scenario, stage)
    _, _, error_m = pair_in_mesh(pinion_angle_rad, P)
    k = float(effective_stiffness_series(np.array([pinion_angle_rad]), P)[0])  # the law's k, damage included
    if k <= 0:
        raise InputError(
            f"operation.initial_state = 'steady': stage {stage + 1}: the teeth in mesh at the start carry no "
            "load (stiffness factor 0): start from rest"
        )
    st = scenario.stages[stage]
    return force_N / k + st.mesh.backlash_um * 1e-6 - error_m


def initial_state(scenario: Scenario) -> tuple[np.ndarray, np.ndarray]:
    """Initial coordinates and velocities of the scene's DOFs (docs/scenario.md, 'Initial state')."""
    topology = scenario.meta.topology
    ndof = {"muller": 1, "two-wheel": 2}.get(topology, 2 * len(scenario.stages) + 2)
    if scenario.operation.initial_state == "rest":
        return np.zeros(ndof), np.zeros(ndof)
    op = steady_operating_point(scenario)
    forces = op["mesh_force_N"]
    st0 = scenario.stages[0]
    if topology == "muller":
        return np.array([static_deflection_m(scenario, 0, 0.0, forces[0])]), np.zeros(1)
    if topology == "two-wheel":
        delta0 = static_deflection_m(scenario, 0, 0.0, forces[0])
        return (
            np.array([0.0, -delta0 / st0.wheel.base_radius_m]),
            np.array([op["pinion_speed_rad_s"][0], op["wheel_speed_rad_s"][0]]),
        )
    shafts = scenario.design.shafts
    lateral = static_lateral_displacements_m(scenario)
    q, v = [], []
    pinion = 0.0
    for k, st in enumerate(scenario.stages):
        delta = static_deflection_m(scenario, k, pinion, forces[k])
        pname, wname = gear_names(k)
        n, _, _ = mesh_directions(st.mesh.centre_line_deg, st.mesh.line_of_action_deg)
        centres = (lateral.get(pname, np.zeros(2)) - lateral.get(wname, np.zeros(2))) @ n
        wheel = (st.pinion.base_radius_m * pinion - delta + centres) / st.wheel.base_radius_m
        q += [pinion, wheel]
        v += [op["pinion_speed_rad_s"][k], op["wheel_speed_rad_s"][k]]
        if k + 1 < len(scenario.stages):
            pinion = wheel - op["pinion_torque_Nm"][k + 1] / shafts[k + 1].stiffness_Nm_per_rad
    motor = op["pinion_torque_Nm"][0] / shafts[0].stiffness_Nm_per_rad
    machine = q[-1] - op["load_torque_Nm"] / shafts[-1].stiffness_Nm_per_rad
    return np.array([motor, *q, machine]), np.array([v[0], *v, v[-1]])


def mesh_frequency_hz(scenario: Scenario, pinion_speed_rad_s: float) -> float:
    """Mesh frequency f_z = z1 w / (2 pi)."""
    return scenario.stages[0].pinion.teeth * pinion_speed_rad_s / (2 * math.pi)


def nominal_speeds_rad_s(scenario: Scenario) -> dict[str, float]:
    """Each rotation coordinate's speed when the motor turns at its synchronous speed and nothing
    deflects (rad/s, in the coordinate's own sense): positive for the motor, the gears of parallel stages
    and the machine (their driven directions); a planetary member's absolute counter-clockwise speed from
    Willis's relation (its sign says which way that member is driven; a fixed member's is 0).
    Muller's model has no rotation coordinates."""
    if scenario.meta.topology == "muller":
        return {}
    w = scenario.design.motor.synchronous_speed_rad_s
    out = {"motor": w} if scenario.meta.topology == "train" else {}
    for k, st in enumerate(scenario.stages):
        hook = stage_kind(st).nominal_speeds
        out.update(hook(st, k, w) if hook is not None else {})
        w = w * st.input_arm_m / st.output_arm_m
    if scenario.meta.topology == "train":
        out["machine"] = w
    return out


def _parallel_speeds(st, k: int, w: float) -> dict[str, float]:
    pname, wname = gear_names(k)
    return {pname: w, wname: w * st.input_arm_m / st.output_arm_m}


def _planetary_speeds(st, k: int, w: float) -> dict[str, float]:
    prefix = stage_prefix(k)
    willis = st.speeds(w)
    out = {prefix + member: st.input_sense * willis.of(member) for member in ("sun", "ring", "carrier")}
    for n in range(st.planets):
        out[f"{prefix}planet_{n + 1}"] = st.input_sense * willis.planet_rad_s
    return out


register_stage_kind("parallel", nominal_speeds=_parallel_speeds)
register_stage_kind("planetary", nominal_speeds=_planetary_speeds)
