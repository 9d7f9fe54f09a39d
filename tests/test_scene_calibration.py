"""Calibration of a scene (``gearbody calibrate``): input refused before anything runs, the files of a
fit, a resume that simulates nothing again, cases read as separate features, and (slow) the recovery of
known mesh stiffness, mesh damping and error amplitude from the features of a run of the same scene."""

from __future__ import annotations

import json

import numpy as np
import pytest
import tomllib

pytest.importorskip("nevergrad")

from gearbody.cli import main  # noqa: E402
from gearbody.model import load_scenario  # noqa: E402
from gearbody.studies import SweepSpecError  # noqa: E402
from gearbody.studies.calibration import Parameter, Target  # noqa: E402
from gearbody.studies.scene_calibration import calibrate_scene, parse_parameter, parse_target  # noqa: E402
from gearbody.studies.sensitivity import read_scene, scene_features  # noqa: E402

STEADY = [
    'operation.initial_state="steady"',
    "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
]
K = "design.mesh.stiffness_single_N_per_m"
C = "design.mesh.damping_Ns_per_m"
E = "production.error_mode.e_um"
A1 = "line_amplitude:signal=pinion_accel_rad_s2,mesh=1"
A2 = "line_amplitude:signal=pinion_accel_rad_s2,mesh=2"


def test_parameters_and_targets_parse_or_name_what_is_wrong():
    p = parse_parameter(f"{K}=0.8e9:1.6e9:log", start=1.0e9)
    assert (p.key, p.lower, p.upper, p.start, p.log) == (K, 0.8e9, 1.6e9, 1.0e9, True)
    assert not parse_parameter(f"{E}=5:30").log
    for text, message in (
        (f"{K}", "expected KEY=low:high"),
        (f"{K}=1e9", "low:high or low:high:log"),
        (f"{K}=1e9:2e9:lin", "low:high or low:high:log"),
        (f"{K}=2e9:1e9", "lower < upper"),
        (f"{E}=-1:30:log", "positive lower bound"),
        (f"{K}=a:b", "must be numbers"),
    ):
        with pytest.raises(SweepSpecError, match=message):
            parse_parameter(text)
    t = parse_target("kd_max:period=4@a", "1.8", "0.1")
    assert (t.feature, t.case, t.label, t.value, t.sigma) == (
        "kd_max:period=4",
        "a",
        "kd_max:period=4@a",
        1.8,
        0.1,
    )
    with pytest.raises(SweepSpecError, match="sigma"):
        parse_target("kd_max", "1.8", "0")


@pytest.mark.parametrize(
    "args, message",
    [
        (["--param", f"{K}=1e9:2e9", "--target", "kd_max@b", "1.2", "0.1"], "no case 'b'"),
        (["--param", f"{K}=1e9:2e9", "--target", "kd_nope", "1.2", "0.1"], "kd_nope"),
        (["--param", f"{K}=-1e9:2e9", "--target", "kd_max", "1.2", "0.1"], "at -1000000000.0"),
        (
            ["--param", f"{K}=1e9:2e9", "--start", f"{K}=3e9", "--target", "kd_max", "1.2", "0.1"],
            "outside the bounds",
        ),
        (
            ["--param", f"{K}=1e9:2e9", "--start", f"{C}=3", "--target", "kd_max", "1.2", "0.1"],
            "not a --param",
        ),
        (["--param", f"{K}=1e9:2e9"], "give one or more --target"),
        (["--target", "kd_max", "1.2", "0.1"], "give one or more --param"),
        (["--param", f"{K}=1e9:2e9", "--target", "kd_max", "1", "1", "--set", f"{K}=1e9"], "also a --param"),
        (
            ["--param", f"{K}=1e9:2e9", "--target", "kd_max", "1", "1", "--budget", "3000"],
            "above the limit of 2000",
        ),
        (
            [
                "--param",
                f"{K}=1e9:2e9",
                "--target",
                "kd_max@a",
                "1",
                "1",
                "--case",
                "a",
                "design.mesh.nope=1",
            ],
            "case 'a': ",
        ),
        (
            ["--param", f"{K}=1e9:2e9", "--target", "kd_max", "1", "1", "--case", "a", f"{E}=3"],
            "case 'a' is read by no target",
        ),
        (
            ["--param", f"{K}=1e9:2e9", "--target", "line_amplitude:signal=nope,mesh=1", "1", "1"],
            "no signal 'nope'",
        ),
        (["--param", f"{K}=1e9:2e9", "--target", "kd_max", "1", "1", "--budget", "0"], "--budget = 0"),
    ],
)
def test_cli_bad_input_exits_2_before_anything_runs(tmp_path, capsys, args, message):
    out = tmp_path / "cal"
    code = main(["calibrate", "one-stage", "--t-end", "0.01", "--quiet", "--out", str(out), *args])
    assert code == 2
    assert message in capsys.readouterr().err
    assert not (out / "evaluations.jsonl").exists()


def test_a_fit_writes_its_files_and_a_rerun_simulates_nothing(tmp_path, capsys):
    """Two cases (two error amplitudes) as separate targets; the calibrated scene reruns."""
    out = tmp_path / "cal"
    args = [
        "calibrate", "one-stage", "--t-end", "0.02", *(x for o in STEADY for x in ("--set", o)),
        "--param", f"{K}=0.9e9:1.5e9:log", "--case", "low", f"{E}=5", "--case", "high", f"{E}=20",
        "--target", f"{A1}@low", "150", "15", "--target", f"{A1}@high", "600", "60",
        "--budget", "3", "--polish-evaluations", "0", "--workers", "1", "--out", str(out),
    ]  # fmt: skip
    assert main(args) == 0
    first = capsys.readouterr().out
    for name in (
        "evaluations.jsonl",
        "calibration.json",
        "calibration.md",
        "convergence.png",
        "calibrated.toml",
    ):
        assert (out / name).is_file(), name
    record = json.loads((out / "calibration.json").read_text())
    assert set(record["features"]) == {f"{A1}@low", f"{A1}@high"}
    assert record["simulations"] == 2 * record["evaluations"]  # each evaluation ran both cases
    k = record["parameters"][K]
    assert 0.9e9 <= k <= 1.5e9 and record["sigma"][K] > 0
    scene = load_scenario(str(out / "calibrated.toml"))
    assert scene.stages[0].mesh.stiffness_single_N_per_m == k
    assert scene.operation.initial_state == "steady"  # the fixed overrides are part of it
    assert any("calibrated by gearbody" in s for s in scene.meta.sources)
    assert tomllib.loads((out / "calibrated.toml").read_text())["meta"]["name"] == "one-stage-calibrated"
    # the same command again: every evaluation replayed from the record, the same fit
    assert main(args) == 0
    again = json.loads((out / "calibration.json").read_text())
    assert again["simulations"] == 0 and again["replayed"] == record["evaluations"]
    assert again["parameters"] == record["parameters"] and again["residuals"] == record["residuals"]
    assert "0 simulations now" in capsys.readouterr().out and "residual/sigma" in first


def test_a_fit_that_ends_on_its_bound_is_warned_about_and_flagged(tmp_path, capsys):
    """A third natural frequency of 5000 Hz is out of reach of stiffnesses up to 1.5e9 N/m (2972 Hz there;
    it rises with the stiffness): the fit ends on the upper bound, exits 0 (the fit is written), and says
    so on stderr, in calibration.json and in calibration.md."""
    out = tmp_path / "cal"
    args = [
        "calibrate", "one-stage", "--t-end", "0.02", *(x for o in STEADY for x in ("--set", o)),
        "--param", f"{K}=0.9e9:1.5e9:log", "--target", "natural_frequency_hz:mode=3", "5000", "10",
        "--budget", "3", "--polish-evaluations", "12", "--workers", "1", "--out", str(out),
    ]  # fmt: skip
    assert main(args) == 0
    captured = capsys.readouterr()
    (warning,) = [line for line in captured.err.splitlines() if "warning" in line]
    assert warning.startswith(f"gearbody calibrate: warning: {K} = 1.5e+09 ends on its upper bound")
    assert "on its upper bound" in captured.out  # the table's flag
    record = json.loads((out / "calibration.json").read_text())
    assert record["at_bound"] == {K: "upper"} and record["identified"] == {K: True}
    assert record["warnings"] == [warning.removeprefix("gearbody calibrate: warning: ")]
    assert "- warning: " + record["warnings"][0] in (out / "calibration.md").read_text()


def test_another_scene_in_the_same_out_is_refused(tmp_path):
    out = tmp_path / "cal"
    kw = dict(
        out=out,
        overrides=["operation.t_end_s=0.01", *STEADY],
        workers=1,
        budget=1,
        polish=False,
        progress=False,
    )
    calibrate_scene("one-stage", [Parameter(K, 0.9e9, 1.5e9)], [Target("kd_max", 1.2, 0.1)], **kw)
    with pytest.raises(Exception, match="records another calibration"):
        calibrate_scene("one-stage", [Parameter(C, 1e3, 1e4)], [Target("kd_max", 1.2, 0.1)], **kw)


@pytest.mark.slow
def test_known_stiffness_damping_and_error_are_recovered_from_a_wrong_start(tmp_path):
    """Targets: five features of a run at known values (1 % sigma); the start is off by +36 % (stiffness),
    -56 % (damping) and +79 % (error). Measured on 2026-12-02: recovered to 2e-5, 4e-4 and 1e-4 relative
    in 61 simulations (109 s wall on 2 shared cores); asserted: 0.1 %, 1 % (damping, the weakest lever:
    its 1-sigma is 3.6 %) and 0.1 %, and each within its own 1-sigma estimate, with no warning."""
    truth = {K: 1.1e9, C: 9000.0, E: 14.0}
    overrides = ["operation.t_end_s=0.2", *STEADY]
    features = [A1, A2, "natural_frequency_hz:mode=3", "rms:signal=pinion_accel_rad_s2", "kd_std"]
    _, base, _ = read_scene("one-stage")
    measured = scene_features(truth, base, overrides, features)
    params = [
        Parameter(K, 0.8e9, 1.6e9, start=1.5e9, log=True),
        Parameter(C, 3000.0, 15000.0, start=4000.0, log=True),
        Parameter(E, 5.0, 30.0, start=25.0),
    ]
    targets = [Target(f, v, 0.01 * abs(v)) for f, v in measured.items()]
    res = calibrate_scene("one-stage", params, targets, out=tmp_path / "cal", overrides=overrides, workers=2,
                          budget=30, polish_evaluations=40, progress=False)  # fmt: skip
    fit = res.fit
    for key, tol in ((K, 1e-3), (C, 1e-2), (E, 1e-3)):
        assert fit.parameters[key] == pytest.approx(truth[key], rel=tol), (key, fit.parameters[key])
        assert abs(fit.parameters[key] - truth[key]) < fit.sigma[key], key
    assert fit.sigma[C] / truth[C] > fit.sigma[K] / truth[K]  # damping is the least determined
    assert fit.warnings() == [] and np.all(np.abs(fit.correlation) <= 1.0)
    assert fit.cost < 1e-2
    assert res.simulations == fit.evaluations


def test_ctrl_c_keeps_the_evaluations_and_the_rerun_ends_as_an_uninterrupted_fit(
    tmp_path, capsys, monkeypatch
):
    from gearbody.studies import scene_calibration

    def args(out):
        return [
            "calibrate", "one-stage", "--t-end", "0.02", *(x for o in STEADY for x in ("--set", o)),
            "--param", f"{K}=0.9e9:1.5e9:log", "--target", A1, "300", "30",
            "--budget", "4", "--batch", "1", "--polish-evaluations", "3", "--workers", "1", "--quiet",
            "--out", str(out),
        ]  # fmt: skip

    assert main(args(tmp_path / "whole")) == 0
    whole = json.loads((tmp_path / "whole" / "calibration.json").read_text())
    real, calls = scene_calibration.run_jobs, []

    def interrupted(*a, **kw):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(*a, **kw)

    monkeypatch.setattr(scene_calibration, "run_jobs", interrupted)
    assert main(args(tmp_path / "cut")) == 130
    err = capsys.readouterr().err
    assert "interrupted: 2 evaluations recorded" in err and "rerun the same command to resume" in err
    monkeypatch.setattr(scene_calibration, "run_jobs", real)
    assert main(args(tmp_path / "cut")) == 0
    resumed = json.loads((tmp_path / "cut" / "calibration.json").read_text())
    assert resumed["replayed"] == 2 and resumed["simulations"] == whole["simulations"] - 2
    assert resumed["parameters"] == whole["parameters"] and resumed["history"] == whole["history"]


def test_the_docs_commands_parse():
    import re
    import shlex
    from pathlib import Path

    from gearbody.cli import _parser

    text = (Path(__file__).resolve().parents[1] / "docs" / "calibration.md").read_text()
    blocks = re.findall(r"```sh\n(.*?)```", text, re.S)
    assert len(blocks) >= 2
    for block in blocks:
        words = shlex.split(block.replace("\\\n", " "))
        assert words[:2] == ["gearbody", "calibrate"]
        _parser().parse_args(words[1:])


@pytest.mark.slow
@pytest.mark.parametrize("executor", ["pool", "dask"])
def test_a_process_pool_and_a_dask_cluster_give_the_serial_fit(tmp_path, executor):
    """Two cases of a point and the points of a batch run in parallel; the fit is bit-identical."""
    import contextlib

    params = [Parameter(K, 0.9e9, 1.5e9, log=True), Parameter(E, 5.0, 30.0)]
    targets = [Target(A1, 400.0, 4.0, "low"), Target(A2, 70.0, 0.7, "high")]
    cases = {"low": [f"{C}=5000"], "high": [f"{C}=9000"]}
    kw = dict(overrides=["operation.t_end_s=0.02", *STEADY], cases=cases, budget=4, batch=2,
              polish_evaluations=3, progress=False)  # fmt: skip
    serial = calibrate_scene("one-stage", params, targets, out=tmp_path / "serial", workers=1, **kw).fit
    with contextlib.ExitStack() as stack:
        if executor == "dask":
            from dask.distributed import LocalCluster

            cluster = stack.enter_context(
                LocalCluster(
                    n_workers=2,
                    processes=True,
                    threads_per_worker=1,
                    host="127.0.0.1",
                    dashboard_address=":0",
                )  # fmt: skip
            )
            where = {"scheduler": cluster.scheduler_address}
        else:
            where = {"workers": 2}
        res = calibrate_scene("one-stage", params, targets, out=tmp_path / executor, **where, **kw)
    assert res.fit.parameters == serial.parameters and res.fit.history == serial.history
    assert res.simulations == 2 * res.fit.evaluations
