"""Mesh kinematics of a pair whose centres move in the plane: the planetary stage's sun-planet (external)
and ring-planet (internal) meshes, with exact involute geometry. Engine-free, compiled with numba.

Members are planar rigid bodies in the fixed frame: centre (x, y) and rotation theta (counter-clockwise
positive, absolute). For a pair of base radii r_b1 (sun or ring) and r_b2 (planet) with d = c_2 - c_1,
D = |d|, phi = atan2(d_y, d_x):

- external (sun-planet), R = r_b1 + r_b2:
  ``delta = r_b1 theta_1 + r_b2 theta_2 - R phi - R inv(alpha_w)``,
- internal (ring-planet), R = r_b1 - r_b2:
  ``delta = r_b1 theta_1 - r_b2 theta_2 - R phi + R inv(alpha_w)``,

with the operating pressure angle ``alpha_w = arccos(R / D)`` and ``inv(a) = tan a - a``: the signed
approach of the two flanks along the line of action (docs/design-notes.md, "Planetary stages"), up to a
constant fixed by the assembly. The flanks are those loaded when the sun drives counter-clockwise
(positive sun torque): on the sun mesh the sun's leading flank, on the ring mesh the planet's flank
facing the ring on the other side (Lin & Parker's psi_sn = psi_n - alpha_s and psi_rn = psi_n + alpha_r:
the two lines of action are mirrored about the planet's radius). Both are unchanged by a rigid rotation
of the pair, and by member 2 rolling around member 1. The gradient of delta is +-r_b on the rotations,
``+n`` on the centre of member 1 and ``-n`` on that of member 2, with the unit line of action ``n =
sin(a) e + cos(a) e_perp`` (external) or ``n = -sin(a) e + cos(a) e_perp`` (internal), e = d / D, e_perp
= e turned by +90 deg (because d(R inv(alpha_w))/dD = sin(alpha_w) and R / D = cos(alpha_w)). A normal
force F does the virtual work F d(delta): the generalised forces are -F d(delta)/dq, the force on member
2 is +F n. Linearised about the assembly this is Lin & Parker's (1999) projection of the centres' motion
on the line of action.

One flank's geometry is used for both flanks (the back-flank contact of a reversing load uses the same
line of action), as in the lateral parallel mesh.

Friction (docs/planetary.md, "Friction"): ``|T| = mu |F| e(p)`` of the mesh law at the contact point,
along ``m = (n_y, -n_x)``, opposing the flanks' sliding ``v_T`` (the power of a unit T, so ``T v_T <= 0``);
arms from the tangent points, ``rho_1 = r_b1 tan(alpha_w) + (p - pitch) p_b`` for the sun or ring,
``rho_p = r_bp tan(alpha_w) -+ (p - pitch) p_b`` for the planet (external: the arms share ``R
tan(alpha_w)``; internal: they grow together, ``rho_r - rho_p = R tan(alpha_w)``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, types
from numba.extending import overload

from .bearings import law_force_xy
from .mesh import I_ARM1, contact_force, friction_force

__all__ = [
    "G_SIZE",
    "involute",
    "operating_pressure_angle_rad",
    "pair_deflection",
    "pair_deflection_rate",
    "planet_forces",
    "planet_mesh_contacts",
    "planet_mesh_states",
    "stage_contact_series",
    "stage_mesh_series",
    "stage_forces",
]


@njit(cache=True)
def involute(alpha_rad: float) -> float:
    """inv(a) = tan a - a."""
    return math.tan(alpha_rad) - alpha_rad


@njit(cache=True)
def operating_pressure_angle_rad(
    centre_distance_m: float, r_b1_m: float, r_b2_m: float, internal: bool
) -> float:
    """arccos(R / D), R = r_b1 + r_b2 (external) or r_b1 - r_b2 (internal); nan if D <= R."""
    R = r_b1_m - r_b2_m if internal else r_b1_m + r_b2_m
    if centre_distance_m <= R:
        return math.nan
    return math.acos(R / centre_distance_m)


@njit(cache=True)
def pair_deflection(q: np.ndarray, r_b1_m: float, r_b2_m: float, internal: bool, phi_ref_rad: float) -> tuple:
    """(delta_m, n_x, n_y, phi_rad, alpha_w_rad) of the pair ``q = [x1, y1, theta1, x2, y2, theta2]``;
    ``n`` is the unit line of action along which the force on member 2 acts when delta > 0 (its
    gradient: d(delta)/d(c_2) = -n, d(delta)/d(c_1) = +n). ``phi_ref_rad`` is the nominal, continuous
    angle of the line of centres (the carrier angle plus the planet's position angle): phi is taken
    within pi of it, so delta does not jump by 2 pi R when atan2 wraps over many carrier revolutions."""
    dx, dy = q[3] - q[0], q[4] - q[1]
    D = math.hypot(dx, dy)
    phi = math.atan2(dy, dx)
    phi += 2.0 * math.pi * math.floor((phi_ref_rad - phi) / (2.0 * math.pi) + 0.5)
    alpha = operating_pressure_angle_rad(D, r_b1_m, r_b2_m, internal)
    ex, ey = dx / D, dy / D
    sa, ca = math.sin(alpha), math.cos(alpha)
    # line of action: sin(a) e + cos(a) e_perp, e_perp = (-ey, ex)
    lx, ly = sa * ex - ca * ey, sa * ey + ca * ex
    if internal:
        R = r_b1_m - r_b2_m
        delta = r_b1_m * q[2] - r_b2_m * q[5] - R * phi + R * involute(alpha)
        return delta, -sa * ex - ca * ey, -sa * ey + ca * ex, phi, alpha
    R = r_b1_m + r_b2_m
    delta = r_b1_m * q[2] + r_b2_m * q[5] - R * phi - R * involute(alpha)
    return delta, lx, ly, phi, alpha


@njit(cache=True)
def pair_deflection_rate(
    q: np.ndarray, q_t: np.ndarray, r_b1_m: float, r_b2_m: float, internal: bool
) -> float:
    """d(delta)/dt = grad(delta) . q_t (the gradient: r_b1 and +-r_b2 on the rotations, +n and -n on the
    centres)."""
    _, nx, ny, _, _ = pair_deflection(q, r_b1_m, r_b2_m, internal, 0.0)  # n does not depend on phi_ref
    return _rate(nx, ny, q_t, r_b1_m, r_b2_m, internal)


@njit(cache=True)
def _rate(nx: float, ny: float, q_t: np.ndarray, r_b1_m: float, r_b2_m: float, internal: bool) -> float:
    """grad(delta) . q_t from the line of action n already computed."""
    rot = r_b1_m * q_t[2] - r_b2_m * q_t[5] if internal else r_b1_m * q_t[2] + r_b2_m * q_t[5]
    return rot + nx * (q_t[0] - q_t[3]) + ny * (q_t[1] - q_t[4])


# Layout of a planet's geometry array (planet_forces): base radii, carrier radius, position angle, planet
# bearing, the mesh-law angle offsets and the deflections of the nominal assembly.
G_RB_SUN, G_RB_PLANET, G_RB_RING, G_CARRIER_RADIUS, G_PSI = 0, 1, 2, 3, 4
G_BEARING_K, G_BEARING_C, G_ANGLE_SUN, G_ANGLE_RING, G_DELTA0_SUN, G_DELTA0_RING = 5, 6, 7, 8, 9, 10
G_SIZE = 11


@njit(cache=True)
def planet_mesh_states(q: np.ndarray, q_t: np.ndarray, G: np.ndarray):
    """The two meshes of one planet (``q``, ``q_t`` as in :func:`planet_forces`): for the sun mesh and
    then the ring mesh, the mesh law's angle, the deflection from the nominal assembly, its rate and the
    line of action (n_x, n_y), then the two operating pressure angles (rad): ``(a_s, d_s, v_s, nx_s, ny_s,
    a_r, d_r, v_r, nx_r, ny_r, alpha_s, alpha_r)``."""
    phi_ref = q[8] + G[G_PSI]
    rbs, rbp, rbr = G[G_RB_SUN], G[G_RB_PLANET], G[G_RB_RING]
    pair = np.empty(6)
    pair_t = np.empty(6)
    # sun mesh: sun (0..2) and planet (9..11)
    for k in range(3):
        pair[k], pair[3 + k] = q[k], q[9 + k]
        pair_t[k], pair_t[3 + k] = q_t[k], q_t[9 + k]
    d, nx_s, ny_s, phi, alpha_s = pair_deflection(pair, rbs, rbp, False, phi_ref)
    rate_s = _rate(nx_s, ny_s, pair_t, rbs, rbp, False)
    angle_s, delta_s = q[2] - phi + G[G_ANGLE_SUN], d - G[G_DELTA0_SUN]
    # ring mesh: ring (3..5) and planet
    for k in range(3):
        pair[k], pair_t[k] = q[3 + k], q_t[3 + k]
    d, nx_r, ny_r, phi, alpha_r = pair_deflection(pair, rbr, rbp, True, phi_ref)
    rate_r = _rate(nx_r, ny_r, pair_t, rbr, rbp, True)
    # the ring's angle relative to the line of centres, negated: it grows as the mesh engages (carrier
    # turning counter-clockwise in the ring), so the law's tooth counter and phase run forwards
    angle_r, delta_r = phi - q[5] + G[G_ANGLE_RING], d - G[G_DELTA0_RING]
    return angle_s, delta_s, rate_s, nx_s, ny_s, angle_r, delta_r, rate_r, nx_r, ny_r, alpha_s, alpha_r


@njit(cache=True)
def planet_mesh_contacts(
    q: np.ndarray, q_t: np.ndarray, G: np.ndarray, P_sun: np.ndarray, P_ring: np.ndarray, sliding: bool
):
    """The contact of one planet's two meshes (``q``, ``q_t`` as in :func:`planet_forces`): for the sun
    mesh and then the ring mesh, the normal force F (N), the friction force T (N), the sliding velocity
    v_T (m/s, the power of a unit T: ``P_f = T v_T <= 0``), the arms of member 1 and of the planet (m) and
    the line of action (n_x, n_y). Friction follows docs/planetary.md, "Friction": sun mesh ``v_T = (c_n' -
    c_s') . m + w_s rho_s + w_p rho_p``, ring mesh ``v_T = (c_r' - c_n') . m + w_r rho_r - w_p rho_p``.
    Without friction (mu = 0) the arms and v_T are computed only when ``sliding`` asks for them (else 0)."""
    a_s, d_s, r_s, nx, ny, a_r, d_r, r_r, mx, my, alpha_s, alpha_r = planet_mesh_states(q, q_t, G)
    rbs, rbp, rbr = G[G_RB_SUN], G[G_RB_PLANET], G[G_RB_RING]
    F_s, fr, rho, _ = contact_force(a_s, d_s, r_s, P_sun)
    T_s = v_s = rho_s = rho_ps = 0.0
    if fr != 0.0 or sliding:  # external: rho_s + rho_p = (r_bs + r_bp) tan(alpha_w)
        dp_pb, ta = rho - P_sun[I_ARM1], math.tan(alpha_s)  # (p - pitch) p_b
        rho_s, rho_ps = rbs * ta + dp_pb, rbp * ta - dp_pb
        v_s = -q_t[0] * ny + q_t[1] * nx + q_t[2] * rho_s + q_t[9] * ny - q_t[10] * nx + q_t[11] * rho_ps
        T_s = friction_force(fr, v_s, P_sun)
    F_r, fr, rho, _ = contact_force(a_r, d_r, r_r, P_ring)
    T_r = v_r = rho_r = rho_pr = 0.0
    if fr != 0.0 or sliding:  # internal: rho_r - rho_p = (r_br - r_bp) tan(alpha_w), both grow with the phase
        dp_pb, ta = rho - P_ring[I_ARM1], math.tan(alpha_r)
        rho_r, rho_pr = rbr * ta + dp_pb, rbp * ta + dp_pb
        v_r = q_t[3] * my - q_t[4] * mx + q_t[5] * rho_r - q_t[9] * my + q_t[10] * mx - q_t[11] * rho_pr
        T_r = friction_force(fr, v_r, P_ring)
    return F_s, T_s, v_s, rho_s, rho_ps, nx, ny, F_r, T_r, v_r, rho_r, rho_pr, mx, my


@njit(cache=True)
def planet_forces(q: np.ndarray, q_t: np.ndarray, G: np.ndarray, P_sun: np.ndarray, P_ring: np.ndarray):
    """Generalised forces (12) of one planet's sun mesh, ring mesh and bearing on the carrier, and the two
    normal mesh forces (N). ``q``, ``q_t``: absolute [x, y, theta] of sun, ring, carrier, planet (m, rad).
    The meshes are :func:`gearbody.physics.mesh.contact_force` on the exact deflection of
    :func:`pair_deflection` (sun mesh: sun = member 1, z1 = z_sun in ``P_sun``; ring mesh: ring = member
    1, z1 = z_ring in ``P_ring``), the law's angle being the sun's rotation relative to the line of
    centres (theta_s - phi) and the line of centres' rotation relative to the ring (phi - theta_r), each
    plus ``G[G_ANGLE_*]``: both grow when the sun drives counter-clockwise; forces -F grad(delta). The
    planet bearing is an isotropic spring-damper between the planet centre and its point on the carrier,
    c_c + r_c (cos, sin)(theta_c + psi), its reaction acting on the carrier at that point. Friction T of
    each law along m = (n_y, -n_x) (docs/planetary.md, "Friction", :func:`planet_mesh_contacts`): sun mesh,
    the sun gets -T m and the moment +T rho_s, the planet +T m and +T rho_p; ring mesh, the ring +T m and
    +T rho_r, the planet -T m and -T rho_p (N, N m). A frictionless law (T = 0) skips it: the same
    arithmetic as without friction."""
    f = np.zeros(12)
    phi_ref = q[8] + G[G_PSI]
    rbs, rbp, rbr = G[G_RB_SUN], G[G_RB_PLANET], G[G_RB_RING]
    F_sun, T, _, rho_s, rho_p, nx, ny, F_ring, T_r, _, rho_r, rho_pr, mx, my = planet_mesh_contacts(
        q, q_t, G, P_sun, P_ring, False
    )
    f[0] -= F_sun * nx
    f[1] -= F_sun * ny
    f[2] -= F_sun * rbs
    f[9] += F_sun * nx
    f[10] += F_sun * ny
    f[11] -= F_sun * rbp
    if T != 0.0:
        f[0] -= T * ny
        f[1] += T * nx
        f[2] += T * rho_s
        f[9] += T * ny
        f[10] -= T * nx
        f[11] += T * rho_p
    f[3] -= F_ring * mx
    f[4] -= F_ring * my
    f[5] -= F_ring * rbr
    f[9] += F_ring * mx
    f[10] += F_ring * my
    f[11] += F_ring * rbp
    if T_r != 0.0:
        f[3] += T_r * my
        f[4] -= T_r * mx
        f[5] += T_r * rho_r
        f[9] -= T_r * my
        f[10] += T_r * mx
        f[11] -= T_r * rho_pr
    # planet bearing on the carrier
    rc = G[G_CARRIER_RADIUS]
    c, s = math.cos(phi_ref), math.sin(phi_ref)
    ex, ey = q[9] - (q[6] + rc * c), q[10] - (q[7] + rc * s)
    vx = q_t[9] - (q_t[6] - rc * s * q_t[8])
    vy = q_t[10] - (q_t[7] + rc * c * q_t[8])
    Fx = -G[G_BEARING_K] * ex - G[G_BEARING_C] * vx  # on the planet
    Fy = -G[G_BEARING_K] * ey - G[G_BEARING_C] * vy
    f[9] += Fx
    f[10] += Fy
    f[6] -= Fx
    f[7] -= Fy
    f[8] += rc * (s * Fx - c * Fy)
    return f, F_sun, F_ring


def _law_rows(P: np.ndarray) -> np.ndarray:
    """A packed law as rows: one shared law (1-D) as a (1, len) view, per-planet laws (N, len) as they are."""
    return P.reshape((1, P.size)) if P.ndim == 1 else P


@overload(_law_rows)
def _law_rows_compiled(P):
    if isinstance(P, types.Array) and P.ndim == 1:
        return lambda P: P.reshape((1, P.size))
    return lambda P: P


@njit(cache=True)
def stage_forces(q: np.ndarray, q_t: np.ndarray, G: np.ndarray, P_sun: np.ndarray, P_ring: np.ndarray):
    """Generalised forces of every planet's meshes and bearing: ``q``, ``q_t`` absolute [x, y, theta] of
    sun, ring, carrier, then planet 1..N (9 + 3 N); ``G`` one geometry row per planet (N x G_SIZE);
    ``P_sun``, ``P_ring`` one packed law shared by every planet (1-D) or one row per planet (N x len,
    a planet's own damaged teeth, docs/planetary.md "Faults"). One call for the whole stage (the
    solver's per-call overhead, not the law, dominates one call per planet)."""
    n = G.shape[0]
    Ps, Pr = _law_rows(P_sun), _law_rows(P_ring)
    ns, nr = Ps.shape[0], Pr.shape[0]
    f = np.zeros(9 + 3 * n)
    qk = np.empty(12)
    qtk = np.empty(12)
    for i in range(9):
        qk[i], qtk[i] = q[i], q_t[i]
    for k in range(n):
        o = 9 + 3 * k
        for i in range(3):
            qk[9 + i], qtk[9 + i] = q[o + i], q_t[o + i]
        fk = planet_forces(qk, qtk, G[k], Ps[k % ns], Pr[k % nr])[0]
        for i in range(9):
            f[i] += fk[i]
        for i in range(3):
            f[o + i] += fk[9 + i]
    return f


@njit(cache=True)
def stage_mesh_series(q: np.ndarray, q_t: np.ndarray, G: np.ndarray) -> np.ndarray:
    """The mesh states of every planet over samples: ``q``, ``q_t`` (n_t x (9 + 3 N)) absolute
    coordinates as in :func:`stage_forces`; returns (n_t, N, 6): law angle, deflection and rate of the
    sun mesh, then of the ring mesh (:func:`planet_mesh_states`)."""
    nt, n = q.shape[0], G.shape[0]
    out = np.empty((nt, n, 6))
    qk = np.empty(12)
    qtk = np.empty(12)
    for m in range(nt):
        for i in range(9):
            qk[i], qtk[i] = q[m, i], q_t[m, i]
        for k in range(n):
            o = 9 + 3 * k
            for i in range(3):
                qk[9 + i], qtk[9 + i] = q[m, o + i], q_t[m, o + i]
            a_s, d_s, v_s, _, _, a_r, d_r, v_r, _, _, _, _ = planet_mesh_states(qk, qtk, G[k])
            out[m, k, 0], out[m, k, 1], out[m, k, 2] = a_s, d_s, v_s
            out[m, k, 3], out[m, k, 4], out[m, k, 5] = a_r, d_r, v_r
    return out


@njit(cache=True)
def stage_contact_series(
    q: np.ndarray, q_t: np.ndarray, G: np.ndarray, P_sun: np.ndarray, P_ring: np.ndarray
) -> np.ndarray:
    """The contacts of every planet over samples (``q``, ``q_t`` n_t x (9 + 3 N) as in
    :func:`stage_mesh_series`, laws as in :func:`stage_forces`): (n_t, N, 6) with F, T, v_T of the sun mesh,
    then of the ring mesh (N, N, m/s; :func:`planet_mesh_contacts`), exactly what the solver integrated."""
    nt, n = q.shape[0], G.shape[0]
    Ps, Pr = _law_rows(P_sun), _law_rows(P_ring)
    ns, nr = Ps.shape[0], Pr.shape[0]
    out = np.empty((nt, n, 6))
    qk = np.empty(12)
    qtk = np.empty(12)
    for m in range(nt):
        for i in range(9):
            qk[i], qtk[i] = q[m, i], q_t[m, i]
        for k in range(n):
            o = 9 + 3 * k
            for i in range(3):
                qk[9 + i], qtk[9 + i] = q[m, o + i], q_t[m, o + i]
            c = planet_mesh_contacts(qk, qtk, G[k], Ps[k % ns], Pr[k % nr], True)
            out[m, k, 0], out[m, k, 1], out[m, k, 2] = c[0], c[1], c[2]
            out[m, k, 3], out[m, k, 4], out[m, k, 5] = c[7], c[8], c[9]
    return out


@njit(cache=True)
def stage_bearing_law_forces(
    q_rel: np.ndarray, q_t: np.ndarray, laws: np.ndarray, carrier_radius_m: float, pins: np.ndarray
) -> np.ndarray:
    """Generalised forces of a planetary stage's bearing laws (docs/planetary.md, "Bearing laws") on its
    coordinates (``q_rel`` displacements from the nominal assembly, ``q_t`` velocities): ``laws`` one
    row per sun, ring, carrier and the planets (``[0, ...]``: the linear bearing, not a law here; else
    :func:`gearbody.physics.bearings.law_force_xy`'s row), ``pins`` one row per planet: pin angle (rad),
    nominal centre x, y (m). A central member's law takes its centre's motion, its rotation turning the
    inner race in the fixed outer; a planet's law its offset from its pin in the carrier frame, the pin
    its inner race and the planet's rotation relative to the carrier its outer, its force acting on the
    planet and, reversed, on the carrier."""
    f = np.zeros(q_rel.size)
    for m in range(3):
        if laws[m, 0] != 0.0:
            o = 3 * m
            fx, fy = law_force_xy(laws[m], q_rel[o], q_rel[o + 1], q_t[o], q_t[o + 1], q_rel[o + 2], 0.0)
            f[o] += fx
            f[o + 1] += fy
    if laws[3, 0] == 0.0:
        return f
    rc = carrier_radius_m
    xc, yc, tc = q_rel[6], q_rel[7], q_rel[8]
    vxc, vyc, wc = q_t[6], q_t[7], q_t[8]
    for n in range(pins.shape[0]):
        b = 9 + 3 * n
        a = tc + pins[n, 0]
        c, s_ = math.cos(a), math.sin(a)
        ex = pins[n, 1] + q_rel[b] - (xc + rc * c)
        ey = pins[n, 2] + q_rel[b + 1] - (yc + rc * s_)
        vx = q_t[b] - (vxc - rc * s_ * wc)
        vy = q_t[b + 1] - (vyc + rc * c * wc)
        fr, ft = law_force_xy(  # in the pin's frame: the pin the inner race, the planet the outer
            laws[3],
            c * ex + s_ * ey,
            -s_ * ex + c * ey,
            c * vx + s_ * vy,
            -s_ * vx + c * vy,
            0.0,
            q_rel[b + 2] - tc,
        )
        Fx, Fy = c * fr - s_ * ft, s_ * fr + c * ft
        f[b] += Fx
        f[b + 1] += Fy
        f[6] -= Fx
        f[7] -= Fy
        f[8] -= rc * (c * Fy - s_ * Fx)
    return f
