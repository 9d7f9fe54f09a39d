"""The command line: list, run (files and plots), modes, help, and refusal of bad input."""

import json
import subprocess
import sys

import numpy as np
import pytest

from gearbody.cli import main
from gearbody.errors import InputError
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


def _no_simulation(monkeypatch):
    """Any simulation, study or render run fails the test: the error must come before them."""
    import gearbody.engine
    import gearbody.render
    import gearbody.studies

    def called(*_a, **_k):
        raise AssertionError("the command did work before checking its input")

    for module, name in ((gearbody.engine, "simulate"), (gearbody.studies, "run_study")):
        monkeypatch.setattr(module, name, called)
    monkeypatch.setattr(gearbody.render, "render", called)


WRITERS = [
    ["run", "one-stage"],
    ["mesh", "one-stage"],
    ["render", "one-stage", "--kinematic"],
    ["render", "one-stage"],
    ["sweep", "one-stage", "--vary", "production.error_mode.e_um=1,2"],
]


@pytest.mark.parametrize("command", WRITERS, ids=lambda c: " ".join(c[:1] + c[2:3]))
def test_out_naming_a_file_or_a_path_under_a_file_is_one_line_exit_2_before_any_work(
    command, tmp_path, capsys, monkeypatch
):
    _no_simulation(monkeypatch)
    plain = tmp_path / "plain"
    plain.write_text("not a folder\n")
    for out, reason in ((plain, "is a file, not a folder"), (plain / "a" / "b", f"{plain} is a file")):
        assert main([*command, "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f"--out {out}: " in err and reason in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plain"]


def test_out_that_cannot_be_written_is_refused_naming_the_reason(tmp_path, capsys, monkeypatch):
    # Root ignores permission bits, so the check tries to write (a probe folder) instead of reading
    # them; here the probe is made to fail as it does for a non-root user in a read-only folder.
    import tempfile

    _no_simulation(monkeypatch)

    def denied(*_a, **_k):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(tempfile, "mkdtemp", denied)
    assert main(["run", "one-stage", "--out", str(tmp_path / "new")]) == 2
    err = capsys.readouterr().err
    assert f"--out {tmp_path / 'new'}: cannot write in {tmp_path}: Permission denied" in err


def test_out_on_a_read_only_mount_is_refused_before_the_simulation(tmp_path):
    """A real read-only file system (a tmpfs mounted read-only in a private mount namespace, which
    needs root and unshare; skipped elsewhere). Root can write a chmod 555 folder, so that is no
    test of the check; this is."""
    import os
    import shutil

    if os.geteuid() != 0 or shutil.which("unshare") is None:
        pytest.skip("needs root and unshare for a private read-only mount")
    ro = tmp_path / "ro"
    ro.mkdir()
    probe = subprocess.run(["unshare", "-m", "mount", "-t", "tmpfs", "-o", "ro", "tmpfs", str(ro)])
    if probe.returncode != 0:
        pytest.skip("mount namespaces not available")
    cli = f"{sys.executable} -m gearbody.cli run one-stage --out {ro}/result"
    done = subprocess.run(
        ["unshare", "-m", "sh", "-c", f"mount -t tmpfs -o ro,size=64k tmpfs {ro} && exec {cli}"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2, done.stderr
    assert done.stderr.strip() == f"gearbody: invalid input: --out {ro}/result: cannot write in {ro}: " + (
        "Read-only file system"
    )
    assert done.stdout == ""


def test_out_in_a_writable_or_new_folder_is_accepted_and_the_probe_leaves_nothing(tmp_path):
    import os

    from gearbody.cli.common import check_out

    assert check_out(tmp_path / "a" / "b") == tmp_path / "a" / "b"
    assert check_out(tmp_path) == tmp_path
    assert list(tmp_path.iterdir()) == []
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o555)
    if os.geteuid() == 0:  # root writes there anyway, so the check agrees: it tries, it does not guess
        assert check_out(locked / "x") == locked / "x"
        (locked / "y").mkdir()
    else:
        with pytest.raises(InputError, match="cannot write in .*: Permission denied"):
            check_out(locked / "x")


BAD_OPTIONS = [
    (["modes", "one-stage"], "--harmonics", "0", ">= 1 and <= 100"),
    (["validate"], "--tolerance", "-1", "> 0"),
    (["validate"], "--tolerance", "nan", "> 0"),
    (["run", "one-stage"], "--t-end", "0", "> 0"),
    (["run", "one-stage"], "--t-end", "nan", "finite"),
    (["run", "one-stage"], "--t-end", "inf", "finite"),
    (["run", "one-stage"], "--t-end", "-1", "> 0"),
    (["run", "one-stage"], "--t-end", "1e400", "finite"),
    (["mesh", "one-stage"], "--stage", "0", ">= 1"),
    (["mesh", "one-stage"], "--load", "-1", ">= 0"),
    (["mesh", "one-stage"], "--load", "nan", ">= 0"),
    (["mesh", "one-stage"], "--load", "1e300", "<= 100"),
    (["sweep", "one-stage", "--out", "x"], "--workers", "0", ">= 1 and <= 256"),
    (["sweep", "one-stage", "--out", "x"], "--samples", "0", ">= 1"),
    (["sweep", "one-stage", "--out", "x"], "--seeds", "-2", ">= 1"),
    (["sweep", "one-stage", "--out", "x"], "--study-seed", "-1", ">= 0"),
    (["sweep", "one-stage", "--out", "x"], "--t-end", "inf", "> 0"),
    (["render", "one-stage"], "--frames", "0", ">= 1 and <= 2000"),
    (["render", "one-stage"], "--zoom", "0", ">= 0.05 and <= 50"),
    (["render", "one-stage"], "--zoom", "nan", ">= 0.05"),
    (["render", "one-stage"], "--fps", "0", ">= 0.1 and <= 120"),
    (["render", "one-stage"], "--elevation", "91", ">= -90 and <= 90"),
    (["render", "one-stage"], "--azimuth", "nan", "finite number"),
    (["render", "one-stage"], "--start", "-1", ">= 0"),
    (["render", "one-stage"], "--end", "inf", ">= 0"),
    (["render", "one-stage"], "--lateral-scale", "-1", ">= 0 and <= 1e+06"),
    (["render", "one-stage"], "--t-end", "0", "> 0"),
]


@pytest.mark.parametrize(("command", "option", "value", "range_text"), BAD_OPTIONS)
def test_every_numeric_option_is_range_checked_exit_2_before_any_work(
    command, option, value, range_text, capsys, monkeypatch
):
    _no_simulation(monkeypatch)
    assert main([*command, f"{option}={value}"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.startswith(f"gearbody: invalid input: {option} = {value}: must be a ")
    assert range_text in err and err.count("\n") == 1


@pytest.mark.parametrize(
    ("command", "option", "value"),
    [(["modes", "one-stage"], "--harmonics", "2.5"), (["run", "one-stage"], "--t-end", "soon")],
)
def test_an_option_that_is_no_number_is_a_usage_error(command, option, value, capsys):
    with pytest.raises(SystemExit) as info:
        main([*command, option, value])
    assert info.value.code == 2
    assert f"argument {option}: must be a" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [("--width", "8", "width_px = 8"), ("--height", "9000", "height_px = 9000")],
)
def test_render_sizes_are_checked_before_the_simulation(
    option, value, message, tmp_path, capsys, monkeypatch
):
    _no_simulation(monkeypatch)
    assert main(["render", "one-stage", option, value, "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err
    assert message in err and "[16, 8192]" in err


def test_render_background_is_range_checked_before_anything_runs(capsys, monkeypatch):
    _no_simulation(monkeypatch)
    assert main(["render", "one-stage", "--background", "2,0,0"]) == 2
    assert "--background = '2,0,0': give R,G,B in [0, 1]" in capsys.readouterr().err


def test_a_misspelled_scene_fails_before_any_output(capsys, tmp_path):
    assert main(["validate", "one-stgae"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and "unknown scene 'one-stgae'; did you mean 'one-stage'?" in err
    out_dir = str(tmp_path / "never")
    for command in (
        ["modes"],
        ["mesh", "--out", out_dir],
        ["run", "--out", out_dir],
        ["render", "--kinematic"],
        ["sweep", "--seeds", "2", "--out", out_dir],
    ):
        assert main([command[0], "one-stgae", *command[1:]]) == 2
        out, err = capsys.readouterr()
        assert out == "" and "did you mean 'one-stage'" in err
    assert list(tmp_path.iterdir()) == []


def test_override_errors_on_the_command_line_quote_the_override(capsys):
    assert main(["modes", "one-stage", "--set", "production.error_mode.e_um=abc"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("gearbody: invalid scenario: --set production.error_mode.e_um=abc (on ")
    assert "(any value)" not in err


def test_scenario_paths_that_are_no_toml_file_are_one_line_exit_2_for_every_command(tmp_path, capsys):
    binary = tmp_path / "drive.toml"
    binary.write_bytes(b"\x8c\xff binary")
    out = str(tmp_path / "out")
    for scene, reason in ((tmp_path, "is a folder"), (binary, "not UTF-8 text")):
        for command in (
            ["run", str(scene), "--out", out],
            ["modes", str(scene)],
            ["mesh", str(scene), "--out", out],
            ["render", str(scene), "--kinematic", "--out", out],
            ["sweep", str(scene), "--seeds", "2", "--out", out],
        ):
            assert main(command) == 2
            err = capsys.readouterr().err
            assert err.count("\n") == 1 and f"{scene}: " in err and reason in err, command
    assert sorted(p.name for p in tmp_path.iterdir()) == ["drive.toml"]


def test_render_result_that_is_no_gearbody_result_is_refused(tmp_path, capsys):
    np.savez(tmp_path / "other.npz", a=np.zeros(2))
    (tmp_path / "zip.npz").write_bytes(b"PK\x03\x04 broken")
    for name in ("other.npz", "zip.npz"):
        assert main(["render", "one-stage", "--result", str(tmp_path / name), "--out", str(tmp_path)]) == 2
        assert f"{name} is not a result written by 'gearbody run'" in capsys.readouterr().err
