"""Every command on every shipped scene (issue 25): each command of ``gearbody`` runs in-process on each
scene that ``gearbody list`` prints, with short settings, and ends with exit code 0 and its files; a new
scene or command is covered without editing this file. The studies (sweep, sensitivity, calibrate) and
``validate --short`` simulate several times per scene and are marked slow; ``validate --short`` of the
scenes test_validation already compares (VALIDATED_SCENES) is left to it."""

from __future__ import annotations

import csv
import json

import pytest
from gearbody_validation.compare import VALIDATED_SCENES, case_scenario, cases

from gearbody.cli import COMMANDS, main
from gearbody.model import load_scenario
from gearbody.model.scenes import list_scenes

SCENES = list_scenes()

T_END = "0.01"  # s: enough output samples for every plot's final window (20 kHz: 50 in the last 25 %)
STUDY_T_END = "0.003"
KEY = "condition.friction_coefficient"  # a key every drive has
COVERED = {
    "list", "new", "run", "modes", "mesh", "render", "validate", "sweep", "sensitivity", "calibrate", "info",
    "analyze", "compare",
}  # fmt: skip


def _is_planetary(stage) -> bool:
    return getattr(stage, "type", "") == "planetary"


def expected_run_plots(scene: str) -> set[str]:
    """The PNGs ``gearbody run`` writes, from the scenario's stages: per parallel stage its K_d over time
    and folded (stage k > 1 tagged _stage_k), the spectrum when the first stage is parallel, per
    planetary stage its planet K_d, load sharing and ring-sensor spectrum."""
    names = set()
    stages = load_scenario(scene).stages
    for k, st in enumerate(stages):
        tag = "" if k == 0 else f"_stage_{k + 1}"
        if _is_planetary(st):
            names |= {f"planet_kd_time{tag}.png", f"load_sharing{tag}.png", f"ring_sensor_spectrum{tag}.png"}
        else:
            names |= {f"kd_time{tag}.png", f"kd_folded{tag}.png"}
    if not _is_planetary(stages[0]):
        names.add("spectrum.png")
    return names


def test_the_matrix_covers_every_command_and_every_listed_scene(capsys):
    """The scenes are what `gearbody list` prints; the commands are all of gearbody's."""
    assert main(["list"]) == 0
    listed = [line.split("\t")[0] for line in capsys.readouterr().out.splitlines()]
    assert listed == SCENES and len(SCENES) >= 15
    parsers = {c.__name__.rsplit(".", 1)[-1] for c in COMMANDS}
    assert {"listing" if c == "list" else c for c in COVERED} == parsers


def test_info_names_the_versions_and_the_force_path(capsys):
    assert main(["info"]) == 0
    out = capsys.readouterr().out
    assert "exudyn" in out and "force path" in out


@pytest.mark.parametrize("scene", SCENES)
def test_run_writes_result_summary_report_and_every_stages_plots(scene, tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", scene, "--t-end", T_END, "--out", str(out), "--quiet", "--report"]) == 0
    for name in ("result.npz", "scenario.toml", "summary.json", "report.html"):
        assert (out / name).is_file(), name
    assert "kd_max" in json.loads((out / "summary.json").read_text())
    written = {p.name for p in out.glob("*.png")}
    expected = expected_run_plots(scene)
    assert expected <= written, expected - written
    assert written - expected <= {"bearing_forces.png"}, written - expected
    _no_error_but_notes(scene, capsys.readouterr().err)


def _no_error_but_notes(scene: str, err: str) -> None:
    """Nothing on stderr, but for a scene with instruments, notes on what a run this short cannot give
    (a tacho of fewer than 3 pulses: the virtual recording has none)."""
    if load_scenario(scene).instruments is None:
        assert err == ""
    else:
        assert all(line.startswith("gearbody: note:") for line in err.splitlines()), err


@pytest.mark.parametrize("scene", SCENES)
def test_analyze_and_compare_take_every_scenes_run(scene, tmp_path, capsys):
    """A run as a recording: analyze writes its report (a short run: what it cannot analyse is a note),
    and compare sets the run beside itself (every ratio 1)."""
    run = tmp_path / "run"
    assert main(["run", scene, "--t-end", T_END, "--out", str(run), "--quiet", "--no-plots"]) == 0
    assert main(["analyze", str(run), "--out", str(tmp_path / "a")]) == 0
    assert (tmp_path / "a" / "report.html").is_file() and (tmp_path / "a" / "features.json").is_file()
    # the run beside its own signals (result.npz; a folder with instruments.mat gives its instruments)
    assert main(["compare", str(run), str(run / "result.npz"), "--out", str(tmp_path / "c")]) == 0
    rows = json.loads((tmp_path / "c" / "comparison.json").read_text())["features"]
    assert rows and all(r["ratio"] == 1.0 for r in rows if r["run"] != 0)
    _no_error_but_notes(scene, capsys.readouterr().err)


@pytest.mark.parametrize("scene", SCENES)
def test_new_writes_a_starting_scenario_that_run_takes(scene, tmp_path, capsys):
    drive = tmp_path / "my-drive.toml"
    assert main(["new", scene, "--out", str(drive)]) == 0
    out = tmp_path / "run"
    assert main(["run", str(drive), "--t-end", "0.002", "--no-plots", "--quiet", "--out", str(out)]) == 0
    assert (out / "summary.json").is_file()


@pytest.mark.parametrize("scene", SCENES)
def test_modes_prints_one_row_per_degree_of_freedom(scene, capsys):
    assert main(["modes", scene, "--harmonics", "2"]) == 0
    text = capsys.readouterr().out
    lines = text.splitlines()
    dofs = lines[1].split("DOFs: ")[1].split(", ")
    head = next(i for i, line in enumerate(lines) if line.lstrip().startswith("mode"))
    rows = lines[head + 1 : head + 1 + len(dofs)]
    assert [int(r.split()[0]) for r in rows] == list(range(1, len(dofs) + 1))
    assert lines[-1].startswith("(w(k f_z) = ")


@pytest.mark.parametrize("scene", SCENES)
def test_mesh_reports_every_stage_and_draws_it(scene, tmp_path, capsys):
    count = len(load_scenario(scene).stages)
    assert main(["mesh", scene, "--out", str(tmp_path)]) == 0
    text = capsys.readouterr().out
    for k in range(1, count + 1):
        assert f"stage {k} of {count}" in text
        assert (tmp_path / f"mesh_stage{k}.png").is_file()


@pytest.mark.parametrize("scene", SCENES)
def test_render_kinematic_draws_a_frame(scene, tmp_path, capsys):
    args = ["render", scene, "--kinematic", "--frames", "1", "--format", "none", "--quiet"]
    assert main([*args, "--width", "96", "--height", "72", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "frame_0000.png").is_file()


# -- the studies and the validation: several simulations per scene -----------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("scene", SCENES)
def test_sweep_runs_every_case(scene, tmp_path, capsys):
    out = tmp_path / "sweep"
    args = ["sweep", scene, "--vary", f"{KEY}=0.0,0.05", "--t-end", STUDY_T_END, "--workers", "1"]
    assert main([*args, "--quiet", "--no-results", "--out", str(out)]) == 0
    with (out / "summary.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert [r["status"] for r in rows] == ["ok", "ok"]


@pytest.mark.slow
@pytest.mark.parametrize("scene", SCENES)
def test_sensitivity_ranks_a_key_by_the_first_stages_kd(scene, tmp_path, capsys):
    out = tmp_path / "sens"
    args = ["sensitivity", scene, "--key", f"{KEY}=0.0:0.05", "--feature", "kd_max", "--feature", "kd_p95"]
    args += ["--samples", "2", "--t-end", STUDY_T_END, "--workers", "1", "--quiet", "--out", str(out)]
    assert main(args) == 0
    assert (out / "indices.csv").is_file()


@pytest.mark.slow
@pytest.mark.parametrize("scene", SCENES)
def test_calibrate_fits_a_key_to_the_first_stages_kd(scene, tmp_path, capsys):
    out = tmp_path / "cal"
    args = ["calibrate", scene, "--param", f"{KEY}=0.0:0.05", "--target", "kd_max", "1.5", "0.5"]
    args += ["--budget", "2", "--polish-evaluations", "0", "--t-end", STUDY_T_END, "--workers", "1"]
    assert main([*args, "--quiet", "--out", str(out)]) == 0
    assert (out / "calibration.json").is_file() and (out / "calibrated.toml").is_file()


@pytest.mark.parametrize("scene", SCENES)
def test_validate_has_its_cases_for_every_scene(scene):
    """What `gearbody validate SCENE --short` runs: its cases' scenarios load, a separation case among
    them (the runs themselves: test_validation for VALIDATED_SCENES, the test below for the others)."""
    found = cases(scene, short=True)
    assert "separation" in [c.name for c in found]
    for case in found:
        case_scenario(scene, case, short=True)


@pytest.mark.slow
@pytest.mark.parametrize("scene", [s for s in SCENES if s not in VALIDATED_SCENES])
def test_validate_short_passes_where_test_validation_does_not_run_it(scene, capsys):
    """test_validation compares every one of VALIDATED_SCENES with the reference (the planetary ones take
    minutes); the CLI runs here on the scenes it leaves out, so every shipped scene is validated."""
    assert main(["validate", scene, "--short"]) == 0, capsys.readouterr().out
