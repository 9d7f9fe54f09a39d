"""Self-checks of the fault errors (run-out and pits, docs/scenario.md "Fault errors") in the independent
references validation/reference.py and validation/reference_lateral.py.

The references themselves never import gearbody; these tests use ``gearbody.model`` only to obtain
resolved scenario dicts (``scenario_to_dict(load_scenario(...))``), as the validation does.
"""

from __future__ import annotations

import copy
import math
import pathlib

import numpy as np
import pytest
from gearbody_validation import reference as ref
from gearbody_validation import reference_lateral as lat
from scipy.integrate import solve_ivp
from shapes import legacy

from gearbody.model import load_scenario, scenario_to_dict

SCEN = pathlib.Path(__file__).resolve().parents[1] / "validation" / "scenarios"
STEADY = [
    'operation.initial_state="steady"',
    "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
]
NO_ERROR_MODE = "production.error_mode={a=0.5,e_um=0.0,r=0.0}"
WHEEL_RUNOUT = 'production.eccentricity=[{gear="wheel",amplitude_um=20.0,phase_deg=0.0}]'
RUNOUTS = [
    {"gear": "pinion", "amplitude_um": 5.0, "phase_deg": 30.0},
    {"gear": "wheel", "amplitude_um": 20.0, "phase_deg": 45.0},
]
PITS = [  # pinion tooth 0 and wheel tooth 29 meet at n = 29 (and the pits overlap on 0.3 <= p < 0.4)
    {"gear": "pinion", "tooth": 0, "depth_um": 5.0, "start_phase": 0.2, "end_phase": 0.5},
    {"gear": "wheel", "tooth": 29, "depth_um": 2.0, "start_phase": 0.3, "end_phase": 0.4},
]


def one_stage(*overrides: str) -> dict:
    return legacy(scenario_to_dict(load_scenario("one-stage", list(overrides))))


def with_faults(sc: dict, runouts=RUNOUTS, pits=PITS) -> dict:
    sc = copy.deepcopy(sc)
    sc["production"]["eccentricity"] = copy.deepcopy(runouts)
    sc["condition"]["pitted_teeth"] = copy.deepcopy(pits)
    return sc


def kinematics(sc: dict, res: dict):
    """u, delta, delta_dot of a one-mesh scene at the output samples, from the returned states."""
    d = sc["design"]
    r1, r2, z1 = d["pinion"]["base_radius_m"], d["wheel"]["base_radius_m"], d["pinion"]["teeth"]
    q, v = res["coordinates"], res["velocities"]
    if sc["meta"]["scene"] == "muller":
        theta = ref.profile_integral(res["time"], sc["operation"]["speed_profile"])
        return theta * d["motor"]["synchronous_speed_rad_s"] * z1 / (2 * math.pi), q[0], v[0]
    ip, iw = (1, 2) if sc["meta"]["scene"] == "one-stage" else (0, 1)
    return q[ip] * z1 / (2 * math.pi), r1 * q[ip] - r2 * q[iw], r1 * v[ip] - r2 * v[iw]


def pits_met(sc: dict, kin) -> bool:
    """True when some sample lies in a pit window (the error is lower than without the pits)."""
    plain = copy.deepcopy(sc)
    plain["condition"]["pitted_teeth"] = []
    return bool(
        np.any(ref.mesh_force_literal(sc, *kin)["E"] < ref.mesh_force_literal(plain, *kin)["E"] - 1e-6)
    )


# ---------------------------------------------------------------------------------------------
# Formulas
# ---------------------------------------------------------------------------------------------
def test_fault_helpers_breakpoints_and_missing_keys():
    sc = with_faults(one_stage())
    u = np.array([0.0, 7.3, 100.0])
    expected = 5e-6 * np.sin(2 * np.pi * u / 29 + np.pi / 6) + 20e-6 * np.sin(2 * np.pi * u / 88 + np.pi / 4)
    np.testing.assert_allclose(ref.runout_error(sc, u), expected, rtol=1e-13, atol=0)
    # pit of pinion tooth 0 on [0.2, 0.5), wheel tooth 29 on [0.3, 0.4)
    p = np.array([0.1, 0.2, 0.35, 0.45, 0.5, 0.35, 0.35])
    i = np.array([0, 0, 0, 0, 0, 1, 1])
    j = np.array([29, 29, 29, 29, 29, 30, 29])
    np.testing.assert_allclose(
        ref.pit_error(sc, p, i, j), -1e-6 * np.array([0, 5, 7, 5, 0, 0, 2]), rtol=1e-15
    )
    sc["condition"]["pitted_teeth"].append(
        {"gear": "pinion", "tooth": 3, "depth_um": 1.0, "start_phase": 0.7, "end_phase": 1.0}
    )
    # pit edges join the break points; 0.3 = h = (1.6 - 1) / 2 up to round-off is kept once
    np.testing.assert_allclose(ref.phase_breakpoints(sc), [0.0, 0.2, 0.3, 0.4, 0.5, 0.7], rtol=1e-12)
    # keys missing (older resolved scenarios) or empty: no fault
    old = one_stage()
    del old["production"]["eccentricity"], old["condition"]["pitted_teeth"]
    assert np.all(ref.runout_error(old, u) == 0.0) and np.all(ref.pit_error(old, p, i, j) == 0.0)
    np.testing.assert_array_equal(ref.phase_breakpoints(old), ref.phase_breakpoints(one_stage()))
    for bad in (
        {"gear": "wheel", "tooth": 88, "depth_um": 1.0, "start_phase": 0.1, "end_phase": 0.2},
        {"gear": "pinion", "tooth": 0, "depth_um": 1.0, "start_phase": 0.3, "end_phase": 0.2},
    ):
        with pytest.raises(ValueError):
            ref.pitted_teeth(with_faults(old, [], [bad]))


def test_mesh_force_with_runout_and_pits_by_hand():
    """F at a given state written out by hand (backlash 50 um, contact): run-out and pits in d only."""
    sc = with_faults(one_stage())
    e0 = (1 - 0.3 * (1 - np.random.default_rng(1).random(29)[0])) * 10e-6  # tooth 0, E(0.5, 10, 0.3)
    e1 = (1 - 0.3 * (1 - np.random.default_rng(1).random(29)[1])) * 10e-6
    delta, ddot, lu, cz = 100e-6, 0.01, 50e-6, 7000.0  # in contact: d > l_u
    mesh = ref._Mesh(sc)
    cases = [  # u, k_z, triangular error, pit depth
        (29.35, 1.2e9, e0 * 0.35 / 0.5, 7e-6),  # n = 29: pinion tooth 0 and wheel tooth 29, both pits
        (29.25, 1.3e9, e0 * 0.25 / 0.5, 5e-6),  # double contact, pinion pit only
        (29.6, 1.2e9, e0 * 0.4 / 0.5, 0.0),  # after both windows
        (30.35, 1.2e9, e1 * 0.35 / 0.5, 0.0),  # teeth 1 / 30: no pit
        (117.35, 1.2e9, e1 * 0.35 / 0.5, 2e-6),  # n = 117: pinion tooth 1, wheel tooth 29
    ]
    runouts = []
    for u, kz, e_tri, pit in cases:
        runout = 5e-6 * math.sin(2 * math.pi * u / 29 + math.pi / 6) + 20e-6 * math.sin(
            2 * math.pi * u / 88 + math.pi / 4
        )
        d = delta + e_tri + runout - pit
        F = kz * (d - lu) + cz * ddot  # the damping sees delta_dot only
        lit = ref.mesh_force_literal(sc, u, delta, ddot)
        assert float(lit["E"]) == pytest.approx(e_tri + runout - pit, rel=1e-12, abs=1e-20)
        assert float(lit["F_t"]) == pytest.approx(cz * ddot, rel=1e-14)
        assert float(lit["F"]) == pytest.approx(F, rel=1e-12)
        # the locked-mode law of the integrator gives the same force in the mode of that state
        n, k = mesh.phase_mode(u, 1.0)
        assert ref._mesh_force(mesh.mode_consts(n, k, 1), u - n, delta, ddot) == pytest.approx(F, rel=1e-12)
        runouts.append(runout)
    assert max(abs(x) for x in runouts) > 5e-6  # the run-out is not negligible at these states


def test_steady_initial_state_uses_the_total_error():
    """delta_0 = F_0 / k + l_u - E with E including run-out and pits (one-stage; two-stage stage by stage,
    whose second pinion starts at a phase p_2 != 0)."""
    pits = [{"gear": "pinion", "tooth": 0, "depth_um": 5.0, "start_phase": 0.0, "end_phase": 0.1}]
    sc = with_faults(one_stage(*STEADY), pits=pits)
    q0, _ = ref.initial_state(sc)
    E0 = 5e-6 * math.sin(math.pi / 6) + 20e-6 * math.sin(math.pi / 4) - 5e-6  # triangle E(0) = 0
    delta0 = 2124.0 / 0.206732 / 1.3e9 + 50e-6 - E0
    assert q0[2] == pytest.approx(-delta0 / 0.206732, rel=1e-13)

    tr = copy.deepcopy(ref.load_scenario(SCEN / "two-stage-steady.toml"))
    st = tr["design"]["stages"]
    st[0].update(eccentricity=copy.deepcopy(RUNOUTS), pitted_teeth=copy.deepcopy(pits))
    st[1]["eccentricity"] = [{"gear": "wheel", "amplitude_um": 30.0, "phase_deg": -60.0}]
    st[1]["error_mode"]["e_um"] = 0.0
    tr["production"]["eccentricity"] = [{"gear": "pinion", "amplitude_um": 999.0, "phase_deg": 0.0}]  # unused
    q0, _ = ref.initial_state(tr)
    Fr = ref.stage_F_rated(tr)
    rp = [x["pinion"]["base_radius_m"] for x in st]
    rw = [x["wheel"]["base_radius_m"] for x in st]
    lu = [x["mesh"]["backlash_um"] * 1e-6 for x in st]
    assert st[0]["error_mode"]["a"] == 0.5 and not st[0]["damaged_teeth"] and not st[1]["damaged_teeth"]
    # stage 1 at p = 0 (double contact; triangle E(0) = 0): the same fault errors as above
    delta1 = Fr[0] / st[0]["mesh"]["stiffness_double_N_per_m"] + lu[0] - E0
    assert q0[2] == pytest.approx(-delta1 / rw[0], rel=1e-13)
    # stage 2: its pinion angle follows the chain, p_2 != 0; only the wheel run-out of stage 2 acts
    u2 = q0[3] * st[1]["pinion"]["teeth"] / (2 * math.pi)
    E2 = 30e-6 * math.sin(2 * math.pi * u2 / st[1]["wheel"]["teeth"] - math.pi / 3)
    delta2 = Fr[1] / float(ref.base_stiffness(u2 % 1.0, st[1]["mesh"])) + lu[1] - E2
    assert q0[4] == pytest.approx((rp[1] * q0[3] - delta2) / rw[1], rel=1e-13)
    assert u2 % 1.0 > 0.0 and abs(E2) > 1e-6


# ---------------------------------------------------------------------------------------------
# Simulations
# ---------------------------------------------------------------------------------------------
@pytest.mark.slow
def test_wheel_runout_gives_a_line_at_the_wheel_rotation_frequency():
    """Steady rated one-stage, 20 um run-out of the wheel: the mesh force spectrum over two wheel
    revolutions (detrended, Hann) has a line at f_w = w_wheel / 2 pi. Measured 13.8 N with, 0.04 N
    without."""
    lines = []
    for extra in ([], [WHEEL_RUNOUT]):
        sc = one_stage(*STEADY, "operation.t_end_s=0.36", *extra)
        res = ref.simulate_reference(sc)
        f_w = float(np.mean(res["velocities"][2])) / (2 * math.pi)
        t, F = res["time"], res["mesh_force_N"]
        m = t <= 2.0 / f_w
        t, F = t[m], F[m]
        assert t[-1] > 2.0 / f_w - 1e-4  # two whole revolutions
        F = F - np.polyval(np.polyfit(t, F, 1), t)
        w = np.hanning(t.size)
        lines.append(abs(2.0 * np.sum(F * w * np.exp(-2j * math.pi * f_w * t)) / np.sum(w)))
    off, on = lines
    assert on > 5.0 and on > 50.0 * off


@pytest.mark.parametrize("gear", ["pinion", "wheel"])
def test_pit_drops_the_force_by_k_depth_on_its_tooth_only(gear):
    """Steady rated, no error mode, a 5 um pit on tooth 0 over 0.2 <= p < 0.5: against the pit-free law at
    the same states the force is lower by exactly k(p) * depth while that tooth is in mesh in the window
    (pinion tooth 0 meets at n = 0, 29, 58; wheel tooth 0 only at n = 0 here) and equal elsewhere; and the
    simulated force equals the pit-free run until the window opens, then drops by k_double * depth."""
    base = one_stage(*STEADY, NO_ERROR_MODE, "operation.t_end_s=0.125")
    pit = {"gear": gear, "tooth": 0, "depth_um": 5.0, "start_phase": 0.2, "end_phase": 0.5}
    sc = with_faults(base, [], [pit])
    t_eval = np.unique(np.concatenate((np.arange(2501) / 20000.0, np.linspace(0.0, 2e-3, 2001))))
    a = ref.simulate_reference(sc, t_eval=t_eval)
    b = ref.simulate_reference(base, t_eval=t_eval)
    u, delta, ddot = kinematics(sc, a)
    lit = ref.mesh_force_literal(base, u, delta, ddot)
    n = np.floor(u).astype(int)
    p = u - n
    tooth = n % 29 if gear == "pinion" else n % 88
    window = (tooth == 0) & (p >= 0.2) & (p < 0.5)
    assert set(np.unique(n[window])) == ({0, 29, 58} if gear == "pinion" else {0})
    dF = a["mesh_force_N"] - lit["F"]
    assert np.max(np.abs(dF[~window])) < 1e-9 * ref.F_rated(sc)
    np.testing.assert_allclose(dF[window], -lit["k"][window] * 5e-6, rtol=1e-9)
    assert set(np.unique(lit["k"][window])) == {1.2e9, 1.3e9}
    # dynamics: identical until the window first opens, then ~ -1.3e9 * 5e-6 = -6500 N (2 us later)
    first = int(np.argmax(window))
    np.testing.assert_array_equal(a["mesh_force_N"][:first], b["mesh_force_N"][:first])
    assert a["mesh_force_N"][first] - b["mesh_force_N"][first] == pytest.approx(-6500.0, rel=2e-3)


@pytest.mark.parametrize("scene", ["one-stage", "two-wheel", "muller"])
def test_outputs_match_the_literal_law_with_faults(scene):
    """The returned force (locked modes, run-out in the event functions) equals the literal law on the
    returned states; one-stage-backlash separates (dead zone, contact events move with the run-out)."""
    sc = with_faults(ref.load_scenario(SCEN / "one-stage-backlash.toml"))
    sc["meta"]["scene"] = scene
    sc["operation"]["t_end_s"] = 0.01
    res = ref.simulate_reference(sc)
    lit = ref.mesh_force_literal(sc, *kinematics(sc, res))
    np.testing.assert_allclose(res["mesh_force_N"], lit["F"], rtol=0, atol=1e-9 * ref.F_rated(sc))
    if scene == "one-stage":
        assert res["kd"].max() > 2.0 and np.any(res["kd"] == 0.0)


@pytest.mark.slow
def test_agrees_with_brute_force_literal_integration_with_faults():
    """Separation with backlash plus run-out (large, to move the contact edges) and pits: segmented
    integration vs a plain tight adaptive integration of the literal right-hand side."""
    runouts = [
        {"gear": "pinion", "amplitude_um": 30.0, "phase_deg": 30.0},
        {"gear": "wheel", "amplitude_um": 20.0, "phase_deg": 45.0},
    ]
    pits = [
        {"gear": "pinion", "tooth": 0, "depth_um": 15.0, "start_phase": 0.2, "end_phase": 0.5},
        {"gear": "wheel", "tooth": 1, "depth_um": 10.0, "start_phase": 0.4, "end_phase": 0.8},
    ]
    sc = with_faults(ref.load_scenario(SCEN / "one-stage-backlash.toml"), runouts, pits)
    sc["operation"]["t_end_s"] = 0.004
    res = ref.simulate_reference(sc)
    d = sc["design"]
    r1, r2 = d["pinion"]["base_radius_m"], d["wheel"]["base_radius_m"]
    k1, k2 = d["coupling"]["stiffness_Nm_per_rad"], d["output_shaft"]["stiffness_Nm_per_rad"]
    mot = d["motor"]
    Mr = d["machine"]["rated_torque_Nm"]

    def rhs(t, y):
        p1, p2, p3, p4, w1, w2, w3, w4 = y
        mesh = ref.mesh_force_literal(sc, p2 * 29 / (2 * math.pi), r1 * p2 - r2 * p3, r1 * w2 - r2 * w3)
        F = float(mesh["F"])
        fr = ref.friction_moments(sc, mesh["p"], F, w2, w3)
        ms = float(ref.kloss_torque(w1, mot["synchronous_speed_rad_s"], mot))
        m1, m2 = k1 * (p1 - p2), k2 * (p3 - p4)
        return [
            w1,
            w2,
            w3,
            w4,
            (ms - m1) / mot["inertia_kg_m2"],
            (m1 - r1 * F + float(fr["M_zt1"])) / d["pinion"]["inertia_kg_m2"],
            (r2 * F - float(fr["M_zt2"]) - m2) / d["wheel"]["inertia_kg_m2"],
            (m2 - Mr) / d["machine"]["inertia_kg_m2"],
        ]

    assert d["coupling"]["damping_Nms_per_rad"] == d["output_shaft"]["damping_Nms_per_rad"] == 0.0
    y0 = np.concatenate(ref.initial_state(sc))
    b = solve_ivp(
        rhs, (0.0, res["time"][-1]), y0, method="DOP853", rtol=1e-12, atol=1e-14, t_eval=res["time"]
    )
    brute = {"coordinates": b.y[:4], "velocities": b.y[4:], "time": res["time"]}
    Fb = ref.mesh_force_literal(sc, *kinematics(sc, brute))["F"]
    assert np.max(np.abs(Fb - res["mesh_force_N"])) / ref.F_rated(sc) < 5e-5
    # the faults matter here: without them the force differs by much more than that
    plain = copy.deepcopy(sc)
    plain["production"]["eccentricity"], plain["condition"]["pitted_teeth"] = [], []
    assert np.max(
        np.abs(ref.simulate_reference(plain)["mesh_force_N"] - res["mesh_force_N"])
    ) > 0.1 * ref.F_rated(sc)
    assert res["kd"].max() > 2.0 and np.any(res["kd"] == 0.0)


def test_train_stages_use_their_own_fault_keys():
    """Two stages with backlash, each with its own run-out and pits (the top-level keys are not used in a
    train): the stage forces equal the literal law of each stage view; a 1-stage train with the faults in
    its stage equals the one-stage scene with them at the top level."""
    tr = copy.deepcopy(ref.load_scenario(SCEN / "two-stage-steady.toml"))
    tr["operation"]["t_end_s"] = 0.01
    s1, s2 = tr["design"]["stages"]
    for st in (s1, s2):
        st["mesh"]["backlash_um"] = 10.0
    s1.update(eccentricity=copy.deepcopy(RUNOUTS), pitted_teeth=copy.deepcopy(PITS))
    s2["eccentricity"] = [{"gear": "wheel", "amplitude_um": 30.0, "phase_deg": -60.0}]
    s2["pitted_teeth"] = [
        {"gear": "pinion", "tooth": 0, "depth_um": 8.0, "start_phase": 0.1, "end_phase": 0.6}
    ]
    tr["production"]["eccentricity"] = [{"gear": "pinion", "amplitude_um": 999.0, "phase_deg": 0.0}]
    tr["condition"]["pitted_teeth"] = [
        {"gear": "pinion", "tooth": 1, "depth_um": 999.0, "start_phase": 0.0, "end_phase": 1.0}
    ]
    res = ref.simulate_reference(tr)
    Fr = ref.stage_F_rated(tr)
    for s, st in enumerate((s1, s2)):
        r1, r2, z1 = st["pinion"]["base_radius_m"], st["wheel"]["base_radius_m"], st["pinion"]["teeth"]
        ip, iw = 1 + 2 * s, 2 + 2 * s
        q, v = res["coordinates"], res["velocities"]
        kin = (q[ip] * z1 / (2 * math.pi), r1 * q[ip] - r2 * q[iw], r1 * v[ip] - r2 * v[iw])
        lit = ref.mesh_force_literal(ref.stage_view(tr, s), *kin)
        np.testing.assert_allclose(res["stage_mesh_force_N"][s], lit["F"], rtol=0, atol=1e-9 * Fr[s])
        assert pits_met(ref.stage_view(tr, s), kin)
    # 1-stage train (via the lateral module's rewrite) == one-stage scene, faults included
    one = with_faults(ref.load_scenario(SCEN / "one-stage-backlash.toml"))
    one["operation"]["t_end_s"] = 0.01
    a = ref.simulate_reference(one)
    b = ref.simulate_reference(lat.as_train(lat.resolve_lateral_defaults(one)))
    np.testing.assert_allclose(b["mesh_force_N"], a["mesh_force_N"], rtol=0, atol=1e-9 * ref.F_rated(one))


def test_lateral_reference_with_faults():
    """lateral-8dof with run-out and pits: the force equals the literal law with delta including the
    centre displacements projected on n; without lateral gears it equals the torsional reference."""
    sc = scenario_to_dict(
        load_scenario(
            "lateral-8dof",
            [*STEADY, "production.error_mode={a=0.5,e_um=10.0,r=0.3}", "operation.t_end_s=0.005"],
        )
    )
    sc = with_faults(legacy(sc))
    res = lat.simulate_reference_lateral(sc)
    d = sc["design"]
    r1, r2 = d["pinion"]["base_radius_m"], d["wheel"]["base_radius_m"]
    nvec = lat.mesh_geometry(d["mesh"])["n"]
    q, v = res["coordinates"], res["velocities"]
    # coordinates [motor, pinion, wheel, machine, pinion x, pinion y, wheel x, wheel y]
    delta = r1 * q[1] - r2 * q[2] + nvec @ (q[4:6] - q[6:8])
    ddot = r1 * v[1] - r2 * v[2] + nvec @ (v[4:6] - v[6:8])
    u = q[1] * d["pinion"]["teeth"] / (2 * math.pi)
    lit = ref.mesh_force_literal(sc, u, delta, ddot)
    np.testing.assert_allclose(res["mesh_force_N"], lit["F"], rtol=0, atol=1e-9 * ref.F_rated(sc))
    assert pits_met(sc, (u, delta, ddot))
    # steady start: total deflection delta_0 = F_0 / k + l_u - E(0) with the fault errors
    E0 = 5e-6 * math.sin(math.pi / 6) + 20e-6 * math.sin(math.pi / 4)
    F0 = d["machine"]["rated_torque_Nm"] / r2
    lu = d["mesh"]["backlash_um"] * 1e-6
    assert delta[0] == pytest.approx(F0 / d["mesh"]["stiffness_double_N_per_m"] + lu - E0, rel=1e-12)
    # no lateral gear: identical to the torsional reference
    tor = with_faults(ref.load_scenario(SCEN / "one-stage-backlash.toml"))
    tor["operation"]["t_end_s"] = 0.005
    a = ref.simulate_reference(tor)
    b = lat.simulate_reference_lateral(tor)
    np.testing.assert_allclose(b["mesh_force_N"], a["mesh_force_N"], rtol=0, atol=1e-9 * ref.F_rated(tor))
