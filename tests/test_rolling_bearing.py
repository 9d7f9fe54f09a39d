"""The ball-by-ball bearing law (gearbody.physics.rolling_bearing): hand-computed forces, the defects'
drops, the cage with its seeded slip, the scenario's bearing tables, and the law against the
reference's own transcription (validation.reference.rolling_bearing)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from gearbody_validation.reference.rolling_bearing import RollingBearing

from gearbody.errors import ScenarioError
from gearbody.model import load_scenario, scenario_to_dict
from gearbody.physics.bearings import BearingDefect, RollingElementBearing, law_force_xy

GEOMETRY = {"balls": 8, "ball_diameter_m": 0.0079375, "pitch_diameter_m": 0.0335026}  # PHM 2009
K = 8.0e9


def law(**changes) -> RollingElementBearing:
    return RollingElementBearing(**{"ball_stiffness_N_per_m_n": K, **GEOMETRY, "cage_slip": 0.0, **changes})


def test_healthy_force_is_the_sum_over_the_balls_by_hand():
    b = law(radial_clearance_m=2e-6, damping_Ns_per_m=300.0)
    theta, u, v = 1.234, (7e-6, 3e-6), (0.01, -0.02)
    gamma = 0.0079375 / 0.0335026
    angles = 0.5 * (1 - gamma) * theta + 2 * math.pi * np.arange(8) / 8
    defl = u[0] * np.cos(angles) + u[1] * np.sin(angles) - 2e-6
    push = K * np.clip(defl, 0, None) ** 1.5
    expected = (-np.sum(push * np.cos(angles)) - 300 * v[0], -np.sum(push * np.sin(angles)) - 300 * v[1])
    assert np.allclose(b.force_xy(*u, *v, theta), expected, rtol=1e-13, atol=1e-9)
    assert np.allclose(b.ball_angles_rad(theta), angles, rtol=0, atol=1e-14)


def test_a_ball_over_an_outer_race_spall_drops_by_the_depth_or_the_sagitta():
    d, D = GEOMETRY["ball_diameter_m"], GEOMETRY["pitch_diameter_m"]
    rho = 1 / (2 / d - 2 / (D + d))  # ball in the outer race
    u = (20e-6, 0.0)  # load on ball 0 at angle 0, which sits in the middle of the spall
    for depth, width, drop in (
        (5e-6, 10.0, 5e-6),  # wide spall: the ball reaches its bottom
        (1e-3, 1.0, None),  # narrow: the ball's curvature limits the drop
    ):
        half = math.radians(width) / 2 * (D + d) / 2
        drop = drop if drop is not None else rho - math.sqrt(rho**2 - half**2)
        spalled = law(defects=(BearingDefect("outer", depth, width, 0.0),))
        healthy = law()
        f0 = -healthy.force_xy(*u, 0, 0)[0]
        f1 = -spalled.force_xy(*u, 0, 0)[0]
        # ball 0 alone changes: K (u - drop)^1.5 instead of K u^1.5
        assert f0 - f1 == pytest.approx(K * (20e-6**1.5 - (20e-6 - drop) ** 1.5), rel=1e-9)
        assert drop < 20e-6


def test_an_inner_race_spall_turns_with_the_shaft_and_a_ball_defect_with_the_spin():
    gamma = GEOMETRY["ball_diameter_m"] / GEOMETRY["pitch_diameter_m"]
    rc = 0.5 * (1 - gamma)
    inner = law(defects=(BearingDefect("inner", 5e-6, 10.0, 0.0),))
    # the spall (at theta) meets ball j (at r_c theta + 2 pi j / 8) where theta (1 - r_c) = 2 pi j / 8;
    # loaded along the spall's direction there, that ball pushes less; half a ball spacing later, no ball
    # is in the spall
    for j in (0, 3, 13):
        theta = 2 * math.pi * j / 8 / (1 - rc)
        u = 20e-6 * np.array([math.cos(theta), math.sin(theta)])
        assert np.hypot(*inner.force_xy(*u, 0, 0, theta)) < np.hypot(*law().force_xy(*u, 0, 0, theta)) - 1.0
        theta += math.pi / 8 / (1 - rc)
        u = 20e-6 * np.array([math.cos(theta), math.sin(theta)])
        assert inner.force_xy(*u, 0, 0, theta) == law().force_xy(*u, 0, 0, theta)
    u = (20e-6, 0.0)
    spin = GEOMETRY["pitch_diameter_m"] / (2 * GEOMETRY["ball_diameter_m"]) * (1 - gamma**2)
    ball = law(defects=(BearingDefect("ball", 5e-6, 20.0, 0.0, ball=0),))
    # ball 0 carries the load near theta = 0 (angle r_c theta small); its defect meets the outer race at
    # spin 0 (theta 0) and the inner at spin pi
    theta_pi = math.pi / spin
    assert -ball.force_xy(*u, 0, 0, 0.0)[0] < -law().force_xy(*u, 0, 0, 0.0)[0] - 1.0
    assert -ball.force_xy(*u, 0, 0, theta_pi)[0] < -law().force_xy(*u, 0, 0, theta_pi)[0] - 1.0
    assert ball.force_xy(*u, 0, 0, theta_pi / 2) == law().force_xy(*u, 0, 0, theta_pi / 2)


def test_cage_slip_is_seeded_bounded_continuous_and_averages_to_the_kinematic_cage():
    rc = 0.5 * (1 - GEOMETRY["ball_diameter_m"] / GEOMETRY["pitch_diameter_m"])
    slipping = law(cage_slip=0.02, slip_seed=3)
    theta = np.linspace(-50.0, 3000.0, 20001)
    cage = np.array([slipping.ball_angles_rad(t)[0] for t in theta])
    assert np.all(np.diff(cage) > 0)  # monotone: never jumps back
    assert np.max(np.abs(np.diff(cage))) < 1.03 * rc * (theta[1] - theta[0])  # continuous, rate within slip
    assert np.max(np.abs(np.diff(cage))) > 1.01 * rc * (theta[1] - theta[0])  # it does slip
    drift = np.abs(cage - rc * theta)
    assert drift.max() < 0.02 * rc * np.abs(theta).max()
    assert np.array_equal(cage, [law(cage_slip=0.02, slip_seed=3).ball_angles_rad(t)[0] for t in theta])
    other = np.array([law(cage_slip=0.02, slip_seed=4).ball_angles_rad(t)[0] for t in theta[::100]])
    assert not np.array_equal(cage[::100], other)


def test_the_law_equals_the_reference_transcription_with_defects_and_slip():
    defects = (
        BearingDefect("outer", 15e-6, 6.0, 80.0),
        BearingDefect("inner", 10e-6, 9.0, -30.0),
        BearingDefect("ball", 12e-6, 25.0, 40.0, ball=5),
    )
    b = law(radial_clearance_m=3e-6, damping_Ns_per_m=500.0, cage_slip=0.015, slip_seed=11, defects=defects)
    table = {
        "parameters": {**{k: getattr(b, k) for k in ("ball_stiffness_N_per_m_n", "radial_clearance_m")}}
        | {"exponent": 1.5, "damping_Ns_per_m": 500.0, "cage_slip": 0.015, "slip_seed": 11},
        "geometry": GEOMETRY,
        "defects": [d.__dict__ for d in defects],
    }
    ref = RollingBearing(table)
    rng = np.random.default_rng(0)
    worst = 0.0
    for _ in range(3000):
        u = rng.uniform(-30e-6, 30e-6, 2)
        v = rng.uniform(-0.1, 0.1, 2)
        theta = rng.uniform(-100, 5000)
        mine = np.array(b.force_xy(*u, *v, theta))
        theirs = np.array(ref.force(*u, *v, theta))
        worst = max(worst, float(np.max(np.abs(mine - theirs))) / (1.0 + float(np.max(np.abs(theirs)))))
        assert np.allclose(law_force_xy(b.row, *u, *v, theta, 0.0), mine, rtol=0, atol=0)
    assert worst < 1e-9


def _rolling(scene: str = "lateral-8dof-ball", **bearing) -> dict:
    data = scenario_to_dict(load_scenario(scene))
    table = data["design"]["stages"][0]["pinion"]["bearing"]
    table.update(
        kind="rolling-elements",
        parameters={"ball_stiffness_N_per_m_n": 5.5e10, "radial_clearance_m": 5e-6},
        **bearing,
    )
    return data


def test_scenario_tables_set_geometry_and_defects_and_refuse_what_cannot_work():
    sc = load_scenario(_rolling(defects=[{"race": "outer", "depth_m": 2e-5, "width_deg": 5.0}]))
    b = sc.stages[0].pinion.bearing
    law_ = b.law()
    assert law_.balls == 8 and law_.defects[0].race == "outer"
    assert "balls" not in b.parameters and b.parameters["cage_slip"] == 0.015  # defaults resolved
    cases = [
        (_rolling(defects=[{"race": "cage", "depth_m": 1e-5, "width_deg": 5.0}]), "race"),
        (
            _rolling(defects=[{"race": "ball", "depth_m": 1e-5, "width_deg": 5.0, "ball": 8}]),
            r"ball = 8.*0 \.\. 7",
        ),
        (_rolling(defects=[{"race": "outer", "depth_m": 0.0, "width_deg": 5.0}]), "depth_m"),
        (_rolling(defects=[{"race": "outer", "depth_m": 1e-5, "width_deg": 120.0}]), "width_deg"),
    ]
    no_geometry = _rolling()
    no_geometry["design"]["stages"][0]["pinion"]["bearing"].pop("geometry")
    cases.append((no_geometry, r"bearing.geometry: required by the 'rolling-elements' law"))
    balls_in_parameters = _rolling()
    balls_in_parameters["design"]["stages"][0]["pinion"]["bearing"]["parameters"]["balls"] = 9
    cases.append((balls_in_parameters, "parameters.balls = 9.0: the 'rolling-elements' law reads it from"))
    hertzian = scenario_to_dict(load_scenario("lateral-8dof-ball"))
    hertzian["design"]["stages"][0]["pinion"]["bearing"]["defects"] = [
        {"race": "outer", "depth_m": 1e-5, "width_deg": 5.0}
    ]
    cases.append((hertzian, "the 'hertzian' law has no defects"))
    slip = _rolling()
    slip["design"]["stages"][0]["pinion"]["bearing"]["parameters"]["cage_slip"] = 0.5
    cases.append((slip, r"cage_slip = 0.5: must be in \[0, 0.1\]"))
    for data, message in cases:
        with pytest.raises(ScenarioError, match=message):
            load_scenario(data)
