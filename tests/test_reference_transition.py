"""The transition width (docs/scenario.md, "Transition width") in the independent references
validation/reference.py and validation/reference_lateral.py: hand-computed values of the smoothed
mesh law, the locked-mode form used by the integrator against the literal transcription, and the
integration against gearbody.

The references never import gearbody; gearbody is used here only for the final comparisons.
"""

from __future__ import annotations

import copy
import math
import pathlib

import numpy as np
import pytest
from gearbody_validation import reference as ref

SCEN = pathlib.Path(__file__).resolve().parents[1] / "validation" / "scenarios"
W = 0.05  # transition width used by the hand-computed cases
KS, KD = 1.2e9, 1.3e9  # single / double contact stiffness of one-stage-steady.toml
H = (1.6 - 1.0) / 2.0  # contact_ratio 1.6


def scenario(w: float = W, **changes) -> dict:
    """one-stage-steady.toml with a transition width and dotted-key changes."""
    sc = copy.deepcopy(ref.load_scenario(SCEN / "one-stage-steady.toml"))
    sc["design"]["mesh"]["transition_width"] = w
    for key, val in changes.items():
        node = sc
        *path, last = key.split(".")
        for part in path:
            node = node[part]
        node[last] = val
    return sc


def locked_law(sc: dict, u: np.ndarray, delta, delta_dot, c: int = 1, w_p=None, w_w=None):
    """Force, error and mu e (friction's magnitude without |F|) of the locked-mode law (what the integrator
    uses) at mesh coordinates u; given the speeds w_p, w_w also the friction force T (slide mode of the
    sliding velocity, as the integrator classifies it)."""
    mesh = ref._Mesh(sc)
    F, E, mue, T = (np.empty(u.size) for _ in range(4))
    for m, um in enumerate(u):
        n, k = mesh.phase_mode(float(um), 1.0)
        mc = mesh.mode_consts(n, k, c)
        p = float(um) - n
        F[m] = ref._mesh_force(mc, p, float(delta[m]), float(delta_dot[m]))
        E[m] = ref._mode_error(mc, p)
        mue[m] = ref._mode_mu_envelope(mesh, mc, p)
        if w_p is not None:
            wp, ww = float(w_p[m]), float(w_w[m])
            v_sl = ref._mode_friction(mesh, mc, 0, p, F[m], wp, ww)[3]
            g = ref._slide_mode(v_sl * mesh.inv_v0)
            T[m] = ref._mode_friction(mesh, mc, g, p, F[m], wp, ww)[0]
    return (F, E, mue, T) if w_p is not None else (F, E, mue)


# ----------------------------------------------------------------------------------------------
# Hand-computed values
# ----------------------------------------------------------------------------------------------
def test_smooth_step_by_hand():
    S = ref.smooth_step
    assert S(-0.5) == 0.0 and S(-3.0) == 0.0 and S(0.5) == 1.0 and S(7.0) == 1.0
    assert S(0.0) == 0.5
    assert float(S(0.25)) == pytest.approx(0.75**3 * (10 - 15 * 0.75 + 6 * 0.75**2), rel=1e-15)
    x = np.linspace(-0.6, 0.6, 241)
    np.testing.assert_allclose(S(x) + S(-x), 1.0, rtol=0, atol=4e-15)
    assert np.all(np.diff(S(x)) >= 0.0)


def test_stiffness_ramp_centre_is_the_mean_and_sharp_outside():
    mesh = scenario()["design"]["mesh"]
    sharp = scenario(0.0)["design"]["mesh"]
    centres = ref.base_stiffness([H, 1.0 - H], mesh)
    np.testing.assert_allclose(centres, 0.5 * (KS + KD), rtol=1e-15)
    # |p - h| >= w/2 and |p - (1 - h)| >= w/2: exactly the sharp value
    p = np.concatenate(
        (
            np.linspace(0.0, H - W / 2, 50),
            np.linspace(H + W / 2, 1 - H - W / 2, 50),
            np.linspace(1 - H + W / 2, 0.999999, 50),
        )
    )
    np.testing.assert_array_equal(ref.base_stiffness(p, mesh), ref.base_stiffness(p, sharp))
    # inside the ramp: strictly between, monotone
    ramp = ref.base_stiffness(np.linspace(H - W / 2, H + W / 2, 11)[1:-1], mesh)
    assert np.all((ramp > KS) & (ramp < KD)) and np.all(np.diff(ramp) < 0)
    # the locked-mode law gives the same stiffness (F = k d with d = delta + E, no damping)
    sc = scenario(**{"production.error_mode.e_um": 0.0})
    u = 5.0 + np.array([H - W / 2, H - W / 4, H, H + W / 3, 1 - H, 1 - H + W / 2, 0.02])
    F, _, _ = locked_law(sc, u, np.full(u.size, 1e-5), np.zeros(u.size))
    np.testing.assert_allclose(F / 1e-5, ref.base_stiffness(u - 5.0, mesh), rtol=1e-14)


def test_mean_stiffness_over_a_period_is_unchanged():
    N = 400_000
    p = (np.arange(N) + 0.5) / N  # midpoint rule: exact to O(1/N^2) on the smooth ramps
    sharp_mean = KD * 2 * H + KS * (1 - 2 * H)
    for w in (0.01, 0.05, 0.1):
        mean = float(np.mean(ref.base_stiffness(p, scenario(w)["design"]["mesh"])))
        assert mean == pytest.approx(sharp_mean, rel=1e-9)


def test_friction_envelope_zero_at_tooth_change_and_one_elsewhere():
    ppp = 0.5
    e = ref.friction_envelope
    assert float(e(0.0, W)) == 0.0
    np.testing.assert_array_equal(e(np.linspace(W / 2, 1 - W / 2, 41), W), 1.0)  # the pitch point too
    # ramps: from 0 at the tooth change to 1 at w/2 after it, from 1 at w/2 before the next down to 0
    s4 = float(ref.smooth_step(0.25))
    assert float(e(W / 4, W)) == pytest.approx(2 * s4 - 1, rel=1e-14)
    assert float(e(1 - W / 4, W)) == pytest.approx(2 * s4 - 1, rel=1e-14)  # 1 - 2 S(-1/4)
    assert 0 < 2 * s4 - 1 < 1
    assert float(e(1 - 1e-12, W)) == pytest.approx(0.0, abs=1e-9)
    ramp = e(np.linspace(0.0, W / 2, 11), W)
    assert np.all(np.diff(ramp) > 0)
    np.testing.assert_array_equal(e([0.0, 0.3, 0.99], 0.0), 1.0)  # w = 0: the sharp law
    # T = -mu |F| e sigma(v_sl / v_0) in the literal helper: forward rolling (r1 w_p = r2 w_w), back flank
    sc = scenario()
    mu = sc["condition"]["friction_coefficient"]
    wp = 107.0
    ww = wp * 0.0681 / 0.2067
    fr = ref.friction_moments(sc, np.array([0.0, ppp, 0.2, 0.8, W / 4]), -2.0, wp, ww)
    expected = [0.0, 0.0, 2 * mu, -2 * mu, 2 * mu * (2 * s4 - 1)]
    np.testing.assert_allclose(fr["T"], expected, rtol=1e-14, atol=1e-12)
    # the locked-mode law: mu e(p) and the force with its slide mode
    u = 7.0 + np.array([0.0, ppp, 0.2, 0.8, W / 4, 1 - W / 4, ppp + 2e-4, ppp - 3e-4])
    n_u = u.size
    _, _, mue, T = locked_law(
        sc, u, np.full(n_u, 1e-5), np.zeros(n_u), w_p=np.full(n_u, wp), w_w=np.full(n_u, ww)
    )
    np.testing.assert_allclose(mue, mu * e(u - 7.0, W), rtol=0, atol=1e-15)
    F = locked_law(sc, u, np.full(n_u, 1e-5), np.zeros(n_u))[0]
    lit = ref.friction_moments(sc, u - 7.0, F, wp, ww)
    np.testing.assert_allclose(T, lit["T"], rtol=1e-12, atol=1e-9)
    assert 0 < abs(T[6]) < mu * F[6] and 0 < abs(T[7]) < mu * F[7]  # within v_0 of no sliding


def test_damaged_tooth_factor_blends_at_the_tooth_change():
    sc = scenario(**{"condition.damaged_teeth": [{"gear": "pinion", "tooth": 3, "stiffness_factor": 0.5}]})
    fg, _ = ref.blended_law(sc, np.array([3.0, 3.0 + W / 2, 3.5, 4.0 - W / 2, 4.0, 2.0 - W / 2, 2.5]))
    assert fg[0] == 0.75  # exactly at the change into tooth 3: half way between teeth 2 and 3
    np.testing.assert_array_equal(fg[1:4], 0.5)  # tooth 3 alone
    assert fg[4] == 0.75  # change out of tooth 3 into tooth 4
    np.testing.assert_array_equal(fg[5:], 1.0)
    lit = ref.mesh_force_literal(sc, np.array([3.0]), 1e-5, 0.0)
    assert float(lit["k"][0]) == 0.75 * KD
    # the damping uses the blended factor too (e = 0 so that d = delta)
    sc0 = copy.deepcopy(sc)
    sc0["production"]["error_mode"]["e_um"] = 0.0
    C = sc["design"]["mesh"]["damping_Ns_per_m"]
    u = np.array([3.0, 3.0 - W / 4, 3.0 + W / 4])
    F, _, _ = locked_law(sc0, u, np.zeros(3), np.full(3, 0.01))
    fgu, _ = ref.blended_law(sc0, u)
    np.testing.assert_allclose(F, C * fgu * 0.01, rtol=1e-14)
    assert F[0] == pytest.approx(0.75 * C * 0.01, rel=1e-15)


def test_error_continuous_across_the_tooth_change_for_a_0():
    changes = {"production.error_mode.a": 0.0, "production.error_mode.r": 0.3}
    e = ref.tooth_error_amplitudes(scenario(**changes))
    eps = 1e-9
    for w in (W, 0.0):
        sc = scenario(w, **changes)
        E = ref.total_error(sc, np.array([3.0 - eps, 3.0, 3.0 + eps]))
        if w > 0:
            assert abs(E[2] - E[0]) < 1e-6 * e[3]  # continuous
            # at the change: half way between the outgoing pair's extended line (0) and e_3 (1 - 0)
            assert E[1] == pytest.approx(0.5 * e[3], rel=1e-14)
            # locked-mode error on either side of u = 3 (the last / first interval of a period)
            _, EL, _ = locked_law(sc, np.array([3.0 - eps, 3.0 + eps]), np.zeros(2), np.zeros(2))
            np.testing.assert_allclose(EL, E[[0, 2]], rtol=0, atol=1e-12 * e[3])
        else:
            assert E[2] - E[0] == pytest.approx(e[3], rel=1e-6)  # the sharp law jumps by e_3


def test_extended_error_shape_and_blend_by_hand():
    e = 7e-6
    shape = ref.error_shape_ext
    q = np.linspace(0.0, 0.999, 37)
    for a in (0.0, 0.3, 0.5, 1.0):
        np.testing.assert_array_equal(shape(q, a, e), ref.error_shape(q, a, e))  # same on [0, 1)
    # straight lines outside [0, 1): p/a below 0, (1 - p)/(1 - a) above 1
    np.testing.assert_allclose(shape([-0.02, 1.02], 0.5, e), [-0.04 * e, -0.04 * e], rtol=1e-12)
    np.testing.assert_allclose(shape([-0.02, 1.02], 0.2, e), [-0.1 * e, -0.025 * e], rtol=1e-12)
    # a = 0: the falling line also below 0; a = 1: the rising line also above 1 (its only line)
    np.testing.assert_allclose(shape([-0.02, 1.02], 0.0, e), [1.02 * e, -0.02 * e], rtol=1e-12)
    np.testing.assert_allclose(shape([-0.02, 1.02], 1.0, e), [-0.02 * e, 1.02 * e], rtol=1e-12)
    # whole error at p = w/4 after a tooth change, by hand: X_out + S(1/4) (X_in - X_out)
    sc = scenario(**{"production.error_mode.a": 0.2})
    ei = ref.tooth_error_amplitudes(sc)
    p = W / 4
    s = float(ref.smooth_step(0.25))
    E_out = ei[4] * (1 - (1 + p)) / 0.8  # pair 4 at phase p + 1
    E_in = ei[5] * p / 0.2
    assert float(ref.total_error(sc, 5 + p)) == pytest.approx(E_out + s * (E_in - E_out), rel=1e-13)
    # and before the next change: X_in + S(-1/4) (X_next - X_in), pair 6 at phase p - 1
    E_in = ei[5] * (1 - (1 - p)) / 0.8
    E_nx = ei[6] * (-p) / 0.2
    s = float(ref.smooth_step(-0.25))
    assert float(ref.total_error(sc, 6 - p)) == pytest.approx(E_in + s * (E_nx - E_in), rel=1e-13)


def test_smoothed_pit_edges_by_hand():
    pit = {"gear": "pinion", "tooth": 2, "depth_um": 5.0, "start_phase": 0.2, "end_phase": 0.6}
    sc = scenario(**{"condition.pitted_teeth": [pit], "production.error_mode.e_um": 0.0})
    d = 5e-6
    u = 2.0 + np.array([0.2 - W / 2, 0.2, 0.2 + W / 2, 0.4, 0.6 - W / 2, 0.6, 0.6 + W / 2])
    np.testing.assert_allclose(ref.total_error(sc, u), [0, -d / 2, -d, -d, -d, -d / 2, 0], atol=1e-20)
    # other teeth are not pitted
    np.testing.assert_array_equal(ref.total_error(sc, u + 1.0), 0.0)


def test_locked_mode_law_equals_the_literal_law():
    """The integrator's locked-mode law against the literal transcription at random points of many
    intervals: every feature at once (factors, pits at the period ends, run-out, friction, a = 0 / 1)."""
    rng = np.random.default_rng(4)
    for a, w, prof in ((0.0, 0.08, "contact-ratio"), (0.3, 0.02, "table"), (1.0, 0.1, "contact-ratio")):
        sc = scenario(
            w,
            **{
                "production.error_mode.a": a,
                "condition.damaged_teeth": [
                    {"gear": "pinion", "tooth": 3, "stiffness_factor": 0.5},
                    {"gear": "wheel", "tooth": 2, "stiffness_factor": 0.7},
                ],
                "condition.pitted_teeth": [
                    {"gear": "pinion", "tooth": 2, "depth_um": 5.0, "start_phase": 0.0, "end_phase": 0.6},
                    {"gear": "wheel", "tooth": 3, "depth_um": 3.0, "start_phase": 0.5, "end_phase": 1.0},
                ],
                "production.eccentricity": [{"gear": "pinion", "amplitude_um": 3.0, "phase_deg": 20.0}],
            },
        )
        if prof == "table":
            sc["design"]["mesh"].update(
                stiffness_profile="table",
                table_phase=[0.1, 0.45, 0.8],
                table_stiffness_N_per_m=[1.2e9, 1.35e9, 1.25e9],
            )
        mesh = ref._Mesh(sc)
        u = rng.uniform(-1.0, 6.0, 3000)
        delta = 2e-5 + 1e-6 * rng.standard_normal(u.size)
        ddot = 1e-3 * rng.standard_normal(u.size)
        # speeds near rolling, either way round, whose sliding velocity spans |v_sl| < v_0 and beyond
        wp = 10.0 * rng.standard_normal(u.size)
        ww = wp * 0.0681 / 0.2067 * (1.0 + 0.02 * rng.standard_normal(u.size))
        F, E, mue, T = locked_law(sc, u, delta, ddot, w_p=wp, w_w=ww)
        lit = ref.mesh_force_literal(sc, u, delta, ddot)
        Fr = ref.F_rated(sc)
        np.testing.assert_allclose(F, lit["F"], rtol=0, atol=1e-12 * Fr)
        np.testing.assert_allclose(E, lit["E"], rtol=0, atol=1e-18)
        mu = sc["condition"]["friction_coefficient"]
        np.testing.assert_allclose(mue, mu * ref.friction_envelope(lit["p"], w), rtol=0, atol=1e-15)
        fr = ref.friction_moments(sc, lit["p"], lit["F"], wp, ww)
        np.testing.assert_allclose(T, fr["T"], rtol=0, atol=1e-12 * Fr)
        slow = np.abs(fr["v_sl"]) < 0.01
        assert 0.01 < np.mean(slow) < 0.5  # both branches of sigma are covered
        assert mesh.bA.size > 8  # ramp ends are break points


def test_limits_are_checked():
    with pytest.raises(ValueError, match="transition_width"):
        ref.check_transition_width(scenario(0.2))
    with pytest.raises(ValueError, match="min\\(2h"):
        ref.check_transition_width(scenario(0.05, **{"design.mesh.contact_ratio": 1.02}))
    with pytest.raises(ValueError, match="pitch_point_phase"):
        ref.check_transition_width(scenario(0.05, **{"design.mesh.pitch_point_phase": 0.01}))
    pit = {"gear": "wheel", "tooth": 1, "depth_um": 5.0, "start_phase": 0.2, "end_phase": 0.22}
    with pytest.raises(ValueError, match="narrower"):
        ref.check_transition_width(scenario(0.05, **{"condition.pitted_teeth": [pit]}))
    sc = scenario(0.05)
    del sc["design"]["mesh"]["transition_width"]  # absent key: the sharp law
    assert ref.check_transition_width(sc) == 0.0


def test_outputs_match_the_literal_law_with_backlash():
    """Returned forces (locked modes, contact events with the blended error) equal the literal law on
    the returned states, with separation in the dead zone."""
    sc = copy.deepcopy(ref.load_scenario(SCEN / "one-stage-backlash.toml"))
    sc["design"]["mesh"]["transition_width"] = 0.05
    sc["operation"]["t_end_s"] = 0.02
    sc["condition"]["damaged_teeth"] = [{"gear": "pinion", "tooth": 3, "stiffness_factor": 0.5}]
    res = ref.simulate_reference(sc)
    d = sc["design"]
    r1, r2, z1 = d["pinion"]["base_radius_m"], d["wheel"]["base_radius_m"], d["pinion"]["teeth"]
    q, v = res["coordinates"], res["velocities"]
    lit = ref.mesh_force_literal(sc, q[1] * z1 / (2 * math.pi), r1 * q[1] - r2 * q[2], r1 * v[1] - r2 * v[2])
    np.testing.assert_allclose(res["mesh_force_N"], lit["F"], rtol=0, atol=1e-9 * ref.F_rated(sc))
    assert np.any(lit["F"] == 0.0)  # the teeth separate


# ----------------------------------------------------------------------------------------------
# Integration against gearbody
# ----------------------------------------------------------------------------------------------
BASE = [
    'operation.initial_state="steady"',
    "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
    "production.error_mode={a=0.5,e_um=10.0,r=0.3}",
    "condition.friction_coefficient=0.05",
    "solver.anti_aliasing=false",
    "operation.t_end_s=0.02",
    "design.mesh.transition_width=0.01",
    "solver.relative_tolerance=1e-13",
    "solver.absolute_tolerance=1e-11",
]
CASES = {
    "plain": [],
    "damaged-tooth": ['condition.damaged_teeth=[{gear="pinion", tooth=3, stiffness_factor=0.5}]'],
    "E(0,10,0)": ["production.error_mode={a=0.0,e_um=10.0,r=0.0}"],
    "pit": [
        'condition.pitted_teeth=[{gear="pinion", tooth=2, depth_um=5.0, start_phase=0.2, end_phase=0.6}]'
    ],
}


@pytest.mark.parametrize("case", list(CASES))
def test_one_stage_agrees_with_gearbody(case):
    from gearbody.engine import simulate
    from gearbody.model import load_scenario, scenario_to_dict

    sc = load_scenario("one-stage", BASE + CASES[case])
    res = simulate(sc)
    out = ref.simulate_reference(scenario_to_dict(sc), t_eval=res.time_s)
    err = np.max(np.abs(out["mesh_force_N"] - res.mesh_force)) / sc.rated_mesh_force_N
    assert err < 5e-3  # measured ~1e-7 (1e-5 %)


def test_two_stage_train_with_per_stage_widths_agrees_with_gearbody():
    from gearbody.engine import simulate
    from gearbody.model import load_scenario, scenario_to_dict

    base = [b for b in BASE if "transition_width" not in b and not b.startswith("production.")]
    stage_errors = [f"design.stages.{k}.error_mode={{a=0.5,e_um=10.0,r=0.3}}" for k in (1, 2)]
    data = scenario_to_dict(load_scenario("two-stage", [*base, *stage_errors]))
    stages = data["design"]["stages"]
    stages[0]["mesh"]["transition_width"] = 0.01
    stages[1]["mesh"]["transition_width"] = 0.02
    stages[1]["damaged_teeth"] = [{"gear": "pinion", "tooth": 1, "stiffness_factor": 0.6}]
    sc = load_scenario(data)
    res = simulate(sc)
    out = ref.simulate_reference(scenario_to_dict(sc), t_eval=res.time_s)
    for k in range(2):
        prefix = "" if k == 0 else "stage_2_"
        err = np.max(np.abs(res[prefix + "mesh_force_N"] - out["stage_mesh_force_N"][k]))
        assert err / sc.stage_rated_force_N(k) < 5e-3  # measured ~1e-7


def test_lateral_8dof_agrees_with_gearbody():
    from gearbody_validation import reference_lateral as lat
    from gearbody_validation.reference_lateral import simulate_reference_lateral

    from gearbody.engine import simulate
    from gearbody.model import load_scenario, scenario_to_dict

    over = [b if b != "operation.t_end_s=0.02" else "operation.t_end_s=0.01" for b in BASE]
    sc = load_scenario("lateral-8dof", [*over, *CASES["damaged-tooth"]])
    res = simulate(sc)
    out = simulate_reference_lateral(scenario_to_dict(sc), t_eval=res.time_s)
    err = np.max(np.abs(out["mesh_force_N"] - res.mesh_force)) / sc.rated_mesh_force_N
    assert err < 5e-3  # measured ~1e-8
    for gear in ("pinion", "wheel"):
        for d, axis in enumerate("xy"):
            f_ref = out["bearing_force_N"][gear][d]
            dev = np.max(np.abs(res[f"{gear}_bearing_force_{axis}_N"] - f_ref))
            assert dev < 1e-3 * np.max(np.abs(f_ref))
    # the friction in the lateral outputs: T = -mu e(p) |F| sigma(v_sl / v_0) of the literal law, with the
    # centres' velocities in v_sl
    p = res["mesh_phase"]
    data = scenario_to_dict(sc)
    view = ref.stage_view(data, 0)
    v = out["velocities"]
    m = lat.mesh_geometry(data["design"]["stages"][0]["mesh"])["m"]
    v_c = m @ (out["centre_velocity_m_s"]["pinion"] - out["centre_velocity_m_s"]["wheel"])
    T = ref.friction_moments(view, p, out["mesh_force_N"], v[1], v[2], v_c)["T"]
    np.testing.assert_allclose(out["stage_friction_force_N"][0], T, rtol=0, atol=1e-6 * sc.rated_mesh_force_N)
