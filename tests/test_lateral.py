"""Lateral models (Figs. 17, 18): modes against scipy, convergence to the torsional model, static
equilibrium on bearings, signs of action and reaction, and the bearing extension point."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest
import scipy.linalg

from gearbody.assembly import mesh_parameters_from_scenario
from gearbody.engine import scene_modes, simulate
from gearbody.model import ScenarioError, load_scenario, scenario_to_dict
from gearbody.physics.bearings import BEARINGS, HertzianBearing, LinearBearing, register_bearing
from gearbody.physics.lateral import mesh_directions, static_bearing_displacement_m
from gearbody.physics.mesh import mean_stiffness_N_per_m

STEADY = [
    'operation.initial_state="steady"',
    "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
]


def _hand_matrices(scenario):
    """M and K of a one-stage lateral scene written out by hand: coordinates
    [motor, pinion x, pinion y, pinion, wheel x, wheel y, wheel, machine], fixed ones dropped."""
    d, st = scenario.design, scenario.stages[0]
    p, w, mesh = st.pinion, st.wheel, st.mesh
    names = ["motor", "pinion_x", "pinion_y", "pinion", "wheel_x", "wheel_y", "wheel", "machine"]
    M = np.diag(
        [
            d.motor.inertia_kg_m2,
            p.mass_kg,
            p.mass_kg,
            p.inertia_kg_m2,
            w.mass_kg,
            w.mass_kg,
            w.inertia_kg_m2,
            d.machine.inertia_kg_m2,
        ]
    )
    K = np.zeros((8, 8))
    k1, k2 = (sh.stiffness_Nm_per_rad for sh in d.shafts)
    K[np.ix_([0, 3], [0, 3])] += k1 * np.array([[1, -1], [-1, 1]])
    K[np.ix_([6, 7], [6, 7])] += k2 * np.array([[1, -1], [-1, 1]])
    lam = math.radians(mesh.line_of_action_deg)
    n = (math.cos(lam), math.sin(lam))
    g = np.array([0, n[0], n[1], p.base_radius_m, -n[0], -n[1], -w.base_radius_m, 0])
    K += mean_stiffness_N_per_m(mesh_parameters_from_scenario(scenario)) * np.outer(g, g)
    for offset, gear in ((1, p), (4, w)):
        b = gear.bearing.parameters
        K[offset, offset] += b["stiffness_x_N_per_m"]
        K[offset + 1, offset + 1] += b["stiffness_y_N_per_m"]
    keep = [i for i, nm in enumerate(names) if not (nm.endswith("_x") and p.lateral == "y")]
    return M[np.ix_(keep, keep)], K[np.ix_(keep, keep)], [names[i] for i in keep]


@pytest.mark.parametrize("scene", ["lateral-6dof", "lateral-8dof"])
def test_lateral_modes_equal_scipy_eigh_on_hand_built_matrices(scene):
    scenario = load_scenario(scene)
    modes = scene_modes(scenario)
    M, K, names = _hand_matrices(scenario)
    assert modes.dof_names == names
    f_ref = np.sqrt(np.abs(scipy.linalg.eigh(K, M, eigvals_only=True))) / (2 * math.pi)
    nonzero = f_ref > 1.0
    np.testing.assert_allclose(modes.frequencies_hz[nonzero], f_ref[nonzero], rtol=1e-6)
    assert modes.frequencies_hz[0] < 0.01  # the free drive train's rigid-body rotation


def test_lateral_8dof_mode_labels_name_each_gear_and_direction():
    modes = scene_modes(load_scenario("lateral-8dof"))
    labels = [modes.label(m) for m in range(len(modes.frequencies_hz))]
    assert labels[0] == "rigid-body rotation"
    for expected in ("lateral x: pinion", "lateral y: pinion", "lateral x: wheel", "lateral y: wheel"):
        assert sum(label.startswith(expected) for label in labels) == 1, labels
    assert sum(label.startswith("torsional") for label in labels) == 3, labels
    for m in range(len(labels)):
        assert modes.energy_shares(m).sum() == pytest.approx(1.0)


def test_torsional_frequencies_converge_to_the_torsional_model_as_bearings_stiffen():
    torsional = scene_modes(load_scenario("one-stage")).frequencies_hz[1:]
    errors = []
    for k in (1e9, 1e11, 1e13, 1e15):
        params = f"{{stiffness_x_N_per_m={k},stiffness_y_N_per_m={k}}}"
        sc = load_scenario(
            "lateral-8dof",
            [f"design.pinion.bearing.parameters={params}", f"design.wheel.bearing.parameters={params}"],
        )
        modes = scene_modes(sc)
        tors = [
            f
            for m, f in enumerate(modes.frequencies_hz)
            if modes.label(m).startswith("torsional") and not modes.is_rigid_body(m)
        ]
        errors.append(np.max(np.abs(np.array(tors[:3]) / torsional - 1)))
    assert errors[0] > 1e-2  # soft bearings really change the torsional modes (mesh mode +)
    # the bearing compliance is in series with the mesh: the error falls like 1 / k_bearing
    for coarse, fine in zip(errors, errors[1:], strict=False):
        assert fine < coarse / 10
    assert errors[-1] < 1e-5


def _quiet(scene, extra=()):
    """Steady rated running with nothing that excites: no errors, constant k_z, no friction."""
    return load_scenario(
        scene,
        [
            *STEADY,
            "production.error_mode={a=0.5,e_um=0.0,r=0.0}",
            "design.mesh.stiffness_double_N_per_m=1.2e9",
            "condition.friction_coefficient=0.0",
            "operation.t_end_s=0.01",
            *extra,
        ],
    )


@pytest.mark.parametrize("scene", ["lateral-6dof", "lateral-8dof", "lateral-8dof-ball"])
def test_steady_start_on_bearings_is_an_equilibrium(scene):
    """Initial bearing displacements and wheel angle balance the rated mesh force exactly: nothing moves
    in the rotating frame (this fails on a wrong sign of the mesh force on either gear)."""
    sc = _quiet(scene)
    res = simulate(sc)
    F = sc.rated_mesh_force_N
    assert np.max(np.abs(res["mesh_force_N"] / F - 1)) < 1e-6
    # the pinion is pushed towards +y by the wheel (paper geometry), the wheel towards -y
    np.testing.assert_allclose(res["pinion_bearing_force_y_N"], F, rtol=1e-6)
    np.testing.assert_allclose(res["wheel_bearing_force_y_N"], -F, rtol=1e-6)
    np.testing.assert_allclose(res["pinion_bearing_force_x_N"], 0.0, atol=1e-6 * F)
    assert np.ptp(res["pinion_y_m"]) < 1e-6 * abs(res["pinion_y_m"][0])
    k_y = sc.stages[0].pinion.bearing.parameters.get("stiffness_y_N_per_m")
    if k_y:
        assert res["pinion_y_m"][0] == pytest.approx(F / k_y, rel=1e-9)
    np.testing.assert_allclose(
        res["wheel_housing_accel_y_m_s2"], -F / sc.stages[0].wheel.bearing.housing_mass_kg, rtol=1e-6
    )


def test_friction_acts_on_the_centres_with_action_and_reaction():
    """lateral-6dof holds x fixed: the bearings pass the friction force on, -T m on the pinion side and
    the opposite on the wheel side; in the paper's geometry m = (-1, 0)."""
    # instantaneous identity: compare exact samples, not the band-limited bearing signals
    sc = _quiet("lateral-6dof", ["condition.friction_coefficient=0.1", "solver.anti_aliasing=false"])
    res = simulate(sc)
    T = res["friction_force_N"]
    np.testing.assert_allclose(res["pinion_bearing_force_x_N"], -T, rtol=1e-12)
    np.testing.assert_allclose(res["wheel_bearing_force_x_N"], T, rtol=1e-12)
    before_pitch = res["mesh_phase"] < 0.5
    assert np.all(T[before_pitch] > 0) and np.all(T[~before_pitch] < 0)


def test_mesh_directions_of_the_paper_and_of_a_real_pair():
    n, m, s1 = mesh_directions(0.0, -90.0)
    np.testing.assert_allclose(n, [0, -1], atol=1e-15)
    np.testing.assert_allclose(m, [-1, 0], atol=1e-15)
    assert s1 == -1
    n, m, s1 = mesh_directions(0.0, 70.0)  # counter-clockwise pinion, 20 deg pressure angle
    assert s1 == 1 and n @ m == pytest.approx(0.0, abs=1e-15)
    assert n[0] * m[1] - n[1] * m[0] == pytest.approx(s1)


def test_static_bearing_displacement_closed_forms_and_root_finder():
    lin = LinearBearing(stiffness_x_N_per_m=2e8, stiffness_y_N_per_m=4e8)
    np.testing.assert_allclose(static_bearing_displacement_m(lin, [1e3, -2e3], (0, 1)), [5e-6, -5e-6])
    np.testing.assert_allclose(static_bearing_displacement_m(lin, [1e3, -2e3], (1,)), [0, -5e-6])
    hz = HertzianBearing(contact_stiffness_N_per_m_n=1e11, radial_clearance_m=5e-6)
    u = static_bearing_displacement_m(hz, [0.0, 1e4], (0, 1))
    assert u[0] == 0 and u[1] == pytest.approx(5e-6 + (1e4 / 1e11) ** (2 / 3))
    np.testing.assert_allclose(hz.force_N(u, np.zeros(2)), [0, -1e4], rtol=1e-12)

    @dataclass(frozen=True)
    class Cubic:  # not a built-in law: solved by the root finder
        k: float

        def force_N(self, displacement_m, velocity_m_s):
            u = np.asarray(displacement_m, float)
            return -self.k * u**3

    u = static_bearing_displacement_m(Cubic(1e20), [8e3, 0.0], (0, 1))
    assert u == pytest.approx([(8e3 / 1e20) ** (1 / 3), 0.0], rel=1e-8)


def test_a_user_bearing_law_runs_without_touching_the_engine():
    """A third law registered by the user: a linear spring written as a generic law (Python user
    function) must give the same run as the built-in linear bearing (Exudyn spring-dampers)."""

    @dataclass(frozen=True)
    class Isotropic:
        stiffness_N_per_m: float
        damping_Ns_per_m: float = 0.0

        def force_N(self, displacement_m, velocity_m_s):
            u, v = np.asarray(displacement_m, float), np.asarray(velocity_m_s, float)
            return -self.stiffness_N_per_m * u - self.damping_Ns_per_m * v

    register_bearing("isotropic-test", Isotropic)
    try:
        tight = ["solver.relative_tolerance=1e-13", "solver.absolute_tolerance=1e-12"]  # same law, 1e-6
        base = load_scenario("lateral-8dof", [*STEADY, "operation.t_end_s=0.01", *tight])
        data = scenario_to_dict(base)
        for gear in ("pinion", "wheel"):
            b = data["design"]["stages"][0][gear]["bearing"]
            k, c = b["parameters"]["stiffness_x_N_per_m"], b["parameters"]["damping_x_Ns_per_m"]
            b["kind"] = "isotropic-test"
            b["parameters"] = {"stiffness_N_per_m": k, "damping_Ns_per_m": c}
        custom = load_scenario(data)
        a, b = simulate(base), simulate(custom)
        F = base.rated_mesh_force_N
        assert np.max(np.abs(a["mesh_force_N"] - b["mesh_force_N"])) < 1e-6 * F
        assert np.max(np.abs(a["wheel_bearing_force_x_N"] - b["wheel_bearing_force_x_N"])) < 1e-6 * F
    finally:
        BEARINGS.pop("isotropic-test", None)


@pytest.mark.parametrize(
    ("override", "needle"),
    [
        ('design.pinion.lateral="z"', "design.pinion.lateral"),
        ("design.mesh.line_of_action_deg=10.0", "line_of_action_deg"),
        ('design.wheel.bearing.kind="magnetic"', "not a registered bearing law"),
        ("design.wheel.bearing.housing_mass_kg=0.0", "housing_mass_kg"),
        ("design.wheel.bearing.parameters={stiffness_x_N_per_m=1e8}", "stiffness_y_N_per_m"),
    ],
)
def test_bad_lateral_input_is_refused_by_name(override, needle):
    with pytest.raises(ScenarioError, match=needle):
        load_scenario("lateral-8dof", [override])


def test_lateral_gear_needs_a_bearing_and_a_lateral_scene():
    with pytest.raises(ScenarioError, match="needs a bearing"):
        load_scenario("one-stage", ['design.pinion.lateral="y"'])
    with pytest.raises(ScenarioError, match="no lateral motion"):
        data = scenario_to_dict(load_scenario("lateral-6dof"))
        data["meta"]["topology"] = "two-wheel"
        data["design"]["shafts"] = []
        load_scenario(data)


def test_a_train_with_lateral_gears_agrees_with_the_independent_reference():
    """Deliverable 3: lateral DOFs per gear in any stage of a train, from the description alone."""
    from gearbody_validation.reference_lateral import simulate_reference_lateral

    data = scenario_to_dict(
        load_scenario("two-stage", [*STEADY, "operation.t_end_s=0.03", "solver.anti_aliasing=false"])
    )
    stage2 = data["design"]["stages"][1]
    stage2["pinion"]["lateral"] = "xy"
    stage2["pinion"]["bearing"] = {
        "kind": "linear",
        "parameters": {"stiffness_x_N_per_m": 5e8, "stiffness_y_N_per_m": 6e8, "damping_x_Ns_per_m": 2e3},
    }
    stage2["wheel"]["lateral"] = "y"
    stage2["wheel"]["bearing"] = {
        "kind": "hertzian",
        "parameters": {
            "contact_stiffness_N_per_m_n": 2e11,
            "radial_clearance_m": 2e-6,
            "damping_Ns_per_m": 3e3,
        },
    }
    stage2["mesh"]["centre_line_deg"] = 30.0
    stage2["mesh"]["line_of_action_deg"] = 100.0  # 30 + (90 - 20): counter-clockwise pinion
    sc = load_scenario(data)
    res = simulate(sc)
    ref = simulate_reference_lateral(scenario_to_dict(sc), t_eval=res.time_s)
    for k in range(2):
        prefix = "" if k == 0 else "stage_2_"
        err = np.abs(res[prefix + "mesh_force_N"] - ref["stage_mesh_force_N"][k]) / sc.stage_rated_force_N(k)
        assert err.max() < 5e-3
    for gear in ("pinion_2", "wheel_2"):
        for d, axis in enumerate("xy"):
            f_ref = ref["bearing_force_N"][gear][d]
            assert np.max(np.abs(res[f"{gear}_bearing_force_{axis}_N"] - f_ref)) < 0.01 * np.max(
                np.abs(f_ref)
            )
    assert "pinion_2_x_m" in res and "wheel_2_x_m" not in res and "wheel_2_y_m" in res
