"""The independent references read the canonical scenario shape (meta.topology, design.stages /
shafts, per-tooth faults in the stages, condition.friction_coefficient only) and give the same outputs,
to the last bit, as on the legacy shape of the same scenario.  In particular a legacy one-stage scene
given as a train of one stage reproduces the one-stage results exactly.

Like the other reference self-checks these never import gearbody code: the legacy dicts are files of
validation/scenarios and scenes/, converted to the canonical shape here.
"""

from __future__ import annotations

import copy
import pathlib

import numpy as np
import pytest
from gearbody_validation import reference as ref
from gearbody_validation import reference_lateral as lat
from shapes import legacy

ROOT = pathlib.Path(__file__).resolve().parents[1]
SCEN = ROOT / "validation" / "scenarios"
SCENES = ROOT / "scenes"


def to_canonical(sc: dict) -> dict:
    """Legacy resolved dict -> canonical shape (one-stage: the train of one stage)."""
    sc = copy.deepcopy(sc)
    scene = sc["meta"].pop("scene")
    sc["meta"]["name"] = scene
    d = sc["design"]
    prod = sc.pop("production", {})
    cond = sc.pop("condition", {})
    if scene == "train":
        stages, shafts = d["stages"], d["shafts"]
    else:
        stage = {
            "pinion": d["pinion"],
            "wheel": d["wheel"],
            "mesh": d["mesh"],
            "error_mode": prod["error_mode"],
            "damaged_teeth": cond.get("damaged_teeth", []),
            "eccentricity": prod.get("eccentricity", []),
            "pitted_teeth": cond.get("pitted_teeth", []),
        }
        stages = [stage]
        shafts = [d["coupling"], d["output_shaft"]] if scene == "one-stage" else []
    sc["meta"]["topology"] = "train" if scene in ("train", "one-stage") else scene
    sc["design"] = {"motor": d["motor"], "machine": d["machine"], "stages": stages, "shafts": shafts}
    sc["condition"] = {"friction_coefficient": cond.get("friction_coefficient", 0.0)}
    return sc


def short(path: pathlib.Path, t_end: float) -> dict:
    sc = legacy(ref.load_scenario(path))
    sc["operation"]["t_end_s"] = t_end
    return sc


def assert_identical(a: dict, b: dict) -> None:
    assert a.keys() == b.keys()
    for key in a:
        if isinstance(a[key], dict):
            assert_identical(a[key], b[key])
        else:
            assert np.array_equal(a[key], b[key], equal_nan=True), key


def faulty_one_stage() -> dict:
    sc = short(SCEN / "one-stage-backlash.toml", 0.01)
    sc["operation"]["load_profile"]["fraction"] = [0.13]  # (M f) / r2 != f (M / r2) here
    sc["condition"]["damaged_teeth"] = [{"gear": "pinion", "tooth": 3, "stiffness_factor": 0.5}]
    sc["condition"]["pitted_teeth"] = [
        {"gear": "wheel", "tooth": 0, "depth_um": 5.0, "start_phase": 0.2, "end_phase": 0.6}
    ]
    sc["production"]["eccentricity"] = [{"gear": "pinion", "amplitude_um": 8.0, "phase_deg": 30.0}]
    return sc


def test_one_stage_as_canonical_train_of_one_stage():
    legacy = faulty_one_stage()
    canon = to_canonical(legacy)
    assert ref.topology(canon) == "train" and ref.is_train(canon)
    assert ref.F_rated(canon) == ref.F_rated(legacy)
    for x, y in zip(ref.initial_state(legacy), ref.initial_state(canon), strict=True):
        assert np.array_equal(x, y)
    # the steady start of the one-stage scene, operation by operation (a train of N >= 2 forms the
    # stage force as f F_rated,s instead, which differs from (M f) / r2 in the last bit at f = 0.13)
    d = legacy["design"]
    r1, r2 = d["pinion"]["base_radius_m"], d["wheel"]["base_radius_m"]
    M_L = d["machine"]["rated_torque_Nm"] * 0.13
    F0 = M_L / r2
    M_p = F0 * r1
    lu = d["mesh"]["backlash_um"] * 1e-6
    delta0 = F0 / ref.effective_stiffness(legacy, 0.0)[0] + lu - ref.total_error(legacy, 0.0)
    phi3 = -delta0 / r2
    k1, k2 = d["coupling"]["stiffness_Nm_per_rad"], d["output_shaft"]["stiffness_Nm_per_rad"]
    wsr = d["motor"]["synchronous_speed_rad_s"]
    w = wsr - ref.steady_slip(M_p, d["motor"]) * wsr
    q0, v0 = ref.initial_state(canon)
    np.testing.assert_array_equal(q0, [M_p / k1, 0.0, phi3, phi3 - M_L / k2])
    np.testing.assert_array_equal(v0, [w, w, w * r1 / r2, w * r1 / r2])
    a = ref.simulate_reference(legacy)
    b = ref.simulate_reference(canon)
    assert_identical(a, b)
    assert a["coordinates"].shape[0] == 4 and np.ptp(a["kd"]) > 0.5  # not a trivial run
    # the transition width, in either shape
    legacy["design"]["mesh"]["transition_width"] = 0.05
    assert_identical(ref.simulate_reference(legacy), ref.simulate_reference(to_canonical(legacy)))


def test_train_canonical_equals_legacy():
    legacy = short(SCEN / "two-stage-steady.toml", 0.01)
    legacy["design"]["stages"][1]["pitted_teeth"] = [
        {"gear": "pinion", "tooth": 2, "depth_um": 3.0, "start_phase": 0.1, "end_phase": 0.5}
    ]
    canon = to_canonical(legacy)
    assert "scene" not in canon["meta"] and "production" not in canon
    np.testing.assert_array_equal(ref.stage_F_rated(canon), ref.stage_F_rated(legacy))
    assert_identical(ref.simulate_reference(legacy), ref.simulate_reference(canon))


@pytest.mark.parametrize("name", ["muller", "two-wheel"])
def test_one_mesh_topologies(name):
    legacy = short(SCENES / f"{name}.toml", 0.02)
    legacy["condition"]["pitted_teeth"] = [
        {"gear": "pinion", "tooth": 1, "depth_um": 4.0, "start_phase": 0.3, "end_phase": 0.7}
    ]
    canon = to_canonical(legacy)
    assert ref.topology(canon) == name and not ref.is_train(canon)
    assert canon["design"]["shafts"] == [] and len(canon["design"]["stages"]) == 1
    assert ref.F_rated(canon) == ref.F_rated(legacy)
    t_eval = np.arange(400) * 5e-5  # the scene files carry no solver table
    a, b = ref.simulate_reference(legacy, t_eval), ref.simulate_reference(canon, t_eval)
    assert_identical(a, b)
    assert np.ptp(a["kd"]) > 0.0
    with pytest.raises(ValueError, match="lateral"):
        lat.simulate_reference_lateral(canon)


def test_lateral_canonical_equals_legacy():
    legacy = short(SCENES / "lateral-6dof.toml", 0.005)
    canon = to_canonical(legacy)
    a = lat.simulate_reference_lateral(legacy)
    b = lat.simulate_reference_lateral(canon)
    assert_identical(a, b)
    assert a["centre_displacement_m"]  # lateral gears present


def test_unknown_topology():
    sc = to_canonical(short(SCEN / "one-stage-steady.toml", 0.01))
    sc["meta"]["topology"] = "one-stage"
    with pytest.raises(ValueError, match="topology"):
        ref.simulate_reference(sc)
