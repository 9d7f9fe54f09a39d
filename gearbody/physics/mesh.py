# size: the compiled mesh law is one unit: every njit function reads the one packed I_* layout (docstring)
"""Gear mesh force law, eqs. (4)-(6) of the paper plus inter-tooth friction. Engine-free.

One scalar law, :func:`mesh_contact`, compiled with numba; the solver calls it through
:func:`torsional_mesh_forces` and post-processing through :func:`mesh_contact_series`, so the forces
reported are exactly the ones integrated. All parameters travel in one float64 array built by
:func:`pack_mesh_parameters` (layout in the ``I_*`` constants) so that a call costs few conversions.

Conventions (docs/scenario.md): mesh phase ``p = frac(phi_p z1 / 2 pi)`` from the computed pinion angle;
pinion tooth ``i = n mod z1`` and wheel tooth ``j = n mod z2`` with ``n = floor(phi_p z1 / 2 pi)``;
``d = delta + E(p)``, ``F_el = k (max(d - l_u, min(d + l_u, 0)))``; damping only in contact;
friction ``T = -mu |F| e(p) sigma(v_sl / v_0)`` opposing the flanks' sliding velocity ``v_sl`` at the
contact point (in forward motoring it reverses at the pitch point, the paper's law), arms ``rho_1, rho_2``
along the line of action, ``sigma`` the regularised sign :func:`smooth_sign` over ``|v_sl| < v_0``.
The error ``E`` is the tooth error mode plus two production/condition faults: a once-per-revolution
run-out of either gear, ``A sin(phi + theta)`` along the line of action (wheel angle taken as
``phi_p z1 / z2``), and a pit on a tooth flank, ``-depth`` while that tooth's pair is between two mesh
phases (material missing: the pair deflects less).

Regularisation (``transition_width`` w, a fraction of the mesh period; 0 = the sharp law of the paper):
every jump of the law at fixed deflection, i.e. the single/double contact switches of k_z, the change of
tooth pair at p = 0 (stiffness factors, errors), the pit edges and the friction at the tooth change (where
the arms jump: the envelope ``e(p)``), is spread over ``|p - p_jump| < w / 2`` by the C2 smooth step
:func:`smooth_step`.
Across the tooth change the factor and the error are blended between the outgoing and incoming pairs
(each evaluated with its own phase, p + 1 or p - 1). Each ramp is antisymmetric about its centre, so the
mean stiffness over a period is unchanged. docs/scenario.md, "Transition width".

The module stays whole (~550 lines): every compiled function here reads the one packed parameter layout
(the ``I_*`` offsets) and numba compiles them together; split, the layout would be written twice.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .motor import load_torque_at, motor_torque_at

# Layout of the packed parameter array.
I_R1, I_R2, I_Z1, I_Z2 = 0, 1, 2, 3
I_KIND, I_KSINGLE, I_KDOUBLE, I_HALF_DOUBLE = 4, 5, 6, 7
I_CZ, I_LU, I_MU, I_PITCH = 8, 9, 10, 11
I_ARM1, I_ARM2, I_PB, I_A = 12, 13, 14, 15
I_NTAB = 16
I_ECC_P, I_ECC_P_PHASE, I_ECC_W, I_ECC_W_PHASE = 17, 18, 19, 20  # run-out amplitudes (m), phases (rad)
I_WIDTH = 21  # transition width w, fraction of the mesh period (0: sharp law)
I_PAIR_N = 22  # points N of the pair stiffness table ("pairs" profile), 0 otherwise
I_V0 = 23  # friction transition speed v_0 (m/s): the direction blends through 0 over |v_sl| < v_0
I_HEADER = 24
# after the header: e_i (z1), pinion factors (z1), wheel factors (z2), table phases (n), table k (n),
# pit depth / start phase / end phase per pinion tooth (3 z1), then per wheel tooth (3 z2);
# "pairs" profile: healthy pair table (N), ratio-table slot per pinion tooth (z1) and per wheel tooth
# (z2) (0 = none, s = the s-th ratio table), ratio tables (N each)

PROFILE_CONTACT_RATIO, PROFILE_TABLE, PROFILE_PAIRS = 0.0, 1.0, 2.0


def pack_mesh_parameters(
    *,
    r1_m: float,
    r2_m: float,
    z1: int,
    z2: int,
    stiffness_single_N_per_m: float,
    stiffness_double_N_per_m: float,
    contact_ratio: float,
    damping_Ns_per_m: float,
    backlash_m: float,
    friction_coefficient: float,
    pitch_point_phase: float,
    pressure_angle_rad: float,
    error_a: float,
    error_depths_m: np.ndarray,
    pinion_factors: np.ndarray | None = None,
    wheel_factors: np.ndarray | None = None,
    table_phase: np.ndarray | None = None,
    table_stiffness_N_per_m: np.ndarray | None = None,
    runout_m: tuple[float, float] = (0.0, 0.0),
    runout_phase_rad: tuple[float, float] = (0.0, 0.0),
    pinion_pits: np.ndarray | None = None,
    wheel_pits: np.ndarray | None = None,
    transition_width: float = 0.0,
    pair_stiffness_N_per_m: np.ndarray | None = None,
    pair_ratios: dict[tuple[str, int], np.ndarray] | None = None,
    friction_transition_speed_m_s: float = 1e-3,
) -> np.ndarray:
    """Pack everything the mesh law needs into one float64 array (see module docstring).

    ``pair_stiffness_N_per_m``: healthy pair stiffness on the grid ``q_m = -h + m (1 + 2h)/(N - 1)``
    (the "pairs" profile, :func:`pair_stiffness_sum`); ``pair_ratios``: ``(gear, tooth) -> ratio table``
    on the same grid for damaged teeth."""
    f = np.ones(z1) if pinion_factors is None else np.asarray(pinion_factors, float)
    g = np.ones(z2) if wheel_factors is None else np.asarray(wheel_factors, float)
    tp = np.zeros(0) if table_phase is None else np.asarray(table_phase, float)
    tk = np.zeros(0) if table_stiffness_N_per_m is None else np.asarray(table_stiffness_N_per_m, float)
    e = np.asarray(error_depths_m, float)
    pits_p = np.zeros((z1, 3)) if pinion_pits is None else np.asarray(pinion_pits, float)
    pits_w = np.zeros((z2, 3)) if wheel_pits is None else np.asarray(wheel_pits, float)
    if pits_p.shape != (z1, 3) or pits_w.shape != (z2, 3):
        raise ValueError("pit arrays must have one (depth_m, start_phase, end_phase) row per tooth")
    if e.shape != (z1,) or f.shape != (z1,) or g.shape != (z2,) or tp.shape != tk.shape:
        raise ValueError(
            "per-tooth arrays must have z1 (errors, pinion factors) or z2 (wheel factors) values"
        )
    head = np.zeros(I_HEADER)
    head[I_R1], head[I_R2], head[I_Z1], head[I_Z2] = r1_m, r2_m, z1, z2
    head[I_KIND] = PROFILE_TABLE if tp.size else PROFILE_CONTACT_RATIO
    pairs = _pair_blocks(pair_stiffness_N_per_m, pair_ratios, tp.size, z1, z2)
    if pairs:
        head[I_KIND], head[I_PAIR_N] = PROFILE_PAIRS, pairs[0].size
    head[I_KSINGLE], head[I_KDOUBLE] = stiffness_single_N_per_m, stiffness_double_N_per_m
    head[I_HALF_DOUBLE] = 0.5 * (contact_ratio - 1.0)
    head[I_CZ], head[I_LU], head[I_MU], head[I_PITCH] = (
        damping_Ns_per_m,
        backlash_m,
        friction_coefficient,
        pitch_point_phase,
    )
    head[I_ARM1] = r1_m * math.tan(pressure_angle_rad)
    head[I_ARM2] = r2_m * math.tan(pressure_angle_rad)
    head[I_PB] = 2.0 * math.pi * r1_m / z1
    head[I_A] = error_a
    head[I_NTAB] = tp.size
    head[I_ECC_P], head[I_ECC_W] = runout_m
    head[I_ECC_P_PHASE], head[I_ECC_W_PHASE] = runout_phase_rad
    head[I_WIDTH] = transition_width
    head[I_V0] = friction_transition_speed_m_s
    return np.concatenate([head, e, f, g, tp, tk, pits_p.T.ravel(), pits_w.T.ravel(), *pairs])


def _pair_blocks(
    pair_stiffness_N_per_m: np.ndarray | None,
    pair_ratios: dict[tuple[str, int], np.ndarray] | None,
    table_points: int,
    z1: int,
    z2: int,
) -> list[np.ndarray]:
    """The "pairs" profile's blocks of the packed array: healthy pair table, ratio-table slot per pinion
    tooth and per wheel tooth, the ratio tables; none without a pair table."""
    if pair_stiffness_N_per_m is None:
        return []
    kp = np.asarray(pair_stiffness_N_per_m, float)
    if table_points or kp.ndim != 1 or kp.size < 2:
        raise ValueError("a pair stiffness table needs >= 2 points and no phase table")
    slots = {"pinion": np.zeros(z1), "wheel": np.zeros(z2)}
    tables = []
    for (gear, tooth), ratio in sorted((pair_ratios or {}).items()):
        ratio = np.asarray(ratio, float)
        if ratio.shape != kp.shape:
            raise ValueError("pair ratio tables must have the pair table's points")
        tables.append(ratio)
        slots[gear][tooth] = len(tables)
    return [kp, slots["pinion"], slots["wheel"], *tables]


@njit(cache=True)
def smooth_step(x: float) -> float:
    """0 for x <= -1/2, 1 for x >= 1/2, C2 quintic in between (value 1/2 at 0, antisymmetric)."""
    if x <= -0.5:
        return 0.0
    if x >= 0.5:
        return 1.0
    u = x + 0.5
    return u * u * u * (10.0 + u * (6.0 * u - 15.0))


@njit(cache=True)
def smooth_sign(x: float) -> float:
    """Regularised sign: -1 for x <= -1, +1 for x >= 1, ``2 S(x / 2) - 1`` in between (C2, odd, 0 at 0)."""
    return 2.0 * smooth_step(0.5 * x) - 1.0


@njit(cache=True)
def stiffness_at_phase(p: float, P: np.ndarray) -> float:
    """k_z(p) of healthy teeth, N/m: single/double contact from the contact ratio, a periodic table, or
    the sum of the pairs in contact ("pairs")."""
    if P[I_KIND] == PROFILE_CONTACT_RATIO:
        h, w = P[I_HALF_DOUBLE], P[I_WIDTH]
        if w > 0.0 and h > 0.0:
            share = 1.0 - smooth_step((p - h) / w) + smooth_step((p - 1.0 + h) / w)
            return P[I_KSINGLE] + (P[I_KDOUBLE] - P[I_KSINGLE]) * share
        return P[I_KDOUBLE] if (p < h or p >= 1.0 - h) else P[I_KSINGLE]
    if P[I_KIND] == PROFILE_PAIRS:
        return _pairs_sum(p, -1, -1, P)[1]
    z1, z2, n = int(P[I_Z1]), int(P[I_Z2]), int(P[I_NTAB])
    o = I_HEADER + 2 * z1 + z2
    ph = P[o : o + n]
    kk = P[o + n : o + 2 * n]
    if p < ph[0]:  # wrap between the last point (shifted by -1) and the first
        x0, k0, x1, k1 = ph[n - 1] - 1.0, kk[n - 1], ph[0], kk[0]
    elif p >= ph[n - 1]:
        x0, k0, x1, k1 = ph[n - 1], kk[n - 1], ph[0] + 1.0, kk[0]
    else:
        m = np.searchsorted(ph, p, side="right") - 1
        x0, k0, x1, k1 = ph[m], kk[m], ph[m + 1], kk[m + 1]
    return k0 + (k1 - k0) * (p - x0) / (x1 - x0)


@njit(cache=True)
def _pairs_offset(P: np.ndarray) -> int:
    """Start of the pair table in P (after the pits)."""
    z1, z2 = int(P[I_Z1]), int(P[I_Z2])
    return I_HEADER + 2 * z1 + z2 + 2 * int(P[I_NTAB]) + 3 * z1 + 3 * z2


@njit(cache=True)
def _pair_table_value(q: float, table: int, P: np.ndarray) -> float:
    """Linear interpolation of pair table ``table`` (0 = healthy k, s >= 1 = ratio table s) at own phase
    q on the grid -h .. 1 + h, held at its end values outside."""
    n = int(P[I_PAIR_N])
    h = P[I_HALF_DOUBLE]
    x = (q + h) * (n - 1) / (1.0 + 2.0 * h)
    if x <= 0.0:
        m, f = 0, 0.0
    elif x >= n - 1:
        m, f = n - 2, 1.0
    else:
        m = int(x)
        f = x - m
    o = _pairs_offset(P)
    if table > 0:
        o += n + int(P[I_Z1]) + int(P[I_Z2]) + (table - 1) * n
    return P[o + m] + f * (P[o + m + 1] - P[o + m])


@njit(cache=True)
def _contact_weight(q: float, P: np.ndarray) -> float:
    """1 while a pair at own phase q is in contact (-h <= q < 1 + h), 0 outside; smooth steps of width w."""
    h, w = P[I_HALF_DOUBLE], P[I_WIDTH]
    if w > 0.0:
        return smooth_step((q + h) / w) * (1.0 - smooth_step((q - 1.0 - h) / w))
    return 1.0 if -h <= q < 1.0 + h else 0.0


@njit(cache=True)
def _pairs_sum(p: float, i: int, j: int, P: np.ndarray):
    """Sum of the pairs in contact at mesh phase p: the period's pair (teeth i, j, own phase p), the
    outgoing (i - 1, j - 1, at p + 1) and the incoming (i + 1, j + 1, at p - 1), each weighted by its
    contact and by its teeth's factors f g and damage ratios. Returns (k, k_healthy), N/m; k_healthy
    with all factors 1 (i < 0: only k_healthy is meaningful, the teeth are not looked up)."""
    z1, z2 = int(P[I_Z1]), int(P[I_Z2])
    slots = _pairs_offset(P) + int(P[I_PAIR_N])
    k = 0.0
    k_healthy = 0.0
    for o in (-1, 0, 1):
        q = p - o
        c = _contact_weight(q, P)
        if c == 0.0:
            continue
        kq = c * _pair_table_value(q, 0, P)
        k_healthy += kq
        if i >= 0:
            io, jo = (i + o) % z1, (j + o) % z2
            kq *= tooth_pair_factor(io, jo, P)
            sp, sw = int(P[slots + io]), int(P[slots + z1 + jo])
            if sp > 0:
                kq *= _pair_table_value(q, sp, P)
            if sw > 0:
                kq *= _pair_table_value(q, sw, P)
        k += kq
    return k, k_healthy


@njit(cache=True)
def teeth_in_mesh(pinion_angle_rad: float, P: np.ndarray):
    """Pinion tooth i and wheel tooth j of the period's pair at a pinion angle."""
    n = math.floor(pinion_angle_rad * P[I_Z1] / (2.0 * math.pi))
    return int(n % int(P[I_Z1])), int(n % int(P[I_Z2]))


@njit(cache=True)
def tooth_pair_factor(i: int, j: int, P: np.ndarray) -> float:
    """Stiffness factor of pinion tooth i meshing with wheel tooth j (change-of-condition factors)."""
    z1 = int(P[I_Z1])
    return P[I_HEADER + z1 + i] * P[I_HEADER + 2 * z1 + j]


@njit(cache=True)
def error_shape(p: float, a: float) -> float:
    """Triangular error shape of Fig. 4 (b, c): 0 at p = 0 and 1, maximum 1 at p = a."""
    if a > 0.0 and (p < a or a >= 1.0):  # outside [0, 1): the straight lines extended (regularised)
        return p / a
    return (1.0 - p) / (1.0 - a) if a < 1.0 else 1.0


@njit(cache=True)
def tooth_error_m(p: float, i: int, P: np.ndarray) -> float:
    """Error E of pinion tooth i's pair at mesh phase p, m: e_i times the triangular shape."""
    return P[I_HEADER + i] * error_shape(p, P[I_A])


@njit(cache=True)
def _pit_m(p: float, tooth: int, offset: int, teeth: int, P: np.ndarray) -> float:
    depth = P[offset + tooth]
    if depth == 0.0:
        return 0.0
    w = P[I_WIDTH]
    if w > 0.0:
        start, end = P[offset + teeth + tooth], P[offset + 2 * teeth + tooth]
        return depth * (smooth_step((p - start) / w) - smooth_step((p - end) / w))
    if P[offset + teeth + tooth] <= p < P[offset + 2 * teeth + tooth]:
        return depth
    return 0.0


@njit(cache=True)
def mesh_error_m(pinion_angle_rad: float, P: np.ndarray) -> float:
    """Total error E at a pinion angle, m: tooth error mode + run-out of both gears - pits (regularised
    across the tooth change when the transition width is non-zero)."""
    return pair_in_mesh(pinion_angle_rad, P)[2]


@njit(cache=True)
def pair_in_mesh(pinion_angle_rad: float, P: np.ndarray):
    """Mesh phase p, stiffness factor and error E (m) of the tooth pair in mesh at a pinion angle.

    With a transition width w, within w/2 of the tooth change the factor and the error are blended
    between the outgoing and incoming pairs, each evaluated at its own phase (p + 1 or p - 1).
    """
    z1, z2 = int(P[I_Z1]), int(P[I_Z2])
    u = pinion_angle_rad * z1 / (2.0 * math.pi)
    n = math.floor(u)
    p = u - n
    i = int(n % z1)
    j = int(n % z2)
    factor = tooth_pair_factor(i, j, P)
    E = _error_at(pinion_angle_rad, p, i, j, P)
    w = P[I_WIDTH]
    if w > 0.0:
        if p < 0.5 * w:
            o, po, s = -1, p + 1.0, 1.0 - smooth_step(p / w)
        elif p > 1.0 - 0.5 * w:
            o, po, s = 1, p - 1.0, smooth_step((p - 1.0) / w)
        else:
            o, po, s = 0, p, 0.0
        if o != 0:
            io, jo = (i + o) % z1, (j + o) % z2
            factor += s * (tooth_pair_factor(io, jo, P) - factor)
            E += s * (_error_at(pinion_angle_rad, po, io, jo, P) - E)
    return p, factor, E


@njit(cache=True)
def _error_at(pinion_angle_rad: float, p: float, i: int, j: int, P: np.ndarray) -> float:
    """:func:`mesh_error_m` with the mesh phase and the teeth in mesh already known (hot path)."""
    z1, z2 = int(P[I_Z1]), int(P[I_Z2])
    E = tooth_error_m(p, i, P)
    if P[I_ECC_P] != 0.0:
        E += P[I_ECC_P] * math.sin(pinion_angle_rad + P[I_ECC_P_PHASE])
    if P[I_ECC_W] != 0.0:
        E += P[I_ECC_W] * math.sin(pinion_angle_rad * z1 / z2 + P[I_ECC_W_PHASE])
    o = I_HEADER + 2 * z1 + z2 + 2 * int(P[I_NTAB])
    return E - _pit_m(p, i, o, z1, P) - _pit_m(p, j, o + 3 * z1, z2, P)


@njit(cache=True)
def _stiffness_and_factor(pinion_angle_rad: float, p: float, factor: float, P: np.ndarray):
    """Effective k (N/m) and damping factor at mesh phase p, given the period's tooth factor f_i g_j."""
    if P[I_KIND] == PROFILE_PAIRS:  # each pair with its own teeth's factors and damage over its contact
        i, j = teeth_in_mesh(pinion_angle_rad, P)
        k, k_healthy = _pairs_sum(p, i, j, P)
        return k, k / k_healthy  # the damping factor, as f_i g_j in the other profiles
    return stiffness_at_phase(p, P) * factor, factor


@njit(cache=True)
def effective_stiffness_series(pinion_angle_rad: np.ndarray, P: np.ndarray) -> np.ndarray:
    """k_z (N/m) the law uses at each pinion angle: profile, tooth factors and tooth damage included."""
    k = np.empty(pinion_angle_rad.size)
    for m in range(pinion_angle_rad.size):
        p, factor, _ = pair_in_mesh(pinion_angle_rad[m], P)
        k[m] = _stiffness_and_factor(pinion_angle_rad[m], p, factor, P)[0]
    return k


@njit(cache=True)
def contact_force(pinion_angle_rad: float, delta_m: float, delta_rate_m_s: float, P: np.ndarray):
    """Normal mesh force F (N, elastic + damping), the friction force's magnitude ``mu |F| e(p)`` (N, its
    direction comes from the sliding: :func:`friction_force`) and the arms rho_1, rho_2 (m).

    ``pinion_angle_rad`` sets the mesh phase and the teeth in mesh; ``delta_m`` is the deflection
    along the line of action (r1 phi_p - r2 phi_w, plus centre motions in lateral models).
    """
    p, factor, E = pair_in_mesh(pinion_angle_rad, P)
    k, factor = _stiffness_and_factor(pinion_angle_rad, p, factor, P)
    d = delta_m + E
    lu = P[I_LU]
    if d > lu:
        F = k * (d - lu) + P[I_CZ] * factor * delta_rate_m_s
    elif d < -lu:
        F = k * (d + lu) + P[I_CZ] * factor * delta_rate_m_s
    else:
        F = 0.0
    friction_N = P[I_MU] * abs(F) * tooth_change_envelope(p, P)  # |F|: the back flank slides too
    dp = p - P[I_PITCH]
    rho1 = P[I_ARM1] + dp * P[I_PB]
    rho2 = P[I_ARM2] - dp * P[I_PB]
    return F, friction_N, rho1, rho2


@njit(cache=True)
def friction_force(friction_N: float, sliding_velocity_m_s: float, P: np.ndarray) -> float:
    """Signed friction force T (N) of magnitude ``friction_N`` opposing ``sliding_velocity_m_s``, the
    velocity whose product with T is the friction power (``T v <= 0``): ``-friction_N sigma(v / v_0)``."""
    if friction_N == 0.0:
        return 0.0
    return -(friction_N * smooth_sign(sliding_velocity_m_s / P[I_V0]))


@njit(cache=True)
def mesh_contact(
    pinion_angle_rad: float,
    delta_m: float,
    delta_rate_m_s: float,
    pinion_speed_rad_s: float,
    wheel_speed_rad_s: float,
    centre_sliding_m_s: float,
    P: np.ndarray,
):
    """Normal mesh force F (N), friction force T (N), arms rho_1, rho_2 (m) and the sliding velocity
    ``v_sl = rho_1 w_p - rho_2 w_w + centre_sliding`` (m/s) of a parallel mesh; ``centre_sliding_m_s`` is
    ``(u_p' - u_w') . m`` of lateral gears (0 for torsional ones). T opposes v_sl: ``T v_sl <= 0``."""
    F, friction_N, rho1, rho2 = contact_force(pinion_angle_rad, delta_m, delta_rate_m_s, P)
    v_sl = rho1 * pinion_speed_rad_s - rho2 * wheel_speed_rad_s + centre_sliding_m_s
    return F, friction_force(friction_N, v_sl, P), rho1, rho2, v_sl


@njit(cache=True)
def tooth_change_envelope(p: float, P: np.ndarray) -> float:
    """Friction's envelope e(p): with a transition width w, ``(2 S(p/w) - 1)(1 - 2 S((p - 1)/w))``, 0 at the
    tooth change where the arms jump (so T rho stays continuous); 1 elsewhere and when w = 0."""
    w = P[I_WIDTH]
    if w > 0.0:
        return (2.0 * smooth_step(p / w) - 1.0) * (1.0 - 2.0 * smooth_step((p - 1.0) / w))
    return 1.0


@njit(cache=True)
def torsional_mesh_forces(phi_p: float, phi_w: float, w_p: float, w_w: float, P: np.ndarray):
    """Generalised mesh moments on pinion and wheel (N m), eq. (1): -r1 F + T rho_1, r2 F - T rho_2."""
    r1, r2 = P[I_R1], P[I_R2]
    F, T, rho1, rho2, _ = mesh_contact(phi_p, r1 * phi_p - r2 * phi_w, r1 * w_p - r2 * w_w, w_p, w_w, 0.0, P)
    return -r1 * F + T * rho1, r2 * F - T * rho2


@njit(cache=True)
def single_mesh_drive_forces(
    t: float, w_motor: float, phi_p: float, phi_w: float, w_p: float, w_w: float, P: np.ndarray, D: np.ndarray
):
    """Generalised forces of a torsional drive with one mesh, in one call (the solver's hot path):
    motor torque, mesh moments on pinion and wheel (eq. 1), minus the load torque, N m."""
    mp, mw = torsional_mesh_forces(phi_p, phi_w, w_p, w_w, P)
    return motor_torque_at(t, w_motor, D), mp, mw, -load_torque_at(t, D)


@njit(cache=True)
def mesh_contact_series(
    pinion_angle_rad: np.ndarray,
    delta_m: np.ndarray,
    delta_rate_m_s: np.ndarray,
    pinion_speed_rad_s: np.ndarray,
    wheel_speed_rad_s: np.ndarray,
    centre_sliding_m_s: np.ndarray,
    P: np.ndarray,
):
    """:func:`mesh_contact` over arrays: returns F (N), T (N) and the sliding velocity v_sl (m/s)."""
    nt = pinion_angle_rad.size
    F = np.empty(nt)
    T = np.empty(nt)
    v = np.empty(nt)
    for m in range(nt):
        F[m], T[m], _, _, v[m] = mesh_contact(
            pinion_angle_rad[m],
            delta_m[m],
            delta_rate_m_s[m],
            pinion_speed_rad_s[m],
            wheel_speed_rad_s[m],
            centre_sliding_m_s[m],
            P,
        )
    return F, T, v


@njit(cache=True)
def mesh_phase_series(pinion_angle_rad: np.ndarray, P: np.ndarray):
    """Mesh phase p in [0, 1), pinion tooth i and wheel tooth j in mesh, for each angle."""
    z1, z2 = int(P[I_Z1]), int(P[I_Z2])
    nt = pinion_angle_rad.size
    p = np.empty(nt)
    i = np.empty(nt, np.int64)
    j = np.empty(nt, np.int64)
    for m in range(nt):
        u = pinion_angle_rad[m] * z1 / (2.0 * math.pi)
        n = math.floor(u)
        p[m] = u - n
        i[m] = int(n % z1)
        j[m] = int(n % z2)
    return p, i, j


@njit(cache=True)
def mesh_gap_series(pinion_angle_rad: np.ndarray, delta_m: np.ndarray, P: np.ndarray) -> np.ndarray:
    """d = delta + E(p) over arrays, m: contact starts or ends where d crosses +-l_u."""
    d = np.empty(pinion_angle_rad.size)
    for m in range(pinion_angle_rad.size):
        d[m] = delta_m[m] + mesh_error_m(pinion_angle_rad[m], P)
    return d


def mesh_breakpoint_phases(P: np.ndarray) -> np.ndarray:
    """Mesh phases in [0, 1) where the force law jumps at fixed deflection: the tooth change (p = 0,
    per-tooth stiffness factors, the friction arms), the single/double contact switches and pit edges. (The
    friction direction follows the sliding velocity, blended over ``|v_sl| < v_0``: no jump at the pitch
    point.)
    None with a non-zero transition width: the law is then continuous in the phase."""
    if P[I_WIDTH] > 0.0:
        return np.zeros(0)
    phases = [0.0]
    if P[I_KIND] != PROFILE_TABLE and 0.0 < P[I_HALF_DOUBLE] < 0.5:
        phases += [P[I_HALF_DOUBLE], 1.0 - P[I_HALF_DOUBLE]]
    z1, z2 = int(P[I_Z1]), int(P[I_Z2])
    o = I_HEADER + 2 * z1 + z2 + 2 * int(P[I_NTAB])
    for offset, teeth in ((o, z1), (o + 3 * z1, z2)):
        pitted = P[offset : offset + teeth] != 0.0
        phases += list(P[offset + teeth : offset + 2 * teeth][pitted])
        phases += list(P[offset + 2 * teeth : offset + 3 * teeth][pitted] % 1.0)
    return np.unique(np.array(phases))


def mean_stiffness_N_per_m(P: np.ndarray) -> float:
    """Exact mean of k_z(p) over one mesh period (healthy teeth), for linearised modes."""
    if P[I_KIND] == PROFILE_CONTACT_RATIO:
        h2 = 2.0 * P[I_HALF_DOUBLE]  # eps - 1
        return float(h2 * P[I_KDOUBLE] + (1.0 - h2) * P[I_KSINGLE])
    if P[I_KIND] == PROFILE_PAIRS:  # each pair contributes its table's integral over its contact
        n, h = int(P[I_PAIR_N]), P[I_HALF_DOUBLE]
        o = _pairs_offset(P)
        k = P[o : o + n]
        return float(0.5 * np.sum(k[1:] + k[:-1]) * (1.0 + 2.0 * h) / (n - 1))
    z1, z2, n = int(P[I_Z1]), int(P[I_Z2]), int(P[I_NTAB])
    o = I_HEADER + 2 * z1 + z2
    ph = np.append(P[o : o + n], P[o] + 1.0)
    kk = np.append(P[o + n : o + 2 * n], P[o + n])
    return float(np.sum(0.5 * (kk[1:] + kk[:-1]) * np.diff(ph)))
