"""Topology of a torsional system, as read from a scenario: inertias, shafts, meshes, drive and load.

This is the one place where a scene becomes bodies and connectors; the Exudyn builder then creates
exactly what it lists. It imports no Exudyn, so it also serves the linearised modal model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..model import Scenario
from ..physics import mesh_parameters_from_scenario, pack_drive_parameters, steady_slip
from ..physics.mesh import stiffness_at_phase, tooth_pair_factor


@dataclass(frozen=True)
class Inertia:
    name: str
    inertia_kg_m2: float


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


def torsional_layout(scenario: Scenario) -> TorsionalLayout:
    """Layout of the ``one-stage`` (Fig. 3) and ``two-wheel`` (Fig. 2) scenes."""
    d = scenario.design
    P = mesh_parameters_from_scenario(scenario)
    drive = pack_drive_parameters(scenario)
    r1, r2 = d.pinion.base_radius_m, d.wheel.base_radius_m
    if scenario.meta.scene == "one-stage":
        inertias = (
            Inertia("motor", d.motor.inertia_kg_m2),
            Inertia("pinion", d.pinion.inertia_kg_m2),
            Inertia("wheel", d.wheel.inertia_kg_m2),
            Inertia("machine", d.machine.inertia_kg_m2),
        )
        shafts = (
            ShaftLink(0, 1, d.coupling.stiffness_Nm_per_rad, d.coupling.damping_Nms_per_rad),
            ShaftLink(2, 3, d.output_shaft.stiffness_Nm_per_rad, d.output_shaft.damping_Nms_per_rad),
        )
        return TorsionalLayout(
            inertias, shafts, (MeshLink(1, 2, r1, r2, P),), motor_at=0, load_at=3, drive=drive
        )
    if scenario.meta.scene == "two-wheel":
        inertias = (
            Inertia("pinion", d.motor.inertia_kg_m2 + d.pinion.inertia_kg_m2),
            Inertia("wheel", d.wheel.inertia_kg_m2 + d.machine.inertia_kg_m2),
        )
        return TorsionalLayout(inertias, (), (MeshLink(0, 1, r1, r2, P),), motor_at=0, load_at=1, drive=drive)
    raise ValueError(f"scene {scenario.meta.scene!r} has no torsional layout")


def reduced_mass_kg(scenario: Scenario) -> float:
    """Muller's reduced mass along the line of action, m = 1 / (r1^2/I_1p + r2^2/I_2p)."""
    d = scenario.design
    return 1.0 / (
        d.pinion.base_radius_m**2 / d.pinion.inertia_kg_m2 + d.wheel.base_radius_m**2 / d.wheel.inertia_kg_m2
    )


def steady_operating_point(scenario: Scenario) -> dict[str, float]:
    """Steady running at t = 0 (friction and error ignored): speeds, mesh force and deflection.

    Raises a ValueError when the motor cannot carry the initial load.
    """
    d, op = scenario.design, scenario.operation
    load = d.machine.rated_torque_Nm * np.interp(0.0, op.load_profile.time_s, op.load_profile.fraction)
    r1, r2 = d.pinion.base_radius_m, d.wheel.base_radius_m
    F0 = load / r2
    pinion_torque = F0 * r1
    s = steady_slip(pinion_torque, d.motor.breakdown_torque_Nm, d.motor.breakdown_slip)
    ws0 = d.motor.synchronous_speed_rad_s * np.interp(0.0, op.speed_profile.time_s, op.speed_profile.fraction)
    w = ws0 - s * d.motor.synchronous_speed_rad_s
    # stiffness in mesh at p = 0: pinion tooth 0 against wheel tooth 0
    P = mesh_parameters_from_scenario(scenario)
    k0 = stiffness_at_phase(0.0, P) * tooth_pair_factor(0, 0, P)
    if F0 > 0 and k0 <= 0:
        raise ValueError("the teeth in mesh at the start carry no load (stiffness factor 0): start from rest")
    delta0 = F0 / k0 + d.mesh.backlash_um * 1e-6 if F0 > 0 else 0.0
    return {
        "load_torque_Nm": load,
        "mesh_force_N": F0,
        "pinion_torque_Nm": pinion_torque,
        "pinion_speed_rad_s": w,
        "wheel_speed_rad_s": w * r1 / r2,
        "deflection_m": delta0,
    }


def initial_state(scenario: Scenario) -> tuple[np.ndarray, np.ndarray]:
    """Initial coordinates and velocities of the scene's DOFs (docs/scenario.md, 'Initial state')."""
    scene = scenario.meta.scene
    ndof = {"muller": 1, "two-wheel": 2, "one-stage": 4}[scene]
    if scenario.operation.initial_state == "rest":
        return np.zeros(ndof), np.zeros(ndof)
    op = steady_operating_point(scenario)
    r2, w_p, w_w, delta0 = (
        scenario.design.wheel.base_radius_m,
        op["pinion_speed_rad_s"],
        op["wheel_speed_rad_s"],
        op["deflection_m"],
    )
    if scene == "muller":
        return np.array([delta0]), np.zeros(1)
    if scene == "two-wheel":
        return np.array([0.0, -delta0 / r2]), np.array([w_p, w_w])
    d = scenario.design
    phi3 = -delta0 / r2
    q = np.array(
        [
            op["pinion_torque_Nm"] / d.coupling.stiffness_Nm_per_rad,
            0.0,
            phi3,
            phi3 - op["load_torque_Nm"] / d.output_shaft.stiffness_Nm_per_rad,
        ]
    )
    return q, np.array([w_p, w_p, w_w, w_w])


def mesh_frequency_hz(scenario: Scenario, pinion_speed_rad_s: float) -> float:
    """Mesh frequency f_z = z1 w / (2 pi)."""
    return scenario.design.pinion.teeth * pinion_speed_rad_s / (2 * math.pi)
