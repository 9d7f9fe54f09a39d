"""Topology of a drive, as read from a scenario: inertias (gears optionally on lateral bearings), shafts,
meshes, drive and load.

This is the one place where a scene becomes bodies and connectors; the Exudyn builder then creates
exactly what it lists. It imports no Exudyn, so it also serves the linearised modal model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..model import Scenario
from ..physics import mesh_parameters_from_scenario, pack_drive_parameters, steady_slip
from ..physics.lateral import mesh_directions, static_bearing_displacement_m
from ..physics.mesh import effective_stiffness_series, pair_in_mesh


@dataclass(frozen=True)
class LateralSupport:
    """A gear centre that translates on a bearing: free directions (0 = x, 1 = y), mass, bearing law."""

    free_directions: tuple[int, ...]
    mass_kg: float
    bearing: object = field(repr=False)  # a gearbody.physics.bearings law (force_N method)
    bearing_kind: str = "linear"
    housing_mass_kg: float = 50.0


@dataclass(frozen=True)
class Inertia:
    name: str
    inertia_kg_m2: float
    lateral: LateralSupport | None = None


@dataclass(frozen=True)
class ShaftLink:
    """Torsional spring-damper M = k (phi_i - phi_j) + C (phi_i' - phi_j')."""

    i: int
    j: int
    stiffness_Nm_per_rad: float
    damping_Nms_per_rad: float = 0.0


@dataclass(frozen=True)
class MeshLink:
    """Gear mesh between pinion inertia i and wheel inertia j, with packed mesh parameters."""

    pinion: int
    wheel: int
    r_pinion_m: float
    r_wheel_m: float
    parameters: np.ndarray = field(repr=False)
    line_of_action: tuple[float, float] = (0.0, -1.0)  # n: direction of the force on the wheel
    friction_direction: tuple[float, float] = (-1.0, 0.0)  # m: friction force on the pinion is +T m


@dataclass(frozen=True)
class TorsionalLayout:
    inertias: tuple[Inertia, ...]
    shafts: tuple[ShaftLink, ...] = ()
    meshes: tuple[MeshLink, ...] = ()
    motor_at: int | None = None
    load_at: int | None = None
    drive: np.ndarray | None = field(default=None, repr=False)

    @property
    def names(self) -> list[str]:
        return [b.name for b in self.inertias]

    @property
    def is_lateral(self) -> bool:
        return any(b.lateral is not None for b in self.inertias)


def gear_names(stage: int) -> tuple[str, str]:
    """Names of a stage's gears: ``pinion``/``wheel`` for the first, ``pinion_2``/``wheel_2``... after."""
    return ("pinion", "wheel") if stage == 0 else (f"pinion_{stage + 1}", f"wheel_{stage + 1}")


def chain_shafts(scenario: Scenario) -> tuple:
    """Shafts in chain order: motor -> stage 1, ..., last stage -> machine."""
    d = scenario.design
    return d.shafts if scenario.meta.scene == "train" else (d.coupling, d.output_shaft)


def torsional_layout(scenario: Scenario) -> TorsionalLayout:
    """Layout of the torsional scenes: ``two-wheel`` (Fig. 2), ``one-stage`` (Fig. 3) and any ``train``
    (Fig. 19 for two stages): motor, then each stage's pinion and wheel, then the machine."""
    d = scenario.design
    drive = pack_drive_parameters(scenario)
    stages = scenario.stages
    params = [mesh_parameters_from_scenario(scenario, k) for k in range(len(stages))]
    if scenario.meta.scene == "two-wheel":
        st = stages[0]
        inertias = (
            Inertia("pinion", d.motor.inertia_kg_m2 + st.pinion.inertia_kg_m2),
            Inertia("wheel", st.wheel.inertia_kg_m2 + d.machine.inertia_kg_m2),
        )
        mesh = MeshLink(0, 1, st.pinion.base_radius_m, st.wheel.base_radius_m, params[0])
        return TorsionalLayout(inertias, (), (mesh,), motor_at=0, load_at=1, drive=drive)
    if scenario.meta.scene not in ("one-stage", "train"):
        raise ValueError(f"scene {scenario.meta.scene!r} has no torsional layout")
    inertias = [Inertia("motor", d.motor.inertia_kg_m2)]
    meshes = []
    for k, st in enumerate(stages):
        pname, wname = gear_names(k)
        inertias += [
            Inertia(pname, st.pinion.inertia_kg_m2, _support(st.pinion)),
            Inertia(wname, st.wheel.inertia_kg_m2, _support(st.wheel)),
        ]
        n, m, _ = mesh_directions(st.mesh.centre_line_deg, st.mesh.line_of_action_deg)
        meshes.append(
            MeshLink(
                2 * k + 1,
                2 * k + 2,
                st.pinion.base_radius_m,
                st.wheel.base_radius_m,
                params[k],
                (float(n[0]), float(n[1])),
                (float(m[0]), float(m[1])),
            )
        )
    inertias.append(Inertia("machine", d.machine.inertia_kg_m2))
    shafts = tuple(
        ShaftLink(2 * k, 2 * k + 1, sh.stiffness_Nm_per_rad, sh.damping_Nms_per_rad)
        for k, sh in enumerate(chain_shafts(scenario))
    )
    return TorsionalLayout(
        tuple(inertias), shafts, tuple(meshes), motor_at=0, load_at=len(inertias) - 1, drive=drive
    )


def _support(gear) -> LateralSupport | None:
    if gear.lateral == "none":
        return None
    return LateralSupport(
        gear.free_directions,
        gear.mass_kg,
        gear.bearing.law(),
        gear.bearing.kind,
        gear.bearing.housing_mass_kg,
    )


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
                out[name] = static_bearing_displacement_m(
                    gear.bearing.law(), sign * forces[k] * n, gear.free_directions
                )
    return out


def reduced_mass_kg(scenario: Scenario) -> float:
    """Muller's reduced mass along the line of action, m = 1 / (r1^2/I_1p + r2^2/I_2p)."""
    d = scenario.design
    return 1.0 / (
        d.pinion.base_radius_m**2 / d.pinion.inertia_kg_m2 + d.wheel.base_radius_m**2 / d.wheel.inertia_kg_m2
    )


def steady_operating_point(scenario: Scenario) -> dict[str, object]:
    """Steady running at t = 0 (friction ignored), stage by stage: speeds, mesh forces, deflections.

    Returns per-stage lists ``mesh_force_N``, ``pinion_torque_Nm``, ``pinion_speed_rad_s``,
    ``wheel_speed_rad_s``, plus ``load_torque_Nm``. Raises ValueError when the motor cannot carry the
    initial load.
    """
    d, op = scenario.design, scenario.operation
    stages = scenario.stages
    load = d.machine.rated_torque_Nm * np.interp(0.0, op.load_profile.time_s, op.load_profile.fraction)
    fraction = load / d.machine.rated_torque_Nm
    forces = [fraction * scenario.stage_rated_force_N(k) for k in range(len(stages))]
    pinion_torques = [f * st.pinion.base_radius_m for f, st in zip(forces, stages, strict=True)]
    s = steady_slip(pinion_torques[0], d.motor.breakdown_torque_Nm, d.motor.breakdown_slip)
    ws0 = d.motor.synchronous_speed_rad_s * np.interp(0.0, op.speed_profile.time_s, op.speed_profile.fraction)
    w = ws0 - s * d.motor.synchronous_speed_rad_s
    pinion_speeds, wheel_speeds = [], []
    for st in stages:
        pinion_speeds.append(w)
        w = w * st.pinion.base_radius_m / st.wheel.base_radius_m  # r_p w_p = r_w w_w: no deflection rate
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
        raise ValueError(
            f"stage {stage + 1}: the teeth in mesh at the start carry no load (stiffness factor 0): "
            "start from rest"
        )
    st = scenario.stages[stage]
    return force_N / k + st.mesh.backlash_um * 1e-6 - error_m


def initial_state(scenario: Scenario) -> tuple[np.ndarray, np.ndarray]:
    """Initial coordinates and velocities of the scene's DOFs (docs/scenario.md, 'Initial state')."""
    scene = scenario.meta.scene
    ndof = {"muller": 1, "two-wheel": 2}.get(scene, 2 * len(scenario.stages) + 2)
    if scenario.operation.initial_state == "rest":
        return np.zeros(ndof), np.zeros(ndof)
    op = steady_operating_point(scenario)
    forces = op["mesh_force_N"]
    st0 = scenario.stages[0]
    if scene == "muller":
        return np.array([static_deflection_m(scenario, 0, 0.0, forces[0])]), np.zeros(1)
    if scene == "two-wheel":
        delta0 = static_deflection_m(scenario, 0, 0.0, forces[0])
        return (
            np.array([0.0, -delta0 / st0.wheel.base_radius_m]),
            np.array([op["pinion_speed_rad_s"][0], op["wheel_speed_rad_s"][0]]),
        )
    shafts = chain_shafts(scenario)
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
