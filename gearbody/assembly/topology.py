"""Topology of a drive, as read from a scenario: inertias (gears optionally on lateral bearings), shafts,
meshes, drive and load.

This is the one place where a scenario becomes bodies and connectors; the Exudyn builder then creates
exactly what it lists. It imports no Exudyn, so it also serves the linearised modal model.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model import Scenario
from ..physics.lateral import mesh_directions
from ..signals import gear_names
from .parameters import mesh_parameters_from_scenario, pack_drive_parameters


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


def torsional_layout(scenario: Scenario) -> TorsionalLayout:
    """Layout of the torsional topologies: ``two-wheel`` (Fig. 2) and any ``train`` (Fig. 3 for one
    stage, Fig. 19 for two): motor, then each stage's pinion and wheel, then the machine."""
    d = scenario.design
    drive = pack_drive_parameters(scenario)
    stages = scenario.stages
    params = [mesh_parameters_from_scenario(scenario, k) for k in range(len(stages))]
    if scenario.meta.topology == "two-wheel":
        st = stages[0]
        inertias = (
            Inertia("pinion", d.motor.inertia_kg_m2 + st.pinion.inertia_kg_m2),
            Inertia("wheel", st.wheel.inertia_kg_m2 + d.machine.inertia_kg_m2),
        )
        mesh = MeshLink(0, 1, st.pinion.base_radius_m, st.wheel.base_radius_m, params[0])
        return TorsionalLayout(inertias, (), (mesh,), motor_at=0, load_at=1, drive=drive)
    if scenario.meta.topology != "train":
        raise ValueError(f"topology {scenario.meta.topology!r} has no torsional layout")
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
        for k, sh in enumerate(d.shafts)
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


def reduced_mass_kg(scenario: Scenario) -> float:
    """Muller's reduced mass along the line of action, m = 1 / (r1^2/I_1p + r2^2/I_2p)."""
    st = scenario.stages[0]
    return 1.0 / (
        st.pinion.base_radius_m**2 / st.pinion.inertia_kg_m2
        + st.wheel.base_radius_m**2 / st.wheel.inertia_kg_m2
    )
