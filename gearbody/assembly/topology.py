"""Topology of a drive, as read from a scenario: inertias (gears optionally on lateral bearings), shafts,
meshes, drive and load.

This is the one place where a scenario becomes bodies and connectors; the Exudyn builder then creates
exactly what it lists. It imports no Exudyn, so it also serves the linearised modal model.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model import Scenario
from ..physics.bearings import LinearBearing
from ..physics.lateral import mesh_directions, tangent_stiffness_N_per_m
from ..physics.mesh import mean_stiffness_N_per_m
from ..signals import gear_names
from .parameters import mesh_parameters_from_scenario, pack_drive_parameters
from .system import (
    BearingItem,
    Body,
    Constraint,
    DriveItem,
    MatrixItem,
    MeshItem,
    MullerItem,
    PairMesh,
    Spring,
    SystemLayout,
    TorqueItem,
)


@dataclass(frozen=True)
class LateralSupport:
    """A gear centre that translates on a bearing: free directions (0 = x, 1 = y), mass, bearing law."""

    free_directions: tuple[int, ...]
    mass_kg: float
    bearing: object = field(repr=False)  # a gearbody.physics.bearings law (force_N method)
    bearing_kind: str = "linear"
    housing_mass_kg: float = 50.0
    rotation_sense: float = 1.0  # +1: the gear's rotation coordinate turns counter-clockwise (about +z)


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
        n, m, s1 = mesh_directions(st.mesh.centre_line_deg, st.mesh.line_of_action_deg)
        inertias += [
            Inertia(pname, st.pinion.inertia_kg_m2, _support(st.pinion, s1)),
            Inertia(wname, st.wheel.inertia_kg_m2, _support(st.wheel, -s1)),
        ]
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


def _support(gear, rotation_sense: int) -> LateralSupport | None:
    """A lateral gear's support; ``rotation_sense`` its rotation's sense about +z (pinion s1, wheel -s1)."""
    if gear.lateral == "none":
        return None
    return LateralSupport(
        gear.free_directions,
        gear.mass_kg,
        gear.bearing.law(),
        gear.bearing.kind,
        gear.bearing.housing_mass_kg,
        float(rotation_sense),
    )


def reduced_mass_kg(scenario: Scenario) -> float:
    """Muller's reduced mass along the line of action, m = 1 / (r1^2/I_1p + r2^2/I_2p)."""
    st = scenario.stages[0]
    return 1.0 / (
        st.pinion.base_radius_m**2 / st.pinion.inertia_kg_m2
        + st.wheel.base_radius_m**2 / st.wheel.inertia_kg_m2
    )


def coordinate_names(b: Inertia) -> list[str]:
    """The coordinates of an inertia: its rotation, or x, y and rotation on lateral bearings."""
    return [f"{b.name}_x", f"{b.name}_y", b.name] if b.lateral is not None else [b.name]


def torsional_coordinates(
    layout: TorsionalLayout, q0, v0, lateral_u0: dict[str, np.ndarray] | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Per-coordinate initial state from rotations and speeds per inertia (``q0``, ``v0``) and the centre
    displacements of lateral gears (``lateral_u0`` by name; lateral velocities start at 0)."""
    n = len(layout.inertias)
    q0 = np.zeros(n) if q0 is None else q0
    v0 = np.zeros(n) if v0 is None else v0
    lateral_u0 = lateral_u0 or {}
    q, v = [], []
    for k, b in enumerate(layout.inertias):
        if b.lateral is None:
            q.append(float(q0[k]))
            v.append(float(v0[k]))
        else:
            u0 = lateral_u0.get(b.name, np.zeros(2))
            q += [float(u0[0]), float(u0[1]), float(q0[k])]
            v += [0.0, 0.0, float(v0[k])]
    return np.array(q), np.array(v)


def torsional_system(
    layout: TorsionalLayout,
    *,
    lateral_u0: dict[str, np.ndarray] | None = None,
    modal_mesh_stiffness_N_per_m=None,
) -> SystemLayout:
    """The system of a torsional layout (gears optionally on lateral bearings): inertias as rotation or
    planar bodies, shafts as springs, bearings (linear: springs per free direction; a law: its own item),
    directions held fixed as constraints, then the drive. Without lateral gears the motor, load and meshes
    are one drive item; with them each mesh, the motor and the load are items of their own.

    With ``modal_mesh_stiffness_N_per_m`` (one value for all meshes, or one per mesh) the meshes are
    constant line-of-action springs of that stiffness, nonlinear bearings their tangent stiffness at
    ``lateral_u0``, and the motor and load are left out: the linearised system for natural frequencies.
    """
    lateral_u0 = lateral_u0 or {}
    modal = modal_mesh_stiffness_N_per_m is not None
    names: list[str] = []
    bodies, rotation = [], []
    for b in layout.inertias:
        rotation.append(len(names) + (0 if b.lateral is None else 2))
        names += coordinate_names(b)
        if b.lateral is None:
            bodies.append(Body("rotation", inertia_kg_m2=b.inertia_kg_m2))
        else:
            bodies.append(Body("planar", inertia_kg_m2=b.inertia_kg_m2, mass_kg=b.lateral.mass_kg))
    items: list = [
        Spring(rotation[sh.i], rotation[sh.j], sh.stiffness_Nm_per_rad, sh.damping_Nms_per_rad)
        for sh in layout.shafts
    ]
    for k, b in enumerate(layout.inertias):
        if b.lateral is not None:
            items += _bearing_items(k, rotation[k] - 2, b, lateral_u0, modal)
    if not modal and not layout.is_lateral and layout.motor_at is not None and layout.load_at is not None:
        meshes = tuple(PairMesh(rotation[m.pinion], rotation[m.wheel], m.parameters) for m in layout.meshes)
        items.append(DriveItem(rotation[layout.motor_at], rotation[layout.load_at], layout.drive, meshes))
        return SystemLayout(tuple(names), tuple(bodies), tuple(items))
    if modal:
        k_modal = np.broadcast_to(np.asarray(modal_mesh_stiffness_N_per_m, float), (len(layout.meshes),))
    for index, m in enumerate(layout.meshes):
        bp, bw = layout.inertias[m.pinion], layout.inertias[m.wheel]
        idx = _mesh_coordinate_index(bp, bw)
        if modal:
            g = np.zeros(len(coordinate_names(bp)) + len(coordinate_names(bw)))
            g[idx[0]], g[idx[3]] = m.r_pinion_m, -m.r_wheel_m
            if idx[1] >= 0:
                g[idx[1]], g[idx[2]] = m.line_of_action
            if idx[4] >= 0:
                g[idx[4]], g[idx[5]] = -m.line_of_action[0], -m.line_of_action[1]
            items.append(MatrixItem((m.pinion, m.wheel), k_modal[index] * np.outer(g, g)))
        elif bp.lateral is None and bw.lateral is None:
            items.append(MeshItem((m.pinion, m.wheel), m.parameters))
        else:
            free = [
                float(d in b.lateral.free_directions) if b.lateral else 0.0 for b in (bp, bw) for d in (0, 1)
            ]
            geometry = np.array([*m.line_of_action, *m.friction_direction, *free])
            items.append(MeshItem((m.pinion, m.wheel), m.parameters, geometry, idx))
    if not modal:
        if layout.motor_at is not None:
            items.append(TorqueItem(layout.motor_at, "motor", layout.drive))
        if layout.load_at is not None:
            items.append(TorqueItem(layout.load_at, "load", layout.drive))
    return SystemLayout(tuple(names), tuple(bodies), tuple(items), modal)


def _bearing_items(body: int, first: int, b: Inertia, lateral_u0, modal: bool) -> list:
    """A lateral gear's bearing: directions held fixed, then the law (springs when linear)."""
    sup, law = b.lateral, b.lateral.bearing
    items: list = [Constraint(first + d) for d in (0, 1) if d not in sup.free_directions]
    if isinstance(law, LinearBearing):
        k = (law.stiffness_x_N_per_m, law.stiffness_y_N_per_m)
        c = (law.damping_x_Ns_per_m, law.damping_y_Ns_per_m)
        items += [Spring(None, first + d, k[d], c[d]) for d in sup.free_directions]
    elif modal:
        K = np.zeros((3, 3))
        K[:2, :2] = tangent_stiffness_N_per_m(law, lateral_u0.get(b.name, np.zeros(2)))
        items.append(MatrixItem((body,), K))
    else:
        items.append(BearingItem(body, law, sup.free_directions, sup.rotation_sense))
    return items


def _mesh_coordinate_index(bp: Inertia, bw: Inertia) -> np.ndarray:
    """Positions in the mesh item's coordinates of [pinion rot, x, y, wheel rot, x, y] (-1: none)."""
    idx = []
    offset = 0
    for b in (bp, bw):
        if b.lateral is None:
            idx += [offset, -1, -1]
            offset += 1
        else:
            idx += [offset + 2, offset, offset + 1]
            offset += 3
    return np.array(idx, dtype=np.int64)


def muller_system(scenario: Scenario, *, modal: bool = False) -> SystemLayout:
    """Muller's one-mass model (Fig. 1): the reduced mass on the line of action; ``modal``: the mesh as a
    spring at its mean stiffness."""
    body = (Body("translation", mass_kg=reduced_mass_kg(scenario)),)
    P = mesh_parameters_from_scenario(scenario, friction=False)
    if modal:
        item = MatrixItem((0,), np.array([[mean_stiffness_N_per_m(P)]]))
    else:
        item = MullerItem(0, P, pack_drive_parameters(scenario), scenario.rated_mesh_force_N)
    return SystemLayout(("deflection",), body, (item,), modal)
