"""Scenarios: TOML and dicts in, bad input refused before anything runs with file, key, value and range."""

import re

import pytest

from gearbody.model import ScenarioError, dump_scenario, load_scenario, parse_override, scenario_to_dict
from gearbody.model.scenes import list_scenes, scene_path


def refused(scene: str, *overrides: str) -> str:
    with pytest.raises(ScenarioError) as info:
        load_scenario(scene, list(overrides))
    return str(info.value)


def test_every_scene_loads_and_round_trips_through_toml(tmp_path):
    assert {"muller", "two-wheel", "one-stage"} <= set(list_scenes())
    for name in list_scenes():
        sc = load_scenario(name)
        path = dump_scenario(sc, tmp_path / f"{name}.toml")
        assert load_scenario(path) == sc
        assert scenario_to_dict(load_scenario(path)) == scenario_to_dict(sc)


def test_python_dict_builds_the_same_scenario_as_the_file():
    sc = load_scenario("one-stage")
    assert load_scenario(scenario_to_dict(sc)) == sc


@pytest.mark.parametrize(
    ("override", "key", "range_text"),
    [
        ("design.pinion.inertia_kg_m2=0", "design.pinion.inertia_kg_m2", "> 0"),
        ("design.motor.inertia_kg_m2=-1.0", "design.motor.inertia_kg_m2", "> 0"),
        ("design.coupling.stiffness_Nm_per_rad=0", "design.coupling.stiffness_Nm_per_rad", "> 0"),
        ("design.mesh.stiffness_single_N_per_m=-5e8", "design.mesh.stiffness_single_N_per_m", "> 0"),
        ("design.wheel.base_radius_m=0", "design.wheel.base_radius_m", "> 0"),
        ("design.pinion.teeth=5", "design.pinion.teeth", ">= 6"),
        ("production.error_mode.a=1.2", "production.error_mode.a", ">= 0 and <= 1"),
        ("production.error_mode.r=-0.1", "production.error_mode.r", ">= 0 and <= 1"),
        ("design.mesh.contact_ratio=0.9", "design.mesh.contact_ratio", ">= 1"),
        ("design.mesh.backlash_um=-3", "design.mesh.backlash_um", ">= 0"),
        ("operation.t_end_s=0", "operation.t_end_s", "> 0"),
        ("operation.t_end_s=-1", "operation.t_end_s", "> 0"),
        ("condition.friction_coefficient=1.5", "condition.friction_coefficient", ">= 0 and < 1"),
    ],
)
def test_non_physical_values_are_refused_naming_file_key_value_and_range(override, key, range_text):
    msg = refused("one-stage", override)
    assert "one-stage.toml" in msg
    assert key in msg
    raw = override.split("=", 1)[1]
    shown = f"{float(raw):.6g}" if any(c in raw for c in ".e") else raw
    assert f"{key} = {shown}:" in msg
    assert range_text in msg


def test_unknown_keys_are_refused_with_the_nearest_valid_key():
    assert "did you mean 'design.pinion'" in refused("one-stage", "design.pinon.teeth=20")
    assert "did you mean 'production.error_mode.e_um'" in refused("one-stage", "production.error_mode.e_mu=3")
    assert "did you mean 'one-stage'" in str(pytest.raises(ScenarioError, load_scenario, "one-stag").value)


def test_wrong_types_are_refused():
    assert "whole number" in refused("one-stage", "design.pinion.teeth=29.5")
    assert "must be a number" in refused("one-stage", 'design.pinion.inertia_kg_m2="heavy"')
    assert "one of" in refused("one-stage", 'meta.scene="three-stage"')
    assert "did you mean 'rest'" in refused("one-stage", 'operation.initial_state="rst"')
    assert "must be a table" in refused("one-stage", "design.pinion=3")
    assert "true or false" not in refused("one-stage", "design.pinion.teeth=true")


def test_missing_required_values_are_refused(tmp_path):
    text = scene_path("two-wheel").read_text()
    broken = re.sub(r"inertia_kg_m2 = 1.733\n", "", text)
    path = tmp_path / "broken.toml"
    path.write_text(broken)
    msg = str(pytest.raises(ScenarioError, load_scenario, path).value)
    assert "broken.toml" in msg and "missing required key 'design.wheel.inertia_kg_m2'" in msg
    text = scene_path("one-stage").read_text()
    no_coupling = re.sub(r"\[design.coupling\][^\[]*", "", text)
    path.write_text(no_coupling)
    assert "design.coupling is required" in str(pytest.raises(ScenarioError, load_scenario, path).value)


def test_cross_checks_between_values():
    assert "base pitch" in refused("one-stage", "design.wheel.base_radius_m=0.25")
    assert "must be < its 29 teeth" in refused(
        "one-stage", 'condition.damaged_teeth=[{gear="pinion",tooth=29,stiffness_factor=0.5}]'
    )
    assert "strictly increasing" in refused(
        "one-stage", "operation.load_profile={time_s=[1.0,0.5],fraction=[0,1]}"
    )
    assert "same length" in refused("one-stage", "operation.load_profile={time_s=[0.0,0.5],fraction=[1]}")
    assert "same length" in refused("one-stage", 'design.mesh.stiffness_profile="table"')


def test_syntax_errors_and_missing_files_name_the_file(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[meta\nscene = 1")
    assert "bad.toml: not valid TOML" in str(pytest.raises(ScenarioError, load_scenario, bad).value)
    assert "no such scenario file" in str(
        pytest.raises(ScenarioError, load_scenario, tmp_path / "x.toml").value
    )


def test_overrides_parse_toml_values():
    assert parse_override("a.b=15") == ("a.b", 15)
    assert parse_override("a.b=1e9") == ("a.b", 1e9)
    assert parse_override('a.b="steady"') == ("a.b", "steady")
    assert parse_override("a.b=steady") == ("a.b", "steady")
    assert parse_override("a=[1, 2]") == ("a", [1, 2])
    with pytest.raises(ScenarioError, match="KEY=VALUE"):
        parse_override("nothing")
