"""The mesh force law of eqs. (4)-(6) plus friction, against hand-computed values."""

import math

import numpy as np
import pytest

from gearbody.physics import (
    contact_force,
    error_shape,
    kloss_torque_Nm,
    mesh_contact,
    pack_mesh_parameters,
    profile_integral,
    profile_value,
    steady_slip,
    tooth_error_depths_m,
    tooth_random_factors,
    torsional_mesh_forces,
)

R1, R2, Z1, Z2 = 0.05, 0.15, 20, 60
K1, K2, EPS = 1.0e9, 1.5e9, 1.6  # single, double contact; h = 0.3


def params(**kw):
    base = dict(
        r1_m=R1,
        r2_m=R2,
        z1=Z1,
        z2=Z2,
        stiffness_single_N_per_m=K1,
        stiffness_double_N_per_m=K2,
        contact_ratio=EPS,
        damping_Ns_per_m=0.0,
        backlash_m=0.0,
        friction_coefficient=0.0,
        pitch_point_phase=0.5,
        pressure_angle_rad=math.radians(20),
        error_a=0.5,
        error_depths_m=np.zeros(Z1),
    )
    base.update(kw)
    return pack_mesh_parameters(**base)


def angle_at(tooth: int, phase: float) -> float:
    """Pinion angle at which mesh period `tooth` is at `phase`."""
    return (tooth + phase) * 2 * math.pi / Z1


def test_stiffness_switches_between_double_and_single_contact_by_contact_ratio():
    P = params()
    d = 1e-5
    assert contact_force(angle_at(0, 0.1), d, 0.0, P)[0] == pytest.approx(K2 * d)  # p < h = 0.3
    assert contact_force(angle_at(0, 0.5), d, 0.0, P)[0] == pytest.approx(K1 * d)
    assert contact_force(angle_at(0, 0.29), d, 0.0, P)[0] == pytest.approx(K2 * d)
    assert contact_force(angle_at(0, 0.31), d, 0.0, P)[0] == pytest.approx(K1 * d)
    assert contact_force(angle_at(0, 0.71), d, 0.0, P)[0] == pytest.approx(K2 * d)  # p >= 1 - h


def test_dead_zone_edges_and_continuity_in_deflection():
    lu = 20e-6
    P = params(backlash_m=lu)
    phi = angle_at(3, 0.5)  # single contact, k = K1
    for d in (-lu, -0.5 * lu, 0.0, 0.5 * lu, lu):
        assert contact_force(phi, d, 0.0, P)[0] == 0.0
    assert contact_force(phi, lu + 1e-6, 0.0, P)[0] == pytest.approx(K1 * 1e-6)
    assert contact_force(phi, -lu - 1e-6, 0.0, P)[0] == pytest.approx(-K1 * 1e-6)  # back flank
    eps = 1e-12
    assert abs(contact_force(phi, lu + eps, 0.0, P)[0]) < K1 * 2 * eps  # no jump at the edge


def test_damping_acts_only_in_contact():
    lu, C = 10e-6, 5000.0
    P = params(backlash_m=lu, damping_Ns_per_m=C)
    phi = angle_at(0, 0.5)
    assert contact_force(phi, 0.0, 0.3, P)[0] == 0.0  # in the gap: no damping force
    assert contact_force(phi, lu + 1e-6, 0.3, P)[0] == pytest.approx(K1 * 1e-6 + C * 0.3)


def test_error_peaks_at_position_a_with_per_tooth_depth():
    e = tooth_error_depths_m(10.0, 0.3, Z1, seed=7)
    for a in (0.1, 0.5, 0.9):
        P = params(error_a=a, error_depths_m=e)
        tooth = 4
        F = contact_force(angle_at(tooth, a), 0.0, 0.0, P)[0]
        k = K2 if (a < 0.3 or a >= 0.7) else K1
        assert F == pytest.approx(k * e[tooth], rel=1e-9)
        # zero at both ends of the mesh period
        assert contact_force(angle_at(tooth, 0.0), 0.0, 0.0, P)[0] == pytest.approx(0.0, abs=1e-9)
    assert error_shape(0.25, 0.5) == pytest.approx(0.5)
    assert error_shape(0.75, 0.5) == pytest.approx(0.5)
    assert error_shape(0.05, 0.1) == pytest.approx(0.5)
    assert error_shape(0.55, 0.1) == pytest.approx(0.5)


def test_random_tooth_errors_follow_eq6_and_are_reproducible_from_the_seed():
    li = np.random.default_rng(3).random(Z1)
    assert np.array_equal(tooth_random_factors(Z1, 3), li)
    e = tooth_error_depths_m(12.0, 0.3, Z1, seed=3)
    assert np.allclose(e, (1 - 0.3 * (1 - li)) * 12e-6)
    assert np.array_equal(e, tooth_error_depths_m(12.0, 0.3, Z1, seed=3))
    assert not np.array_equal(e, tooth_error_depths_m(12.0, 0.3, Z1, seed=4))
    assert np.allclose(tooth_error_depths_m(12.0, 0.0, Z1, seed=3), 12e-6)  # r = 0: no scatter
    assert np.all(e <= 12e-6) and np.all(e >= 0.7 * 12e-6)


def test_tooth_in_mesh_follows_the_pinion_angle_and_damage_repeats_once_per_revolution():
    f = np.ones(Z1)
    f[5] = 0.2
    P = params(pinion_factors=f)
    d = 1e-5
    assert contact_force(angle_at(5, 0.5), d, 0.0, P)[0] == pytest.approx(0.2 * K1 * d)
    assert contact_force(angle_at(5 + Z1, 0.5), d, 0.0, P)[0] == pytest.approx(0.2 * K1 * d)
    assert contact_force(angle_at(6, 0.5), d, 0.0, P)[0] == pytest.approx(K1 * d)
    g = np.ones(Z2)
    g[7] = 0.0  # broken wheel tooth: wheel tooth j = n mod z2
    P = params(wheel_factors=g)
    assert contact_force(angle_at(7, 0.5), d, 0.0, P)[0] == 0.0
    assert contact_force(angle_at(7 + Z2, 0.5), d, 0.0, P)[0] == 0.0
    assert contact_force(angle_at(7 + Z1, 0.5), d, 0.0, P)[0] == pytest.approx(K1 * d)


def test_friction_reverses_at_the_pitch_point_in_forward_rolling_and_with_the_sliding_backwards():
    mu = 0.08
    P = params(friction_coefficient=mu)
    d = 1e-5
    alpha = math.radians(20)
    pb = 2 * math.pi * R1 / Z1
    for w1 in (100.0, -100.0):  # forward motoring, then the same states turning backwards
        w2 = w1 * R1 / R2  # rolling: w1 r1 = w2 r2
        for p, sign in ((0.4, 1.0), (0.6, -1.0)):
            F, T, rho1, rho2, v_sl = mesh_contact(angle_at(2, p), d, 0.0, w1, w2, 0.0, P)
            assert F > 0
            assert T == pytest.approx(sign * math.copysign(1.0, w1) * mu * abs(F))  # the paper's reversal
            assert rho1 == pytest.approx(R1 * math.tan(alpha) + (p - 0.5) * pb)
            assert rho2 == pytest.approx(R2 * math.tan(alpha) - (p - 0.5) * pb)
            assert v_sl == pytest.approx(rho1 * w1 - rho2 * w2)
            assert v_sl == pytest.approx((p - 0.5) * pb * (w1 + w2))  # rolling sliding, by hand
            assert T * v_sl < 0  # friction power T (rho1 w1 - rho2 w2) dissipates
    # moments of eq. (1): pinion -r1 F + T rho1, wheel r2 F - T rho2
    phi = angle_at(2, 0.4)
    for w1 in (100.0, -100.0):
        F, T, rho1, rho2, _ = mesh_contact(phi, d, 0.0, w1, w1 * R1 / R2, 0.0, P)
        m1, m2 = torsional_mesh_forces(phi, (R1 * phi - d) / R2, w1, w1 * R1 / R2, P)
        assert m1 == pytest.approx(-R1 * F + T * rho1)
        assert m2 == pytest.approx(R2 * F - T * rho2)


def test_friction_direction_is_regularised_below_the_transition_speed():
    mu, v0 = 0.08, 2e-3
    P = params(friction_coefficient=mu, friction_transition_speed_m_s=v0)
    phi, d = angle_at(2, 0.4), 1e-5
    F = contact_force(phi, d, 0.0, P)[0]

    def T(v):  # the sliding set through the centres' term alone: rho1 w1 - rho2 w2 = 0
        return mesh_contact(phi, d, 0.0, 0.0, 0.0, v, P)[1]

    assert T(0.0) == 0.0
    assert T(v0) == -mu * F and T(10 * v0) == -mu * F  # full Coulomb friction from v0 on
    assert T(-v0) == mu * F
    assert T(0.5 * v0) == pytest.approx(-T(-0.5 * v0), rel=1e-15)  # odd
    # 2 S(x / 2) - 1 at x = 1/2 with S(x) = u^3 (10 - 15 u + 6 u^2), u = x + 1/2 = 3/4
    u = 0.75
    assert T(0.5 * v0) == pytest.approx(-mu * F * (2 * u**3 * (10 - 15 * u + 6 * u**2) - 1), rel=1e-12)
    ts = [T(v) for v in np.linspace(-2 * v0, 2 * v0, 81)]
    assert np.all(np.diff(ts) <= 0)  # monotone: never pushes along the sliding


def test_table_profile_interpolates_periodically():
    P = params(table_phase=np.array([0.0, 0.5]), table_stiffness_N_per_m=np.array([1e9, 2e9]))
    d = 1e-6
    assert contact_force(angle_at(0, 0.25), d, 0.0, P)[0] == pytest.approx(1.5e9 * d)
    assert contact_force(angle_at(0, 0.75), d, 0.0, P)[0] == pytest.approx(1.5e9 * d)  # wraps to p = 1
    P = params(table_phase=np.array([0.2, 0.6]), table_stiffness_N_per_m=np.array([1e9, 2e9]))
    # before the first point: between (0.6 - 1, 2e9) and (0.2, 1e9)
    assert contact_force(angle_at(0, 0.0), d, 0.0, P)[0] == pytest.approx((2e9 - 1e9 * 0.4 / 0.6 * 1.0) * d)


def test_kloss_characteristic_and_its_steady_slip():
    ws, mb, sb = 100.0, 1000.0, 0.1
    assert kloss_torque_Nm(ws * (1 - sb), ws, ws, mb, sb) == pytest.approx(mb)  # breakdown point
    assert kloss_torque_Nm(ws, ws, ws, mb, sb) == 0.0
    assert kloss_torque_Nm(ws * (1 + sb), ws, ws, mb, sb) == pytest.approx(-mb)  # generator
    s = steady_slip(400.0, mb, sb)
    assert s < sb
    assert kloss_torque_Nm(ws * (1 - s), ws, ws, mb, sb) == pytest.approx(400.0)
    # converter-fed: the characteristic shifts with w_s, slip speed relative to the rated w_s
    assert kloss_torque_Nm(50 - ws * s, 50.0, ws, mb, sb) == pytest.approx(400.0)
    with pytest.raises(ValueError, match="breakdown"):
        steady_slip(1500.0, mb, sb)


def test_profiles_are_piecewise_linear_and_integrate_exactly():
    t = np.array([0.0, 1.0, 2.0])
    f = np.array([0.0, 1.0, 1.0])
    assert profile_value(0.5, t, f) == pytest.approx(0.5)
    assert profile_value(5.0, t, f) == 1.0
    assert profile_value(-1.0, t, f) == 0.0
    assert profile_integral(1.0, t, f) == pytest.approx(0.5)
    assert profile_integral(3.0, t, f) == pytest.approx(2.5)
    tt = np.array([0.5, 1.0])
    ff = np.array([2.0, 0.0])  # held at 2 before 0.5
    assert profile_integral(0.75, tt, ff) == pytest.approx(1.0 + 0.25 * (2.0 + 1.0) / 2)


def test_friction_dissipates_on_the_back_flank_too():
    P = params(friction_coefficient=0.1)
    for p in (0.3, 0.7):
        phi = angle_at(1, p)
        for w1 in (50.0, -50.0):  # generator mode (back flanks, forward), and backwards
            F, T, rho1, rho2, v_sl = mesh_contact(phi, -1e-5, 0.0, w1, w1 * R1 / R2, 0.0, P)
            assert F < 0  # back-flank contact
            assert T == pytest.approx(0.1 * abs(F) * (1.0 if (p < 0.5) == (w1 > 0) else -1.0))
            assert T * (rho1 * w1 - rho2 * w1 * R1 / R2) < 0
