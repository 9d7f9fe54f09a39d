"""The calibrated one-stage scenes (issue 18, Fig. 12 by calibration): what they state, no simulation."""

from __future__ import annotations

import json

import pytest
from gearbody_validation.paper import fig_12_calibration as cal

from gearbody.model import load_scenario
from gearbody.model.io import read_toml
from gearbody.model.scenes import list_scenes, scene_path

FITS = [fit for fit in cal.FITS.values() if fit.scene in list_scenes()]


def _value(data: dict, key: str) -> float:
    node = data
    for part in key.split("."):
        node = node[part]
    return float(node)


def test_the_pre_registered_fit_ships_its_scene():
    assert cal.FITS["fig3"].scene == cal.CALIBRATED_SCENE in list_scenes()


@pytest.mark.parametrize("fit", FITS, ids=lambda f: f.scene)
def test_the_calibrated_scene_loads_and_names_its_identification(fit):
    sc = load_scenario(fit.scene)
    assert any("fig_12_calibration.py" in s and "Fig. 12 (a), (d)" in s for s in sc.meta.sources)
    assert "one-stage` stays the documented scene" in scene_path(fit.scene).read_text()


@pytest.mark.parametrize("fit", FITS, ids=lambda f: f.scene)
def test_its_values_lie_inside_the_stated_bounds(fit):
    data = read_toml(scene_path(fit.scene))
    for key in fit.fitted:
        b = cal.BOUND[key]
        if key == cal.RATING.key:  # the rating is stated by the keys it scales
            scale = (
                _value(data, "design.motor.breakdown_torque_Nm")
                / cal.SCALED_BY_RATING["design.motor.breakdown_torque_Nm"]
            )
            value = scale * cal.RATED_KW
            for k, v in cal.SCALED_BY_RATING.items():
                assert _value(data, k) == pytest.approx(v * scale, rel=1e-5), k
        else:
            value = _value(data, key)
        assert b.lower <= value <= b.upper, key


@pytest.mark.parametrize("fit", FITS, ids=lambda f: f.scene)
def test_it_differs_from_one_stage_only_in_the_fitted_keys(fit):
    base = read_toml(scene_path(cal.SCENE))
    calibrated = read_toml(scene_path(fit.scene))
    changed = set(cal.scene_values({k: 1.0 for k in fit.fitted}))
    assert set(calibrated) == set(base) and set(calibrated["design"]) == set(base["design"])
    for section, table in base["design"].items():
        assert set(calibrated["design"][section]) == set(table), section
        for key, value in table.items():
            if f"design.{section}.{key}" not in changed:
                assert calibrated["design"][section][key] == value, f"design.{section}.{key}"
    for part in ("production", "operation", "condition"):
        assert calibrated[part] == base[part], part
    assert calibrated["meta"]["seed"] == base["meta"]["seed"]


@pytest.mark.parametrize("fit", FITS, ids=lambda f: f.scene)
def test_the_scene_file_is_the_one_its_calibration_record_writes(fit):
    record_path = fit.record_file()
    if record_path is None:
        pytest.skip("no calibration record in this checkout")
    record = json.loads(record_path.read_text())
    assert scene_path(fit.scene).read_text() == cal.scene_text(fit, record)
    assert list(record["parameters"]) == list(fit.fitted)


def test_the_bounds_table_states_a_reason_for_every_bound():
    for b in cal.BOUND.values():
        assert b.lower < b.upper and len(b.reason) > 40, b.key
    for fit in cal.FITS.values():
        assert set(fit.fitted) <= set(cal.BOUND)
    assert set(cal.FIT_CASES) <= set(cal.CASES)
