"""The whole mesh law at a mesh coordinate u, literal and vectorised (used by the self-checks, the
steady initial states and the tests; the integration uses its locked-mode form, :mod:`.modes`):
the total error (triangle + run-out + pits, blended at the tooth change with a transition width), the
effective stiffness and damping factor, the "pairs" sum, the mesh force and the friction (its force
from the sliding velocity, moments and power).
"""

from __future__ import annotations

import math

import numpy as np

from .law_terms import (
    base_stiffness,
    contact_weight,
    error_shape,
    error_shape_ext,
    friction_envelope,
    friction_sigma,
    friction_transition_speed,
    half_double,
    mesh_law,
    pair_table,
    pit_error,
    runout_error,
    smooth_step,
    tooth_error_amplitudes,
    tooth_factors,
    transition_width,
)
from .scenario import TWO_PI


def total_error(scenario: dict, u):
    """The whole error E at the mesh coordinate u: triangular shape (eq. 6) + run-out + pits
    (with w > 0 blended with the outgoing / incoming pair near the tooth change, :func:`blended_law`)."""
    if transition_width(scenario["design"]["mesh"]) > 0.0:
        return blended_law(scenario, u)[1]
    u = np.asarray(u, dtype=float)
    n = np.floor(u).astype(np.int64)
    p = u - n
    i = np.mod(n, int(scenario["design"]["pinion"]["teeth"]))
    j = np.mod(n, int(scenario["design"]["wheel"]["teeth"]))
    a = float(scenario["production"]["error_mode"]["a"])
    E = error_shape(p, a, tooth_error_amplitudes(scenario)[i])
    return E + runout_error(scenario, u) + pit_error(scenario, p, i, j)


def pair_law(scenario: dict, m, q):
    """Tooth factor f_i g_j and error (triangle + pits, no run-out) of the pair of mesh period m
    (i = m mod z1, j = m mod z2) evaluated at phase q (possibly outside [0, 1))."""
    z1 = int(scenario["design"]["pinion"]["teeth"])
    z2 = int(scenario["design"]["wheel"]["teeth"])
    m = np.asarray(m, dtype=np.int64)
    i, j = np.mod(m, z1), np.mod(m, z2)
    f, g = tooth_factors(scenario)
    a = float(scenario["production"]["error_mode"]["a"])
    E = error_shape_ext(q, a, tooth_error_amplitudes(scenario)[i]) + pit_error(scenario, q, i, j)
    return f[i] * g[j], E


def blended_law(scenario: dict, u) -> tuple[np.ndarray, np.ndarray]:
    """Tooth factor f g and whole error E at the mesh coordinate u, blended at the tooth change:
    p < w/2: X = X_out + S(p/w) (X_in - X_out), outgoing pair (i - 1, j - 1) at phase p + 1;
    p > 1 - w/2: X = X_in + S((p - 1)/w) (X_next - X_in), incoming pair (i + 1, j + 1) at p - 1.
    The run-out (a function of u only) is the same for all pairs and is added once.
    With w = 0: f_i g_j and the sharp E."""
    u = np.asarray(u, dtype=float)
    n = np.floor(u).astype(np.int64)
    p = u - n
    w = transition_width(scenario["design"]["mesh"])
    fg_in, E_in = pair_law(scenario, n, p)
    if w > 0.0:
        fg_out, E_out = pair_law(scenario, n - 1, p + 1.0)
        fg_nx, E_nx = pair_law(scenario, n + 1, p - 1.0)
        s0, s1 = smooth_step(p / w), smooth_step((p - 1.0) / w)
        low, high = p < w / 2, p > 1.0 - w / 2
        fg_hi = np.where(high, fg_in + s1 * (fg_nx - fg_in), fg_in)
        fg = np.where(low, fg_out + s0 * (fg_in - fg_out), fg_hi)
        E = np.where(low, E_out + s0 * (E_in - E_out), np.where(high, E_in + s1 * (E_nx - E_in), E_in))
    else:
        fg, E = fg_in, E_in
    return fg, E + runout_error(scenario, u)


def pair_stiffness(scenario: dict, u, healthy: bool = False):
    """The "pairs" law at the mesh coordinate u (literal): with p, n from u and the period's teeth
    (i, j) = (n mod z1, n mod z2), k = sum over o = -1, 0, +1 of c(q) K(q) f_io g_jo R_pinion,io(q)
    R_wheel,jo(q), q = p - o, (io, jo) = (i + o, j + o) (modulo z1, z2); K and R linear between the
    grid points and held at their end values outside.  healthy: all f, g, R = 1 (:func:`base_stiffness`)."""
    mesh = scenario["design"]["mesh"]
    u = np.asarray(u, dtype=float)
    n = np.floor(u).astype(np.int64)
    p = u - n
    if healthy:
        return base_stiffness(p, mesh)
    z1 = int(scenario["design"]["pinion"]["teeth"])
    z2 = int(scenario["design"]["wheel"]["teeth"])
    grid, K, ratios = pair_table(mesh)
    h, w = half_double(mesh), transition_width(mesh)
    f, g = tooth_factors(scenario)
    k = np.zeros(u.shape)
    for o in (-1, 0, 1):
        q = p - o
        io, jo = np.mod(n + o, z1), np.mod(n + o, z2)
        term = contact_weight(q, h, w) * np.interp(q, grid, K) * f[io] * g[jo]
        for (gear, tooth), R in ratios.items():
            on = (io if gear == "pinion" else jo) == tooth
            term = term * np.where(on, np.interp(q, grid, R), 1.0)
        k = k + term
    return k


def effective_stiffness(scenario: dict, u) -> tuple[np.ndarray, np.ndarray]:
    """Stiffness k of the law at the mesh coordinate u and the factor of its damping: k_z(p) f_i g_j and
    f_i g_j (w > 0: the blended factor); "pairs": the pair sum and k / k_healthy."""
    mesh = scenario["design"]["mesh"]
    u = np.asarray(u, dtype=float)
    if mesh_law(mesh) == "pairs":
        k = pair_stiffness(scenario, u)
        return k, k / pair_stiffness(scenario, u, healthy=True)
    n = np.floor(u).astype(np.int64)
    p = u - n
    if transition_width(mesh) > 0.0:  # factor blended with the outgoing / incoming pair
        fg = blended_law(scenario, u)[0]
    else:
        f, g = tooth_factors(scenario)
        fg = f[np.mod(n, int(scenario["design"]["pinion"]["teeth"]))]
        fg = fg * g[np.mod(n, int(scenario["design"]["wheel"]["teeth"]))]
    return base_stiffness(p, mesh) * fg, fg


def mesh_force_literal(scenario: dict, u, delta, delta_dot) -> dict:
    """Vectorised, literal transcription of the mesh-force paragraph (used by the self-checks).

    u: pinion mesh coordinate phi_p z1 / (2 pi); delta = r1 phi_p - r2 phi_w; delta_dot its rate.
    E is the total error (triangular shape, run-out, pits); it enters d only, never the damping.
    """
    d_ = scenario["design"]
    mesh = d_["mesh"]
    z1, z2 = int(d_["pinion"]["teeth"]), int(d_["wheel"]["teeth"])
    u = np.asarray(u, dtype=float)
    n = np.floor(u).astype(np.int64)
    p = u - n
    i = np.mod(n, z1)
    j = np.mod(n, z2)
    # k = k_z(p) f_i g_j and the damping factor f_i g_j (w > 0: blended at the tooth change);
    # "pairs": the sum over the pairs in contact and k / k_healthy
    k, fg = effective_stiffness(scenario, u)
    Cf = float(mesh["damping_Ns_per_m"]) * fg
    if transition_width(mesh) > 0.0:  # error blended near the tooth change
        E = blended_law(scenario, u)[1]
    else:
        e_i = tooth_error_amplitudes(scenario)[i]
        E = error_shape(p, float(scenario["production"]["error_mode"]["a"]), e_i)
        E = E + runout_error(scenario, u) + pit_error(scenario, p, i, j)  # fault errors: in d only
    d = np.asarray(delta, dtype=float) + E
    lu = float(mesh["backlash_um"]) * 1e-6
    F_el = k * np.maximum(d - lu, np.minimum(d + lu, 0.0))
    contact = np.abs(d) > lu
    F_t = np.where(contact, Cf * np.asarray(delta_dot, float), 0.0)
    return {
        "F": F_el + F_t,
        "F_el": F_el,
        "F_t": F_t,
        "p": p,
        "i": i,
        "j": j,
        "k": k,
        "E": E,
        "d": d,
        "fg": fg,
    }


def friction_moments(scenario: dict, p, F, w_p, w_w, v_centres=0.0) -> dict:
    """Friction of the mesh (literal, docs/scenario.md "Friction"): arms rho_1 = r1 tan(alpha_w) + (p -
    pitch) p_b, rho_2 = r2 tan(alpha_w) - (p - pitch) p_b, sliding velocity v_sl = rho_1 w_p - rho_2 w_w
    + v_centres (lateral models: (u_p' - u_w') . m), T = -mu |F| e(p) sigma(v_sl / v_0), the moments
    M_zt1 = T rho_1, M_zt2 = T rho_2 and the friction power P_f = T v_sl (<= 0)."""
    d_ = scenario["design"]
    mesh = d_["mesh"]
    r1, r2 = float(d_["pinion"]["base_radius_m"]), float(d_["wheel"]["base_radius_m"])
    z1 = int(d_["pinion"]["teeth"])
    ppp = float(mesh["pitch_point_phase"])
    tan_a = math.tan(math.radians(float(mesh["pressure_angle_deg"])))
    pb = TWO_PI * r1 / z1
    p = np.asarray(p, dtype=float)
    rho1 = r1 * tan_a + (p - ppp) * pb
    rho2 = r2 * tan_a - (p - ppp) * pb
    v_sl = rho1 * np.asarray(w_p, dtype=float) - rho2 * np.asarray(w_w, dtype=float) + v_centres
    mu = float(scenario["condition"]["friction_coefficient"])
    e = friction_envelope(p, transition_width(mesh))
    sigma = friction_sigma(v_sl / friction_transition_speed(scenario))
    T = -mu * np.abs(np.asarray(F, dtype=float)) * e * sigma
    return {
        "T": T,
        "rho1": rho1,
        "rho2": rho2,
        "v_sl": v_sl,
        "M_zt1": T * rho1,
        "M_zt2": T * rho2,
        "P_f": T * v_sl,
    }
