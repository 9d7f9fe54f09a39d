"""Meshes stated by gear geometry (issue 7): scenario resolution, the "pairs" stiffness law (hand-computed
cases), ISO and potential-energy profiles in scenes, tooth damage from geometry in the mesh law."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearbody.assembly import mesh_parameters_from_scenario
from gearbody.model import ScenarioError, load_scenario, scenario_to_dict
from gearbody.model.io import read_toml
from gearbody.model.resolve import pair_geometry
from gearbody.model.scenes import scene_path
from gearbody.physics.mesh import (
    I_HALF_DOUBLE,
    contact_force,
    effective_stiffness_series,
    mean_stiffness_N_per_m,
    mesh_breakpoint_phases,
    pack_mesh_parameters,
    stiffness_at_phase,
)
from gearbody.physics.mesh_stiffness import spur_pair, stage_pair_table, static_transmission_error_m
from gearbody.physics.stiffness_iso import iso_stiffness

CRACK = 'condition.damaged_teeth=[{gear="pinion",tooth=3,crack_depth_mm=%g}]'


# ------------------------------------------------------------------------------------ resolution


def test_geometry_fixes_radii_contact_ratio_pitch_point_and_backlash():
    sc = load_scenario("one-stage-geometry")
    st = sc.stages[0]
    m, alpha = 0.005, math.radians(20.0)
    assert st.pinion.base_radius_m == pytest.approx(m * 29 * math.cos(alpha) / 2, rel=1e-12)
    assert st.wheel.base_radius_m == pytest.approx(m * 88 * math.cos(alpha) / 2, rel=1e-12)
    assert st.pinion.face_width_m == pytest.approx(0.06)
    # contact ratio by hand: (sqrt(ra1^2 - rb1^2) + sqrt(ra2^2 - rb2^2) - a sin(alpha)) / (pi m cos(alpha))
    r1, r2 = m * 29 / 2, m * 88 / 2
    g = (
        math.sqrt((r1 + m) ** 2 - (r1 * math.cos(alpha)) ** 2)
        + math.sqrt((r2 + m) ** 2 - (r2 * math.cos(alpha)) ** 2)
        - (r1 + r2) * math.sin(alpha)
    )
    assert st.mesh.contact_ratio == pytest.approx(g / (math.pi * m * math.cos(alpha)), rel=1e-12)
    # pitch point C = r1 sin(alpha) from T1; phase 0.5 + (C - (A + E)/2) / p_b
    A = (r1 + r2) * math.sin(alpha) - math.sqrt((r2 + m) ** 2 - (r2 * math.cos(alpha)) ** 2)
    E = math.sqrt((r1 + m) ** 2 - (r1 * math.cos(alpha)) ** 2)
    pitch = 0.5 + (r1 * math.sin(alpha) - 0.5 * (A + E)) / (math.pi * m * math.cos(alpha))
    assert st.mesh.pitch_point_phase == pytest.approx(pitch, rel=1e-12)
    assert st.mesh.pressure_angle_deg == pytest.approx(20.0, rel=1e-12)
    assert st.mesh.backlash_um == pytest.approx(53.2 * math.cos(alpha), rel=1e-12)  # j_bn / 2


def test_resolved_geometry_scenes_reload_unchanged():
    for name in ("one-stage-geometry", "two-stage-geometry"):
        sc = load_scenario(name)
        assert load_scenario(scenario_to_dict(sc)) == sc


@pytest.mark.parametrize(
    ("override", "words"),
    [
        ("design.mesh.contact_ratio=1.6", ["design.mesh.contact_ratio = 1.6", "1.7418"]),
        ("design.pinion.base_radius_m=0.07", ["design.pinion.base_radius_m = 0.07", "0.0681277"]),
        ("design.mesh.geometry.bore_diameter_wheel_mm=[]", ["bore_diameter_wheel_mm"]),
        ("design.mesh.geometry.helix_angle_deg=15", ["helix_angle_deg = 15", "iso-6336-b"]),
        ("design.pinion.teeth=12", ["teeth_pinion = 12", "undercut"]),
        ("design.mesh.geometry.profile_shift_pinion=1.2", ["tip_radius_wheel_m", "interference"]),
        ("design.mesh.stiffness_profile='contact-ratio'", None),  # hand-given k with geometry radii: fine
    ],
)
def test_geometry_refusals_name_key_and_value(override, words):
    if words is None:
        sc = load_scenario("one-stage-geometry", [override])
        assert sc.stages[0].mesh.stiffness_single_N_per_m == 1.2e9
        return
    if override.endswith("=[]"):  # remove the key instead
        data = read_toml(scene_path("one-stage-geometry"))
        del data["design"]["mesh"]["geometry"]["bore_diameter_wheel_mm"]
        with pytest.raises(ScenarioError) as exc:
            load_scenario(data)
    else:
        with pytest.raises(ScenarioError) as exc:
            load_scenario("one-stage-geometry", [override])
    for w in words:
        assert w in str(exc.value)


def test_computed_profiles_need_geometry_and_damage_needs_potential_energy():
    with pytest.raises(ScenarioError, match="geometry"):
        load_scenario("one-stage", ["design.mesh.stiffness_profile='potential-energy'"])
    with pytest.raises(ScenarioError, match="potential-energy"):
        load_scenario("one-stage", [CRACK % 2.0])
    with pytest.raises(ScenarioError, match="base_radius_m is required"):
        data = read_toml(scene_path("one-stage"))
        del data["design"]["wheel"]["base_radius_m"]
        load_scenario(data)


def test_crack_past_the_centre_line_is_refused_before_running():
    with pytest.raises(ScenarioError, match="damaged_teeth"):
        load_scenario("one-stage-geometry", [CRACK % 20.0])


# ------------------------------------------------------------- one geometry, two stiffness modules


def test_energy_pair_and_gear_geometry_agree_on_the_line_of_action():
    sc = load_scenario("two-stage-geometry")
    for st in sc.stages:
        geo = pair_geometry(st.mesh, st.pinion.teeth, st.wheel.teeth)
        pair = spur_pair(st.mesh.geometry, st.pinion.teeth, st.wheel.teeth)
        assert pair.contact_ratio == pytest.approx(geo.transverse_contact_ratio, rel=1e-12)
        p = np.linspace(-0.3, 1.3, 17)
        np.testing.assert_allclose(pair.roll_position_m(p), geo.position_on_line_of_action_m(p), rtol=1e-12)
        # the law's friction arm rho_1 = r1 tan(alpha_w) + (p - pitch) p_b is the flank's radius s(p)
        P = mesh_parameters_from_scenario(sc, sc.stages.index(st))
        for ph in (0.1, 0.5, 0.9):
            angle = ph * 2 * math.pi / st.pinion.teeth
            _, _, rho1, rho2 = contact_force(angle, 1e-3, 0.0, P)
            s1, s2 = geo.friction_arms_m(geo.position_on_line_of_action_m(ph))
            assert rho1 == pytest.approx(s1, rel=1e-9)
            assert rho2 == pytest.approx(s2, rel=1e-9)


def test_iso_profile_in_a_scene_is_method_b_at_the_rated_line_load():
    sc = load_scenario("one-stage-geometry", ["design.mesh.stiffness_profile='iso-6336-b'"])
    st = sc.stages[0]
    geo = pair_geometry(st.mesh, 29, 88)
    f_t = sc.stage_rated_force_N(0) * math.cos(math.radians(20.0))
    iso = iso_stiffness(geo, line_load_N_per_mm=f_t / 60.0)
    assert f_t / 60.0 > 100.0  # no line-load correction at this load
    assert st.mesh.stiffness_single_N_per_m == pytest.approx(iso.single_N_per_m, rel=1e-12)
    P = mesh_parameters_from_scenario(sc)
    assert mean_stiffness_N_per_m(P) == pytest.approx(iso.mesh_alpha_N_per_m, rel=1e-9)


# ------------------------------------------------------------------ "pairs" law, hand-computed


def _pairs_P(width=0.0, ratios=None, pinion_factors=None):
    """z1 = 4, z2 = 6, eps = 1.5 (h = 0.25): grid q = -0.25, 0.125, 0.5, 0.875, 1.25."""
    return pack_mesh_parameters(
        r1_m=0.05,
        r2_m=0.075,
        z1=4,
        z2=6,
        stiffness_single_N_per_m=1.0,
        stiffness_double_N_per_m=1.0,
        contact_ratio=1.5,
        damping_Ns_per_m=100.0,
        backlash_m=0.0,
        friction_coefficient=0.0,
        pitch_point_phase=0.5,
        pressure_angle_rad=math.radians(20),
        error_a=0.5,
        error_depths_m=np.zeros(4),
        pinion_factors=pinion_factors,
        transition_width=width,
        pair_stiffness_N_per_m=np.array([4.0, 6.0, 8.0, 6.0, 2.0]) * 1e8,
        pair_ratios=ratios,
    )


def _angle(period: int, phase: float) -> float:
    return (period + phase) * 2 * math.pi / 4


def test_pairs_law_sums_the_pairs_in_contact_by_hand():
    P = _pairs_P()
    assert P[I_HALF_DOUBLE] == 0.25
    # p = 0.1: outgoing pair at q = 1.1 (between 0.875 -> 6 and 1.25 -> 2: 6 - 4 * 0.6 = 3.6) plus the
    # period's pair at q = 0.1 (between -0.25 -> 4 and 0.125 -> 6: 4 + 2 * 0.35/0.375)
    k_hand = (3.6 + 4.0 + 2.0 * 0.35 / 0.375) * 1e8
    assert stiffness_at_phase(0.1, P) == pytest.approx(k_hand, rel=1e-12)
    F, *_ = contact_force(_angle(0, 0.1), 1e-5, 0.0, P)
    assert F == pytest.approx(k_hand * 1e-5, rel=1e-12)
    # p = 0.5: the period's pair alone, 8e8; p = 0.9: it (q = 0.9) and the incoming pair (q = -0.1)
    assert stiffness_at_phase(0.5, P) == pytest.approx(8e8)
    k09 = (6.0 - 4.0 * 0.025 / 0.375 + 4.0 + 2.0 * 0.15 / 0.375) * 1e8
    assert stiffness_at_phase(0.9, P) == pytest.approx(k09, rel=1e-12)
    # mean: the pair's stiffness integrated over its contact (trapezoids of the table), per period
    assert mean_stiffness_N_per_m(P) == pytest.approx(0.375 * (5 + 7 + 7 + 4) * 1e8, rel=1e-6)
    np.testing.assert_allclose(mesh_breakpoint_phases(P), [0.0, 0.25, 0.75])


def test_damaged_tooth_acts_on_its_pair_over_its_whole_contact():
    ratio = np.array([0.5, 0.5, 0.5, 0.5, 0.5])
    P = _pairs_P(ratios={("pinion", 2): ratio})
    healthy = _pairs_P()
    # pinion tooth 2 is the period's tooth in period 2; its pair is also in contact at the end of
    # period 1 (incoming, p >= 0.75) and the start of period 3 (outgoing, p < 0.25)
    cases = [
        (1, 0.5, 0.0),  # period 1, middle: tooth 1 alone
        (1, 0.9, 1.0),  # incoming pair (tooth 2) at q = -0.1
        (2, 0.5, 1.0),  # tooth 2 alone, halved
        (3, 0.1, 1.0),  # outgoing (tooth 2) at q = 1.1
        (3, 0.5, 0.0),
        (6, 0.5, 1.0),  # period 6: tooth 6 mod 4 = 2 again
    ]
    for period, phase, affected in cases:
        k = effective_stiffness_series(np.array([_angle(period, phase)]), P)[0]
        k0 = effective_stiffness_series(np.array([_angle(period, phase)]), healthy)[0]
        q_damaged = {1: phase - 1.0, 2: phase, 3: phase + 1.0, 6: phase}[period] if affected else None
        expected = (
            k0 - 0.5 * np.interp(q_damaged, [-0.25, 0.125, 0.5, 0.875, 1.25], [4, 6, 8, 6, 2]) * 1e8
            if affected
            else k0
        )
        assert k == pytest.approx(expected, rel=1e-12), (period, phase)
    # damping factor k / k_healthy: at p = 0.5 of period 2 the damping force is halved too
    F, *_ = contact_force(_angle(2, 0.5), 1e-12, 1.0, P)
    assert F == pytest.approx(0.5 * (8e8 * 1e-12 + 100.0), rel=1e-12)


def test_stiffness_factor_in_pairs_law_spans_the_pair_not_the_period():
    f = np.ones(4)
    f[2] = 0.0  # tooth 2 lost (the paper's factor 0.0)
    P = _pairs_P(pinion_factors=f)
    k = effective_stiffness_series(np.array([_angle(1, 0.9), _angle(2, 0.5), _angle(3, 0.1)]), P)
    # period 1 end: only tooth 1's pair (q = 0.9); period 2 middle: nothing; period 3 start: tooth 3's pair
    assert k[0] == pytest.approx((6.0 - 4.0 * 0.025 / 0.375) * 1e8)
    assert k[1] == 0.0
    assert k[2] == pytest.approx((4.0 + 2.0 * 0.35 / 0.375) * 1e8)


def test_pairs_law_with_transition_width_is_smooth_and_keeps_the_mean():
    P0, Pw = _pairs_P(), _pairs_P(width=0.05)
    assert mean_stiffness_N_per_m(Pw) == pytest.approx(mean_stiffness_N_per_m(P0), rel=1e-4)
    p = np.linspace(0.2, 0.3, 2001)  # across the end of the outgoing pair at h = 0.25
    k = np.array([stiffness_at_phase(x, Pw) for x in p])
    assert np.max(np.abs(np.diff(k))) < 0.01 * k.max()
    assert stiffness_at_phase(0.5, Pw) == pytest.approx(stiffness_at_phase(0.5, P0))


# ------------------------------------------------------------------ tooth damage from geometry


def test_crack_depth_lowers_only_its_pair_and_vanishes_at_depth_zero():
    healthy = mesh_parameters_from_scenario(load_scenario("one-stage-geometry"))
    z1 = 29
    angles = (np.arange(z1 * 200) + 0.5) / 200 * 2 * math.pi / z1  # one pinion revolution
    k_h = effective_stiffness_series(angles, healthy)
    np.testing.assert_array_equal(
        effective_stiffness_series(
            angles, mesh_parameters_from_scenario(load_scenario("one-stage-geometry", [CRACK % 0.0]))
        ),
        k_h,
    )
    u = angles * z1 / (2 * math.pi)
    window = (u >= 3 - 0.371) & (u < 4 + 0.371)  # tooth 3's pair: periods 3 -+ h
    previous = None
    for depth in (0.5, 1.0, 2.0, 3.0):
        k = effective_stiffness_series(
            angles, mesh_parameters_from_scenario(load_scenario("one-stage-geometry", [CRACK % depth]))
        )
        np.testing.assert_array_equal(k[~window], k_h[~window])
        assert np.all(k[window] < k_h[window])
        if previous is not None:
            assert np.all(k[window] < previous[window])
        previous = k


def test_broken_tip_loses_contact_where_the_missing_part_would_touch():
    sc = load_scenario(
        "one-stage-geometry",
        ['condition.damaged_teeth=[{gear="pinion",tooth=0,broken_height_fraction=0.5}]'],
    )
    table = stage_pair_table(sc.stages[0])
    ratio = table.ratios[("pinion", 0)]
    q = table.own_phase
    # the pinion tip meets the wheel late in the contact (q near 1 + h): the ratio is 0 there, 1 early
    assert ratio[q < 0.2].min() == 1.0
    assert ratio[-1] == 0.0


def test_static_transmission_error_is_force_over_stiffness():
    k = np.array([1e9, 5e8, 0.0])
    te = static_transmission_error_m(k, 1e4, error_m=np.array([1e-6, 0.0, 0.0]), backlash_m=5e-5)
    assert te[0] == pytest.approx(1e-5 - 1e-6 + 5e-5)
    assert te[1] == pytest.approx(2e-5 + 5e-5)
    assert math.isinf(te[2])


@pytest.mark.parametrize("damage", ["crack_depth_mm=2.0", "stiffness_factor=0.5"])
def test_steady_start_is_in_equilibrium_with_a_damaged_tooth_in_mesh(damage):
    """The static deflection uses the law's own k (the pairs with their damage), not the healthy sum."""
    from gearbody.engine import simulate

    sc = load_scenario(
        "one-stage-geometry",
        [
            'operation.initial_state="steady"',
            "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
            "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
            "operation.t_end_s=0.001",
            "solver.anti_aliasing=false",
            f'condition.damaged_teeth=[{{gear="pinion",tooth=0,{damage}}}]',
        ],
    )
    assert simulate(sc).mesh_force[0] == pytest.approx(sc.rated_mesh_force_N, rel=1e-9)
