"""Layout and initial state of a drive with planetary stages (a "compound" train): motor, shafts,
parallel stages (torsional), planetary stages (every member a planar body) and machine, in the
coordinates of docs/planetary.md, "The stage in a drive". Engine-free: the Exudyn builder
(:mod:`gearbody.engine.compound`) creates exactly what :func:`compound_layout` lists.

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
from ..model.planetary import PlanetaryStage
from ..physics.mesh import I_LU, I_MU
from ..physics.planetary_mesh import G_BEARING_K, G_DELTA0_RING, G_DELTA0_SUN, stage_forces
from ..signals import stage_prefix
from .operating_point import static_deflection_m, steady_operating_point
from .parameters import mesh_parameters_from_scenario, pack_drive_parameters
from .planetary_layout import CENTRAL, PlanetaryLayout, layout_from_stage
from .topology import gear_names

__all__ = [
    "ChainShaft",
    "CompoundLayout",
    "PlanetaryLink",
    "compound_initial_state",
    "compound_layout",
    "bearing_law_forces",
    "has_bearing_laws",
    "stage_stiffness_matrix",
    "planetary_member_names",
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
    """A parallel (torsional) stage's mesh between pinion and wheel coordinates."""

    stage: int
    pinion: int
    wheel: int
    parameters: np.ndarray = field(repr=False)


@dataclass(frozen=True)
class CompoundLayout:
    dof_names: tuple[str, ...]
    inertias: tuple[float, ...]  # per rotation-only body (motor, gears, machine): its inertia
    rotation_bodies: tuple[int, ...]  # coordinate index of each rotation-only body
    shafts: tuple[ChainShaft, ...]
    meshes: tuple[ParallelMesh, ...]
    planetary: tuple[PlanetaryLink, ...]
    motor_at: int
    load_at: int
    drive: np.ndarray = field(repr=False)


def compound_layout(scenario: Scenario, *, modal: bool = False) -> CompoundLayout:
    """The coordinates, bodies, shafts, meshes and planetary stages of a train with planetary stages
    (``modal``: planetary meshes as constant springs at their mean stiffness, for the modes)."""
    d = scenario.design
    names: list[str] = ["motor"]
    inertias, bodies = [d.motor.inertia_kg_m2], [0]
    meshes, planetary = [], []
    ends = []  # per stage: (input coordinate, its sense, output coordinate, its sense)
    for k, st in enumerate(scenario.stages):
        if isinstance(st, PlanetaryStage):
            link = PlanetaryLink(
                k,
                layout_from_stage(
                    st,
                    k,
                    scenario.meta.seed,
                    modal=modal,
                    friction_coefficient=0.0 if modal else scenario.condition.friction_coefficient,
                    friction_transition_speed_m_s=scenario.condition.friction_transition_speed_m_s,
                ),
                len(names),
                planetary_member_names(k, st.planets),
                st.input,
                st.output,
                st.fixed,
                st.input_sense,
                st.output_sense,
                scenario.stage_rated_force_N(k),
            )
            for member in link.names:
                names += [f"{member}_x", f"{member}_y", member]
            planetary.append(link)
            ends.append(
                (
                    link.rotation_index(st.input),
                    st.input_sense,
                    link.rotation_index(st.output),
                    st.output_sense,
                )
            )
        else:
            pname, wname = gear_names(k)
            ip = len(names)
            names += [pname, wname]
            inertias += [st.pinion.inertia_kg_m2, st.wheel.inertia_kg_m2]
            bodies += [ip, ip + 1]
            meshes.append(ParallelMesh(k, ip, ip + 1, mesh_parameters_from_scenario(scenario, k)))
            ends.append((ip, 1, ip + 1, 1))
    names.append("machine")
    inertias.append(d.machine.inertia_kg_m2)
    bodies.append(len(names) - 1)
    shafts = []
    upstream = (0, 1)
    for k, sh in enumerate(d.shafts):
        down = (len(names) - 1, 1) if k == len(ends) else (ends[k][0], ends[k][1])
        shafts.append(
            ChainShaft(
                upstream[0], down[0], sh.stiffness_Nm_per_rad, sh.damping_Nms_per_rad, upstream[1], down[1]
            )
        )
        if k < len(ends):
            upstream = (ends[k][2], ends[k][3])
    return CompoundLayout(
        tuple(names),
        tuple(inertias),
        tuple(bodies),
        tuple(shafts),
        tuple(meshes),
        tuple(planetary),
        0,
        len(names) - 1,
        pack_drive_parameters(scenario),
    )


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
    first = scenario.stages[0]
    pitch_rad = (
        2 * math.pi / (first.pinion.teeth if not isinstance(first, PlanetaryStage) else _input_teeth(first))
    )
    for shift in START_SHIFTS:
        try:
            return _steady_state(scenario, layout, shift * pitch_rad)
        except InputError as exc:
            if "no static equilibrium" not in str(exc) or shift == START_SHIFTS[-1]:
                raise


def _input_teeth(stage: PlanetaryStage) -> int:
    """Teeth that set the mesh period along the input member's angle (the carrier: the ring's)."""
    return stage.sun.teeth if stage.input == "sun" else stage.ring.teeth


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
