"""A planetary stage in a drive's coordinates (:class:`PlanetaryLink`): its members' names, bodies,
supports and force terms in the compound layout (:mod:`gearbody.assembly.compound`), its linearised
stiffness, its bearing laws and its static state under given torques (docs/planetary.md, "The stage in a
drive"). Registers the planetary stage kind's ``layout_part``."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..model import Scenario
from ..model.kinds import register_stage_kind
from ..physics.compiled import compiled
from ..physics.mesh import I_LU, I_MU
from ..physics.planetary_mesh import G_BEARING_K, G_DELTA0_RING, G_DELTA0_SUN, stage_forces
from ..signals import stage_prefix
from .planetary_layout import CENTRAL, PlanetaryLayout, layout_from_stage
from .system import Body, MatrixItem, SliceTerm, Spring, SystemLayout

__all__ = [
    "PlanetaryLink",
    "bearing_law_forces",
    "has_bearing_laws",
    "planetary_member_names",
    "planetary_part",
    "stage_static_displacements",
    "stage_stiffness_matrix",
]


MAX_NEWTON_ITERATIONS = 30
REGULARISING_N_PER_M = 1e7
LAW_NEWTON_ITERATIONS = 300
"""The weak spring of the static start's first pass on members that sit on bearing laws, N/m."""
STATIC_TOLERANCE = 1e-9
"""Largest residual force of the static start, relative to the stage's largest external torque (N or
N m per N m)."""


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
        terms = [SliceTerm(self.first, self.size, _stage_forces(self))]
        if has_bearing_laws(self):
            terms.append(SliceTerm(self.first, self.size, _law_forces(self)))
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
            f[o : o + 2] += member.bearing_law.force_N(q_rel[o : o + 2], q_t[o : o + 2])
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
        fr, ft = law.force_N(u, du)
        Fx, Fy = c * fr - s_ * ft, s_ * fr + c * ft  # on the planet, fixed frame
        f[b] += Fx
        f[b + 1] += Fy
        f[6] -= Fx
        f[7] -= Fy
        f[8] -= rc * (c * Fy - s_ * Fx)
    return f


def _support_forces(link: PlanetaryLink, q_rel: np.ndarray) -> np.ndarray:
    """Central members' bearings and the fixed member's torsional support (elastic part) on the stage's
    coordinates (displacements from the nominal assembly)."""
    f = np.zeros(link.size)
    for m, member in enumerate(link.layout.members):
        o = 3 * m
        f[o : o + 2] -= member.bearing_stiffness_N_per_m * q_rel[o : o + 2]
        if member.torsion_stiffness_Nm_per_rad is not None:
            f[o + 2] -= member.torsion_stiffness_Nm_per_rad * q_rel[o + 2]
    if has_bearing_laws(link):
        f += bearing_law_forces(link, q_rel, np.zeros(link.size))
    return f


def stage_static_displacements(
    link: PlanetaryLink,
    input_torque_Nm: float,
    output_torque_Nm: float,
    input_angle_rad: float = 0.0,
    carrier_speed_rad_s: float = 0.0,
) -> np.ndarray:
    """Static equilibrium of a planetary stage (displacements from the nominal assembly) under the signed
    external torques on its input and output members and the planets' centrifugal forces m_p w_c^2
    (c_n - c_c) of a carrier turning at ``carrier_speed_rad_s``: exact deflections, the mesh laws at this
    state without damping or friction; the input rotation held at ``input_angle_rad`` (the gauge);
    Newton from the nominal assembly (docs/planetary.md, "Initial state")."""
    ref, G_true = link.reference(), link.geometry_rows()
    Ps_true, Pr_true = (P.copy() for P in link.layout.mesh_arrays())
    Ps_true[..., I_MU] = Pr_true[..., I_MU] = 0.0  # the steady start ignores friction (as for trains)
    # Solved on the loaded flanks: the backlash moved into the assembly deflection (delta - l_u with no
    # clearance is the law's contact branch), so Newton starts from a law without a dead zone; the
    # result is then checked with the true law (every loaded mesh on its flank).
    G, Ps, Pr = G_true.copy(), Ps_true.copy(), Pr_true.copy()
    G[:, G_DELTA0_SUN] += Ps[..., I_LU]
    G[:, G_DELTA0_RING] += Pr[..., I_LU]
    Ps[..., I_LU] = Pr[..., I_LU] = 0.0
    gauge = 3 * CENTRAL.index(link.input) + 2
    free = np.array([i for i in range(link.size) if i != gauge])
    torques = np.zeros(link.size)
    torques[3 * CENTRAL.index(link.input) + 2] += input_torque_Nm
    torques[3 * CENTRAL.index(link.output) + 2] += output_torque_Nm
    zero = np.zeros(link.size)
    w2 = link.layout.planet.mass_kg * carrier_speed_rad_s**2

    def residual(x: np.ndarray) -> np.ndarray:
        q = np.zeros(link.size)
        q[gauge] = input_angle_rad
        q[free] = x
        f = stage_forces(ref + q, zero, G, Ps, Pr) + _support_forces(link, q) + torques
        c = ref + q
        f[9::3] += w2 * (c[9::3] - c[6])
        f[10::3] += w2 * (c[10::3] - c[7])
        f[soft] -= regularise[0] * q[soft]
        return f[free]

    # A bearing law with a clearance carries nothing at the nominal assembly (its members then hang on
    # the meshes alone, the carrier on nothing): first solved with a weak spring (REGULARISING_N_PER_M)
    # on every translation of a member on a law, then without it from there (the bearings in contact).
    lay = link.layout
    soft = np.array(
        [3 * m + d for m, mem in enumerate(lay.members) if mem.bearing_law for d in (0, 1)], dtype=int
    )
    regularise = [REGULARISING_N_PER_M if has_bearing_laws(link) else 0.0]
    G_soft = G.copy()
    if lay.planet.bearing_law is not None:  # the planets' weak spring acts on their pins (the carrier)
        G_soft[:, G_BEARING_K] += REGULARISING_N_PER_M
    G_free = G
    # the residual's scale: the torques, or with no load the planets' centrifugal forces
    scale = max(abs(input_torque_Nm), abs(output_torque_Nm), w2 * link.layout.carrier_radius_m, 1.0)
    # Newton with a central-difference Jacobian (the laws are piecewise linear in the deflections, the
    # geometry smooth): steps of 1e-9 m on centres and 1e-9 m / r_c on rotations
    steps = np.array([1e-9 if i % 3 < 2 else 1e-9 / link.layout.carrier_radius_m for i in free])
    x = np.zeros(free.size)

    def newton(
        x: np.ndarray, iterations: int = MAX_NEWTON_ITERATIONS, max_step_m: float = np.inf
    ) -> np.ndarray:
        r = residual(x)
        for _ in range(iterations):
            if np.max(np.abs(r)) <= STATIC_TOLERANCE * scale:
                break
            J = np.empty((free.size, free.size))
            for j, h in enumerate(steps):
                e = np.zeros(free.size)
                e[j] = h
                J[:, j] = (residual(x + e) - residual(x - e)) / (2 * h)
            try:
                dx = np.linalg.solve(J, r)
            except np.linalg.LinAlgError:  # a member free in the backlash (no load): any equilibrium will do
                dx = np.linalg.lstsq(J, r, rcond=None)[0]
            longest = np.max(np.abs(dx / steps)) * 1e-9  # in m (rotations times r_c)
            x = x - dx * min(1.0, max_step_m / longest)
            r = residual(x)
        return x

    if regularise[0]:  # steps of at most a micrometre while the bearing contacts close
        G = G_soft
        x = newton(x, LAW_NEWTON_ITERATIONS, 1e-6)
        G, regularise[0] = G_free, 0.0
        x = newton(x, LAW_NEWTON_ITERATIONS, 1e-6)
    x = newton(x)
    G, Ps, Pr = G_true, Ps_true, Pr_true
    x = newton(x)  # with the backlash: one step at most when every loaded mesh is on its flank
    r = residual(x)
    if not np.max(np.abs(r)) <= STATIC_TOLERANCE * scale:
        raise InputError(
            f"operation.initial_state = 'steady': stage {link.stage + 1}: no static equilibrium of the "
            f"planetary stage found in {MAX_NEWTON_ITERATIONS} Newton steps (largest residual "
            f"{np.max(np.abs(r)):.3g} N or N m); start from rest"
        )
    q = np.zeros(link.size)
    q[gauge] = input_angle_rad
    q[free] = x
    return q


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


def _law_forces(link: PlanetaryLink):
    """factory() -> the stage's Python bearing laws (docs/planetary.md, "Bearing laws")."""

    def factory():
        def laws(q, q_t):
            return bearing_law_forces(link, q, q_t)

        return laws

    return factory


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
