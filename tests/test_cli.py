"""The command line: list, run (files and plots), modes, help, and refusal of bad input."""

import json
import subprocess
import sys

import numpy as np

from gearbody.cli import main
from gearbody.model import load_scenario


def test_list_prints_one_scene_per_line_name_first(capsys):
    assert main(["list"]) == 0
    names = [line.split()[0] for line in capsys.readouterr().out.splitlines()]
    assert {"muller", "two-wheel", "one-stage"} <= set(names)


def test_run_writes_result_resolved_scenario_summary_and_plots(tmp_path, capsys):
    out = tmp_path / "run"
    assert (
        main(
            [
                "run",
                "two-wheel",
                "--t-end",
                "0.05",
                "--set",
                "production.error_mode.e_um=12",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    with np.load(out / "result.npz") as z:
        assert {"time", "mesh_force_N", "kd"} <= set(z.files)
        assert z["time"][-1] == np.float64(0.05)
    summary = json.loads((out / "summary.json").read_text())
    for key in (
        "kd_max",
        "separation_fraction",
        "mesh_frequency_hz",
        "mean_speed_rad_s",
        "simulated_time_s",
        "wall_time_s",
    ):
        assert key in summary
    assert summary["simulated_time_s"] == 0.05
    resolved = load_scenario(out / "scenario.toml")
    assert resolved.stages[0].error_mode.e_um == 12 and resolved.operation.t_end_s == 0.05
    for png in ("kd_time.png", "kd_folded.png", "spectrum.png"):
        assert (out / png).stat().st_size > 10_000
    assert "kd_max" in capsys.readouterr().out


def test_resolved_scenario_reruns_to_the_same_result(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    assert main(["run", "muller", "--t-end", "0.02", "--out", str(a), "--quiet", "--no-plots"]) == 0
    assert main(["run", str(a / "scenario.toml"), "--out", str(b), "--quiet", "--no-plots"]) == 0
    with np.load(a / "result.npz") as za, np.load(b / "result.npz") as zb:
        assert np.array_equal(za["mesh_force_N"], zb["mesh_force_N"])


def test_modes_prints_frequencies_and_resonance_speeds(capsys):
    assert main(["modes", "one-stage"]) == 0
    out = capsys.readouterr().out
    assert "2843.8" in out and "w(1f_z)" in out


def test_bad_input_exits_2_with_the_key_named(capsys):
    assert main(["run", "one-stage", "--set", "design.pinion.teeth=3"]) == 2
    err = capsys.readouterr().err
    assert "design.pinion.teeth = 3" in err and ">= 6" in err
    assert main(["run", "no-such-scene"]) == 2


def test_help_explains_every_run_option():
    out = subprocess.run(
        [sys.executable, "-m", "gearbody.cli", "run", "--help"], capture_output=True, text=True, check=True
    ).stdout
    for option in ("--set", "--t-end", "--out", "--no-plots", "--quiet", "result.npz", "summary.json"):
        assert option in out
