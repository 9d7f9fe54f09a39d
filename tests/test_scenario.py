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


@pytest.mark.parametrize(
    ("content", "reason"),
    [
        (b"\x8c\xff\x00binary", "not UTF-8 text"),
        (b"PK\x03\x04 an npz is a zip archive", "zip/npz archive"),
        (b"[meta]\x00\x00", "binary file"),
    ],
)
def test_binary_and_non_utf8_scenario_files_are_one_line_input_errors(tmp_path, content, reason):
    path = tmp_path / "drive.toml"
    path.write_bytes(content)
    msg = str(pytest.raises(ScenarioError, load_scenario, path).value)
    assert msg.startswith(f"{path}: ") and reason in msg and "\n" not in msg


def test_a_folder_a_result_and_a_path_under_a_file_are_refused_as_scenarios(tmp_path):
    import numpy as np

    np.savez(tmp_path / "result.npz", t=np.zeros(3))
    (tmp_path / "plain").write_text("x = 1\n")
    for path, reason in (
        (tmp_path, "is a folder, not a scenario file"),
        (tmp_path / "result.npz", "zip/npz archive"),
        (tmp_path / "plain" / "drive.toml", "cannot read the scenario file: Not a directory"),
    ):
        msg = str(pytest.raises(ScenarioError, load_scenario, path).value)
        assert msg.startswith(str(path)) and reason in msg


def test_override_errors_quote_the_override_as_typed_not_the_scene_file():
    msg = refused("one-stage", "production.error_mode.e_um=abc")
    assert msg.startswith("--set production.error_mode.e_um=abc (on ")
    assert msg.endswith("production.error_mode.e_um = 'abc': must be a number")  # no "(any value)"
    typed = 'condition.damaged_teeth=[{gear="pinon",tooth=0}]'
    assert refused("one-stage", typed).startswith(f"--set '{typed}' (on ")
    # a cross-check between keys blames the override that set one of them
    assert refused("one-stage", "design.wheel.base_radius_m=0.25").startswith(
        "--set design.wheel.base_radius_m=0.25 (on "
    )
    assert refused("one-stage", "design.pinon.teeth=3").startswith("--set design.pinon.teeth=3: ")


def test_an_error_of_the_file_itself_still_names_the_file(tmp_path):
    path = tmp_path / "drive.toml"
    path.write_text(scene_path("one-stage").read_text().replace("teeth = 29", "teeth = 3"))
    msg = refused(str(path), "production.error_mode.e_um=5")
    assert msg.startswith(f"{path}: design.pinion.teeth = 3: must be >= 6")


def test_list_items_are_named_by_the_1_based_dotted_keys_users_type():
    spall = 'condition.damaged_teeth=[{gear="pinion",tooth=0,spall_width_fraction=0.5}]'
    msg = refused("one-stage-geometry", spall)
    assert "): condition.damaged_teeth.1.spall_end_diameter_mm = 0: must be >" in msg
    assert "[" not in msg.split("): ", 1)[1]
    two = 'condition.damaged_teeth=[{gear="pinion",tooth=3},{gear="wheel",tooth=99}]'
    assert "condition.damaged_teeth.2.tooth = 99 on the wheel: must be < its 88 teeth" in refused(
        "one-stage", two
    )
    pit = 'condition.pitted_teeth=[{gear="pinion",tooth=3,depth_um=1,start_phase=0.5,end_phase=0.2}]'
    assert "condition.pitted_teeth.1.end_phase = 0.2 must be > start_phase" in refused("one-stage", pit)
    bearing = 'design.stages.1.pinion.bearing={kind="x"}'
    assert "design.stages.1.pinion.bearing.kind = 'x': not a registered" in refused("two-stage", bearing)
    assert "condition.damaged_teeth has no item 1" in refused("one-stage", "condition.damaged_teeth.1.gear=x")


@pytest.mark.parametrize("raw", ["1e400", "-1e400", "1" + "0" * 400, "-" + "9" * 400, "1" + "0" * 5000])
def test_numbers_too_large_for_a_float_are_input_errors(raw):
    msg = refused("one-stage", f"production.error_mode.e_um={raw}")
    assert msg.startswith("--set production.error_mode.e_um=")
    assert any(t in msg for t in ("must be finite", "too large for a floating-point", "4300 digits"))
    assert "sys." not in msg and len(msg) < 800


def test_two_entries_for_the_same_damaged_tooth_are_refused():
    entry = '{gear="pinion",tooth=4,stiffness_factor=0.5}'
    msg = refused("one-stage", f"condition.damaged_teeth=[{entry},{entry}]")
    assert "condition.damaged_teeth.2: one entry per damaged tooth: pinion tooth 4 is also entry 1" in msg
    msg = refused("two-stage", f"design.stages.2.damaged_teeth=[{entry},{{gear='wheel',tooth=1}},{entry}]")
    assert "design.stages.2.damaged_teeth.3: one entry per damaged tooth" in msg
    ok = load_scenario("one-stage", [f'condition.damaged_teeth=[{entry},{{gear="wheel",tooth=4}}]'])
    assert [(t.gear, t.tooth) for t in ok.stages[0].damaged_teeth] == [("pinion", 4), ("wheel", 4)]


def test_a_shorthand_override_after_a_section_replaced_by_a_non_table_is_an_input_error():
    # found by tests/test_fuzz_inputs.py: an AttributeError before
    assert "meta = []: must be a table" in refused("one-stage", "meta=[]", "condition.damaged_teeth=")
    assert "design = 1: must be a table" in refused("one-stage", "design=1", "production.error_mode.e_um=1")
    msg = refused("one-stage", "design.stages=2", "production.error_mode.e_um=1")
    assert "design.stages = 2: must be a list" in msg


def test_a_bore_outside_the_root_circle_or_overflowing_the_stiffness_is_an_input_error():
    # found by tests/test_fuzz_inputs.py: accepted (1000 mm) or an OverflowError (6e-299 mm) before
    key = "design.mesh.geometry.bore_diameter_pinion_mm"
    assert f"{key} = 1000: must be < the pinion's root diameter 132.5 mm" in refused(
        "one-stage-geometry", f"{key}=1000"
    )
    with pytest.warns(UserWarning, match="outside the Sainsot fit range"):
        assert "potential-energy stiffness overflows" in refused("one-stage-geometry", f"{key}=6e-299")
