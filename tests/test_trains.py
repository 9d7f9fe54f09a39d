"""Gear trains from a description: one-stage train = one-stage scene; two-stage equilibrium and modes."""

import math

import numpy as np
import pytest
import scipy.linalg

from gearbody.engine import scene_modes, simulate
from gearbody.model import ScenarioError, load_scenario, scenario_to_dict, scene_path
from gearbody.model.io import read_toml

STEADY = [
    'operation.initial_state="steady"',
    "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
]


def one_stage_as_train(*overrides):
    """The one-stage scene as loaded from its shorthand file, and the same drive written by hand as
    [[design.stages]] and [[design.shafts]] (not by gearbody's own conversion)."""
    sc = load_scenario("one-stage", list(overrides))
    d = read_toml(scene_path("one-stage"))
    design = d["design"]
    stage = {
        "pinion": design.pop("pinion"),
        "wheel": design.pop("wheel"),
        "mesh": design.pop("mesh"),
        "error_mode": d.pop("production")["error_mode"],
    }
    design["shafts"] = [design.pop("coupling"), design.pop("output_shaft")]
    design["stages"] = [stage]
    d["meta"]["name"] = "one-stage"
    stage_overrides = [
        o.replace("condition.damaged_teeth", "design.stages.1.damaged_teeth") for o in overrides
    ]
    return sc, load_scenario(d, stage_overrides)


def test_a_one_stage_train_is_the_one_stage_scene():
    sc, train = one_stage_as_train(
        *STEADY,
        "operation.t_end_s=0.02",
        'condition.damaged_teeth=[{gear="pinion",tooth=3,stiffness_factor=0.5}]',
    )
    a, b = simulate(sc), simulate(train)
    assert np.array_equal(a.mesh_force, b.mesh_force)
    assert np.array_equal(a["machine_speed_rad_s"], b["machine_speed_rad_s"])
    assert scene_modes(sc).frequencies_hz == pytest.approx(scene_modes(train).frequencies_hz)


def test_two_stage_steady_start_is_an_equilibrium_without_excitation():
    sc = load_scenario("two-stage", [*STEADY, "operation.t_end_s=0.03", "condition.friction_coefficient=0"])
    d = scenario_to_dict(sc)
    for st in d["design"]["stages"]:
        st["mesh"]["stiffness_double_N_per_m"] = st["mesh"]["stiffness_single_N_per_m"]
        st["error_mode"]["e_um"] = 0.0
    sc = load_scenario(d)
    r = simulate(sc)
    assert np.max(np.abs(r.kd - 1.0)) < 2e-3
    assert np.max(np.abs(r["stage_2_kd"] - 1.0)) < 2e-3
    assert r.meta["stages"][1]["rated_mesh_force_N"] == pytest.approx(
        sc.design.machine.rated_torque_Nm / sc.stages[1].wheel.base_radius_m
    )


def test_two_stage_kinematics_and_rated_forces():
    sc = load_scenario("two-stage", [*STEADY, "operation.t_end_s=0.1"])
    r = simulate(sc)
    w = r.time_s > 0.03
    fz1, fz2 = np.mean(r["mesh_frequency_hz"][w]), np.mean(r["stage_2_mesh_frequency_hz"][w])
    assert fz2 / fz1 == pytest.approx((23 / 29) * (29 / 88), rel=1e-3)  # z1' w2 / (z1 w1), w2 = w1 z1/z2
    assert np.mean(r.kd[w]) == pytest.approx(1.0, abs=0.02)
    assert np.mean(r["stage_2_kd"][w]) == pytest.approx(1.0, abs=0.02)


def test_two_stage_modes_equal_eigh_on_hand_built_matrices():
    sc = load_scenario("two-stage")
    d = sc.design
    modes = scene_modes(sc)
    k1, k2 = modes.mean_mesh_stiffness_N_per_m
    s1, s2 = sc.stages
    J = [
        d.motor.inertia_kg_m2,
        s1.pinion.inertia_kg_m2,
        s1.wheel.inertia_kg_m2,
        s2.pinion.inertia_kg_m2,
        s2.wheel.inertia_kg_m2,
        d.machine.inertia_kg_m2,
    ]
    K = np.zeros((6, 6))
    for (i, j), sh in zip([(0, 1), (2, 3), (4, 5)], d.shafts, strict=True):
        K[np.ix_([i, j], [i, j])] += sh.stiffness_Nm_per_rad * np.array([[1, -1], [-1, 1]])
    for (i, j), st, k in (((1, 2), s1, k1), ((3, 4), s2, k2)):
        r1, r2 = st.pinion.base_radius_m, st.wheel.base_radius_m
        K[np.ix_([i, j], [i, j])] += k * np.array([[r1 * r1, -r1 * r2], [-r1 * r2, r2 * r2]])
    expected = np.sqrt(np.abs(scipy.linalg.eigh(K, np.diag(J), eigvals_only=True))) / (2 * math.pi)
    assert modes.frequencies_hz[1:] == pytest.approx(expected[1:], rel=1e-6)


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ("design.shafts=[]", "needs 3"),
        (
            "design.pinion={teeth=20,base_radius_m=0.05,inertia_kg_m2=0.1,mass_kg=1.0}",
            "design.pinion does not apply to a drive of 2 stages; write design.stages.N.pinion with N = 1..2",
        ),
        ("design.stages=[]", "at least one"),
    ],
)
def test_train_descriptions_are_checked(override, message):
    with pytest.raises(ScenarioError, match=message):
        load_scenario("two-stage", [override])


def test_shaft_keys_are_refused_outside_trains():
    with pytest.raises(ScenarioError, match="topology 'two-wheel' has no shafts"):
        load_scenario("two-wheel", ["design.shafts=[{stiffness_Nm_per_rad=1e5}]"])
    with pytest.raises(ScenarioError, match="design.coupling does not apply to topology 'two-wheel'"):
        load_scenario("two-wheel", ["design.coupling.stiffness_Nm_per_rad=1e5"])
