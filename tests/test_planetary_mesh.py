"""Exact planar kinematics of the planetary meshes (gearbody.physics.planetary_mesh) against finite
differences, rigid motions, hand-computed centre-distance changes and the Willis kinematics of a whole
stage."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearbody.physics.planetary_mesh import involute, pair_deflection, pair_deflection_rate

ALPHA0 = math.radians(20.0)
M = 0.004  # module, m
Z_S, Z_P, Z_R = 21, 30, 81
R_S, R_P, R_R = (M * z / 2 for z in (Z_S, Z_P, Z_R))  # pitch radii
RB_S, RB_P, RB_R = (r * math.cos(ALPHA0) for r in (R_S, R_P, R_R))


def _pair(internal: bool, psi: float = 0.7, dc=(0.0, 0.0)) -> np.ndarray:
    """Member 1 at the origin, member 2 on the standard centre distance at angle psi (+ dc)."""
    D = R_R - R_P if internal else R_S + R_P
    return np.array([0.0, 0.0, 0.3, D * math.cos(psi) + dc[0], D * math.sin(psi) + dc[1], -0.2])


@pytest.mark.parametrize("internal", [False, True])
def test_the_gradient_is_plus_minus_the_base_radii_and_the_line_of_action(internal):
    rb1 = RB_R if internal else RB_S
    q = _pair(internal, dc=(3e-5, -2e-5))
    delta, nx, ny, phi, alpha = pair_deflection(q, rb1, RB_P, internal, 0.7)
    assert math.hypot(nx, ny) == pytest.approx(1.0)
    h = 1e-7
    grad = np.empty(6)
    for k in range(6):
        e = np.zeros(6)
        e[k] = h
        grad[k] = (
            pair_deflection(q + e, rb1, RB_P, internal, 0.7)[0]
            - pair_deflection(q - e, rb1, RB_P, internal, 0.7)[0]
        ) / (2 * h)
    expected = np.array([nx, ny, rb1, -nx, -ny, -RB_P if internal else RB_P])
    np.testing.assert_allclose(grad, expected, rtol=1e-6, atol=1e-8)
    # the rate is the gradient times the velocities
    qt = np.array([0.3, -0.1, 12.0, 0.2, 0.4, -7.0])
    assert pair_deflection_rate(q, qt, rb1, RB_P, internal) == pytest.approx(float(grad @ qt), rel=1e-6)
    # the line of action makes the operating pressure angle with the normal of the line of centres, on
    # the sun mesh leaning towards the planet, on the ring mesh away from it (mirrored lines of action)
    e = np.array([math.cos(phi), math.sin(phi)])
    assert float(np.dot([nx, ny], e)) == pytest.approx(-math.sin(alpha) if internal else math.sin(alpha))
    assert float(np.dot([nx, ny], [-e[1], e[0]])) == pytest.approx(math.cos(alpha))


@pytest.mark.parametrize("internal", [False, True])
def test_rigid_rotation_and_rolling_leave_the_deflection_unchanged(internal):
    rb1 = RB_R if internal else RB_S
    q0 = _pair(internal)
    d0 = pair_deflection(q0, rb1, RB_P, internal, 0.7)[0]
    for psi in (0.5, 2.0, 9.0, -4.0):
        c, s = math.cos(psi), math.sin(psi)
        rotated = q0.copy()
        for i in (0, 3):
            rotated[i], rotated[i + 1] = c * q0[i] - s * q0[i + 1], s * q0[i] + c * q0[i + 1]
        rotated[[2, 5]] += psi  # the whole pair turns rigidly about the origin
        assert pair_deflection(rotated, rb1, RB_P, internal, 0.7 + psi)[0] == pytest.approx(d0, abs=1e-12)
        rolled = rotated.copy()
        rolled[2] = q0[2]  # member 1 held; member 2 rolls around it: spin (1 +- r_b1 / r_b2) psi
        rolled[5] = q0[5] + psi * (1 - rb1 / RB_P if internal else 1 + rb1 / RB_P)
        assert pair_deflection(rolled, rb1, RB_P, internal, 0.7 + psi)[0] == pytest.approx(d0, abs=1e-12)


@pytest.mark.parametrize("internal", [False, True])
def test_a_larger_centre_distance_opens_the_external_mesh_and_closes_the_internal_one(internal):
    rb1 = RB_R if internal else RB_S
    R = rb1 - RB_P if internal else rb1 + RB_P
    psi = 0.7
    q = _pair(internal, psi)
    D0 = math.hypot(q[3], q[4])
    dD = 20e-6
    moved = _pair(internal, psi, dc=(dD * math.cos(psi), dD * math.sin(psi)))
    change = (
        pair_deflection(moved, rb1, RB_P, internal, psi)[0] - pair_deflection(q, rb1, RB_P, internal, psi)[0]
    )
    exact = R * (involute(math.acos(R / (D0 + dD))) - involute(math.acos(R / D0)))
    assert change == pytest.approx(exact if internal else -exact, rel=1e-9)
    assert change == pytest.approx((1 if internal else -1) * math.sin(ALPHA0) * dD, rel=1e-3)  # first order


def test_a_ring_fixed_stage_turning_by_the_willis_kinematics_keeps_every_mesh_deflection():
    """Sun input, ring fixed: carrier theta_c, sun (1 + z_r / z_s) theta_c, planets (1 - z_r / z_p) theta_c;
    the planet centres on the carrier circle r_s + r_p at theta_c + psi_n (three equally spaced)."""
    r_c = R_S + R_P
    psis = [2 * math.pi * n / 3 for n in range(3)]
    ref = None
    for theta_c in np.linspace(0.0, 12.0, 25):
        theta_s = theta_c * (1 + Z_R / Z_S)
        theta_p = theta_c * (1 - Z_R / Z_P)
        out = []
        for psi in psis:
            cx, cy = r_c * math.cos(theta_c + psi), r_c * math.sin(theta_c + psi)
            sun = pair_deflection(
                np.array([0.0, 0.0, theta_s, cx, cy, theta_p]), RB_S, RB_P, False, theta_c + psi
            )[0]
            ring = pair_deflection(
                np.array([0.0, 0.0, 0.0, cx, cy, theta_p]), RB_R, RB_P, True, theta_c + psi
            )[0]
            out += [sun, ring]
        if ref is None:
            ref = out
        np.testing.assert_allclose(out, ref, atol=1e-12)


def _constant_mesh(z1: int, z2: int, r1: float, r2: float, k: float = 5e8, c: float = 0.0) -> np.ndarray:
    from gearbody.physics.mesh import pack_mesh_parameters

    return pack_mesh_parameters(
        r1_m=r1, r2_m=r2, z1=z1, z2=z2, stiffness_single_N_per_m=k, stiffness_double_N_per_m=k,
        contact_ratio=1.6, damping_Ns_per_m=c, backlash_m=0.0, friction_coefficient=0.0,
        pitch_point_phase=0.5, pressure_angle_rad=ALPHA0, error_a=0.0, error_depths_m=np.zeros(z1),
    )  # fmt: skip


def test_planet_forces_are_minus_the_gradient_of_the_mesh_and_bearing_energy():
    """Constant stiffness, no backlash, no damping: the forces derive from V = k_s d_s^2 / 2 + k_r d_r^2 / 2
    + k_b |e|^2 / 2, so the whole stage is conservative (every sign and arm of the 12 forces checked)."""
    from gearbody.physics import planetary_mesh as pm

    k_s, k_r, k_b = 5e8, 6e8, 1e8
    P_s, P_r = _constant_mesh(Z_S, Z_P, RB_S, RB_P, k_s), _constant_mesh(Z_R, Z_P, RB_R, RB_P, k_r)
    G = np.zeros(pm.G_SIZE)
    G[[pm.G_RB_SUN, pm.G_RB_PLANET, pm.G_RB_RING, pm.G_CARRIER_RADIUS, pm.G_PSI]] = (
        RB_S,
        RB_P,
        RB_R,
        R_S + R_P,
        2.1,
    )
    G[pm.G_BEARING_K] = k_b
    rng = np.random.default_rng(4)
    theta_c = 5.3
    r_c = R_S + R_P
    planet = [r_c * math.cos(theta_c + 2.1), r_c * math.sin(theta_c + 2.1), -0.7]
    q = np.array([0, 0, 1.1, 0, 0, 0.2, 0, 0, theta_c, *planet])
    q = q + rng.normal(0.0, 2e-5, 12)  # a few um and urad off the assembly everywhere
    G[pm.G_DELTA0_SUN] = (
        pm.pair_deflection(q[[0, 1, 2, 9, 10, 11]], RB_S, RB_P, False, theta_c + 2.1)[0] - 3e-6
    )
    G[pm.G_DELTA0_RING] = (
        pm.pair_deflection(q[[3, 4, 5, 9, 10, 11]], RB_R, RB_P, True, theta_c + 2.1)[0] + 2e-6
    )

    def energy(x):
        phi_ref = x[8] + 2.1
        d_s = pm.pair_deflection(x[[0, 1, 2, 9, 10, 11]], RB_S, RB_P, False, phi_ref)[0] - G[pm.G_DELTA0_SUN]
        d_r = pm.pair_deflection(x[[3, 4, 5, 9, 10, 11]], RB_R, RB_P, True, phi_ref)[0] - G[pm.G_DELTA0_RING]
        e = x[9:11] - (x[6:8] + r_c * np.array([math.cos(phi_ref), math.sin(phi_ref)]))
        return 0.5 * k_s * d_s**2 + 0.5 * k_r * d_r**2 + 0.5 * k_b * float(e @ e)

    f, F_s, F_r = pm.planet_forces(q, np.zeros(12), G, P_s, P_r)
    assert F_s == pytest.approx(3e-6 * k_s, rel=1e-3) and F_r == pytest.approx(-2e-6 * k_r, rel=1e-3)
    h = 1e-9
    grad = np.array([(energy(q + h * e) - energy(q - h * e)) / (2 * h) for e in np.eye(12)])
    np.testing.assert_allclose(f, -grad, rtol=1e-5, atol=1e-3)
