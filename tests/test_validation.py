"""gearbody agrees with the independent reference (short version of `gearbody validate`)."""

import numpy as np
import pytest
from gearbody_validation.compare import VALIDATED_SCENES, cases, compare_case, run_validation
from gearbody_validation.reference import simulate_reference

from gearbody.engine import simulate
from gearbody.model import load_scenario, scenario_to_dict

pytestmark = pytest.mark.slow  # every test here runs gearbody and the reference


@pytest.mark.parametrize("scene", VALIDATED_SCENES)
def test_scene_agrees_with_independent_reference_within_half_a_percent(scene):
    for case in cases(scene, short=True):
        r = compare_case(scene, case, short=True)
        assert r.max_error_percent <= 0.5, (scene, case.name, r.max_error_percent)
        assert not r.bearing_error_percent > 1.0, (scene, case.name, r.bearing_error_percent)
        if case.must_separate:
            assert r.kd_max > 2.0 and r.separated_fraction > 0.05


def test_comparison_detects_a_model_difference():
    """The yardstick can fail: a reference run with 20 % more mesh damping is far outside 0.5 %."""
    sc = load_scenario("one-stage", [*cases("one-stage")[0].overrides, "operation.t_end_s=0.05"])
    res = simulate(sc)
    other = scenario_to_dict(sc)
    other["design"]["stages"][0]["mesh"]["damping_Ns_per_m"] *= 1.2
    other["design"]["stages"][0]["error_mode"]["e_um"] = 12.0
    ref = simulate_reference(other, t_eval=res.time_s)
    assert np.max(np.abs(res.mesh_force - ref["mesh_force_N"])) / sc.rated_mesh_force_N > 0.005


def test_bearing_comparison_detects_a_model_difference():
    """A reference whose wheel bearing is 10 % stiffer in y differs by more than the 1 % bearing limit."""
    from gearbody_validation.compare import bearing_force_errors_percent
    from gearbody_validation.reference_lateral import simulate_reference_lateral

    overrides = [*cases("lateral-8dof")[0].overrides, "operation.t_end_s=0.03", "solver.anti_aliasing=false"]
    sc = load_scenario("lateral-8dof", overrides)
    res = simulate(sc)
    same = bearing_force_errors_percent(
        res, simulate_reference_lateral(scenario_to_dict(sc), t_eval=res.time_s)
    )
    assert max(same.values()) < 0.01
    other = scenario_to_dict(sc)
    other["design"]["stages"][0]["wheel"]["bearing"]["parameters"]["stiffness_y_N_per_m"] *= 1.1
    changed = bearing_force_errors_percent(res, simulate_reference_lateral(other, t_eval=res.time_s))
    assert changed["wheel_y"] > 1.0


def test_validate_command_prints_a_table_and_reports_failure(capsys):
    lines = []
    assert run_validation(["two-wheel"], short=True, echo=lines.append)
    assert any(line.split()[:2] == ["two-wheel", "steady"] for line in lines)
    assert not run_validation(["two-wheel"], short=True, tolerance_percent=1e-9, echo=lines.append)


@pytest.mark.parametrize("case", ["separation", "run-up"])
def test_muller_full_length_cases_pass_at_the_default_tolerance(case):
    """Issue 16: at atol 1e-8 m (the rotations' 1e-8 rad taken for metres) Muller's full separation and
    run-up missed by 0.66 % and 10.3 %; its own default (3e-11 m of deflection) passes with margin."""
    c = {c.name: c for c in cases("muller")}[case]
    result = compare_case("muller", c, short=False)
    assert result.passed and result.max_error_percent < 0.1, result
