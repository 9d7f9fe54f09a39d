"""Self-checks of the independent lateral reference model (validation/reference_lateral.py) against
hand-computed facts, the torsional reference and a brute-force literal integration.

Like the other reference self-checks these never import gearbody code: the validation folder is put on
sys.path and imported as the plain package ``validation``.
"""

from __future__ import annotations

import copy
import importlib
import math
import pathlib
import sys

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from shapes import legacy

ROOT = pathlib.Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))
ref = importlib.import_module("validation.reference")
lat = importlib.import_module("validation.reference_lateral")

SCEN = ROOT / "validation" / "scenarios"
SCENES = ROOT / "scenes"
STEADY = {
    "initial_state": "steady",
    "speed_profile": {"time_s": [0.0], "fraction": [1.0]},
    "load_profile": {"time_s": [0.0], "fraction": [1.0]},
}


def scene(name: str, t_end: float, steady: bool = True) -> dict:
    sc = legacy(ref.load_scenario(SCENES / f"{name}.toml"))
    if steady:
        sc["operation"].update(copy.deepcopy(STEADY))
    sc["operation"]["t_end_s"] = t_end
    return sc


def quiet(sc: dict) -> dict:
    """e = 0, r = 0, mu = 0, constant mesh stiffness: the steady start must be an exact equilibrium."""
    sc = copy.deepcopy(sc)
    stages = sc["design"]["stages"] if sc["meta"]["scene"] == "train" else [None]
    for st in stages:
        mesh = sc["design"]["mesh"] if st is None else st["mesh"]
        em = sc["production"]["error_mode"] if st is None else st["error_mode"]
        mesh["stiffness_double_N_per_m"] = mesh["stiffness_single_N_per_m"]
        em.update(e_um=0.0, r=0.0)
    sc["condition"]["friction_coefficient"] = 0.0
    return sc


def static_u0(gear: dict, f: np.ndarray) -> np.ndarray:
    """Static displacement written out by hand (docs/scenario.md, 'Initial state steady')."""
    par = gear["bearing"]["parameters"]
    f = f.copy()
    if gear["lateral"] == "y":
        f[0] = 0.0
    if gear["bearing"]["kind"] == "linear":
        return np.array([f[0] / par["stiffness_x_N_per_m"], f[1] / par["stiffness_y_N_per_m"]])
    fn = np.hypot(*f)
    return f / fn * (par["radial_clearance_m"] + (fn / par["contact_stiffness_N_per_m_n"]) ** (1 / 1.5))


# ---------------------------------------------------------------------------------------------
# Pure formulas
# ---------------------------------------------------------------------------------------------
def test_geometry_defaults_and_refusal():
    g = lat.mesh_geometry({})  # defaults: centre line 0 deg, line of action -90 deg
    np.testing.assert_allclose(g["n"], [0.0, -1.0], atol=1e-15)
    np.testing.assert_allclose(g["m"], [-1.0, 0.0], atol=1e-15)  # friction on the pinion along -x
    assert g["s1"] == -1.0  # the pinion turns clockwise
    g = lat.mesh_geometry({"centre_line_deg": 30.0, "line_of_action_deg": 30.0 + 70.0})
    assert g["s1"] == 1.0
    np.testing.assert_allclose(g["m"], [-g["n"][1], g["n"][0]])
    assert abs(g["m"] @ g["n"]) < 1e-15
    with pytest.raises(ValueError):
        lat.mesh_geometry({"centre_line_deg": 0.0, "line_of_action_deg": -20.0})  # 70 deg off the normal
    sc = scene("lateral-8dof", 0.001)
    del sc["design"]["pinion"]["bearing"]
    with pytest.raises(ValueError):
        lat.simulate_reference_lateral(sc)


def test_bearing_laws_by_hand():
    lin = {
        "kind": "linear",
        "parameters": {
            "stiffness_x_N_per_m": 4e8,
            "stiffness_y_N_per_m": 8e8,
            "damping_x_Ns_per_m": 2e3,
            "damping_y_Ns_per_m": 3e3,
        },
    }
    f = lat.bearing_force(lin, [1e-6, -2e-6], [0.1, 0.2])
    np.testing.assert_allclose(f, [-(400.0 + 200.0), -(-1600.0 + 600.0)], rtol=1e-14)
    hz = {
        "kind": "hertzian",
        "parameters": {
            "contact_stiffness_N_per_m_n": 1e11,
            "radial_clearance_m": 5e-6,
            "exponent": 1.5,
            "damping_Ns_per_m": 2e3,
        },
    }
    # r = 13 um (5-12-13 triangle), p = 8 um: k p^1.5 = 1e11 * 2.2627417e-8 = 2262.74 N
    u = np.array([5e-6, 12e-6])
    spring = 1e11 * (8e-6) ** 1.5
    assert spring == pytest.approx(2262.7417, rel=1e-7)
    f = lat.bearing_force(hz, u, [0.0, 0.0])
    np.testing.assert_allclose(f, -spring * np.array([5, 12]) / 13, rtol=1e-14)
    # radial velocity 0.13 m/s outwards: + C * 0.13... u'.u/r with u' = (0.05, 0.12) -> 0.13 m/s
    f = lat.bearing_force(hz, u, [0.05, 0.12])
    np.testing.assert_allclose(f, -(spring + 2e3 * 0.13) * np.array([5, 12]) / 13, rtol=1e-12)
    # separating fast: f_r < 0 -> no pull
    np.testing.assert_array_equal(lat.bearing_force(hz, u, [-0.05 * 30, -0.12 * 30]), [0.0, 0.0])
    # inside the clearance, and at the centre
    np.testing.assert_array_equal(lat.bearing_force(hz, [3e-6, 4e-6], [1.0, 1.0]), [0.0, 0.0])
    np.testing.assert_array_equal(lat.bearing_force(hz, [0.0, 0.0], [1.0, 1.0]), [0.0, 0.0])
    # static displacement solves force(u0, 0) + f = 0
    for law in (lin, hz):
        f = np.array([3000.0, -4000.0])
        u0 = lat.static_displacement(law, f, (0, 1))
        np.testing.assert_allclose(lat.bearing_force(law, u0, [0, 0]) + f, 0.0, atol=1e-9)
        u0y = lat.static_displacement(law, f, (1,))
        assert u0y[0] == 0.0
        np.testing.assert_allclose(lat.bearing_force(law, u0y, [0, 0])[1] - 4000.0, 0.0, atol=1e-9)
    assert lat.static_displacement(hz, [0.0, 0.0], (0, 1)).tolist() == [0.0, 0.0]


def test_steady_initial_state_literal():
    """Hand-written steady start of lateral-8dof: static bearing displacements, total deflection."""
    sc = scene("lateral-8dof", 0.001)
    q0, v0 = lat.initial_state_lateral(sc)
    d = sc["design"]
    r1, r2 = d["pinion"]["base_radius_m"], d["wheel"]["base_radius_m"]
    F0 = d["machine"]["rated_torque_Nm"] / r2
    n = np.array([math.cos(math.radians(-90.0)), math.sin(math.radians(-90.0))])
    up, uw = static_u0(d["pinion"], -F0 * n), static_u0(d["wheel"], F0 * n)
    assert up[1] == pytest.approx(F0 / 4e8, rel=1e-12) and uw[1] == pytest.approx(-F0 / 8e8, rel=1e-12)
    np.testing.assert_allclose(q0[4:], [up[0], up[1], uw[0], uw[1]], rtol=1e-14, atol=1e-30)
    delta = r1 * q0[1] - r2 * q0[2] + (up - uw) @ n
    assert delta == pytest.approx(F0 / 1.3e9 + 50e-6, rel=1e-12)  # k(p=0) double contact, + l_u, E(0)=0
    assert q0[1] == 0.0 and np.all(v0[4:] == 0.0)
    assert v0[2] == pytest.approx(v0[1] * r1 / r2, rel=1e-15)


# ---------------------------------------------------------------------------------------------
# Simulations
# ---------------------------------------------------------------------------------------------
def test_no_lateral_gear_equals_torsional_reference():
    """With no lateral gear the model is the torsional one (one-stage with backlash and damaged teeth,
    and a two-stage train with separation). Measured: identical to the last bit."""
    one = copy.deepcopy(ref.load_scenario(SCEN / "one-stage-backlash.toml"))
    one["operation"]["t_end_s"] = 0.01
    one["condition"]["damaged_teeth"] = [{"gear": "pinion", "tooth": 1, "stiffness_factor": 0.5}]
    two = copy.deepcopy(ref.load_scenario(SCEN / "two-stage-steady.toml"))
    two["operation"]["t_end_s"] = 0.01
    for sc in (one, two):
        a = ref.simulate_reference(sc)
        b = lat.simulate_reference_lateral(sc)
        Fr = ref.stage_F_rated(sc)[:, None]
        np.testing.assert_allclose(
            b["stage_mesh_force_N"] / Fr, a["stage_mesh_force_N"] / Fr, rtol=0, atol=1e-9
        )
        np.testing.assert_allclose(b["coordinates"], a["coordinates"], rtol=1e-9, atol=1e-12)
        assert b["bearing_force_N"] == {} and np.ptp(a["stage_kd"]) > 0.1


def test_stiff_linear_bearings_approach_torsional_model():
    """Bearing stiffness 1e11 -> 1e12 N/m: the mesh force approaches the torsional one ~ 1/k
    (measured 1.9e-2 and 1.8e-3 of F_rated)."""
    sc = lat.resolve_lateral_defaults(scene("lateral-8dof", 0.005))
    tor = copy.deepcopy(sc)
    tor["design"]["pinion"]["lateral"] = tor["design"]["wheel"]["lateral"] = "none"
    a = ref.simulate_reference(tor)
    err = []
    for k in (1e11, 1e12):
        s2 = copy.deepcopy(sc)
        for g in ("pinion", "wheel"):
            s2["design"][g]["bearing"]["parameters"].update(stiffness_x_N_per_m=k, stiffness_y_N_per_m=k)
        r = lat.simulate_reference_lateral(s2)
        err.append(np.max(np.abs(r["mesh_force_N"] - a["mesh_force_N"])) / ref.F_rated(sc))
    assert err[1] < 3e-3
    assert 5.0 < err[0] / err[1] < 20.0


@pytest.mark.parametrize(
    "variant", ["8dof-linear", "8dof-ball", "6dof-linear", "6dof-ball", "rotated", "train"]
)
def test_steady_start_stays_at_rest_in_the_rotating_frame(variant):
    """e = 0, mu = 0, constant k_z: the steady start is an exact equilibrium, also laterally, for linear
    and Hertzian bearings, 'y' and 'xy', a rotated geometry and a two-stage train with lateral gears on
    stage 2. Checks the static displacement formula and the action/reaction signs."""
    if variant == "train":
        sc = copy.deepcopy(ref.load_scenario(SCEN / "two-stage-steady.toml"))
        sc["operation"]["t_end_s"] = 0.01
        st = sc["design"]["stages"][1]
        st["pinion"].update(
            lateral="y",
            bearing={
                "kind": "linear",
                "housing_mass_kg": 40.0,
                "parameters": {
                    "stiffness_x_N_per_m": 1e9,
                    "stiffness_y_N_per_m": 6e8,
                    "damping_x_Ns_per_m": 1e3,
                    "damping_y_Ns_per_m": 1e3,
                },
            },
        )
        ball = ref.load_scenario(SCENES / "lateral-8dof-ball.toml")["design"]["wheel"]
        st["wheel"].update(lateral="xy", bearing=copy.deepcopy(ball["bearing"]))
        st["mesh"].update(centre_line_deg=90.0, line_of_action_deg=90.0 + 70.0)  # s1 = +1
        gears = {"pinion_2": st["pinion"], "wheel_2": st["wheel"]}
        stage, mesh = 1, st["mesh"]
    else:
        geo, law = variant.split("-") if "-" in variant else ("8dof", "linear")
        sc = scene(f"lateral-{geo}", 0.01)
        balls = ref.load_scenario(SCENES / "lateral-8dof-ball.toml")["design"]
        for g in ("pinion", "wheel"):
            if law == "ball" or (variant == "rotated" and g == "wheel"):
                sc["design"][g]["bearing"] = copy.deepcopy(balls[g]["bearing"])
        if variant == "rotated":
            sc["design"]["mesh"].update(centre_line_deg=30.0, line_of_action_deg=30.0 - 70.0)
        gears = {"pinion": sc["design"]["pinion"], "wheel": sc["design"]["wheel"]}
        stage, mesh = 0, sc["design"]["mesh"]
    sc = quiet(sc)
    res = lat.simulate_reference_lateral(sc)
    np.testing.assert_allclose(res["stage_kd"], 1.0, rtol=0, atol=1e-6)
    F0 = ref.stage_F_rated(sc)[stage]
    lam = math.radians(mesh.get("line_of_action_deg", -90.0))
    n = np.array([math.cos(lam), math.sin(lam)])
    for (name, gear), sign in zip(gears.items(), (-1.0, 1.0), strict=True):
        f_mesh = sign * F0 * n  # mesh force on the centre, friction off
        u0 = static_u0(gear, f_mesh)
        U = res["centre_displacement_m"][name]
        np.testing.assert_allclose(U, u0[:, None] * np.ones_like(U), rtol=0, atol=1e-6 * np.abs(u0).max())
        # force on the housing = the static mesh force, in free and in fixed directions alike
        B = res["bearing_force_N"][name]
        np.testing.assert_allclose(B, f_mesh[:, None] * np.ones_like(B), rtol=0, atol=1e-7 * F0)
        if gear["lateral"] == "y":
            assert np.all(U[0] == 0.0)
        assert np.allclose(res["housing_accel_m_s2"][name], B / gear["bearing"]["housing_mass_kg"])


def test_friction_direction_and_fixed_direction_signal():
    """mu > 0, paper geometry: T = -mu |F| sigma(v_sl / v_0) with the centres' velocities in v_sl (the
    literal law on the returned states; T > 0 before the pitch point in forward running), the x force
    on the pinion is T m_x = -T, on the wheel +T; with lateral 'y' the x bearing signal is that mesh
    component; the friction power T v_sl is <= 0 at every sample."""
    sc = scene("lateral-6dof", 0.004)
    mu = sc["condition"]["friction_coefficient"]
    assert mu > 0
    res = lat.simulate_reference_lateral(sc)
    q, v = res["coordinates"], res["velocities"]
    p = np.mod(q[1] * sc["design"]["pinion"]["teeth"] / (2 * math.pi), 1.0)
    F = res["mesh_force_N"]
    m = lat.mesh_geometry(sc["design"]["mesh"])["m"]
    v_c = m @ (res["centre_velocity_m_s"]["pinion"] - res["centre_velocity_m_s"]["wheel"])
    fr = ref.friction_moments(sc, p, F, v[1], v[2], v_c)
    T = res["stage_friction_force_N"][0]
    np.testing.assert_allclose(T, fr["T"], rtol=0, atol=1e-9 * np.abs(F).max())
    fast = np.abs(fr["v_sl"]) >= 0.01  # full sliding: the force of the phase-only law of earlier versions
    s = np.where(p < sc["design"]["mesh"]["pitch_point_phase"], 1.0, -1.0)
    np.testing.assert_array_equal(T[fast], (mu * np.abs(F) * s)[fast])
    assert np.mean(fast) > 0.9
    assert np.all(T * fr["v_sl"] <= 0.0)
    fx_pinion = res["mesh_force_on_centre_N"]["pinion"][0]
    np.testing.assert_allclose(fx_pinion, -T, rtol=0, atol=1e-9 * np.abs(F).max())
    np.testing.assert_allclose(res["mesh_force_on_centre_N"]["wheel"][0], -fx_pinion, rtol=1e-12)
    np.testing.assert_array_equal(res["bearing_force_N"]["pinion"][0], fx_pinion)  # x held fixed
    np.testing.assert_array_equal(res["centre_displacement_m"]["pinion"][0], 0.0)
    assert np.any(T > 0) and np.any(T < 0)
    # y: the wheel pushes the pinion towards +y
    np.testing.assert_allclose(res["mesh_force_on_centre_N"]["pinion"][1], F, rtol=1e-12)


def test_momentum_balance_and_accelerations():
    """Both gears free in x and y: the mesh forces cancel, so the forces on the housing sum to
    -(m_p a_p + m_w a_w); accelerations checked against the differentiated velocities."""
    sc = scene("lateral-8dof-ball", 0.003)
    sc["operation"]["load_profile"]["fraction"] = [0.3]  # lighter load: a more lively lateral motion
    # friction's direction blended over 1 cm/s: its reversals span several of the 1 us samples that the
    # differences below compare (at the default 1 mm/s they take ~2 us, a step between two samples)
    sc["condition"]["friction_transition_speed_m_s"] = 0.01
    t = np.linspace(0.0, 0.003, 3001)
    res = lat.simulate_reference_lateral(sc, t_eval=t)
    Fr = ref.F_rated(sc)
    total = res["bearing_force_N"]["pinion"] + res["bearing_force_N"]["wheel"]
    inertial = sum(sc["design"][g]["mass_kg"] * res["centre_accel_m_s2"][g] for g in ("pinion", "wheel"))
    np.testing.assert_allclose(total, -inertial, rtol=0, atol=1e-9 * Fr)
    np.testing.assert_allclose(
        res["mesh_force_on_centre_N"]["pinion"], -res["mesh_force_on_centre_N"]["wheel"], atol=1e-9 * Fr
    )
    for g in ("pinion", "wheel"):
        V, A = res["centre_velocity_m_s"][g], res["centre_accel_m_s2"][g]
        scale = np.abs(A).max()
        assert scale > 10.0  # it does move
        # one-sided differences: at a force jump (contact onset) only one side is smooth
        fwd = np.diff(V, axis=1) / np.diff(t)
        err = np.minimum(np.abs(fwd[:, 1:] - A[:, 1:-1]), np.abs(fwd[:, :-1] - A[:, 1:-1]))
        assert err.max() < 0.02 * scale


def _literal_rhs(sc: dict):
    """Brute force 8-DOF one-stage right-hand side from the literal helpers (no modes, no events)."""
    d = sc["design"]
    mot, op = d["motor"], sc["operation"]
    r1, r2 = d["pinion"]["base_radius_m"], d["wheel"]["base_radius_m"]
    z1 = d["pinion"]["teeth"]
    mesh = d["mesh"]
    lam = math.radians(mesh["line_of_action_deg"])
    n = np.array([math.cos(lam), math.sin(lam)])
    m = np.array([n[1], -n[0]])  # s1 = -1 for the default geometry: m = -(-n_y, n_x)
    k1, k2 = d["coupling"]["stiffness_Nm_per_rad"], d["output_shaft"]["stiffness_Nm_per_rad"]
    mp, mw = d["pinion"]["mass_kg"], d["wheel"]["mass_kg"]

    def rhs(t, y):
        phi, w = y[:4], y[8:12]
        up, uw, vp, vw = y[4:6], y[6:8], y[12:14], y[14:16]
        lit = ref.mesh_force_literal(
            sc,
            phi[1] * z1 / (2 * math.pi),
            r1 * phi[1] - r2 * phi[2] + (up - uw) @ n,
            r1 * w[1] - r2 * w[2] + (vp - vw) @ n,
        )
        F = float(lit["F"])
        fr = ref.friction_moments(sc, lit["p"], F, w[1], w[2], (vp - vw) @ m)
        T = float(fr["T"])
        ws = mot["synchronous_speed_rad_s"] * ref.profile_value(t, op["speed_profile"])
        Ms = float(ref.kloss_torque(w[0], ws, mot))
        Mr = d["machine"]["rated_torque_Nm"] * ref.profile_value(t, op["load_profile"])
        M1, M2 = k1 * (phi[0] - phi[1]), k2 * (phi[2] - phi[3])
        acc = [
            (Ms - M1) / mot["inertia_kg_m2"],
            (M1 - r1 * F + float(fr["M_zt1"])) / d["pinion"]["inertia_kg_m2"],
            (r2 * F - float(fr["M_zt2"]) - M2) / d["wheel"]["inertia_kg_m2"],
            (M2 - Mr) / d["machine"]["inertia_kg_m2"],
        ]
        ap = (-F * n + T * m + lat.bearing_force(d["pinion"]["bearing"], up, vp)) / mp
        aw = (F * n - T * m + lat.bearing_force(d["wheel"]["bearing"], uw, vw)) / mw
        return np.concatenate((w, vp, vw, acc, ap, aw))

    return rhs


@pytest.mark.slow
def test_agrees_with_brute_force_literal_integration():
    """Hertzian bearings with contact loss (light load, large errors, small backlash: bearings and teeth
    separate): the segmented reference vs a plain tight-tolerance integration of the literal equations
    (measured 1.2e-7 of F_rated)."""
    sc = scene("lateral-8dof-ball", 0.004)
    sc["operation"]["load_profile"]["fraction"] = [0.01]
    sc["design"]["mesh"]["backlash_um"] = 5.0
    sc["production"]["error_mode"]["e_um"] = 30.0
    res = lat.simulate_reference_lateral(sc)
    q0, v0 = lat.initial_state_lateral(sc)
    b = solve_ivp(
        _literal_rhs(sc),
        (0.0, 0.004),
        np.concatenate((q0, v0)),
        method="DOP853",
        rtol=1e-12,
        atol=1e-15,
        t_eval=res["time_s"],
    )
    Fr = ref.F_rated(sc)
    zero_bearing = np.hypot(*res["bearing_law_force_N"]["wheel"]) == 0.0
    assert zero_bearing.any() and not zero_bearing.all()  # the wheel bearing loses contact
    assert np.any(res["kd"] < 0.0)  # back-flank contact (and so also separation) happens
    y = b.y
    lit = ref.mesh_force_literal(
        sc,
        y[1] * 29 / (2 * math.pi),
        sc["design"]["pinion"]["base_radius_m"] * y[1]
        - sc["design"]["wheel"]["base_radius_m"] * y[2]
        - y[5]
        + y[7],
        sc["design"]["pinion"]["base_radius_m"] * y[9]
        - sc["design"]["wheel"]["base_radius_m"] * y[10]
        - y[13]
        + y[15],
    )["F"]
    assert np.max(np.abs(lit - res["mesh_force_N"])) / Fr < 5e-6
    fw = np.array(
        [
            lat.bearing_force(sc["design"]["wheel"]["bearing"], y[6:8, i], y[14:16, i])
            for i in range(y.shape[1])
        ]
    )
    assert np.max(np.abs(-fw.T - res["bearing_force_N"]["wheel"])) / Fr < 1e-5
    # the returned bearing forces are the literal law on the returned states
    Q, V = res["coordinates"], res["velocities"]
    fr = np.array(
        [lat.bearing_force(sc["design"]["wheel"]["bearing"], Q[6:8, i], V[6:8, i]) for i in range(Q.shape[1])]
    )
    np.testing.assert_allclose(res["bearing_law_force_N"]["wheel"], fr.T, rtol=0, atol=1e-9 * Fr)


def test_self_convergence_with_contact_loss():
    """Rattling case (bearings and teeth separate), rtol 1e-10 vs 1e-11 (measured 4.6e-7 of F_rated over
    5 ms; 1.3e-5 over 10 ms against rtol 1e-13, converging ~10x per decade of rtol)."""
    sc = scene("lateral-8dof-ball", 0.005)
    sc["operation"]["load_profile"]["fraction"] = [0.01]
    sc["design"]["mesh"]["backlash_um"] = 5.0
    sc["production"]["error_mode"]["e_um"] = 30.0
    a = lat.simulate_reference_lateral(sc)
    b = lat.simulate_reference_lateral(sc, rtol=1e-11)
    Fr = ref.F_rated(sc)
    assert np.max(np.abs(a["mesh_force_N"] - b["mesh_force_N"])) / Fr < 2e-5
    for g in ("pinion", "wheel"):
        assert np.max(np.abs(a["bearing_force_N"][g] - b["bearing_force_N"][g])) / Fr < 2e-5
