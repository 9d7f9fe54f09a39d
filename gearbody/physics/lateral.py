"""Lateral mesh geometry and forces: gears whose centres move on bearings (Figs. 17, 18). Engine-free.

Conventions (docs/scenario.md, "Lateral models"): ``n`` is the unit line of action (direction of the
mesh force the pinion exerts on the wheel), ``m = s1 z x n`` the friction direction with ``s1`` the
pinion's rotation sense. The deflection includes the centre displacements projected on the line of
action, ``delta = r1 phi_p - r2 phi_w + (u_p - u_w) . n``; the pinion receives ``-F n + T m`` and the
moment ``-r1 F + T rho_1``, the wheel ``+F n - T m`` and ``r2 F - T rho_2`` (action and reaction; the
paper's eqs. (7) and (9) print the same sign on both gears). T opposes the sliding velocity
``rho_1 phi_p' - rho_2 phi_w' + (u_p' - u_w') . m`` (free directions only), so ``T v_sl <= 0``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .mesh import I_R1, I_R2, mesh_contact


def mesh_directions(centre_line_deg: float, line_of_action_deg: float) -> tuple[np.ndarray, np.ndarray, int]:
    """Line of action n, friction direction m and the pinion's rotation sense s1 (+1 counter-clockwise)."""
    lam, gam = math.radians(line_of_action_deg), math.radians(centre_line_deg)
    n = np.array([math.cos(lam), math.sin(lam)])
    e_perp = np.array([-math.sin(gam), math.cos(gam)])
    s1 = 1 if n @ e_perp > 0 else -1
    m = s1 * np.array([-n[1], n[0]])
    return n, m, s1


# Index array of a lateral mesh connector: positions in the connector's coordinate vector q of
# [pinion rotation, pinion x, pinion y, wheel rotation, wheel x, wheel y]; -1 where a gear has no
# such coordinate (a torsional gear) -- a direction held fixed still has a coordinate, always 0.
@njit(cache=True)
def lateral_mesh_forces(q, q_t, idx, geometry, P):
    """Generalised forces of one mesh on its connector coordinates (N and N m).

    ``geometry = [n_x, n_y, m_x, m_y, free_px, free_py, free_wx, free_wy]`` (free_* are 1.0 for a free
    direction, 0.0 for a fixed one: fixed directions receive no force).
    """
    r1, r2 = P[I_R1], P[I_R2]
    nx, ny, mx, my = geometry[0], geometry[1], geometry[2], geometry[3]
    ip, iw = idx[0], idx[3]
    delta = r1 * q[ip] - r2 * q[iw]
    rate = r1 * q_t[ip] - r2 * q_t[iw]
    if idx[1] >= 0:
        delta += q[idx[1]] * nx + q[idx[2]] * ny
        rate += q_t[idx[1]] * nx + q_t[idx[2]] * ny
    if idx[4] >= 0:
        delta -= q[idx[4]] * nx + q[idx[5]] * ny
        rate -= q_t[idx[4]] * nx + q_t[idx[5]] * ny
    # sliding of the pinion's flank point relative to the wheel's along m (the power of a unit T)
    sliding = 0.0
    if idx[1] >= 0:
        sliding += q_t[idx[1]] * mx * geometry[4] + q_t[idx[2]] * my * geometry[5]
    if idx[4] >= 0:
        sliding -= q_t[idx[4]] * mx * geometry[6] + q_t[idx[5]] * my * geometry[7]
    F, T, rho1, rho2, _ = mesh_contact(q[ip], delta, rate, q_t[ip], q_t[iw], sliding, P)
    out = np.zeros(q.size)
    out[ip] = -r1 * F + T * rho1
    out[iw] = r2 * F - T * rho2
    fx, fy = -F * nx + T * mx, -F * ny + T * my  # on the pinion; the wheel gets the opposite
    if idx[1] >= 0:
        out[idx[1]] = fx * geometry[4]
        out[idx[2]] = fy * geometry[5]
    if idx[4] >= 0:
        out[idx[4]] = -fx * geometry[6]
        out[idx[5]] = -fy * geometry[7]
    return out


def static_bearing_displacement_m(law, force_on_gear_N, free_directions: tuple[int, ...]) -> np.ndarray:
    """Centre displacement u0 at which the bearing balances a static force on the gear (free directions).

    Closed forms for the linear and Hertzian laws (docs/scenario.md); any other law is solved with
    scipy's root finder from guesses 1 to 300 um along the force (a law with angles at its angles 0).
    """
    from .bearings import HertzianBearing, LinearBearing

    f = np.zeros(2)
    for d in free_directions:
        f[d] = force_on_gear_N[d]
    if not free_directions or not np.any(f):
        return np.zeros(2)
    if isinstance(law, LinearBearing):
        return np.array([f[0] / law.stiffness_x_N_per_m, f[1] / law.stiffness_y_N_per_m])
    if isinstance(law, HertzianBearing):
        size = float(np.hypot(*f))
        reach = law.radial_clearance_m + (size / law.contact_stiffness_N_per_m_n) ** (1.0 / law.exponent)
        return f / size * reach
    from scipy.optimize import root

    free = list(free_directions)

    scale_N = float(np.hypot(*f))

    def residual(x_um):  # micrometres and relative force keep the problem well scaled
        u = np.zeros(2)
        u[free] = x_um * 1e-6
        return (np.asarray(law.force_N(u, np.zeros(2)), float) + f)[free] / scale_N

    for reach_um in (1.0, 3.0, 10.0, 30.0, 100.0, 300.0):  # along the force, beyond any clearance
        sol = root(
            residual, reach_um * f[free] / scale_N, method="lm", options={"xtol": 1e-15, "ftol": 1e-15}
        )
        if sol.success and np.max(np.abs(residual(sol.x))) <= 1e-9:
            break
    else:
        raise ValueError(f"no static equilibrium of the bearing law {law!r} under {f} N: {sol.message}")
    u = np.zeros(2)
    u[free] = sol.x * 1e-6
    return u


def tangent_stiffness_N_per_m(law, displacement_m, relative_step: float = 1e-6) -> np.ndarray:
    """2x2 tangent stiffness -d f_b / d u of a bearing law at a displacement (central differences)."""
    u0 = np.asarray(displacement_m, float)
    h = max(relative_step * float(np.hypot(*u0)), 1e-12)
    K = np.zeros((2, 2))
    for d in range(2):
        du = np.zeros(2)
        du[d] = h
        K[:, d] = -(np.asarray(law.force_N(u0 + du, np.zeros(2))) - law.force_N(u0 - du, np.zeros(2))) / (
            2 * h
        )
    return K
