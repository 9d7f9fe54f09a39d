"""Initial states ("rest" | "steady") of the torsional models, literal from docs/scenario.md: the steady
start puts every mesh at its static force with the law's own stiffness and total error at the initial
angle (damaged teeth, table stiffness, faults included), shafts at their static torques and the speeds
on the Kloss stable branch passed on through the base radii.
"""

from __future__ import annotations

import numpy as np

from .law import effective_stiffness, total_error
from .scenario import (
    TWO_PI,
    design_shafts,
    profile_value,
    stage_F_rated,
    stage_view,
    steady_slip,
    topology,
    train_stages,
)


def initial_state(scenario: dict) -> tuple[np.ndarray, np.ndarray]:
    """Initial coordinates and velocities for initial_state "rest" | "steady" (coordinates: muller
    [x], two-wheel [pinion, wheel], train [motor, pinion_1, wheel_1, ..., machine])."""
    scene = topology(scenario)
    if scene == "train":
        return _train_initial_state(scenario)
    n_dof = {"muller": 1, "two-wheel": 2}[scene]
    kind = scenario["operation"]["initial_state"]
    q0 = np.zeros(n_dof)
    v0 = np.zeros(n_dof)
    if kind == "rest":
        return q0, v0
    if kind != "steady":
        raise ValueError(f"unknown initial_state {kind!r}")
    view = stage_view(scenario, 0)
    d_ = view["design"]
    r1, r2 = float(d_["pinion"]["base_radius_m"]), float(d_["wheel"]["base_radius_m"])
    mesh = d_["mesh"]
    lu = float(mesh["backlash_um"]) * 1e-6
    load0 = float(profile_value(0.0, scenario["operation"]["load_profile"]))
    M_L = float(d_["machine"]["rated_torque_Nm"]) * load0
    F0 = M_L / r2
    M_p = F0 * r1
    k0 = float(effective_stiffness(view, 0.0)[0])  # w > 0: factor blended with the outgoing pair
    E0 = float(total_error(view, 0.0))  # total error at p = 0, tooth 0 (fault errors included)
    delta0 = F0 / k0 + lu - E0 if F0 != 0.0 else 0.0
    if scene == "muller":
        q0[0] = delta0
        return q0, v0
    motor = d_["motor"]
    wsr = float(motor["synchronous_speed_rad_s"])
    ws0 = wsr * float(profile_value(0.0, scenario["operation"]["speed_profile"]))
    w = ws0 - steady_slip(M_p, motor) * wsr
    q0[:] = [0.0, -delta0 / r2]
    v0[:] = [w, w * r1 / r2]
    return q0, v0


def chain_speeds(scenario: dict, pinion_torque_1: float, r_p: list, r_w: list, v0: np.ndarray) -> None:
    """Steady speeds of a chain into v0[0 .. 2N+1]: the motor and pinion 1 on the Kloss stable branch at
    pinion 1's torque, each wheel its pinion's speed times r_p / r_w, each next pinion the previous
    wheel, the machine the last wheel (docs/scenario.md, "Gear trains", initial state "steady")."""
    N = len(r_p)
    motor = scenario["design"]["motor"]
    wsr = float(motor["synchronous_speed_rad_s"])
    ws0 = wsr * float(profile_value(0.0, scenario["operation"]["speed_profile"]))
    w = ws0 - steady_slip(pinion_torque_1, motor) * wsr
    v0[0] = w
    for s in range(N):
        v0[1 + 2 * s] = w
        w = w * r_p[s] / r_w[s]
        v0[2 + 2 * s] = w
    v0[2 * N + 1] = w


def _train_initial_state(scenario: dict) -> tuple[np.ndarray, np.ndarray]:
    """Initial state of a train (section "Gear trains" of docs/scenario.md), stage by stage."""
    stages = train_stages(scenario)
    N = len(stages)
    q0 = np.zeros(2 * N + 2)
    v0 = np.zeros(2 * N + 2)
    kind = scenario["operation"]["initial_state"]
    if kind == "rest":
        return q0, v0
    if kind != "steady":
        raise ValueError(f"unknown initial_state {kind!r}")
    d_ = scenario["design"]
    shaft_k = [float(sh["stiffness_Nm_per_rad"]) for sh in design_shafts(scenario)]
    load0 = float(profile_value(0.0, scenario["operation"]["load_profile"]))
    M_L = float(d_["machine"]["rated_torque_Nm"]) * load0
    r_p = [float(st["pinion"]["base_radius_m"]) for st in stages]
    r_w = [float(st["wheel"]["base_radius_m"]) for st in stages]
    z_p = [int(st["pinion"]["teeth"]) for st in stages]
    if N == 1:  # F = M_L / r_w: the operations of the former one-stage scene (same value to round-off)
        F = [M_L / r_w[0]]
    else:
        F = [load0 * Fr for Fr in stage_F_rated(scenario)]  # F_s = f F_rated,s
    pinion_torque = [F[s] * r_p[s] for s in range(N)]
    # speeds: motor = pinion 1 from the Kloss stable branch, wheel = pinion r_p / r_w, next pinion = wheel
    chain_speeds(scenario, pinion_torque[0], r_p, r_w, v0)
    # angles: pinion 1 = 0, then stage by stage in power-flow order
    pinion = 0.0
    for s in range(N):
        view = stage_view(scenario, s)
        mesh = view["design"]["mesh"]
        u = pinion * z_p[s] / TWO_PI
        k = float(effective_stiffness(view, u)[0])  # w > 0: factor blended near the tooth change
        E = float(total_error(view, u))  # fault errors included
        lu = float(mesh["backlash_um"]) * 1e-6
        if F[s] == 0.0:
            delta = 0.0
        elif k == 0.0:
            raise ValueError(f"steady start: stage {s} meshes with zero stiffness at its initial angle")
        else:
            delta = F[s] / k + lu - E
        q0[1 + 2 * s] = pinion
        wheel = (r_p[s] * pinion - delta) / r_w[s]
        q0[2 + 2 * s] = wheel
        if s + 1 < N:
            pinion = wheel - pinion_torque[s + 1] / shaft_k[s + 1]
    q0[0] = q0[1] + pinion_torque[0] / shaft_k[0]
    q0[2 * N + 1] = q0[2 * N] - M_L / shaft_k[N]
    return q0, v0
