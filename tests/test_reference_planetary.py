"""Self-checks of the independent reference of planetary stages (validation/reference/planetary*.py,
docs/planetary.md "The stage in a drive") from the equations, and its cross-check against gearbody's
Exudyn prototype (gearbody.engine.planetary, called as a black box)."""

from __future__ import annotations

import copy
import math
import pathlib

import numpy as np
import pytest

try:  # the installed name of validation/ (a worktree's editable install may point elsewhere)
    from gearbody_validation import reference as ref
    from gearbody_validation.reference import planetary as rp
    from gearbody_validation.reference import planetary_model as pm
except ImportError:  # pragma: no cover
    from validation import reference as ref
    from validation.reference import planetary as rp
    from validation.reference import planetary_model as pm


def stage_dict(zs=21, zp=30, zr=81, N=3, k=(3e8, 5e8), damping=500.0, e_um=0.0, r=0.0) -> dict:
    """The contract's example stage (docs/planetary.md), sun input, carrier output, ring fixed."""
    mesh = {"stiffness_single_N_per_m": k[0], "stiffness_double_N_per_m": k[1], "damping_Ns_per_m": damping}
    return {
        "type": "planetary",
        "planets": N,
        "planet_angles_deg": [],
        "module_mm": 4.0,
        "pressure_angle_deg": 20.0,
        "input": "sun",
        "output": "carrier",
        "sun": {"teeth": zs, "inertia_kg_m2": 0.01, "mass_kg": 2.0, "bearing_stiffness_N_per_m": 1e8},
        "planet": {"teeth": zp, "inertia_kg_m2": 0.01, "mass_kg": 1.5, "bearing_stiffness_N_per_m": 1e8},
        "ring": {
            "teeth": zr,
            "inertia_kg_m2": 1.0,
            "mass_kg": 10.0,
            "bearing_stiffness_N_per_m": 1e9,
            "torsion_stiffness_Nm_per_rad": 1e8,
        },
        "carrier": {"inertia_kg_m2": 0.5, "mass_kg": 8.0, "bearing_stiffness_N_per_m": 1e9},
        "sun_mesh": dict(mesh),
        "ring_mesh": dict(mesh),
        "sun_error_mode": {"a": 0.5, "e_um": e_um, "r": r},
        "ring_error_mode": {"a": 0.5, "e_um": e_um, "r": r},
    }


def perturbed(st, rng, scale=1e-5):
    q = st.q_nominal + scale * rng.standard_normal(st.n_dof)
    return q, rng.standard_normal(st.n_dof)


def deflections(st, q):
    g = st.mesh_geometry(q, np.zeros(st.n_dof))
    return np.concatenate((g["sun"][0], g["ring"][0]))


def test_geometry_contact_ratios_and_ratio():
    st = pm.PlanetaryStage(stage_dict())
    assert st.contact_ratio["sun"] == pytest.approx(1.611, abs=1e-3)
    assert st.contact_ratio["ring"] == pytest.approx(1.936, abs=1e-3)
    assert st.ratio == pytest.approx(1.0 + 81 / 21, rel=1e-12)
    assert (st.s_in, st.s_out) == (1.0, 1.0)
    assert np.all(deflections(st, st.q_nominal) == 0.0)


def test_deflection_gradient_against_finite_differences():
    """delta_dot = grad(delta) . q_t (the rate the law uses) and the line of action n = -d delta / d c_n."""
    st = pm.PlanetaryStage(stage_dict(22, 29, 80))
    rng = np.random.default_rng(3)
    for _ in range(5):
        q, v = perturbed(st, rng)
        h = 1e-7
        fd = (deflections(st, q + h * v) - deflections(st, q - h * v)) / (2 * h)
        g = st.mesh_geometry(q, v)
        rate = np.concatenate((g["sun"][1], g["ring"][1]))
        assert np.max(np.abs(rate - fd)) < 1e-8 * np.max(np.abs(fd))
        for kind in ("sun", "ring"):
            for n in range(st.N):
                grad = np.empty(2)
                for c in range(2):
                    e = np.zeros(st.n_dof)
                    e[9 + 3 * n + c] = h
                    j = n if kind == "sun" else st.N + n
                    grad[c] = (deflections(st, q + e)[j] - deflections(st, q - e)[j]) / (2 * h)
                nvec = np.array([g[kind][2][n], g[kind][3][n]])
                assert np.max(np.abs(grad + nvec)) < 1e-7
                assert np.hypot(*nvec) == pytest.approx(1.0, abs=1e-14)


def test_rigid_rotation_and_rigid_rolling_leave_deflections_unchanged():
    st = pm.PlanetaryStage(stage_dict(22, 29, 80))
    rng = np.random.default_rng(5)
    q, _ = perturbed(st, rng)
    d0 = deflections(st, q)
    for beta in (0.3, -2.0, 7.0 * math.pi + 0.1):  # rigid rotation of everything about the origin
        qr = q.copy()
        c, s = math.cos(beta), math.sin(beta)
        qr[0::3], qr[1::3] = c * q[0::3] - s * q[1::3], s * q[0::3] + c * q[1::3]
        qr[2::3] += beta
        assert np.max(np.abs(deflections(st, qr) - d0)) < 1e-12
    w = st.rigid_speeds("sun", 1.0)  # ring fixed: sun, carrier and planets roll
    wn = w[2] - st.r_bs / st.r_bp * (w[0] - w[2])
    for t in (0.01, 1.0, 25.0):  # up to ~4 carrier revolutions
        qr = st.q_nominal.copy()
        qr[[2, 5, 8]] = w * t
        a = st.psi + w[2] * t
        qr[9::3], qr[10::3], qr[11::3] = st.r_c * np.cos(a), st.r_c * np.sin(a), wn * t
        assert np.max(np.abs(deflections(st, qr))) < 1e-12


def test_static_load_sharing_and_reactions():
    """Sun input T, ring on its torsion spring, carrier loaded by -T (1 + r_br / r_bs): every mesh carries
    T / (N r_bs) (in-phase teeth), the ring reacts T r_br / r_bs, the carrier's bearings
    -T (1 + r_br / r_bs)."""
    st = pm.PlanetaryStage(stage_dict())
    T = 500.0
    rb = st.r_br / st.r_bs
    q = st.static_equilibrium(np.array([T, 0.0, -T * (1.0 + rb)]))
    z = np.zeros(st.n_dof)
    modes = st.mesh_modes(q, z)
    mcs = [law.mode_consts(*m[:3]) for law, m in zip(st.meshes, modes, strict=True)]  # m = [n, k, c, g]
    geo = st.mesh_geometry(q, z)
    F = st.mesh_forces(geo, mcs, modes)
    F0 = T / (st.N * st.r_bs)
    for kind in ("sun", "ring"):
        assert np.max(np.abs(np.array(F[kind]) / F0 - 1.0)) < 1e-9
    assert -st.kt * q[5] == pytest.approx(T * rb, rel=1e-9)  # ring support reaction
    # the torque the planets exert on the carrier through the bearings balances the applied one
    Q = st.generalised_forces(q, z, geo, F, damping=False)
    assert Q[8] == pytest.approx(T * (1.0 + rb), rel=1e-9)
    assert np.max(np.abs(Q[[2, 5, 8]] + [T, 0.0, -T * (1 + rb)])) < 1e-6


def test_free_undamped_stage_conserves_energy():
    """No load, no damping, constant mesh stiffness: T + V of the circling stage is constant."""
    sd = stage_dict(22, 29, 80, k=(4e8, 4e8), damping=0.0)
    st = pm.PlanetaryStage(sd, F_rated=1e3)
    system = rp._Chain([rp._PlanetaryBlock(st, 0, 0)], st.n_dof, st.mass_vector())
    v0 = st.rigid_state(st.rigid_speeds("sun", 50.0, ("carrier", 10.0)))
    rng = np.random.default_rng(7)
    v0 = v0 + 0.05 * rng.standard_normal(st.n_dof)  # m/s and rad/s: vibration on top of the rolling
    y0 = np.concatenate((st.q_nominal, v0))
    t = np.linspace(0.0, 0.005, 11)
    res = rp.integrate(system, y0, t, 1e-12, system.default_atol(1e-12), "DOP853")
    Y = res["Y"]
    M = st.mass_vector()

    def energy(y):
        q, v = y[: st.n_dof], y[st.n_dof :]
        E = 0.5 * np.sum(M * v * v)
        for m in range(3):
            E += 0.5 * st.kb[m] * (q[3 * m] ** 2 + q[3 * m + 1] ** 2)
        E += 0.5 * st.kt * q[3 * st.i_fix + 2] ** 2
        a = q[8] + st.psi
        E += 0.5 * st.kb[3] * np.sum((q[9::3] - q[6] - st.r_c * np.cos(a)) ** 2)
        E += 0.5 * st.kb[3] * np.sum((q[10::3] - q[7] - st.r_c * np.sin(a)) ** 2)
        return E + 0.5 * 4e8 * np.sum(deflections(st, q) ** 2)

    E = np.array([energy(Y[:, i]) for i in range(t.size)])
    assert np.max(np.abs(E / E[0] - 1.0)) < 1e-8
    assert np.max(np.abs(deflections(st, Y[: st.n_dof, -1]))) > 1e-7  # it did vibrate


def test_refusals():
    bad = stage_dict()
    bad["ring"]["teeth"] = 80
    with pytest.raises(ValueError, match="z_r"):
        pm.PlanetaryStage(bad)
    bad = stage_dict(N=4)  # (21 + 81) / 4 not an integer
    with pytest.raises(ValueError, match="not an integer"):
        pm.PlanetaryStage(bad)
    bad = stage_dict()
    bad["sun"]["torsion_stiffness_Nm_per_rad"] = 1e6
    with pytest.raises(ValueError, match="not fixed"):
        pm.PlanetaryStage(bad)


def on_a_jump(st, res, lu_m: float) -> dict:
    """Per mesh key, the samples within 1e-6 of a mesh period of a phase break point or within 1 nm of the
    backlash edge: the sampled force jumps there, and which side a sample falls on is decided by state
    differences far below the tolerances (Exudyn's steps cluster at every jump)."""
    geo = st.mesh_geometry(res["coordinates"], res["velocities"])
    out = {}
    for n in range(st.N):
        for kind in ("sun", "ring"):
            law = st.laws[kind]
            p = np.mod(geo[kind][4][n] * law.cz, 1.0)
            dist = np.min(np.abs((p[:, None] - law.bA[None, :] + 0.5) % 1.0 - 0.5), axis=1)
            edge = np.abs(np.abs(geo[kind][0][n]) - lu_m) < 1e-9
            out[f"planet_{n + 1}_{kind}_mesh_force_N"] = (dist < 1e-6) | edge
    return out


@pytest.mark.parametrize(
    "teeth, backlash_um",
    [((21, 30, 81), 0.0), ((22, 29, 80), 0.0), ((22, 29, 80), 10.0)],
    ids=["in-phase", "sequential", "sequential-separating"],
)
def test_stage_agrees_with_gearbody_prototype(teeth, backlash_um):
    """The same stage in both models, suddenly loaded at rigid rolling (with backlash: the teeth
    separate and strike again): per-mesh forces within 0.5 % of F = T / (N r_bs) over 0.01 s, away from
    the jumps of the law (measured over 0.02 s: 6.6e-8, 9.8e-8; separating 6.3e-5, 16 % of the mesh
    samples separated; ~2-4 s each, so not marked slow)."""
    from gearbody.assembly.planetary_layout import PlanetaryMember, layout_from_geometry
    from gearbody.engine.planetary import build_planetary, planetary_mesh_forces, solve_planetary
    from gearbody.physics.planetary import PlanetaryGeometry

    sd = stage_dict(*teeth)
    for key in ("sun_mesh", "ring_mesh"):
        sd[key]["backlash_um"] = backlash_um
    st = pm.PlanetaryStage(copy.deepcopy(sd))
    T, ws = 500.0, 100.0
    torques = {"sun": T, "carrier": -T * (1.0 + st.r_br / st.r_bs)}
    members = {
        name: PlanetaryMember(
            name,
            sd[name]["mass_kg"],
            sd[name]["inertia_kg_m2"],
            sd[name]["bearing_stiffness_N_per_m"],
            torsion_stiffness_Nm_per_rad=sd[name].get("torsion_stiffness_Nm_per_rad"),
        )
        for name in ("sun", "ring", "carrier", "planet")
    }
    geometry = PlanetaryGeometry(*teeth, 3, 4e-3, 20.0)
    lu = backlash_um * 1e-6
    layout = layout_from_geometry(
        geometry,
        **members,
        stiffness_single_N_per_m=(3e8, 3e8),
        stiffness_double_N_per_m=(5e8, 5e8),
        damping_Ns_per_m=(500.0, 500.0),
        backlash_m=(lu, lu),
    )
    wc = ws / st.ratio
    system = build_planetary(layout, torques_Nm=torques, sun_speed_rad_s=ws, carrier_speed_rad_s=wc)
    states = solve_planetary(system, 0.01, absolute_tolerance=1e-10, max_step_s=1e-4)
    gb = planetary_mesh_forces(system, states)
    ref = rp.simulate_reference_planetary_stage(
        sd, torques_Nm=torques, sun_speed_rad_s=ws, carrier_speed_rad_s=wc, t_eval=states["time_s"]
    )
    F0 = T / (3 * st.r_bs)
    jumps = on_a_jump(st, ref, lu)
    for key, on_jump in jumps.items():
        assert np.max(np.abs(gb[key])) > 0.5 * F0  # loaded
        assert np.mean(on_jump) < 0.1
        assert np.max(np.abs(ref[key] - gb[key])[~on_jump]) < 5e-3 * F0, key
    assert np.max(np.abs(ref["sun_q"] - states["sun_q"])) < 1e-8
    if lu > 0.0:  # the teeth did separate
        assert np.mean([np.mean(ref[key] == 0.0) for key in jumps]) > 0.05


# ---------------------------------------------------------------------------------------------------------
# The drive: motor -> shafts -> planetary / parallel stages -> machine
# ---------------------------------------------------------------------------------------------------------
SCEN = pathlib.Path(__file__).resolve().parents[1] / "validation" / "scenarios"


def two_stage(t_end: float) -> dict:
    sc = copy.deepcopy(ref.load_scenario(SCEN / "two-stage-steady.toml"))
    sc["condition"]["friction_coefficient"] = 0.0
    sc["operation"]["t_end_s"] = t_end
    return sc


def planetary_drive(inp="sun", out="carrier", T_in=300.0, t_end=0.005, k=(4e8, 4e8), second=False) -> dict:
    """The contract's example stage between the two-stage scene's motor (150 rad/s) and machine, its
    rated torque set so that the input member carries T_in; optionally followed by that scene's stage 2."""
    sc = two_stage(t_end)
    par = sc["design"]["stages"][1]
    st = stage_dict(k=k)
    st["input"], st["output"] = inp, out
    fixed = ({"sun", "ring", "carrier"} - {inp, out}).pop()
    st["ring"].pop("torsion_stiffness_Nm_per_rad")
    st[fixed]["torsion_stiffness_Nm_per_rad"] = 1e8
    P = pm.PlanetaryStage(st)
    M = T_in * P.r_eq_out / P.r_eq_in
    if second:
        M *= par["wheel"]["base_radius_m"] / par["pinion"]["base_radius_m"]
    sc["design"]["stages"] = [st, par] if second else [st]
    sc["design"]["shafts"] = sc["design"]["shafts"][: 3 if second else 2]
    sc["design"]["machine"]["rated_torque_Nm"] = M
    sc["design"]["motor"]["synchronous_speed_rad_s"] = 150.0
    return sc


def test_drive_of_parallel_stages_is_the_train():
    """With no planetary stage the drive is the reference's train (same law, other assembly): the two-stage
    scene (backlash 50 um, errors, friction off) for 20 ms."""
    sc = two_stage(0.02)
    a = ref.simulate_reference(sc)
    b = rp.simulate_reference_drive(sc)
    for s, key in enumerate(("mesh_force_N", "stage_2_mesh_force_N")):
        assert np.max(np.abs(a["stage_mesh_force_N"][s] - b[key])) < 1e-6 * b["F_rated_N"][s]
    assert np.max(np.abs(a["coordinates"] - b["coordinates"])) < 1e-9


@pytest.mark.parametrize(
    "inp, out",
    [("sun", "carrier"), ("carrier", "sun"), ("sun", "ring"), ("ring", "sun"), ("ring", "carrier")],
)
def test_drive_steady_start_is_the_rated_load(inp, out):
    """Steady start: every planet mesh at F_rated (kd = 1) with the turning sense of the contract; with
    the carrier fixed (no circling planets) and constant mesh stiffness it stays there."""
    sc = planetary_drive(inp, out, t_end=0.002 if "carrier" in (inp, out) else 0.005)
    res = rp.simulate_reference_drive(sc)
    kd = np.array([v for key, v in res.items() if key.endswith("_mesh_kd")])
    assert kd.shape[0] == 6
    assert np.max(np.abs(kd[:, 0] - 1.0)) < 1e-9
    v = res["velocities"]
    assert v[0, 0] > 0.0 and v[-1, 0] > 0.0  # motor and machine turn forward
    P = pm.PlanetaryStage(sc["design"]["stages"][0])
    assert v[-1, 0] == pytest.approx(v[0, 0] / abs(P.ratio), rel=1e-12)
    if "carrier" not in (inp, out):
        assert np.max(np.abs(kd - 1.0)) < 1e-6


def test_drive_steady_start_carries_the_planets_centrifugal_load():
    """The contract's steady start includes each planet's centrifugal force m_p w_c^2 (c_n - c_c): sun
    input at ~150 rad/s, carrier at ~31 rad/s, 144 N per planet. Without it the mesh forces swung by 2.8 %
    of F_rated; with it (no tooth errors, constant stiffness here) they stay at K_d = 1 (6e-10 measured)."""
    res = rp.simulate_reference_drive(planetary_drive("sun", "carrier"))
    kd = np.array([v for key, v in res.items() if key.endswith("_mesh_kd")])
    assert np.max(np.abs(kd - 1.0)) < 1e-6


def test_drive_two_stage_signals_and_rest_start():
    sc = planetary_drive(second=True, t_end=0.002)
    res = rp.simulate_reference_drive(sc)
    assert "planet_3_ring_mesh_force_N" in res and "stage_2_mesh_force_N" in res and "stage_2_kd" in res
    assert res["F_rated_N"][0] == pytest.approx(
        300.0 / (3 * pm.PlanetaryStage(sc["design"]["stages"][0]).r_bs)
    )
    assert abs(res["stage_2_kd"][0] - 1.0) < 1e-9 and abs(res["planet_1_sun_mesh_kd"][0] - 1.0) < 1e-9
    sc["operation"]["initial_state"] = "rest"
    sc["operation"]["speed_profile"] = {"time_s": [0.0, 1.0], "fraction": [0.0, 1.0]}
    res = rp.simulate_reference_drive(sc, t_eval=np.linspace(0.0, 0.002, 5))
    assert np.all(np.isfinite(res["planet_2_sun_mesh_force_N"]))
    assert np.all(res["sun_q"][0] == [0.0, 0.0, 0.0])


def test_random_tooth_errors_use_the_stage_and_member_draw():
    st = pm.PlanetaryStage(stage_dict(e_um=10.0, r=0.3), seed=4, stage_index=2)
    for kind, key, z in (("sun", 1, 21), ("ring", 2, 81)):
        l_rand = np.random.default_rng([4, 2, key]).random(z)
        assert np.array_equal(st.laws[kind].e_amp, (1.0 - 0.3 * (1.0 - l_rand)) * 10.0 * 1e-6)


def test_static_sharing_with_tooth_errors():
    """E(0.5, 10 um, 0.3) on the sun's and ring's teeth: the planets mesh different teeth, so they share
    the load unequally, but the sun's torque balance holds exactly: sum_n F_sn r_bs = T."""
    st = pm.PlanetaryStage(stage_dict(22, 29, 80, e_um=10.0, r=0.3))
    T = 500.0
    rb = st.r_br / st.r_bs
    q = st.static_equilibrium(np.array([T, 0.0, -T * (1.0 + rb)]), theta_gauge=0.05)
    z = np.zeros(st.n_dof)
    modes = st.mesh_modes(q, z)
    mcs = [law.mode_consts(*m[:3]) for law, m in zip(st.meshes, modes, strict=True)]  # m = [n, k, c, g]
    F = st.mesh_forces(st.mesh_geometry(q, z), mcs, modes)
    assert sum(F["sun"]) * st.r_bs == pytest.approx(T, rel=1e-9)
    assert sum(F["ring"]) * st.r_br == pytest.approx(T * rb, rel=1e-9)
    assert np.ptp(F["sun"]) > 1e-3 * T / (st.N * st.r_bs)
