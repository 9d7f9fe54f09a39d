"""Bearing laws (the extension point for bearing compliance) against hand-computed cases."""

from dataclasses import dataclass

import numpy as np
import pytest

from gearbody.physics.bearings import (
    BEARINGS,
    BearingLaw,
    HertzianBearing,
    LinearBearing,
    make_bearing,
    register_bearing,
)


def test_linear_bearing_restores_per_direction():
    b = LinearBearing(
        stiffness_x_N_per_m=2e8, stiffness_y_N_per_m=1e8, damping_x_Ns_per_m=300.0, damping_y_Ns_per_m=100.0
    )
    f = b.force_N([1e-6, -2e-6], [0.01, 0.02])
    assert f == pytest.approx([-(200.0 + 3.0), -(-200.0 + 2.0)])
    assert isinstance(b, BearingLaw)
    with pytest.raises(ValueError, match="stiffness_y_N_per_m = 0"):
        LinearBearing(stiffness_x_N_per_m=1e8, stiffness_y_N_per_m=0)


def test_ball_bearing_has_a_dead_zone_and_a_three_halves_power_law():
    c, kb = 10e-6, 1e10
    b = HertzianBearing(contact_stiffness_N_per_m_n=kb, radial_clearance_m=c)
    assert np.all(b.force_N([0.7 * c, 0.7 * c], [0, 0]) == 0.0)  # |u| < c: no contact
    f1 = b.force_N([c + 1e-6, 0.0], [0, 0])
    f2 = b.force_N([c + 2e-6, 0.0], [0, 0])
    assert f1 == pytest.approx([-kb * 1e-6**1.5, 0.0])
    assert f2[0] / f1[0] == pytest.approx(2**1.5)
    # continuous at the clearance
    assert np.linalg.norm(b.force_N([c + 1e-12, 0.0], [0, 0])) < 1e-6


def test_ball_bearing_force_is_radial_and_the_gradient_of_its_potential():
    b = HertzianBearing(contact_stiffness_N_per_m_n=5e9, radial_clearance_m=2e-6)
    u = np.array([3e-6, -4e-6])  # |u| = 5 um
    f = b.force_N(u, [0, 0])
    assert f[0] * u[1] - f[1] * u[0] == pytest.approx(0.0, abs=1e-12)  # along u
    assert f @ u < 0  # towards the centre
    h = 1e-10
    grad = [(b.potential_J(u + h * e) - b.potential_J(u - h * e)) / (2 * h) for e in np.eye(2)]
    assert f == pytest.approx(-np.array(grad), rel=1e-5)


def test_ball_bearing_damping_acts_in_contact_and_never_pulls():
    b = HertzianBearing(contact_stiffness_N_per_m_n=1e10, radial_clearance_m=0.0, damping_Ns_per_m=1e3)
    u = np.array([1e-6, 0.0])
    f_in = b.force_N(u, [0.01, 0.0])  # moving outwards: more force
    assert f_in[0] == pytest.approx(-(1e10 * 1e-9 + 10.0))
    f_out = b.force_N(u, [-1.0, 0.0])  # moving away fast: damping would pull; clipped to zero
    assert np.all(f_out == 0.0)


def test_a_user_bearing_law_plugs_in_by_name():
    @dataclass(frozen=True)
    class CubicBearing:
        stiffness_N_per_m3: float

        def force_N(self, displacement_m, velocity_m_s):
            return -self.stiffness_N_per_m3 * np.asarray(displacement_m, float) ** 3

    register_bearing("cubic", CubicBearing)
    try:
        b = make_bearing("cubic", stiffness_N_per_m3=1e20)
        assert isinstance(b, BearingLaw)
        assert b.force_N([1e-6, 0.0], [0, 0]) == pytest.approx([-1e2, 0.0])
    finally:
        BEARINGS.pop("cubic")
    with pytest.raises(ValueError, match="kinds: hertzian, linear"):
        make_bearing("magnetic")
    with pytest.raises(TypeError, match="force_N"):
        register_bearing("bad", object)
