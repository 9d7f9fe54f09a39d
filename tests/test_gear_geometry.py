"""Involute gear-pair geometry against hand-computed values, and gearbody's mesh-phase convention."""

import math

import numpy as np
import pytest

from gearbody.physics import pack_mesh_parameters, stiffness_at_phase
from gearbody.physics.gear_geometry import (
    GearGeometryError,
    backlash_half_width_m,
    backlash_range_m,
    gear_pair_geometry,
    inverse_involute,
    involute,
    normal_backlash_m,
)

ALPHA = math.radians(20.0)


def one_stage():
    return gear_pair_geometry(module_m=5e-3, teeth_pinion=29, teeth_wheel=88, face_width_m=0.06)


def pair_62():
    return gear_pair_geometry(module_m=2e-3, teeth_pinion=62, teeth_wheel=62, face_width_m=0.02)


def iso_example_1(**kw):
    """ISO/TR 6336-30 Example 1: m_n 8 mm, 20 deg, z 17/103, beta 15.8 deg, x 0.145/0, a_w 500 mm,
    b 100 mm, h_fP = 1.4 m_n."""
    base = dict(
        module_m=8e-3,
        teeth_pinion=17,
        teeth_wheel=103,
        face_width_m=0.1,
        helix_angle_deg=15.8,
        profile_shift_pinion=0.145,
        profile_shift_wheel=0.0,
        centre_distance_m=0.5,
        dedendum_coefficient=1.4,
    )
    base.update(kw)
    return gear_pair_geometry(**base)


def textbook_contact_ratio(m, z1, z2, alpha=ALPHA, ha=1.0):
    """Standard spur pair: eps = [sqrt(ra1² - rb1²) + sqrt(ra2² - rb2²) - a sin(alpha)] / p_b."""
    r1, r2 = m * z1 / 2, m * z2 / 2
    rb1, rb2 = r1 * math.cos(alpha), r2 * math.cos(alpha)
    ga = (
        math.sqrt((r1 + ha * m) ** 2 - rb1**2)
        + math.sqrt((r2 + ha * m) ** 2 - rb2**2)
        - (r1 + r2) * math.sin(alpha)
    )
    return ga / (math.pi * m * math.cos(alpha))


def test_involute_and_its_inverse():
    assert involute(math.radians(20)) == pytest.approx(0.014904383867336446, rel=1e-12)
    assert inverse_involute(involute(0.4)) == pytest.approx(0.4, rel=1e-12)


def test_standard_spur_pair_radii_centre_distance_and_contact_ratio():
    g = one_stage()
    assert g.pitch_radius_pinion_m == pytest.approx(0.0725, rel=1e-12)
    assert g.pitch_radius_wheel_m == pytest.approx(0.220, rel=1e-12)
    assert g.base_radius_pinion_m == pytest.approx(0.068128, abs=1e-6)  # the scene's values
    assert g.base_radius_wheel_m == pytest.approx(0.206732, abs=1e-6)
    assert g.tip_radius_pinion_m == pytest.approx(0.0775, rel=1e-12)
    assert g.root_radius_wheel_m == pytest.approx(0.220 - 1.25 * 5e-3, rel=1e-12)
    assert g.centre_distance_m == pytest.approx(0.2925, rel=1e-12)
    assert g.working_pressure_angle_rad == pytest.approx(ALPHA, rel=1e-9)
    assert g.transverse_base_pitch_m == pytest.approx(math.pi * 5e-3 * math.cos(ALPHA), rel=1e-12)
    assert g.line_of_action_length_m == pytest.approx(0.2925 * math.sin(ALPHA), rel=1e-12)
    assert g.pitch_point_position_m == pytest.approx(0.0725 * math.sin(ALPHA), rel=1e-12)
    eps = textbook_contact_ratio(5e-3, 29, 88)
    assert g.transverse_contact_ratio == pytest.approx(eps, rel=1e-12)
    assert g.overlap_ratio == 0.0
    # points on the line of action: A < B < C < D < E here, B and D one base pitch from E and A
    assert g.contact_start_position_m < g.single_start_position_m < g.pitch_point_position_m
    assert g.pitch_point_position_m < g.single_end_position_m < g.contact_end_position_m
    assert g.single_end_position_m - g.contact_start_position_m == pytest.approx(g.transverse_base_pitch_m)
    print(
        f"one-stage 29/88 m 5 mm: eps_alpha = {g.transverse_contact_ratio:.5f}, "
        f"pitch point phase {g.pitch_point_phase:.4f}"
    )


def test_contact_ratio_of_the_62_62_reference_pair():
    assert pair_62().transverse_contact_ratio == pytest.approx(1.78978, abs=1e-5)


def test_two_stage_second_stage_contact_ratio():
    g = gear_pair_geometry(module_m=8e-3, teeth_pinion=23, teeth_wheel=71, face_width_m=0.08)
    assert g.transverse_contact_ratio == pytest.approx(textbook_contact_ratio(8e-3, 23, 71), rel=1e-12)
    assert g.base_radius_pinion_m == pytest.approx(0.086452, abs=1e-6)  # scenes/two-stage.toml
    assert g.base_radius_wheel_m == pytest.approx(0.266873, abs=1e-6)
    print(f"two-stage stage 2, 23/71 m 8 mm: eps_alpha = {g.transverse_contact_ratio:.5f}")


def test_iso_example_1_helical_geometry():
    g = iso_example_1()
    alpha_t = math.atan(math.tan(ALPHA) / math.cos(math.radians(15.8)))
    assert g.transverse_pressure_angle_rad == pytest.approx(alpha_t, rel=1e-12)
    assert math.degrees(alpha_t) == pytest.approx(20.7197, abs=1e-4)
    assert g.reference_centre_distance_m == pytest.approx(0.4988475, abs=1e-7)
    # the working centre distance 500 mm belongs to x1 + x2 = 0.145: the no-backlash distance of the
    # shifts is 499.998 mm, and 500 mm gives x1 + x2 = 0.14522 (tip alteration k = -0.0009)
    from_shifts = iso_example_1(centre_distance_m=None)
    assert from_shifts.centre_distance_m == pytest.approx(0.5, abs=3e-6)
    assert g.tip_alteration_coefficient == pytest.approx(-0.00093, abs=1e-5)
    assert math.degrees(g.working_pressure_angle_rad) == pytest.approx(21.0661, abs=1e-4)
    # eps_alpha from tips d + 2 m_n (1 + x) and eps_beta = b sin(beta) / (pi m_n)
    assert g.tip_radius_pinion_m * 2e3 == pytest.approx(159.660, abs=1e-3)
    assert g.tip_radius_wheel_m * 2e3 == pytest.approx(872.355, abs=1e-3)
    assert g.transverse_contact_ratio == pytest.approx(1.54934, abs=1e-5)
    assert g.overlap_ratio == pytest.approx(0.1 * math.sin(math.radians(15.8)) / (math.pi * 8e-3), rel=1e-12)
    assert g.overlap_ratio == pytest.approx(1.08337, abs=1e-5)
    print(
        f"ISO/TR 6336-30 Ex. 1: eps_alpha = {g.transverse_contact_ratio:.5f}, "
        f"eps_beta = {g.overlap_ratio:.5f}, "
        f"eps_gamma = {g.total_contact_ratio:.5f}, a_w(x) = {from_shifts.centre_distance_m * 1e3:.4f} mm"
    )


def test_tip_shortening_applies_the_tip_alteration():
    g = iso_example_1(tip_shortening=True)
    k = g.tip_alteration_coefficient
    assert g.tip_radius_pinion_m == pytest.approx(iso_example_1().tip_radius_pinion_m + k * 8e-3, rel=1e-12)
    assert g.transverse_contact_ratio < iso_example_1().transverse_contact_ratio


def test_centre_distance_not_matching_the_shifts_is_refused():
    with pytest.raises(GearGeometryError, match=r"centre_distance_m = 0\.501.*does not match"):
        iso_example_1(centre_distance_m=0.501)


def test_pitch_point_is_mid_single_zone_for_the_symmetric_pair():
    g = pair_62()
    mid_single = 0.5 * (g.single_start_position_m + g.single_end_position_m)
    assert g.pitch_point_position_m == pytest.approx(mid_single, rel=1e-12)
    assert g.pitch_point_phase == pytest.approx(0.5, abs=1e-12)


def test_phase_positions_follow_the_convention():
    g = one_stage()
    eps, h = g.transverse_contact_ratio, g.half_double_contact
    pos = g.position_on_line_of_action_m
    assert pos(0.5 - eps / 2) == pytest.approx(g.contact_start_position_m, rel=1e-12)
    assert pos(0.5 + eps / 2) == pytest.approx(g.contact_end_position_m, rel=1e-12)
    assert pos(h) == pytest.approx(g.single_start_position_m, rel=1e-12)  # single contact from p = h ...
    assert pos(1 - h) == pytest.approx(g.single_end_position_m, rel=1e-12)  # ... to p = 1 - h
    assert pos(g.pitch_point_phase) == pytest.approx(g.pitch_point_position_m, rel=1e-12)
    assert pos(1.0) - pos(0.0) == pytest.approx(g.transverse_base_pitch_m, rel=1e-12)
    p = np.linspace(0, 1, 7)
    assert g.phase_at_position(pos(p)) == pytest.approx(p, abs=1e-12)


def test_pairs_in_contact_match_the_double_contact_zones_of_stiffness_at_phase():
    g = one_stage()
    P = pack_mesh_parameters(
        r1_m=g.base_radius_pinion_m,
        r2_m=g.base_radius_wheel_m,
        z1=29,
        z2=88,
        stiffness_single_N_per_m=1.0,
        stiffness_double_N_per_m=2.0,
        contact_ratio=g.transverse_contact_ratio,
        damping_Ns_per_m=0.0,
        backlash_m=0.0,
        friction_coefficient=0.0,
        pitch_point_phase=g.pitch_point_phase,
        pressure_angle_rad=g.working_pressure_angle_rad,
        error_a=0.5,
        error_depths_m=np.zeros(29),
    )
    h = g.half_double_contact
    for p in [
        *np.linspace(0, 1, 1001, endpoint=False),
        h,
        1 - h,
        math.nextafter(h, 0),
        math.nextafter(1 - h, 0),
    ]:
        pairs = g.pairs_in_contact(float(p))
        assert len(pairs) == round(stiffness_at_phase(float(p), P)), p
        for _, s in pairs:
            assert g.contact_start_position_m - 1e-12 <= s <= g.contact_end_position_m + 1e-12
    offsets_early = [k for k, _ in g.pairs_in_contact(0.1)]
    assert offsets_early == [-1, 0]  # the outgoing pair is further along the line of action
    (_, s_prev), (_, s_now) = g.pairs_in_contact(0.1)
    assert s_prev - s_now == pytest.approx(g.transverse_base_pitch_m, rel=1e-12)
    assert [k for k, _ in g.pairs_in_contact(0.95)] == [0, 1]
    assert [k for k, _ in g.pairs_in_contact(0.5)] == [0]


def test_friction_arms_are_the_radii_of_curvature_and_sum_to_t1t2():
    g = one_stage()
    s = g.position_on_line_of_action_m(np.linspace(0, 1, 11))
    rho1, rho2 = g.friction_arms_m(s)
    assert rho1 + rho2 == pytest.approx(np.full(11, g.line_of_action_length_m), rel=1e-12)
    rho1_c, rho2_c = g.friction_arms_m(g.pitch_point_position_m)
    assert rho1_c == pytest.approx(g.base_radius_pinion_m * math.tan(g.working_pressure_angle_rad), rel=1e-12)
    assert rho2_c == pytest.approx(g.base_radius_wheel_m * math.tan(g.working_pressure_angle_rad), rel=1e-12)
    # the same arms as mesh.py's rho_1 = r1 tan(alpha_w) + (p - pitch) p_b, rho_2 = r2 tan(alpha_w) - (...)
    p = 0.3
    r1, r2, pb = g.base_radius_pinion_m, g.base_radius_wheel_m, 2 * math.pi * g.base_radius_pinion_m / 29
    dp = p - g.pitch_point_phase
    rho1_p, rho2_p = g.friction_arms_m(g.position_on_line_of_action_m(p))
    assert rho1_p == pytest.approx(r1 * math.tan(ALPHA) + dp * pb, rel=1e-12)
    assert rho2_p == pytest.approx(r2 * math.tan(ALPHA) - dp * pb, rel=1e-12)


def test_backlash_from_allowances_and_half_width():
    g = one_stage()
    # E_sn = -100 um and -150 um, centre distance +20 um: j_bn = 250 cos20 + 40 sin20 um
    j = normal_backlash_m(
        g,
        thickness_allowance_pinion_m=-100e-6,
        thickness_allowance_wheel_m=-150e-6,
        centre_distance_deviation_m=20e-6,
    )
    assert j == pytest.approx((250 * math.cos(ALPHA) + 40 * math.sin(ALPHA)) * 1e-6, rel=1e-12)
    assert backlash_half_width_m(g, j) == pytest.approx(j / 2, rel=1e-12)  # spur: l_u = j_bn / 2
    j_min, j_max = backlash_range_m(
        g,
        thickness_allowances_pinion_m=(-80e-6, -120e-6),
        thickness_allowances_wheel_m=(-100e-6, -160e-6),
        centre_distance_allowances_m=(25e-6, -25e-6),
    )
    assert j_min == pytest.approx((180 * math.cos(ALPHA) - 50 * math.sin(ALPHA)) * 1e-6, rel=1e-12)
    assert j_max == pytest.approx((280 * math.cos(ALPHA) + 50 * math.sin(ALPHA)) * 1e-6, rel=1e-12)
    helical = iso_example_1()
    assert backlash_half_width_m(helical, 1e-4) == pytest.approx(
        0.5e-4 / math.cos(helical.base_helix_angle_rad)
    )


def test_backlash_that_jams_is_refused():
    with pytest.raises(GearGeometryError, match="normal_backlash_min_m"):
        backlash_range_m(
            one_stage(),
            thickness_allowances_pinion_m=(0.0, -50e-6),
            thickness_allowances_wheel_m=(0.0, -50e-6),
            centre_distance_allowances_m=(20e-6, -20e-6),
        )


def test_undercut_is_refused():
    with pytest.raises(GearGeometryError, match=r"teeth_pinion = 10: undercut.*>= 17\.1"):
        gear_pair_geometry(module_m=5e-3, teeth_pinion=10, teeth_wheel=40, face_width_m=0.05)
    # a positive shift cures it: x >= 1 - 10 sin²(20 deg) / 2 = 0.415
    g = gear_pair_geometry(
        module_m=5e-3, teeth_pinion=10, teeth_wheel=40, face_width_m=0.05, profile_shift_pinion=0.42
    )
    assert g.transverse_contact_ratio > 1


def test_contact_ratio_below_one_is_refused():
    with pytest.raises(GearGeometryError, match=r"transverse_contact_ratio = 0\.89.*>= 1"):
        gear_pair_geometry(
            module_m=5e-3, teeth_pinion=30, teeth_wheel=30, face_width_m=0.05, addendum_coefficient=0.5
        )


def test_tip_too_thin_is_refused():
    with pytest.raises(GearGeometryError, match=r"profile_shift_pinion = 1: tip too thin"):
        gear_pair_geometry(
            module_m=5e-3, teeth_pinion=20, teeth_wheel=40, face_width_m=0.05, profile_shift_pinion=1.0
        )


def test_interference_is_refused():
    # wheel tip given so large that contact would start before T1, below the pinion base circle
    with pytest.raises(GearGeometryError, match="before T1"):
        gear_pair_geometry(
            module_m=5e-3, teeth_pinion=29, teeth_wheel=88, face_width_m=0.06, tip_diameters_m=(0.155, 0.462)
        )
    # a strongly shifted wheel: its involute starts high up, and the pinion tip reaches below it
    with pytest.raises(GearGeometryError, match="root interference"):
        gear_pair_geometry(
            module_m=5e-3,
            teeth_pinion=18,
            teeth_wheel=40,
            face_width_m=0.06,
            profile_shift_pinion=0.0,
            profile_shift_wheel=1.5,
        )


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("module_m", 0.0),
        ("module_m", -1e-3),
        ("teeth_pinion", 0),
        ("teeth_wheel", 30.5),
        ("face_width_m", 0.0),
        ("pressure_angle_deg", 0.0),
        ("pressure_angle_deg", 50.0),
        ("helix_angle_deg", 45.0),
        ("addendum_coefficient", 0.0),
        ("dedendum_coefficient", 0.9),
        ("centre_distance_m", -0.1),
    ],
)
def test_bad_inputs_are_refused_naming_the_parameter(key, value):
    kw = dict(module_m=5e-3, teeth_pinion=29, teeth_wheel=88, face_width_m=0.06)
    kw[key] = value
    with pytest.raises(GearGeometryError, match=rf"^{key} = .*allowed"):
        gear_pair_geometry(**kw)
