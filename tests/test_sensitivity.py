"""Sensitivity analysis (gearbody.studies.sensitivity, ``gearbody sensitivity``): the Ishigami function's
known indices through the same sample -> job -> executor -> record -> analysis path as gearbody runs,
resume, failed rows, input errors before anything runs, and on gearbody a key that cannot affect a
feature gets an index of zero while one that matters gets a large one."""

import importlib
import json
import math
import struct
import sys

import numpy as np
import pytest

from gearbody.cli import main
from gearbody.model import load_scenario
from gearbody.studies import SweepSpecError
from gearbody.studies.executors import failure
from gearbody.studies.sensitivity import MissingRowsError, analyse_model, ishigami, parse_key_range

# the module (the attribute gearbody.studies.sensitivity is the public function of that name)
sens = importlib.import_module("gearbody.studies.sensitivity")

STEADY_OVERRIDES = (  # steady rated running from t = 0 (as conftest.STEADY_OVERRIDES)
    'operation.initial_state="steady"',
    "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
)
PI_RANGE = (-math.pi, math.pi)
ISHIGAMI = {"x1": PI_RANGE, "x2": PI_RANGE, "x3": PI_RANGE}
# a = 7, b = 0.1 (Ishigami & Homma 1990; Saltelli et al. 2008, Global Sensitivity Analysis, 4.5)
S1_REF = {"x1": 0.3139, "x2": 0.4424, "x3": 0.0}
ST_REF = {"x1": 0.5576, "x2": 0.4424, "x3": 0.2437}
S13_REF = 0.2437


# --- Ishigami: the indices are known ------------------------------------------------------------------
@pytest.fixture(scope="module")
def sobol_ishigami(tmp_path_factory):
    out = tmp_path_factory.mktemp("sobol")
    return out, analyse_model(
        ishigami, ISHIGAMI, ["y"], out=out, method="sobol", samples=1024, seed=1, workers=1, progress=False
    )


def test_ishigami_sobol_indices_within_sampling_error(sobol_ishigami):
    """N = 1024 (8192 runs, serial, one per job: ~2 s). Tolerance: twice SALib's 95 % half-width
    (about 4 standard errors), which must itself be small for the check to mean anything."""
    out, res = sobol_ishigami
    assert res.rows == res.ran == 1024 * 8 and res.skipped == 0
    for key in ISHIGAMI:
        s1, s1_conf = res.index("y", "S1", key), res.index("y", "S1_conf", key)
        st, st_conf = res.index("y", "ST", key), res.index("y", "ST_conf", key)
        assert 0 < s1_conf < 0.1 and 0 < st_conf < 0.1
        assert abs(s1 - S1_REF[key]) <= 2 * s1_conf, (key, s1, s1_conf)
        assert abs(st - ST_REF[key]) <= 2 * st_conf, (key, st, st_conf)
    s2, s2_conf = res.indices["y"]["S2"], res.indices["y"]["S2_conf"]
    assert abs(s2[0, 2] - S13_REF) <= 2 * s2_conf[0, 2]
    assert abs(s2[0, 1]) <= 2 * s2_conf[0, 1] and abs(s2[1, 2]) <= 2 * s2_conf[1, 2]


def test_sobol_writes_the_record_and_the_tables(sobol_ishigami):
    out, res = sobol_ishigami
    assert len(list((out / "evaluations").glob("row-*.json"))) == 8192
    entry = json.loads((out / "evaluations" / "row-000005.json").read_text())["rows"][0]
    spec = json.loads((out / "sensitivity.json").read_text())
    x = dict(zip(spec["spec"]["keys"], spec["sample"][5], strict=True))
    assert entry["ok"] and entry["row"] == 5 and entry["values"]["y"] == ishigami(x)["y"]
    lines = (out / "indices.csv").read_text().splitlines()
    assert lines[0] == "feature,key,S1,S1_conf,ST,ST_conf" and len(lines) == 4
    assert "| y | x1 | x3 |" in (out / "indices.md").read_text()
    assert (
        json.loads((out / "indices.json").read_text())["indices"]["y"]["S2"][0][2]
        == res.indices["y"]["S2"][0, 2]
    )
    assert _png_size(out / "indices.png")[0] == 1000


def test_ishigami_morris_screening(tmp_path):
    """On the 4-level grid {-pi, -pi/3, pi/3, pi} every x2 step changes 7 sin^2 x2 by 7 x 3/4 over a
    jump of 2/3 of the range: mu*(x2) = 7.875 exactly. Every x1 step is positive (mu = mu*); x3 acts
    only through its interaction with x1 (mu* > 0, effects of both signs); the dummy x4 does nothing."""
    keys = {**ISHIGAMI, "x4": (0.0, 1.0)}
    for seed in (0, 1, 2):
        res = analyse_model(
            ishigami,
            keys,
            ["y"],
            out=tmp_path / f"m{seed}",
            method="morris",
            samples=30,
            seed=seed,
            workers=1,
            batch=10,
            progress=False,
        )
        ix = {k: res.index("y", "mu_star", k) for k in keys}
        assert ix["x2"] == pytest.approx(7.875, rel=1e-12)
        assert res.index("y", "mu", "x1") == pytest.approx(ix["x1"], rel=1e-12)
        assert ix["x1"] > ix["x3"] > 0 and abs(res.index("y", "mu", "x3")) < ix["x3"]
        assert ix["x4"] == 0 and res.index("y", "sigma", "x4") == 0


def test_process_pool_gives_the_serial_indices(tmp_path):
    kw = {"method": "morris", "samples": 10, "seed": 3, "batch": 8, "progress": False}
    serial = analyse_model(ishigami, ISHIGAMI, ["y"], out=tmp_path / "serial", workers=1, **kw)
    pool = analyse_model(ishigami, ISHIGAMI, ["y"], out=tmp_path / "pool", workers=2, **kw)
    for name in ("mu_star", "sigma", "mu"):
        np.testing.assert_array_equal(serial.indices["y"][name], pool.indices["y"][name])


@pytest.mark.slow
def test_a_dask_cluster_gives_the_serial_indices(tmp_path):
    from dask.distributed import LocalCluster

    kw = {"method": "morris", "samples": 10, "seed": 3, "batch": 8, "progress": False}
    serial = analyse_model(ishigami, ISHIGAMI, ["y"], out=tmp_path / "serial", workers=1, **kw)
    with LocalCluster(
        n_workers=2, processes=True, threads_per_worker=1, host="127.0.0.1", dashboard_address=":0"
    ) as cluster:
        res = analyse_model(
            ishigami, ISHIGAMI, ["y"], out=tmp_path / "dask", scheduler=cluster.scheduler_address, **kw
        )
    assert res.ran == 40
    np.testing.assert_array_equal(serial.indices["y"]["mu_star"], res.indices["y"]["mu_star"])


def test_without_salib_the_error_says_what_to_install(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "SALib", None)
    with pytest.raises(ImportError, match=r"pip install gearbody\[calibrate\]"):
        analyse_model(ishigami, ISHIGAMI, ["y"], out=tmp_path / "a", progress=False)
    argv = ["sensitivity", "one-stage", "--key", "design.mesh.damping_Ns_per_m=1:2", "--feature", "kd_max"]
    assert main([*argv, "--out", str(tmp_path / "b")]) == 2
    assert "pip install gearbody[calibrate]" in capsys.readouterr().err
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()


# --- resume, a different spec, failed rows -------------------------------------------------------------
STOP_AFTER = math.inf  # counting() is interrupted after this many evaluations (serial: same process)


def counting(values, log):
    """Ishigami, each evaluation appended to ``log``; a Ctrl-C after STOP_AFTER evaluations."""
    with open(log, "a+") as f:
        f.seek(0)
        if len(f.readlines()) >= STOP_AFTER:
            raise KeyboardInterrupt
        f.write(json.dumps(values) + "\n")
    return ishigami(values)


def test_resume_evaluates_every_row_once(tmp_path, monkeypatch):
    log = tmp_path / "log.jsonl"
    kw = {
        "method": "morris",
        "samples": 10,
        "seed": 2,
        "workers": 1,
        "model_args": (str(log),),
        "progress": False,
    }
    monkeypatch.setattr(sys_module(), "STOP_AFTER", 20)
    with pytest.raises(KeyboardInterrupt):
        analyse_model(counting, ISHIGAMI, ["y"], out=tmp_path / "a", **kw)
    assert len(list((tmp_path / "a" / "evaluations").glob("*.json"))) == 20
    assert not (tmp_path / "a" / "indices.csv").exists()
    monkeypatch.setattr(sys_module(), "STOP_AFTER", math.inf)
    res = analyse_model(counting, ISHIGAMI, ["y"], out=tmp_path / "a", **kw)
    assert (res.ran, res.skipped, res.rows) == (20, 20, 40)
    sample = json.loads((tmp_path / "a" / "sensitivity.json").read_text())["sample"]
    seen = [tuple(json.loads(line).values()) for line in log.read_text().splitlines()]
    assert sorted(seen) == sorted(tuple(row) for row in sample)  # every row once
    again = analyse_model(counting, ISHIGAMI, ["y"], out=tmp_path / "a", **kw)
    assert again.ran == 0 and len(log.read_text().splitlines()) == 40
    fresh = analyse_model(ishigami, ISHIGAMI, ["y"], out=tmp_path / "b", **{**kw, "model_args": ()})
    np.testing.assert_array_equal(res.indices["y"]["mu_star"], fresh.indices["y"]["mu_star"])


def test_a_different_spec_in_the_same_out_is_refused(tmp_path):
    kw = {"method": "morris", "seed": 0, "workers": 1, "progress": False}
    analyse_model(ishigami, ISHIGAMI, ["y"], out=tmp_path, samples=4, **kw)
    with pytest.raises(SweepSpecError, match=r"different sensitivity analysis \(samples: 4 there, 5 now\)"):
        analyse_model(ishigami, ISHIGAMI, ["y"], out=tmp_path, samples=5, **kw)
    with pytest.raises(SweepSpecError, match=r"bounds: .* there"):
        analyse_model(ishigami, {**ISHIGAMI, "x3": (0, 1)}, ["y"], out=tmp_path, samples=4, **kw)
    (tmp_path / "sensitivity.json").write_text("{}")
    with pytest.raises(SweepSpecError, match="not a gearbody sensitivity file"):
        analyse_model(ishigami, ISHIGAMI, ["y"], out=tmp_path, samples=4, **kw)


BROKEN = True


def fragile(values):
    """Ishigami, failing where x1 > 2 while BROKEN."""
    if BROKEN and values["x1"] > 2.0:
        raise ValueError(f"x1 = {values['x1']:.3f} is out of the model's reach")
    return ishigami(values)


def test_failed_rows_are_recorded_and_refused_then_retried(tmp_path, monkeypatch):
    kw = {"method": "sobol", "samples": 16, "seed": 0, "workers": 1, "progress": False}
    with pytest.raises(
        MissingRowsError, match=r"rows failed or missing \(rows \d+.*ValueError: x1 = "
    ) as err:
        analyse_model(fragile, ISHIGAMI, ["y"], out=tmp_path, **kw)
    assert err.value.exit_code == 1 and "exclude" not in str(err.value)  # Sobol: no exclusion offered
    sample = np.array(json.loads((tmp_path / "sensitivity.json").read_text())["sample"])
    bad = np.flatnonzero(sample[:, 0] > 2.0)
    entry = json.loads((tmp_path / "evaluations" / f"row-{bad[0]:06d}.json").read_text())["rows"][0]
    assert not entry["ok"] and entry["error_type"] == "ValueError" and "Traceback" in entry["traceback"]
    with pytest.raises(SweepSpecError, match="Morris only"):
        analyse_model(fragile, ISHIGAMI, ["y"], out=tmp_path, exclude_failed=True, **kw)
    monkeypatch.setattr(sys_module(), "BROKEN", False)
    res = analyse_model(fragile, ISHIGAMI, ["y"], out=tmp_path, retry_failed=True, **kw)
    assert res.ran == len(bad) and res.skipped == res.rows - len(bad)


def test_morris_can_exclude_the_trajectories_with_failed_rows(tmp_path):
    kw = {"method": "morris", "samples": 12, "seed": 0, "workers": 1, "progress": False}
    with pytest.raises(MissingRowsError, match="--exclude-failed"):
        analyse_model(fragile, ISHIGAMI, ["y"], out=tmp_path, **kw)
    res = analyse_model(fragile, ISHIGAMI, ["y"], out=tmp_path, exclude_failed=True, **kw)
    sample = np.array(json.loads((tmp_path / "sensitivity.json").read_text())["sample"])
    bad_traj = set(np.flatnonzero(sample[:, 0] > 2.0) // 4)
    assert 0 < len(bad_traj) < 11 and set(res.excluded_rows) == {r for r in range(48) if r // 4 in bad_traj}
    assert np.all(np.isfinite(res.indices["y"]["mu_star"])) and "excluded" in res.table()


def test_a_job_whose_worker_died_records_its_rows_failed(tmp_path, monkeypatch):
    def dying(task, jobs, **kw):
        for jid, _ in jobs:
            yield jid, failure(RuntimeError("worker lost"))

    monkeypatch.setattr(sens, "run_jobs", dying)
    with pytest.raises(MissingRowsError, match="RuntimeError: worker lost"):
        analyse_model(ishigami, ISHIGAMI, ["y"], out=tmp_path, samples=2, batch=3, workers=1, progress=False)
    entries = [
        e for p in (tmp_path / "evaluations").glob("*.json") for e in json.loads(p.read_text())["rows"]
    ]
    assert sorted(e["row"] for e in entries) == list(range(8)) and not any(e["ok"] for e in entries)


# --- input errors, before anything runs ---------------------------------------------------------------
@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"keys": ["x1"]}, "expected KEY=low:high"),
        ({"keys": ["x1=1:1"]}, "needs finite low < high"),
        ({"keys": ["x1=a:2"]}, "two numbers"),
        ({"keys": ["x1=0:1:5"]}, "two numbers"),
        ({"keys": {"x1": (0, 1, 2)}}, r"as \(low, high\)"),
        ({"keys": {"x1": "0:1"}}, r"as \(low, high\)"),
        ({"keys": []}, "at least one --key"),
        ({"method": "fast"}, "valid are morris, sobol"),
        ({"method": "sobol", "samples": 100}, "power of 2"),
        ({"samples": 1}, "--samples"),
        ({"levels": 5}, "--levels must be even"),
        ({"max_runs": 10}, "32 runs, above the limit of 10; lower --samples or give --force"),
        ({"workers": 0}, "--workers"),
    ],
)
def test_bad_input_is_refused_before_anything_runs(tmp_path, kw, message):
    args = {"keys": ISHIGAMI, "samples": 8, **kw}
    with pytest.raises(SweepSpecError, match=message):
        analyse_model(ishigami, args.pop("keys"), ["y"], out=tmp_path / "out", progress=False, **args)
    assert not (tmp_path / "out").exists()


def test_force_lifts_the_run_limit(tmp_path):
    keys = {k: np.array(b) for k, b in ISHIGAMI.items()}  # ranges as arrays are fine too
    res = analyse_model(
        ishigami, keys, ["y"], out=tmp_path, samples=8, max_runs=10, force=True, workers=1, progress=False
    )
    assert res.rows == 32


def test_cli_help_states_the_run_limit(capsys):
    with pytest.raises(SystemExit):
        main(["sensitivity", "--help"])
    assert f"At most {sens.MAX_RUNS} runs" in " ".join(capsys.readouterr().out.split())


def test_parse_key_range():
    assert parse_key_range("design.mesh.damping_Ns_per_m=3e3:1.2e4") == (
        "design.mesh.damping_Ns_per_m",
        3000.0,
        12000.0,
    )
    with pytest.raises(SweepSpecError, match="not a dotted scenario key"):
        parse_key_range("design..mesh=1:2")


ONE_STAGE = [*(f"--set={o}" for o in STEADY_OVERRIDES), "--t-end", "0.03", "--workers", "1", "--quiet"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            ["--key", "design.mesh.no_such_key=1:2", "--feature", "kd_max"],
            "--key design.mesh.no_such_key=1.0:2.0",
        ),
        (
            ["--key", "design.mesh.damping_Ns_per_m=-5000:1000", "--feature", "kd_max"],
            "damping_Ns_per_m = -5000.0",
        ),
        (["--key", "design.mesh.damping_Ns_per_m=1:2", "--feature", "kd_maximum"], "--feature kd_maximum"),
        (["--key", "design.mesh.damping_Ns_per_m=1:2", "--feature", "kd_max:signal=x"], "option 'signal=x'"),
        (["--key", "design.mesh.damping_Ns_per_m=1:2"], "give one or more --feature"),
        (
            ["--key", "design.mesh.damping_Ns_per_m=1:2", "--feature", "rms:signal=wheel_accel_m_s2"],
            "records no signal 'wheel_accel_m_s2'; it records ",
        ),
        (
            ["--key", "design.mesh.damping_Ns_per_m=1:2", "--feature", "kd_max:stage=2"],
            "records no signal 'stage_2_kd'",
        ),
        (["--key", "design.mesh.damping_Ns_per_m=2:1", "--feature", "kd_max"], "low < high"),
        (
            ["--key", "design.mesh.damping_Ns_per_m=1:2", "--feature", "kd_max", "--samples", "1001"],
            "2002 runs, above the limit of 2000",
        ),
        (
            [
                "--key",
                "design.mesh.damping_Ns_per_m=1:2",
                "--feature",
                "kd_max",
                "--set",
                "design.mesh.damping_Ns_per_m=5",
            ],
            "also a --key",
        ),
    ],
)
def test_cli_bad_input_exits_2_before_anything_runs(tmp_path, capsys, args, message):
    out = tmp_path / "out"
    assert main(["sensitivity", "one-stage", *args, *ONE_STAGE, "--out", str(out)]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


# --- on gearbody ----------------------------------------------------------------------------------------
STIFFNESS, PINION_MASS = "design.mesh.stiffness_single_N_per_m", "design.pinion.mass_kg"
LINE = "line_amplitude:signal=pinion_accel_rad_s2,mesh=1"


def test_a_key_that_cannot_affect_the_features_gets_zero_on_gearbody(tmp_path, capsys):
    """one-stage is torsional: its gears have no lateral freedom (lateral = "none"), so the pinion's
    mass enters no equation (only its inertia does) and cannot move K_d or the mesh line: its Morris
    indices are exactly 0. The mesh stiffness (1.0e9..1.25e9 N/m) moves both, far above their
    confidence half-widths. 12 steady runs of 0.03 s."""
    assert load_scenario("one-stage").stages[0].pinion.lateral == "none"
    out = tmp_path / "sens"
    argv = [
        "sensitivity",
        "one-stage",
        "--key",
        f"{STIFFNESS}=1.0e9:1.25e9",
        "--key",
        f"{PINION_MASS}=5:20",
        "--feature",
        "kd_max",
        "--feature",
        LINE,
        "--samples",
        "4",
        "--seed",
        "1",
        *ONE_STAGE,
        "--out",
        str(out),
    ]
    assert main(argv) == 0
    rows = {(r["feature"], r["key"]): r for r in _csv(out / "indices.csv")}
    for feature, large in (("kd_max", 0.05), (LINE, 50.0)):
        mass, stiff = rows[(feature, PINION_MASS)], rows[(feature, STIFFNESS)]
        assert float(mass["mu_star"]) == 0.0 and float(mass["sigma"]) == 0.0
        assert float(stiff["mu_star"]) > large and float(stiff["mu_star"]) > 5 * float(stiff["mu_star_conf"])
    assert _png_size(out / "indices.png")[0] == 1000
    capsys.readouterr()
    assert main([a for a in argv if a != "--quiet"]) == 0  # a rerun resumes: nothing left to run
    captured = capsys.readouterr()
    assert (
        "12 of 12 rows already recorded" in captured.err and "(0 runs now, 12 recorded before" in captured.out
    )


def test_cli_runs_that_fail_exit_1_recorded_with_their_cause(tmp_path, capsys):
    """The final quarter of a 0.03 s run holds 0.18 pinion revolutions: a synchronous average over 2 or more
    fails in every run (4 runs), found only once the speed is known."""
    out = tmp_path / "failing"
    feature = "fm4:signal=pinion_accel_rad_s2"
    argv = ["sensitivity", "one-stage", "--key", f"{STIFFNESS}=1.0e9:1.25e9", "--feature", feature]
    assert main([*argv, "--samples", "2", *ONE_STAGE, "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert (
        f"4 of 4 rows failed or missing (rows 0, 1, 2, 3; row 0: FeatureError: feature {feature}: the window "
        "holds less than 2 revolutions of the pinion"
    ) in err
    assert "--exclude-failed" in err and not (out / "indices.csv").exists()
    entries = [json.loads(p.read_text())["rows"][0] for p in sorted((out / "evaluations").glob("*.json"))]
    assert [e["error_type"] for e in entries] == ["FeatureError"] * 4


def test_mesh_damping_cannot_move_an_undamped_natural_frequency(tmp_path):
    """Natural frequencies are those of the undamped linearisation: the mesh damping has Sobol indices
    exactly 0 on the mesh mode (elastic mode 3, the pinion's); the mesh stiffness carries all of its
    variance (S1 = ST = 1 within sampling error). Modes only, no simulation: 64 x 4 eigen-analyses."""
    damping, f = "design.mesh.damping_Ns_per_m", "natural_frequency_hz:mode=3"
    res = sens.sensitivity(
        "one-stage",
        {STIFFNESS: (1.0e9, 1.25e9), damping: (3000, 12000)},
        [f],
        out=tmp_path,
        method="sobol",
        samples=64,
        seed=0,
        second_order=False,
        workers=1,
        progress=False,
    )
    assert res.index(f, "S1", damping) == 0 and res.index(f, "ST", damping) == 0
    for name in ("S1", "ST"):
        value, conf = res.index(f, name, STIFFNESS), res.index(f, f"{name}_conf", STIFFNESS)
        assert conf < 0.5 and abs(value - 1.0) <= 2 * conf, (name, value, conf)


# --- helpers --------------------------------------------------------------------------------------------
def sys_module():
    return sys.modules[__name__]


def _csv(path):
    import csv

    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def _png_size(path):
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", head[16:24])


DAMPING_ON_KD = [
    "sensitivity",
    "one-stage",
    "--key",
    "design.mesh.damping_Ns_per_m=3000:12000",
    "--feature",
    "kd_max",
]


@pytest.mark.parametrize(
    "option, message",
    [
        (["--samples", "-1"], "--samples = -1: must be a whole number >= 2"),
        (["--t-end", "-1"], "--t-end = -1: must be a finite number > 0"),
        (["--t-end", "nan"], "--t-end = nan: must be a finite number > 0"),
        (["--workers", "0"], "--workers = 0: must be a whole number >= 1"),
        (["--seed", "-3"], "--seed = -3: must be a whole number >= 0"),
    ],
)
def test_numeric_options_are_refused_as_typed(tmp_path, capsys, option, message):
    from gearbody.cli import main

    assert main([*DAMPING_ON_KD, *option, "--out", str(tmp_path / "s"), "--quiet"]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "s").exists()


def test_an_out_that_is_a_file_is_refused_before_anything_runs(tmp_path, capsys):
    from gearbody.cli import main

    (tmp_path / "f").write_text("x")
    assert main([*DAMPING_ON_KD, "--out", str(tmp_path / "f"), "--quiet"]) == 2
    assert "is a file, not a folder" in capsys.readouterr().err
