"""A planetary stage in a drive's coordinates (:class:`PlanetaryLink`): its members' names, bodies,
supports and force terms in the compound layout (:mod:`gearbody.assembly.compound`), its linearised
stiffness and its bearing laws (docs/planetary.md, "The stage in a drive"); its static state under
given torques is :mod:`gearbody.assembly.planetary_static`. Registers the planetary stage kind's
``layout_part``."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model import Scenario
from ..model.kinds import register_stage_kind
from ..physics.compiled import compiled
from ..physics.planetary_mesh import stage_bearing_law_forces, stage_forces
from ..signals import stage_prefix
from .planetary_layout import CENTRAL, PlanetaryLayout, layout_from_stage
from .system import Body, MatrixItem, SliceTerm, Spring, SystemLayout

__all__ = [
    "PlanetaryLink",
    "bearing_law_forces",
    "has_bearing_laws",
    "planetary_member_names",
    "planetary_part",
    "stage_stiffness_matrix",
]


def planetary_member_names(stage: int, planets: int) -> tuple[str, ...]:
    """Member names of a planetary stage: sun, ring, carrier, planet_1..N (with the stage prefix)."""
    p = stage_prefix(stage)
    return (*(p + m for m in CENTRAL), *(f"{p}planet_{n + 1}" for n in range(planets)))


@dataclass(frozen=True)
class PlanetaryLink:
    """A planetary stage in the coordinate list: its layout, the index of its first coordinate (sun x;
    9 + 3 N consecutive coordinates), roles, turning senses and rated force per planet mesh."""

    stage: int
    layout: PlanetaryLayout = field(repr=False)
    first: int
    names: tuple[str, ...]
    input: str
    output: str
    fixed: str
    input_sense: int
    output_sense: int
    rated_force_N: float

    def rotation_index(self, member: str) -> int:
        """Coordinate index of a central member's rotation."""
        return self.first + 3 * CENTRAL.index(member) + 2

    @property
    def size(self) -> int:
        return 3 * len(self.names)

    def reference(self) -> np.ndarray:
        """Absolute coordinates of the nominal assembly (planet centres on the carrier circle)."""
        ref = np.zeros(self.size)
        for n in range(len(self.layout.planet_angles_rad)):
            ref[9 + 3 * n : 11 + 3 * n] = self.layout.planet_centre_m(n)
        return ref

    def geometry_rows(self) -> np.ndarray:
        """One geometry row per planet for :func:`gearbody.physics.planetary_mesh.stage_forces`."""
        return np.array([self.layout.geometry(n) for n in range(len(self.layout.planet_angles_rad))])

    # -- its part of the drive's system (gearbody.assembly.compound_system) ---------------------------
    @property
    def coordinate_names(self) -> list[str]:
        """x, y and rotation of every member."""
        return [c for member in self.names for c in (f"{member}_x", f"{member}_y", member)]

    @property
    def ends(self) -> tuple[int, int, int, int]:
        """(input rotation coordinate, its sense, output rotation coordinate, its sense) for the shafts."""
        return (
            self.rotation_index(self.input),
            self.input_sense,
            self.rotation_index(self.output),
            self.output_sense,
        )

    def bodies(self) -> list[Body]:
        """A planar body per member: sun, ring, carrier, planets."""
        lay = self.layout
        members = (*lay.members, *([lay.planet] * (len(self.names) - 3)))
        return [Body("planar", inertia_kg_m2=m.inertia_kg_m2, mass_kg=m.mass_kg) for m in members]

    def supports(self) -> list:
        """The central members' bearings (springs to the ground; a bearing law is a drive term) and the
        fixed member's torsional support."""
        items = []
        for m, member in enumerate(self.layout.members):
            o = self.first + 3 * m
            for d in (0, 1) if member.bearing_law is None else ():
                items.append(
                    Spring(None, o + d, member.bearing_stiffness_N_per_m, member.bearing_damping_Ns_per_m)
                )
            if member.torsion_stiffness_Nm_per_rad is not None:
                items.append(
                    Spring(
                        None, o + 2, member.torsion_stiffness_Nm_per_rad, member.torsion_damping_Nms_per_rad
                    )
                )
        return items

    def modal_items(self, system: SystemLayout, bearing_states: dict[int, np.ndarray]) -> list:
        """The stage's stiffness at the nominal assembly (its meshes at their mean stiffness, with
        ``compound_layout(..., modal=True)``), bearing laws linearised at ``bearing_states[stage]``."""
        bodies = tuple(dict.fromkeys(system.body_of(c)[0] for c in range(self.first, self.first + self.size)))
        return [
            MatrixItem(bodies, stage_stiffness_matrix(self, bearing_state=bearing_states.get(self.stage)))
        ]

    def drive_meshes(self) -> list:
        return []

    def drive_terms(self) -> list[SliceTerm]:
        """The stage's meshes and planet bearings, then its bearing laws, as terms of the drive item."""
        terms = [SliceTerm(self.first, self.size, _stage_forces(self), _stage_kernel(self))]
        if has_bearing_laws(self):
            terms.append(SliceTerm(self.first, self.size, _law_forces(self), _laws_kernel(self)))
        return terms


def stage_stiffness_matrix(
    link: PlanetaryLink, step: float = 1e-7, bearing_state: np.ndarray | None = None
) -> np.ndarray:
    """-d(forces)/dq of a planetary stage's meshes and planet bearings at the nominal assembly, by central
    differences (``step`` m on centres, m / r_c on rotations): with ``compound_layout(..., modal=True)``
    the meshes are springs at their mean stiffness through zero deflection, so this is the exact
    geometry's linearisation (Lin & Parker's matrices in the fixed frame) to O(step^2). Bearing laws
    (``bearing_law_forces``) are linearised at ``bearing_state`` (displacements; default nominal), e.g.
    the static state under the rated load, where a bearing with clearance carries its load."""
    ref, G = link.reference(), link.geometry_rows()
    Ps, Pr = link.layout.mesh_arrays()
    zero = np.zeros(link.size)
    at = np.zeros(link.size) if bearing_state is None else bearing_state
    laws = has_bearing_laws(link)
    K = np.empty((link.size, link.size))
    for j in range(link.size):
        h = step if j % 3 < 2 else step / link.layout.carrier_radius_m
        e = np.zeros(link.size)
        e[j] = h
        K[:, j] = -(stage_forces(ref + e, zero, G, Ps, Pr) - stage_forces(ref - e, zero, G, Ps, Pr)) / (2 * h)
        if laws:
            K[:, j] -= (bearing_law_forces(link, at + e, zero) - bearing_law_forces(link, at - e, zero)) / (
                2 * h
            )
    return K


def has_bearing_laws(link: PlanetaryLink) -> bool:
    """True when a member of the stage sits on a bearing law (not the linear isotropic bearing)."""
    return any(m.bearing_law is not None for m in (*link.layout.members, link.layout.planet))


def bearing_law_forces(link: PlanetaryLink, q_rel: np.ndarray, q_t: np.ndarray) -> np.ndarray:
    """Generalised forces of the stage's bearing laws (docs/planetary.md, "Bearing laws"), on its
    coordinates (``q_rel``: displacements from the nominal assembly, ``q_t``: velocities). A central
    member's law takes its centre's displacement and velocity (the housing is fixed); a planet's law takes
    its centre's offset from its pin, e = c_n - P_n, and its rate, both turned into the carrier frame
    (angle theta_c + pin angle), and its force, turned back, acts on the planet and, reversed, on the
    carrier at the pin (with the moment (P_n - c_c) x (-F))."""
    lay = link.layout
    f = np.zeros(link.size)
    for m, member in enumerate(lay.members):
        if member.bearing_law is not None:
            o = 3 * m
            turn = (q_rel[o + 2],) if getattr(member.bearing_law, "ROTATING", False) else ()  # its inner race
            f[o : o + 2] += member.bearing_law.force_N(q_rel[o : o + 2], q_t[o : o + 2], *turn)
    law = lay.planet.bearing_law
    if law is None:
        return f
    rc = lay.carrier_radius_m
    xc, yc, tc = q_rel[6], q_rel[7], q_rel[8]  # the carrier's nominal centre and rotation are 0
    vxc, vyc, wc = q_t[6], q_t[7], q_t[8]
    for n in range(len(lay.planet_angles_rad)):
        b = 9 + 3 * n
        a = tc + lay.pin_angle_rad(n)
        c, s_ = np.cos(a), np.sin(a)
        px, py = lay.planet_centre_m(n)
        ex = px + q_rel[b] - (xc + rc * c)
        ey = py + q_rel[b + 1] - (yc + rc * s_)
        vx = q_t[b] - (vxc - rc * s_ * wc)
        vy = q_t[b + 1] - (vyc + rc * c * wc)
        u = np.array([c * ex + s_ * ey, -s_ * ex + c * ey])  # carrier frame: radial, tangential
        du = np.array([c * vx + s_ * vy, -s_ * vx + c * vy])
        turn = (0.0, q_rel[b + 2] - tc) if getattr(law, "ROTATING", False) else ()  # pin inner, planet outer
        fr, ft = law.force_N(u, du, *turn)
        Fx, Fy = c * fr - s_ * ft, s_ * fr + c * ft  # on the planet, fixed frame
        f[b] += Fx
        f[b + 1] += Fy
        f[6] -= Fx
        f[7] -= Fy
        f[8] -= rc * (c * Fy - s_ * Fx)
    return f


def _stage_forces(link: PlanetaryLink):
    """factory() -> the stage's meshes and planet bearings on its coordinates (displacements)."""

    def factory():
        ref, G = link.reference(), link.geometry_rows()
        Ps, Pr = link.layout.mesh_arrays()  # shared laws, or one row per planet (faulted planet teeth)
        forces = compiled(stage_forces, ref, ref, G, Ps, Pr)  # for this stage's array shapes

        def stage(q, q_t):
            return forces(q + ref, q_t, G, Ps, Pr)

        return stage

    return factory


def _stage_kernel(link: PlanetaryLink):
    """kernel() -> the compiled path's kernel of :func:`_stage_forces` and its packed parameters."""

    def kernel():
        from ..physics.kernels import pack, planetary_stage_kernel

        Ps, Pr = link.layout.mesh_arrays()
        block = pack([link.first, link.size], link.reference(), link.geometry_rows(), Ps, Pr)
        return planetary_stage_kernel, block

    return kernel


def law_rows(link: PlanetaryLink) -> tuple[np.ndarray, np.ndarray] | None:
    """(law rows of sun, ring, carrier, planet; pin rows: angle, nominal centre) for the compiled
    :func:`gearbody.physics.planetary_mesh.stage_bearing_law_forces`, or None when a law has no
    ``law_row`` (a user's Python law)."""
    lay = link.layout
    laws = [m.bearing_law for m in (*lay.members, lay.planet)]
    if any(law is not None and not hasattr(law, "law_row") for law in laws):
        return None
    rows = [np.zeros(5) if law is None else np.asarray(law.law_row(), float) for law in laws]
    width = max(r.size for r in rows)
    table = np.zeros((4, width))
    for i, r in enumerate(rows):
        table[i, : r.size] = r
    pins = np.array(
        [(lay.pin_angle_rad(n), *lay.planet_centre_m(n)) for n in range(len(lay.planet_angles_rad))], float
    )
    return table, pins


def _law_forces(link: PlanetaryLink):
    """factory() -> the stage's bearing laws (docs/planetary.md, "Bearing laws"): the compiled function
    the compiled path calls where every law has a row, else the laws' own ``force_N``."""

    def factory():
        rows = law_rows(link)
        if rows is None:

            def laws(q, q_t):
                return bearing_law_forces(link, q, q_t)

            return laws
        table, pins = rows
        rc = link.layout.carrier_radius_m
        forces = compiled(stage_bearing_law_forces, np.zeros(link.size), np.zeros(link.size), table, rc, pins)

        def compiled_laws(q, q_t):
            return forces(q, q_t, table, rc, pins)

        return compiled_laws

    return factory


def _laws_kernel(link: PlanetaryLink):
    """kernel() -> the compiled path's kernel of the stage's bearing laws, or None (a Python law)."""
    rows = law_rows(link)
    if rows is None:
        return None

    def kernel():
        from ..physics.kernels import pack, planetary_laws_kernel

        table, pins = rows
        return planetary_laws_kernel, pack([link.first, link.size, link.layout.carrier_radius_m], table, pins)

    return kernel


def planetary_part(scenario: Scenario, k: int, first: int, modal: bool) -> PlanetaryLink:
    """Stage k (planetary) of a compound layout, its sun's x at coordinate ``first`` (``modal``: its
    meshes constant springs at their mean stiffness, without friction)."""
    st = scenario.stages[k]
    return PlanetaryLink(
        k,
        layout_from_stage(
            st,
            k,
            scenario.meta.seed,
            modal=modal,
            friction_coefficient=0.0 if modal else scenario.condition.friction_coefficient,
            friction_transition_speed_m_s=scenario.condition.friction_transition_speed_m_s,
        ),
        first,
        planetary_member_names(k, st.planets),
        st.input,
        st.output,
        st.fixed,
        st.input_sense,
        st.output_sense,
        scenario.stage_rated_force_N(k),
    )


register_stage_kind("planetary", layout_part=planetary_part)
