"""Layout and initial state of a drive with planetary stages (a "compound" train): motor, shafts,
parallel stages (torsional), planetary stages (every member a planar body) and machine, in the
coordinates of docs/planetary.md, "The stage in a drive". Engine-free: the Exudyn builder
(:func:`gearbody.engine.build.build`) creates exactly what its system lists
(:mod:`gearbody.assembly.compound_system`).

Coordinates: ``motor``, per parallel stage ``pinion(_s)`` and ``wheel(_s)``, per planetary stage
``<p>sun_x, <p>sun_y, <p>sun, <p>ring_x, ..., <p>carrier, <p>planet_1_x, ..., <p>planet_N`` (prefix
``<p>`` empty for stage 1, ``stage_<s>_`` after; x, y and rotation displacements from the nominal
assembly, absolute rotations counter-clockwise), then ``machine``. Parallel-stage and chain rotations are
positive in their driven direction; a planetary input (output) member turns with sense ``s_in``
(``s_out``), so a shaft to it acts on ``s theta``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..model import Scenario
from ..model.kinds import register_stage_kind, stage_kind
from ..physics.mesh import I_R1, I_R2, mean_stiffness_N_per_m
from .operating_point import static_deflection_m, steady_operating_point
from .parameters import mesh_parameters_from_scenario, pack_drive_parameters
from .planetary_layout import CENTRAL
from .planetary_link import (
    PlanetaryLink,
    bearing_law_forces,
    has_bearing_laws,
    planetary_member_names,
    stage_stiffness_matrix,
)
from .planetary_static import stage_static_displacements
from .system import Body, MatrixItem, PairMesh, SystemLayout
from .topology import gear_names

__all__ = [
    "ChainShaft",
    "CompoundLayout",
    "ParallelMesh",
    "PlanetaryLink",
    "compound_initial_state",
    "compound_layout",
    "bearing_law_forces",
    "has_bearing_laws",
    "stage_static_displacements",
    "stage_stiffness_matrix",
    "planetary_member_names",
]


@dataclass(frozen=True)
class ChainShaft:
    """Torsional spring-damper of the chain, moment ``k (s_i q_i - s_j q_j) + C (...)'`` on coordinates
    i (upstream) and j (downstream); s = -1 where a planetary member turns clockwise."""

    i: int
    j: int
    stiffness_Nm_per_rad: float
    damping_Nms_per_rad: float
    sign_i: int = 1
    sign_j: int = 1


@dataclass(frozen=True)
class ParallelMesh:
    """A parallel (torsional) stage in a compound layout: pinion and wheel rotations, their mesh."""

    stage: int
    pinion: int
    wheel: int
    parameters: np.ndarray = field(repr=False)
    names: tuple[str, str] = ("pinion", "wheel")
    inertias_kg_m2: tuple[float, float] = (0.0, 0.0)

    @property
    def first(self) -> int:
        return self.pinion

    @property
    def coordinate_names(self) -> list[str]:
        return list(self.names)

    @property
    def ends(self) -> tuple[int, int, int, int]:
        return (self.pinion, 1, self.wheel, 1)

    def bodies(self) -> list[Body]:
        return [Body("rotation", inertia_kg_m2=i) for i in self.inertias_kg_m2]

    def supports(self) -> list:
        return []

    def modal_items(self, system: SystemLayout, bearing_states: dict[int, np.ndarray]) -> list:
        """The mesh as a line-of-action spring at its mean stiffness."""
        g = np.array([self.parameters[I_R1], -self.parameters[I_R2]])
        pair = (system.body_of(self.pinion)[0], system.body_of(self.wheel)[0])
        return [MatrixItem(pair, mean_stiffness_N_per_m(self.parameters) * np.outer(g, g))]

    def drive_meshes(self) -> list[PairMesh]:
        return [PairMesh(self.pinion, self.wheel, self.parameters)]

    def drive_terms(self) -> list:
        return []


def parallel_part(scenario: Scenario, k: int, first: int, modal: bool) -> ParallelMesh:
    """Stage k (parallel) of a compound layout: its pinion at coordinate ``first``, its wheel next."""
    st = scenario.stages[k]
    return ParallelMesh(
        k,
        first,
        first + 1,
        mesh_parameters_from_scenario(scenario, k),
        gear_names(k),
        (st.pinion.inertia_kg_m2, st.wheel.inertia_kg_m2),
    )


register_stage_kind("parallel", layout_part=parallel_part)


@dataclass(frozen=True)
class CompoundLayout:
    """The coordinates of a drive with planetary stages: the motor, each stage's part (its
    ``coordinate_names`` in order), the machine; the chain's shafts; the drive's parameters."""

    dof_names: tuple[str, ...]
    parts: tuple  # per stage, its kind's layout_part
    shafts: tuple[ChainShaft, ...]
    motor_inertia_kg_m2: float
    machine_inertia_kg_m2: float
    drive: np.ndarray = field(repr=False)

    @property
    def motor_at(self) -> int:
        return 0

    @property
    def load_at(self) -> int:
        return len(self.dof_names) - 1

    @property
    def meshes(self) -> tuple[ParallelMesh, ...]:
        """The parallel stages."""
        return tuple(p for p in self.parts if isinstance(p, ParallelMesh))

    @property
    def planetary(self) -> tuple[PlanetaryLink, ...]:
        """The planetary stages."""
        return tuple(p for p in self.parts if isinstance(p, PlanetaryLink))


def compound_layout(scenario: Scenario, *, modal: bool = False) -> CompoundLayout:
    """The coordinates, bodies, shafts and stage parts of a train with planetary stages (``modal``:
    planetary meshes as constant springs at their mean stiffness, for the modes)."""
    d = scenario.design
    names: list[str] = ["motor"]
    parts = []
    for k, st in enumerate(scenario.stages):
        kind = stage_kind(st)
        if kind.layout_part is None:
            raise InputError(
                f"stage {k + 1} (type {kind.name!r}): its kind has no layout part; it cannot be built"
            )
        part = kind.layout_part(scenario, k, len(names), modal)
        names += part.coordinate_names
        parts.append(part)
    names.append("machine")
    shafts = []
    upstream = (0, 1)
    for k, sh in enumerate(d.shafts):
        down = (len(names) - 1, 1) if k == len(parts) else parts[k].ends[:2]
        shafts.append(
            ChainShaft(
                upstream[0], down[0], sh.stiffness_Nm_per_rad, sh.damping_Nms_per_rad, upstream[1], down[1]
            )
        )
        if k < len(parts):
            upstream = parts[k].ends[2:]
    return CompoundLayout(
        tuple(names),
        tuple(parts),
        tuple(shafts),
        d.motor.inertia_kg_m2,
        d.machine.inertia_kg_m2,
        pack_drive_parameters(scenario),
    )


START_SHIFTS = (0.0, 0.01, -0.01, 0.03, -0.03, 0.1)
"""Start angles of the drive tried by the steady start, in tooth pitches of the first stage's input: a
planetary stage's static state can straddle a jump of a mesh stiffness (Newton then cycles between its
two sides), and a start a little further on is as good a steady state."""


def compound_initial_state(scenario: Scenario, layout: CompoundLayout) -> tuple[np.ndarray, np.ndarray]:
    """Initial coordinates and velocities (docs/planetary.md, "Initial state"): all zero from rest;
    'steady': rigid speeds, each stage at static equilibrium under its share of the initial load, the
    chain's angles stage by stage in power-flow order as for trains, the first stage's input at angle 0
    (or, where a static state straddles a stiffness jump, turned by a :data:`START_SHIFTS` fraction of its
    tooth pitch)."""
    n = len(layout.dof_names)
    if scenario.operation.initial_state == "rest":
        return np.zeros(n), np.zeros(n)
    for k, st in enumerate(scenario.stages):
        if not isinstance(layout.parts[k], (ParallelMesh, PlanetaryLink)):
            raise InputError(
                f"operation.initial_state = 'steady': stage {k + 1} (type {stage_kind(st).name!r}) has no "
                "steady start; use operation.initial_state = 'rest'"
            )
    first = scenario.stages[0]
    pitch_rad = 2 * math.pi / first.input_teeth
    for shift in START_SHIFTS:
        try:
            return _steady_state(scenario, layout, shift * pitch_rad)
        except InputError as exc:
            if "no static equilibrium" not in str(exc) or shift == START_SHIFTS[-1]:
                raise


def _steady_state(scenario: Scenario, layout: CompoundLayout, start_angle_rad: float):
    n = len(layout.dof_names)
    q, v = np.zeros(n), np.zeros(n)
    op = steady_operating_point(scenario)
    links = {link.stage: link for link in layout.planetary}
    meshes = {m.stage: m for m in layout.meshes}
    shafts = scenario.design.shafts
    angle_in = start_angle_rad  # the stage input's angle in the chain's driven direction
    for k, st in enumerate(scenario.stages):
        force, w_in = op["mesh_force_N"][k], op["pinion_speed_rad_s"][k]
        T_in = force * st.input_arm_m
        if k == 0:
            q[0], v[0] = angle_in + T_in / shafts[0].stiffness_Nm_per_rad, w_in
        if k in links:
            link = links[k]
            s_in, s_out = link.input_sense, link.output_sense
            o = link.first
            speeds = {}
            if w_in:
                willis = st.speeds(w_in)
                speeds = {m: s_in * willis.of(m) for m in CENTRAL} | {"planet": s_in * willis.planet_rad_s}
            q[o : o + link.size] = stage_static_displacements(
                link,
                s_in * T_in,
                -s_out * force * st.output_arm_m,
                s_in * angle_in,
                speeds.get("carrier", 0.0),
            )
            for m, member in enumerate(CENTRAL):
                v[o + 3 * m + 2] = speeds.get(member, 0.0)
            wc = speeds.get("carrier", 0.0)
            for p in range(st.planets):  # planet centres turn with the carrier about its (static) centre
                x, y = (
                    np.add(link.layout.planet_centre_m(p), q[o + 9 + 3 * p : o + 11 + 3 * p])
                    - q[o + 6 : o + 8]
                )
                v[o + 9 + 3 * p : o + 12 + 3 * p] = (-wc * y, wc * x, speeds.get("planet", 0.0))
            angle_out = s_out * q[link.rotation_index(st.output)]
        else:
            m = meshes[k]
            delta = static_deflection_m(scenario, k, angle_in, force)
            q[m.pinion] = angle_in
            q[m.wheel] = angle_out = (st.pinion.base_radius_m * angle_in - delta) / st.wheel.base_radius_m
            v[m.pinion], v[m.wheel] = w_in, op["wheel_speed_rad_s"][k]
        if k + 1 < len(scenario.stages):
            T_next = op["mesh_force_N"][k + 1] * scenario.stages[k + 1].input_arm_m
            angle_in = angle_out - T_next / shafts[k + 1].stiffness_Nm_per_rad
        else:
            q[-1] = angle_out - op["load_torque_Nm"] / shafts[-1].stiffness_Nm_per_rad
            v[-1] = op["wheel_speed_rad_s"][k]
    return q, v
