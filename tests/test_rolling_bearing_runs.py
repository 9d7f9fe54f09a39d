"""Runs on ball-by-ball bearings with defects: both force paths bit-identical (lateral gears and the
members of a planetary stage), the defect changes the run, and the bearing force signal is the law's."""

from __future__ import annotations

import numpy as np
import pytest
from gearbody_validation.compare import BEARING_DEFECT

from gearbody.engine import compiled_path
from gearbody.engine.simulate import simulate
from gearbody.model import load_scenario, scenario_to_dict

WORKS, WHY = compiled_path.compiled_path_status()

GEOMETRY = {"balls": 9, "ball_diameter_m": 0.008, "pitch_diameter_m": 0.04, "contact_angle_deg": 0.0}


def _both_paths(data_or_scene, overrides=()):
    runs = {}
    for path in ("python", "compiled"):
        sc = load_scenario(data_or_scene, [*overrides, f'solver.force_path="{path}"'])
        runs[path] = simulate(sc)
    return runs["python"], runs["compiled"]


def _assert_identical(python, compiled):
    assert list(python.signals) == list(compiled.signals)
    for name in python.signals:
        assert np.array_equal(python[name], compiled[name], equal_nan=True), name


@pytest.mark.skipif(not WORKS, reason=f"no compiled path here: {WHY}")
def test_the_bearing_defect_case_is_bit_identical_on_both_paths_and_the_defects_act():
    overrides = [*BEARING_DEFECT["lateral-8dof-ball"], "operation.t_end_s=0.03"]
    python, compiled = _both_paths("lateral-8dof-ball", overrides)
    _assert_identical(python, compiled)
    assert compiled.meta["solver_statistics"]["force_path"] == "compiled"
    healthy = simulate(load_scenario("lateral-8dof-ball", [o for o in overrides if ".defects=" not in o]))
    change = np.abs(compiled["pinion_bearing_force_y_N"] - healthy["pinion_bearing_force_y_N"]).max()
    assert change > 0.05 * np.abs(healthy["pinion_bearing_force_y_N"]).max()


def test_the_bearing_force_signal_is_the_law_at_the_gears_state():
    overrides = [*BEARING_DEFECT["lateral-8dof-ball"], "operation.t_end_s=0.01", "solver.anti_aliasing=false"]
    sc = load_scenario("lateral-8dof-ball", overrides)
    r = simulate(sc)
    law = sc.stages[0].pinion.bearing.law()
    for i in range(0, r.time_s.size, 37):
        u = (r["pinion_x_m"][i], r["pinion_y_m"][i])
        v = (r["pinion_x_velocity_m_s"][i], r["pinion_y_velocity_m_s"][i])
        f = law.force_N(u, v, -r["pinion_angle_rad"][i])  # the pinion turns clockwise (s1 = -1)
        assert np.allclose(
            -f, (r["pinion_bearing_force_x_N"][i], r["pinion_bearing_force_y_N"][i]), rtol=1e-12
        )


def _planetary_on_rolling_bearings() -> dict:
    data = scenario_to_dict(load_scenario("planetary"))
    st = data["design"]["stages"][0]
    for member, defects in (("sun", [{"race": "inner", "depth_m": 1e-5, "width_deg": 10.0}]), ("planet", [])):
        st[member].pop("bearing_stiffness_N_per_m")
        st[member]["bearing"] = {
            "kind": "rolling-elements",
            "parameters": {"ball_stiffness_N_per_m_n": 2e10, "damping_Ns_per_m": 200.0},
            "geometry": GEOMETRY,
            "defects": defects,
        }
    return data


@pytest.mark.skipif(not WORKS, reason=f"no compiled path here: {WHY}")
def test_planetary_members_on_rolling_bearings_run_bit_identical_on_both_paths():
    python, compiled = _both_paths(_planetary_on_rolling_bearings(), ["operation.t_end_s=0.004"])
    _assert_identical(python, compiled)
    assert np.all(np.isfinite(compiled["sun_bearing_force_x_N"]))
    assert np.abs(compiled["sun_bearing_force_x_N"]).max() > 0


def test_planetary_members_on_rolling_bearings_agree_with_the_reference():
    """The sun on a ball-by-ball bearing with an inner-race spall, the planets on ball-by-ball bearings
    (their outer race turned by the planet about its pin): gearbody's every mesh force against the
    reference's own transcription of the law (docs/scenario.md), steady rated, 0.02 s."""
    from gearbody_validation.compare import reference_input
    from gearbody_validation.reference.planetary_drive import simulate_reference_drive

    sc = load_scenario(
        _planetary_on_rolling_bearings(), ["operation.t_end_s=0.02", "solver.anti_aliasing=false"]
    )
    res = simulate(sc)
    ref = simulate_reference_drive(reference_input(sc), res.time_s)
    rated = sc.stage_rated_force_N(0)
    names = [f"planet_{n + 1}_{m}_mesh_force_N" for n in range(sc.stages[0].planets) for m in ("sun", "ring")]
    worst = max(float(np.max(np.abs(res[n] - ref[n]))) / rated for n in names)
    assert worst < 1e-4, worst  # 0.01 % of F_rated (measured 8e-7; with the races held still: 0.067)
    assert np.ptp(res["sun_bearing_force_x_N"]) > 0
