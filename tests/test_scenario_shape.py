"""One canonical scenario shape: every drive a chain of stages and shafts; the single-stage shorthand
converted once on load; keys that do not apply refused naming what to write; per-stage keys."""

import copy

import pytest

import gearbody as gb
from gearbody.model import ScenarioError, list_scenes, load_scenario, scenario_to_dict, scene_path
from gearbody.model.io import read_toml


@pytest.mark.parametrize("name", list_scenes())
def test_every_scene_loads_in_both_shapes_to_the_same_scenario(name):
    written = load_scenario(name)  # as shipped: shorthand or [[design.stages]]
    canonical = scenario_to_dict(written)
    assert set(canonical["design"]) == {"motor", "machine", "stages", "shafts"}
    assert "production" not in canonical and set(canonical["condition"]) == {
        "friction_coefficient",
        "friction_transition_speed_m_s",
    }
    assert load_scenario(canonical) == written
    assert written.name == name and canonical["meta"]["name"] == name
    assert written.meta.topology in ("train", "two-wheel", "muller")


def test_a_one_stage_drive_is_a_train_of_one_stage():
    sc = load_scenario("one-stage")
    assert sc.meta.topology == "train" and len(sc.stages) == 1 and len(sc.design.shafts) == 2
    raw = read_toml(scene_path("one-stage"))
    assert sc.stages[0].error_mode.e_um == raw["production"]["error_mode"]["e_um"]
    assert sc.design.shafts[0].stiffness_Nm_per_rad == raw["design"]["coupling"]["stiffness_Nm_per_rad"]


def test_files_of_earlier_versions_with_meta_scene_still_load():
    raw = read_toml(scene_path("one-stage"))
    legacy = copy.deepcopy(raw)
    legacy["meta"].pop("topology")
    legacy["meta"]["scene"] = "one-stage"
    assert load_scenario(legacy).stages == load_scenario(raw).stages
    legacy["meta"]["scene"] = "three-stage"
    with pytest.raises(ScenarioError, match="meta.scene = 'three-stage': must be one of"):
        load_scenario(legacy)


@pytest.mark.parametrize(
    ("override", "instead"),
    [
        ("production.error_mode.e_um=50", "design.stages.N.error_mode.e_um with N = 1..2"),
        (
            'condition.damaged_teeth=[{gear="pinion",tooth=3,stiffness_factor=0.1}]',
            "design.stages.N.damaged_teeth",
        ),
        ("design.mesh.backlash_um=5", "design.stages.N.mesh.backlash_um with N = 1..2"),
        ("design.coupling.damping_Nms_per_rad=10", "design.shafts.N.damping_Nms_per_rad with N = 1..3"),
    ],
)
def test_a_key_that_does_not_apply_to_a_train_is_refused_naming_what_to_write(override, instead):
    with pytest.raises(ScenarioError) as info:
        load_scenario("two-stage", [override])
    msg = str(info.value)
    assert override.split("=")[0].rsplit(".", 1)[0].split("[")[0][:20] in msg
    assert "does not apply to a drive of 2 stages" in msg and instead in msg


def test_a_shorthand_key_in_a_train_file_is_refused(tmp_path):
    raw = read_toml(scene_path("two-stage"))
    raw["production"] = {"error_mode": {"a": 0.5, "e_um": 50.0, "r": 0.0}}
    with pytest.raises(ScenarioError, match="production.error_mode does not apply to a drive of 2 stages"):
        load_scenario(raw)


def test_per_stage_keys_change_only_their_stage():
    base = load_scenario("two-stage")
    sc = load_scenario(
        "two-stage", ["design.stages.2.mesh.backlash_um=5", "design.stages.1.error_mode.e_um=15"]
    )
    assert sc.stages[1].mesh.backlash_um == 5 and sc.stages[0].mesh == base.stages[0].mesh
    assert sc.stages[0].error_mode.e_um == 15 and sc.stages[1].error_mode == base.stages[1].error_mode
    shafts = load_scenario("two-stage", ["design.shafts.2.damping_Nms_per_rad=7"]).design.shafts
    assert shafts[1].damping_Nms_per_rad == 7 and shafts[0] == base.design.shafts[0]
    # the same on a one-stage drive, in its own words and in stage words
    a = load_scenario("one-stage", ["production.error_mode.e_um=12"])
    b = load_scenario("one-stage", ["design.stages.1.error_mode.e_um=12"])
    assert a == b and a.stages[0].error_mode.e_um == 12


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ("design.stages.3.mesh.backlash_um=5", "no item 3; design.stages has 2 (valid: 1..2)"),
        ("design.stages.0.mesh.backlash_um=5", "valid: 1..2"),
        ("design.stages.x.mesh.backlash_um=5", "address an item by its number, 1..2"),
        ("design.shafts.4.stiffness_Nm_per_rad=1e5", "valid: 1..3"),
    ],
)
def test_a_stage_index_out_of_range_is_refused_with_the_valid_range(override, message):
    with pytest.raises(ScenarioError, match=message.replace("(", r"\(").replace(")", r"\)")):
        load_scenario("two-stage", [override])


def test_messages_about_a_one_stage_drive_name_the_keys_the_user_wrote():
    with pytest.raises(ScenarioError, match=r"production\.error_mode\.a = 1\.2: must be >= 0 and <= 1"):
        load_scenario("one-stage", ["production.error_mode.a=1.2"])
    with pytest.raises(ScenarioError, match=r"design\.stages\.2\.error_mode\.a = 1\.2"):
        load_scenario("two-stage", ["design.stages.2.error_mode.a=1.2"])


def test_topology_and_name_are_separate_and_results_report_the_name():
    sc = load_scenario("two-stage", ["operation.t_end_s=0.02", 'operation.initial_state="steady"'])
    assert (sc.meta.topology, sc.name) == ("train", "two-stage")
    result = gb.simulate(sc)
    assert result.name == "two-stage" and result.meta["topology"] == "train"


def test_python_api_changes_a_scenario_without_dotted_strings():
    sc = load_scenario("two-stage")
    changed = sc.replace(operation=gb.steady(0.3, speed_fraction=0.8)).with_stage(
        1, mesh=sc.stages[1].mesh.replace(backlash_um=5.0)
    )
    by_keys = load_scenario(
        "two-stage",
        [
            "operation.t_end_s=0.3",
            'operation.initial_state="steady"',
            "operation.speed_profile={time_s=[0.0],fraction=[0.8]}",
            "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
            "design.stages.2.mesh.backlash_um=5",
        ],
    )
    assert changed == by_keys
    with pytest.raises(ScenarioError, match="must be >= 0"):
        sc.with_stage(0, error_mode=sc.stages[0].error_mode.replace(r=-1.0))
    with pytest.raises(ScenarioError, match="stage 2: the drive has 2 stage"):
        sc.with_stage(2)


def test_four_periods_preset_is_the_paper_run_of_the_one_stage_scene():
    sc = load_scenario("one-stage")
    assert gb.four_periods(2.0) == sc.operation
    with pytest.raises(ScenarioError, match="four_periods"):
        gb.four_periods(1.0, run_up_s=2.0)


def test_studies_vary_and_draw_per_stage_keys_and_refuse_shorthand_on_trains(tmp_path):
    from gearbody.studies import Study, run_study

    study = Study.build(
        "two-stage",
        vary=["design.stages.2.mesh.backlash_um=5,20"],
        random=["design.stages.1.error_mode.e_um=uniform(5,15)"],
        samples=2,
    )
    scenarios = [study.load_case(case) for case in study.cases()]
    assert sorted({sc.stages[1].mesh.backlash_um for sc in scenarios}) == [5.0, 20.0]
    assert all(5 <= sc.stages[0].error_mode.e_um <= 15 for sc in scenarios)
    assert all(sc.stages[1].error_mode == scenarios[0].stages[1].error_mode for sc in scenarios)
    with pytest.raises(ScenarioError, match="production.error_mode does not apply to a drive of 2 stages"):
        run_study("two-stage", vary=["production.error_mode.e_um=5,50"], out_dir=tmp_path, progress=False)
    assert not any(tmp_path.glob("cases/*/summary.json"))  # refused before anything ran


def test_the_installed_layout_has_no_mapped_package_under_gearbody():
    import sys

    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover
        import tomli as tomllib
    from pathlib import Path

    pyproject = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text())
    mapped = pyproject["tool"]["setuptools"]["package-dir"]
    assert mapped and not [name for name in mapped if name == "gearbody" or name.startswith("gearbody.")]
    packages = set(pyproject["tool"]["setuptools"]["packages"])
    on_disk = {
        ".".join(p.parent.relative_to(Path(gb.__file__).parents[1]).parts)
        for p in Path(gb.__file__).parent.rglob("__init__.py")
    }
    assert on_disk <= packages, f"packages missing from pyproject.toml: {sorted(on_disk - packages)}"


def test_the_paper_reproduction_writes_into_the_checkout_it_runs_from(monkeypatch, tmp_path):
    from pathlib import Path

    from gearbody_validation.paper import common

    checkout = Path(__file__).resolve().parents[1]
    monkeypatch.chdir(checkout)
    assert common.resolve_output_dir() == checkout / "validation" / "paper"
    monkeypatch.chdir(tmp_path)  # elsewhere: the current directory, never beside the installed scripts
    assert common.resolve_output_dir() == tmp_path / common.DEFAULT_OUT
    assert common.resolve_output_dir() != Path(common.__file__).resolve().parent


def test_an_infeasible_drive_is_an_input_error_on_the_command_line(tmp_path, capsys):
    from gearbody.cli import main

    overload = [
        "--set",
        'operation.initial_state="steady"',
        "--set",
        "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
        "--set",
        "design.machine.rated_torque_Nm=6000",
    ]
    assert main(["run", "one-stage", *overload, "--t-end", "0.01", "--out", str(tmp_path), "--no-plots"]) == 2
    assert "breakdown torque" in capsys.readouterr().err
    assert main(["run", "two-stage", "--set", "production.error_mode.e_um=50", "--t-end", "0.01"]) == 2
    assert "design.stages.N.error_mode.e_um with N = 1..2" in capsys.readouterr().err
    assert not (tmp_path / "result.npz").exists()


def test_accuracy_levels_set_method_and_tolerance_in_the_coordinates_units():
    def solver(scene, *overrides):
        s = load_scenario(scene, list(overrides)).solver
        return s.method, s.absolute_tolerance

    assert solver("one-stage") == ("DOPRI5", 1e-8)
    assert solver("muller") == ("DOPRI5", pytest.approx(3e-11))  # a deflection in m, not an angle
    assert solver("two-stage", 'solver.accuracy="draft"') == ("ODE23", 3e-5)
    assert solver("one-stage", 'solver.accuracy="tight"') == ("DOPRI5", 1e-10)
    assert solver("one-stage", 'solver.accuracy="draft"', "solver.absolute_tolerance=1e-6") == ("ODE23", 1e-6)
    with pytest.raises(ScenarioError, match="solver.accuracy = 'fast': must be one of 'draft', 'default'"):
        load_scenario("one-stage", ['solver.accuracy="fast"'])
    sc = load_scenario("one-stage", ['solver.accuracy="draft"'])
    assert load_scenario(scenario_to_dict(sc)) == sc  # the resolved method and tolerance are written out
