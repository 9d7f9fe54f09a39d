"""Self-checks of the independent reference model (validation/reference.py) against hand-computed facts.

These tests never import gearbody: the reference must stand on its own.
"""

from __future__ import annotations

import copy
import math
import pathlib

import numpy as np
import pytest
from gearbody_validation import reference as ref
from scipy.integrate import solve_ivp

ROOT = pathlib.Path(__file__).resolve().parents[1]

SCEN = ROOT / "validation" / "scenarios"


def scenario(name: str = "one-stage-steady", **changes) -> dict:
    """Load a resolved scenario and apply dotted-key changes, e.g. ``**{"design.mesh.backlash_um": 5}``."""
    sc = copy.deepcopy(ref.load_scenario(SCEN / f"{name}.toml"))
    for key, val in changes.items():
        node = sc
        *path, last = key.split(".")
        for part in path:
            node = node[part]
        node[last] = val
    return sc


def mesh_kinematics(sc: dict, res: dict):
    """u, delta, delta_dot at the output samples, computed here from the returned states."""
    d = sc["design"]
    r1, r2, z1 = d["pinion"]["base_radius_m"], d["wheel"]["base_radius_m"], d["pinion"]["teeth"]
    q, v = res["coordinates"], res["velocities"]
    scene = sc["meta"]["scene"]
    if scene == "muller":
        wsr = d["motor"]["synchronous_speed_rad_s"]
        theta = ref.profile_integral(res["time"], sc["operation"]["speed_profile"]) * wsr
        return theta * z1 / (2 * math.pi), q[0], v[0]
    ip, iw = (1, 2) if scene == "one-stage" else (0, 1)
    return q[ip] * z1 / (2 * math.pi), r1 * q[ip] - r2 * q[iw], r1 * v[ip] - r2 * v[iw]


def whole_periods(u: np.ndarray) -> slice:
    """Sample range between the first and the last integer crossing of u (whole mesh periods)."""
    n = np.floor(u)
    idx = np.nonzero(np.diff(n))[0] + 1
    assert idx.size >= 3, "need a few mesh periods"
    return slice(idx[0], idx[-1])


CONSTANT_K = {
    "design.mesh.stiffness_profile": "table",
    "design.mesh.table_phase": [0.0],
    "design.mesh.table_stiffness_N_per_m": [1.25e9],
}


# ---------------------------------------------------------------------------------------------
# Pure formulas
# ---------------------------------------------------------------------------------------------
def test_random_l_reproducible_and_error_amplitudes():
    sc = scenario()
    l_ref = np.random.default_rng(1).random(29)
    assert np.array_equal(ref.random_l(1, 29), l_ref)
    e_i = ref.tooth_error_amplitudes(sc)
    assert e_i.shape == (29,)
    np.testing.assert_allclose(e_i, (1 - 0.3 * (1 - l_ref)) * 10e-6, rtol=0, atol=1e-20)
    assert np.all(e_i <= 10e-6) and np.all(e_i >= 0.7 * 10e-6)
    # r = 0 gives the same error on every tooth
    sc0 = scenario(**{"production.error_mode.r": 0.0})
    np.testing.assert_allclose(ref.tooth_error_amplitudes(sc0), 10e-6, rtol=1e-15)


def test_triangular_error_shape():
    e = 7e-6
    # E(0.5, e): apex e at p = 0.5, zero at both ends, linear flanks
    p = np.array([0.0, 0.25, 0.5, 0.75, 1.0 - 1e-12])
    np.testing.assert_allclose(ref.error_shape(p, 0.5, e), [0, e / 2, e, e / 2, 0], atol=1e-16)
    # E(0.1, e): apex at 0.1
    np.testing.assert_allclose(ref.error_shape([0.05, 0.1, 0.55], 0.1, e), [e / 2, e, e / 2], rtol=1e-12)
    # limiting shapes a = 0 and a = 1 (see report: not zero at both ends)
    np.testing.assert_allclose(ref.error_shape([0.0, 0.5], 0.0, e), [e, e / 2], rtol=1e-12)
    np.testing.assert_allclose(ref.error_shape([0.0, 0.5, 0.999], 1.0, e), [0, e / 2, 0.999 * e], rtol=1e-12)
    # negative error E(0.5, -e, 0)
    assert ref.error_shape(0.5, 0.5, -e) == pytest.approx(-e)


def test_stiffness_profile_and_tooth_factors():
    mesh = scenario()["design"]["mesh"]
    h = (1.6 - 1.0) / 2  # = 0.30000000000000004 in binary floating point
    k = ref.base_stiffness([0.0, h - 1e-9, h, 0.5, 1 - h - 1e-9, 1 - h, 0.99], mesh)
    np.testing.assert_array_equal(k, [1.3e9, 1.3e9, 1.2e9, 1.2e9, 1.2e9, 1.3e9, 1.3e9])
    tab = dict(mesh, stiffness_profile="table", table_phase=[0.2, 0.6], table_stiffness_N_per_m=[1e9, 2e9])
    # periodic linear interpolation with period 1: 0.6 -> 1.2(=0.2) spans 0.6
    np.testing.assert_allclose(
        ref.base_stiffness([0.2, 0.4, 0.6, 0.9, 0.0], tab), [1e9, 1.5e9, 2e9, 1.5e9, 1e9 + 1e9 / 3]
    )
    sc = scenario(
        **{
            "condition.damaged_teeth": [
                {"gear": "pinion", "tooth": 3, "stiffness_factor": 0.5},
                {"gear": "wheel", "tooth": 87, "stiffness_factor": 0.2},
            ]
        }
    )
    f, g = ref.tooth_factors(sc)
    assert f[3] == 0.5 and g[87] == 0.2 and f.sum() == 28.5 and g.sum() == pytest.approx(87.2)
    # tooth in mesh after n whole periods: pinion n mod 29, wheel n mod 88 (n = -1 -> 28, 87)
    lit = ref.mesh_force_literal(sc, np.array([3.5, -0.5, 88 + 3.5]), 1e-5, 0.0)
    np.testing.assert_array_equal(lit["i"], [3, 28, 91 % 29])
    np.testing.assert_array_equal(lit["j"], [3, 87, 3])
    np.testing.assert_allclose(lit["k"], [0.6e9, 1.2e9 * 0.2, 1.2e9 * f[91 % 29]])


def test_backlash_dead_zone_and_contact_damping():
    sc = scenario(**{"design.mesh.backlash_um": 5.0, "production.error_mode.e_um": 0.0})
    lu = 5.0 * 1e-6
    d = np.array([-8e-6, -lu, -2e-6, 0.0, 4.9e-6, lu, 9e-6])
    lit = ref.mesh_force_literal(sc, np.full(d.size, 0.5), d, 0.01)  # p = 0.5: single contact 1.2e9
    k = 1.2e9
    np.testing.assert_allclose(lit["F_el"], [k * -3e-6, 0, 0, 0, 0, 0, k * 4e-6], atol=1e-6)
    np.testing.assert_allclose(lit["F_t"], [70.0, 0, 0, 0, 0, 0, 70.0])  # damping only when |d| > l_u


def test_reduced_mass_formula():
    sc = scenario()
    r1, r2, i1, i2 = 0.0681, 0.2067, 0.0205, 1.73
    m = 1.0 / (r1**2 / i1 + r2**2 / i2)
    assert ref.reduced_mass(sc) == pytest.approx(m, rel=1e-14)
    assert m == pytest.approx(3.9856, abs=1e-3)


def test_kloss_formula_and_steady_slip():
    motor = scenario()["design"]["motor"]
    wsr, mb, sb = 108.63, 1750.0, 0.0719
    # breakdown: M_s = M_b at slip s_b; zero at synchronous speed; odd in the slip
    assert ref.kloss_torque(wsr * (1 - sb), wsr, motor) == pytest.approx(mb, rel=1e-13)
    assert ref.kloss_torque(wsr, wsr, motor) == 0.0
    assert ref.kloss_torque(wsr * (1 + sb), wsr, motor) == pytest.approx(-mb, rel=1e-13)
    # slip is referred to the *rated* synchronous speed even when the converter runs at 40 %
    assert ref.kloss_torque(0.4 * wsr - sb * wsr, 0.4 * wsr, motor) == pytest.approx(mb, rel=1e-13)
    m_p = 2124.0 * 0.0681 / 0.2067
    s = ref.steady_slip(m_p, motor)
    assert 0 < s < sb  # stable branch
    assert ref.kloss_torque(wsr * (1 - s), wsr, motor) == pytest.approx(m_p, rel=1e-12)
    assert ref.steady_slip(0.0, motor) == 0.0


def test_friction_dissipates_in_rolling():
    """Rigid rolling (r1 w1 = r2 w2): v_sl = (p - pitch) p_b (w1 + w2), T = -mu |F| sigma(v_sl / v_0)
    opposes it, so the friction power is < 0 away from the pitch point: forward (T > 0 before the
    pitch point, the paper's reversal), backward (every sign turned) and with back-flank contact (F < 0)."""
    sc = scenario()
    p = np.linspace(0, 1, 1001, endpoint=False)
    r1, r2, mu, v0 = 0.0681, 0.2067, 0.05, 0.01
    pb = 2 * math.pi * r1 / 29
    for w1, F in ((107.0, 1.0e4), (-4.0, 1.0e4), (107.0, -1.0e4)):
        w2 = w1 * r1 / r2
        fr = ref.friction_moments(sc, p, F, w1, w2)
        np.testing.assert_allclose(fr["v_sl"], (p - 0.5) * pb * (w1 + w2), rtol=0, atol=1e-15)
        power = fr["M_zt1"] * w1 - fr["M_zt2"] * w2  # pinion gets +M_zt1, wheel -M_zt2
        np.testing.assert_allclose(power, fr["P_f"], rtol=1e-12, atol=1e-12)
        assert np.all(power <= 0.0)
        assert power[p != 0.5].max() < 0
        fast = np.abs(fr["v_sl"]) >= v0  # outside the transition: the full force mu |F|
        np.testing.assert_array_equal(fr["T"][fast], -mu * abs(F) * np.sign(fr["v_sl"][fast]))
        assert 0 < np.mean(~fast) < 0.05 if abs(w1) > 100 else np.mean(~fast) > 0.2
        if w1 > 0:  # forward: T > 0 before the pitch point and < 0 after (the phase-only law's signs)
            assert fr["T"][p < 0.5].min() > 0 and fr["T"][p > 0.5].max() < 0
        else:
            assert fr["T"][p < 0.5].max() < 0 and fr["T"][p > 0.5].min() > 0
    # arms continuous at the pitch point and equal to r tan(alpha_w); no sliding there, so no friction
    at_pitch = ref.friction_moments(sc, 0.5, 1.0e4, 107.0, 107.0 * r1 / r2)
    assert at_pitch["rho1"] == pytest.approx(r1 * math.tan(math.radians(20.0)), rel=1e-14)
    assert at_pitch["rho2"] == pytest.approx(r2 * math.tan(math.radians(20.0)), rel=1e-14)
    assert at_pitch["T"] == pytest.approx(0.0, abs=1e-8)  # v_sl = 0 to round-off (mu F = 500 N)


# ---------------------------------------------------------------------------------------------
# Simulations
# ---------------------------------------------------------------------------------------------
def test_output_grid_and_shapes():
    sc = scenario(**{"operation.t_end_s": 0.01})
    res = ref.simulate_reference(sc)
    np.testing.assert_array_equal(res["time"], np.arange(201) / 20000.0)
    assert res["coordinates"].shape == (4, 201) and res["velocities"].shape == (4, 201)
    assert res["mesh_force_N"].shape == (201,) and res["nfev"].shape == ()
    np.testing.assert_allclose(res["kd"], res["mesh_force_N"] / ref.F_rated(sc))
    for scene, n_dof in (("two-wheel", 2), ("muller", 1)):
        r = ref.simulate_reference(scenario(**{"meta.scene": scene, "operation.t_end_s": 0.002}))
        assert r["coordinates"].shape == (n_dof, 41)
    # initial state: steady
    assert res["kd"][0] == pytest.approx(1.0, rel=1e-12)
    assert res["coordinates"][1, 0] == 0.0


def test_exact_rolling_equilibrium_one_stage():
    """Constant k, e = 0, mu = 0: the 'steady' initial state is an exact equilibrium of the rolling motion."""
    sc = scenario(
        **CONSTANT_K,
        **{
            "production.error_mode.e_um": 0.0,
            "condition.friction_coefficient": 0.0,
            "operation.t_end_s": 0.01,
        },
    )
    res = ref.simulate_reference(sc)
    v = res["velocities"]
    # integration round-off (rtol 1e-10 on angles of ~1 rad) excites the stiff mesh very slightly
    np.testing.assert_allclose(v, v[:, :1] * np.ones_like(v), rtol=1e-7)
    np.testing.assert_allclose(res["kd"], 1.0, rtol=1e-5)
    m_p = 2124.0 * 0.0681 / 0.2067
    w = 108.63 * (1 - ref.steady_slip(m_p, sc["design"]["motor"]))
    np.testing.assert_allclose(v[:, 0], [w, w, w * 0.0681 / 0.2067, w * 0.0681 / 0.2067], rtol=1e-14)


def test_static_deflection_mean_force_one_stage():
    """Steady rated running, e = 0: the mean mesh force over whole mesh periods is the rated force."""
    sc = scenario(**{"production.error_mode.e_um": 0.0, "operation.t_end_s": 0.05})
    res = ref.simulate_reference(sc)
    u, delta, _ = mesh_kinematics(sc, res)
    w = whole_periods(u)
    assert np.mean(res["kd"][w]) == pytest.approx(1.0, abs=0.03)  # friction moves it by ~1 %
    # mean deflection lies between the static deflections for double and single contact
    assert 10275.76 / 1.3e9 < np.mean(delta[w]) < 10275.76 / 1.2e9
    # friction takes power out of the gears at every sample; the returned T is the literal law's
    v = res["velocities"]
    fr = ref.friction_moments(sc, u % 1.0, res["mesh_force_N"], v[1], v[2])
    T = res["stage_friction_force_N"][0]
    np.testing.assert_allclose(T, fr["T"], rtol=0, atol=1e-9 * ref.F_rated(sc))
    power = T * fr["rho1"] * v[1] - T * fr["rho2"] * v[2]
    assert np.all(power <= 0.0) and np.mean(power[w]) < 0.0
    sc0 = copy.deepcopy(sc)
    sc0["condition"]["friction_coefficient"] = 0.0
    res0 = ref.simulate_reference(sc0)
    assert np.mean(res0["kd"][whole_periods(mesh_kinematics(sc0, res0)[0])]) == pytest.approx(1.0, abs=3e-3)


def test_two_wheel_kinematics_and_energy_balance():
    """two-wheel, mu = 0, C_z = 0, constant k, e = 0, constant motor/load settings:
    mean r1 w1 = mean r2 w2, and kinetic + mesh strain energy change = motor work - load work."""
    sc = scenario(
        **CONSTANT_K,
        **{
            "meta.scene": "two-wheel",
            "production.error_mode.e_um": 0.0,
            "condition.friction_coefficient": 0.0,
            "design.mesh.damping_Ns_per_m": 0.0,
            "operation.t_end_s": 0.04,
            "operation.load_profile.time_s": [0.0, 0.0002],
            "operation.load_profile.fraction": [1.0, 0.6],
        },
    )
    t = np.linspace(0.0, 0.04, 16001)
    res = ref.simulate_reference(sc, t)
    (p1, p2), (w1, w2) = res["coordinates"], res["velocities"]
    r1, r2 = 0.0681, 0.2067
    u = p1 * 29 / (2 * math.pi)
    w = whole_periods(u)
    assert abs(np.mean(r1 * w1[w] - r2 * w2[w])) < 1e-4 * np.mean(r1 * w1[w])
    # energy balance (the load drops from 1.0 to 0.6 in 0.2 ms: free vibration, no damping)
    J1, J2 = 1.2 + 0.0205, 1.73 + 20.0
    k = 1.25e9
    energy = 0.5 * J1 * w1**2 + 0.5 * J2 * w2**2 + 0.5 * k * (r1 * p1 - r2 * p2) ** 2
    ms = ref.kloss_torque(w1, 108.63, sc["design"]["motor"])
    power = ms * w1 - 2124.0 * ref.profile_value(t, sc["operation"]["load_profile"]) * w2
    dt = t[1] - t[0]
    work = np.concatenate(([0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * dt)))
    err = np.abs(energy - energy[0] - work)
    assert err.max() < 1e-8 * energy[0]  # achieved: ~1.6e-10
    # the free mesh vibration is sizeable, so this is not a trivial check
    assert np.ptp(res["kd"][t > 0.001]) > 0.2


def test_muller_reduced_mass_dynamics():
    """Muller, constant k, C_z = 0, e = 0, from rest with rated load: x = F/k (1 - cos(sqrt(k/m) t))."""
    sc = scenario(
        **CONSTANT_K,
        **{
            "meta.scene": "muller",
            "production.error_mode.e_um": 0.0,
            "design.mesh.damping_Ns_per_m": 0.0,
            "operation.initial_state": "rest",
            "operation.t_end_s": 0.005,
        },
    )
    res = ref.simulate_reference(sc)
    m = ref.reduced_mass(sc)
    k = 1.25e9
    F = ref.F_rated(sc)
    x = F / k * (1 - np.cos(math.sqrt(k / m) * res["time"]))
    np.testing.assert_allclose(res["coordinates"][0], x, rtol=0, atol=1e-8 * F / k)
    np.testing.assert_allclose(res["kd"], k * x / F, rtol=0, atol=1e-7)


def test_kloss_steady_speed_after_load_change():
    """two-wheel, e = 0, mu = 0, constant k: after the load ramps 0.5 -> 1 the mean pinion speed
    settles at the Kloss steady speed for the rated pinion torque."""
    sc = scenario(
        **CONSTANT_K,
        **{
            "meta.scene": "two-wheel",
            "production.error_mode.e_um": 0.0,
            "condition.friction_coefficient": 0.0,
            "operation.t_end_s": 0.15,
            "operation.load_profile.time_s": [0.01, 0.02],
            "operation.load_profile.fraction": [0.5, 1.0],
        },
    )
    res = ref.simulate_reference(sc)
    motor = sc["design"]["motor"]
    w0 = 108.63 * (1 - ref.steady_slip(0.5 * 2124.0 * 0.0681 / 0.2067, motor))
    w1 = 108.63 * (1 - ref.steady_slip(2124.0 * 0.0681 / 0.2067, motor))
    assert res["velocities"][0, 0] == pytest.approx(w0, rel=1e-14)
    late = res["time"] > 0.12
    assert np.mean(res["velocities"][0, late]) == pytest.approx(w1, rel=2e-4)
    assert abs(w1 - w0) > 0.5  # the check is not trivial


def test_mesh_force_output_matches_literal_formula():
    """The returned force (locked-mode formula) equals the literal spec formula on the returned states."""
    for name, changes in (
        ("one-stage-backlash", {"operation.t_end_s": 0.01}),
        ("one-stage-runup", {"operation.t_end_s": 0.05, "meta.scene": "muller"}),
        (
            "one-stage-steady",
            {"operation.t_end_s": 0.01, "meta.scene": "two-wheel", "production.error_mode.a": 0.0},
        ),
    ):
        sc = scenario(name, **changes)
        res = ref.simulate_reference(sc)
        lit = ref.mesh_force_literal(sc, *mesh_kinematics(sc, res))
        np.testing.assert_allclose(res["mesh_force_N"], lit["F"], rtol=0, atol=1e-9 * ref.F_rated(sc))


def _literal_one_stage_rhs(sc: dict):
    """Brute-force right-hand side built from the literal (vectorised) helper formulas."""
    d = sc["design"]
    r1, r2, z1 = d["pinion"]["base_radius_m"], d["wheel"]["base_radius_m"], d["pinion"]["teeth"]
    mot, op = d["motor"], sc["operation"]
    k1, c1 = d["coupling"]["stiffness_Nm_per_rad"], d["coupling"]["damping_Nms_per_rad"]
    k2, c2 = d["output_shaft"]["stiffness_Nm_per_rad"], d["output_shaft"]["damping_Nms_per_rad"]

    def rhs(t, y):
        p1, p2, p3, p4, w1, w2, w3, w4 = y
        mesh = ref.mesh_force_literal(sc, p2 * z1 / (2 * math.pi), r1 * p2 - r2 * p3, r1 * w2 - r2 * w3)
        F = float(mesh["F"])
        fr = ref.friction_moments(sc, mesh["p"], F, w2, w3)
        ws = mot["synchronous_speed_rad_s"] * ref.profile_value(t, op["speed_profile"])
        ms = float(ref.kloss_torque(w1, ws, mot))
        m1 = k1 * (p1 - p2) + c1 * (w1 - w2)
        m2 = k2 * (p3 - p4) + c2 * (w3 - w4)
        mr = d["machine"]["rated_torque_Nm"] * ref.profile_value(t, op["load_profile"])
        return [
            w1,
            w2,
            w3,
            w4,
            (ms - m1) / mot["inertia_kg_m2"],
            (m1 - r1 * F + float(fr["M_zt1"])) / d["pinion"]["inertia_kg_m2"],
            (r2 * F - float(fr["M_zt2"]) - m2) / d["wheel"]["inertia_kg_m2"],
            (m2 - mr) / d["machine"]["inertia_kg_m2"],
        ]

    return rhs


def test_agrees_with_brute_force_literal_integration():
    """Separation with backlash (dead zone, damping switching): segmented integration vs a plain
    tight adaptive integration of the literal right-hand side.  E(0.5, 140, 0.3): with friction from the
    sliding velocity the file's 120 um no longer separates within these 4 ms (K_d 0.05 at 1.1 ms, where
    the phase-only law did)."""
    sc = scenario("one-stage-backlash", **{"operation.t_end_s": 0.004, "production.error_mode.e_um": 140.0})
    res = ref.simulate_reference(sc)
    q0, v0 = ref.initial_state(sc)
    b = solve_ivp(
        _literal_one_stage_rhs(sc),
        (0.0, res["time"][-1]),
        np.concatenate((q0, v0)),
        method="DOP853",
        rtol=1e-12,
        atol=1e-14,
        t_eval=res["time"],
    )
    r1, r2 = 0.0681, 0.2067
    Fb = ref.mesh_force_literal(
        sc, b.y[1] * 29 / (2 * math.pi), r1 * b.y[1] - r2 * b.y[2], r1 * b.y[5] - r2 * b.y[6]
    )["F"]
    assert np.max(np.abs(Fb - res["mesh_force_N"])) / ref.F_rated(sc) < 5e-5
    assert res["kd"].max() > 2.0 and np.any(res["kd"] == 0.0)  # separation really happens


def test_self_convergence_short_window():
    for name in ("one-stage-separation", "one-stage-backlash"):
        sc = scenario(name, **{"operation.t_end_s": 0.02})
        a = ref.simulate_reference(sc)
        b = ref.simulate_reference(sc, rtol=1e-11)
        assert np.max(np.abs(a["mesh_force_N"] - b["mesh_force_N"])) / ref.F_rated(sc) < 5e-5


def test_standstill_on_a_phase_boundary_does_not_chatter():
    """Rest at u = 0 (a phase boundary) with zero speed for a while: no endless zero-length segments."""
    sc = scenario(
        **{
            "operation.initial_state": "rest",
            "operation.t_end_s": 0.02,
            "operation.speed_profile.time_s": [0.01, 0.02],
            "operation.speed_profile.fraction": [0.0, 0.2],
            "operation.load_profile.fraction": [0.0],
            "design.mesh.backlash_um": 5.0,
        }
    )
    res = ref.simulate_reference(sc)
    assert np.all(res["coordinates"][:, res["time"] <= 0.01] == 0.0)
    assert res["velocities"][0, -1] > 0.0
