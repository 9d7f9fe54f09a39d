"""Parameter studies: spec parsing, files written per case, resume, failures, and serial = process
pool = Dask results bit for bit."""

import csv
import json
import shutil
import sys

import numpy as np
import pytest

from gearbody.cli import main
from gearbody.model import ScenarioError, load_scenario
from gearbody.studies import (
    Study,
    SweepSpecError,
    executors,
    parse_random,
    parse_vary,
    run_study,
    runner,
    store,
)

SCENE = "two-wheel"  # steady start in its scene file; 0.02 s simulate in ~0.1 s
T_END = ["operation.t_end_s=0.02"]
E_UM = "production.error_mode.e_um"
_real_run_case = runner.run_case
OVERLOAD = "operation.load_profile={time_s=[0.0],fraction=[1.0]},{time_s=[0.0],fraction=[5.0]}"


def _run(out, **kw):
    kw.setdefault("workers", 1)
    return run_study(SCENE, out_dir=out, vary=[f"{E_UM}=5,15"], base_overrides=T_END, progress=False, **kw)


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    out = tmp_path_factory.mktemp("serial")
    return out, _run(out)


def _force(out, case_id):
    with np.load(out / "cases" / case_id / "result.npz") as z:
        return z["mesh_force_N"]


# --- spec -----------------------------------------------------------------------------------------


def test_ranges_are_inclusive_linspace_and_lists_are_toml_literals():
    a = parse_vary(f"{E_UM}=0:20:5")
    assert a.key == E_UM and a.texts == ("0", "5", "10", "15", "20") and a.values == (0, 5, 10, 15, 20)
    assert parse_vary("x=0.1:0.3:3").values == (0.1, 0.2, 0.3)  # not 0.30000000000000004
    assert parse_vary("x=0:1:3").texts == ("0.0", "0.5", "1.0")
    assert parse_vary("x=-1e9:1e9:3").values == (-1e9, 0.0, 1e9)
    lst = parse_vary('x="a,b", "c" ,true,[1,2],{t=[0.0],f=[1.0]}')
    assert lst.texts == ('"a,b"', '"c"', "true", "[1,2]", "{t=[0.0],f=[1.0]}")
    assert lst.values == ("a,b", "c", True, [1, 2], {"t": [0.0], "f": [1.0]})
    api = Study.build(SCENE, vary={E_UM: [5, 7.5], "operation.initial_state": ["rest", "steady"]})
    assert [a.texts for a in api.vary] == [("5", "7.5"), ('"rest"', '"steady"')]


def test_cases_are_grid_times_samples_times_seeds_with_stable_ids():
    study = Study.build(
        SCENE,
        vary=[f"{E_UM}=5,15", "production.error_mode.a=0.2:0.4:2"],
        random=["production.error_mode.r=uniform(0.1,0.5)"],
        samples=3,
        seeds=2,
        base_overrides=T_END,
    )
    cases = study.cases()
    assert len(cases) == 2 * 2 * 3 * 2 and cases[0].id == "case-0000" and cases[-1].id == "case-0023"
    assert study.keys == [E_UM, "production.error_mode.a", "production.error_mode.r", "meta.seed"]
    c = cases[7]  # e=5, a=0.4, sample 0, seed 2
    assert c.values[E_UM] == 5 and c.values["production.error_mode.a"] == 0.4 and c.values["meta.seed"] == 2
    assert c.overrides[:2] == ("operation.t_end_s=0.02", f"{E_UM}=5") and c.overrides[-1] == "meta.seed=2"
    assert [x.overrides for x in study.cases()] == [x.overrides for x in cases]


def test_random_draws_are_reproducible_from_the_study_seed():
    def draws(seed, random):
        return [c.values for c in Study.build(SCENE, random=random, samples=50, study_seed=seed).cases()]

    random = {
        E_UM: "uniform(5,15)",
        "production.error_mode.r": "normal(0.3,0.05)",
        "meta.seed": "choice(1,2,3)",
    }
    a, b, c = draws(7, random), draws(7, random), draws(8, random)
    assert a == b and a != c
    e = np.array([v[E_UM] for v in a])
    assert e.min() >= 5 and e.max() < 15 and e.std() > 1
    assert {v["meta.seed"] for v in a} == {1, 2, 3}
    r = np.array([v["production.error_mode.r"] for v in a])
    assert abs(r.mean() - 0.3) < 0.03 and 0.02 < r.std() < 0.08
    # each key draws from its own stream: adding a key leaves the others' draws alone
    fewer = draws(7, {E_UM: "uniform(5,15)"})
    assert [v[E_UM] for v in fewer] == list(e)
    assert str(parse_random("k=normal(0, 2.5)").distribution) == "normal(0.0,2.5)"


@pytest.mark.parametrize(
    ("kw", "named"),
    [
        ({"vary": ["production.error_mode.e_um"]}, "--vary production.error_mode.e_um"),
        ({"vary": ["e=0:20"]}, "--vary e=0:20"),
        ({"vary": ["e=0:x:3"]}, "stop must be a number"),
        ({"vary": ["e=0:20:0"]}, "count must be a whole number >= 1"),
        ({"vary": ["e=1,,2"]}, "--vary e=1,,2"),
        ({"vary": ["e=1,1"]}, "repeated value"),
        ({"vary": ["bad key=1,2"]}, "not a dotted scenario key"),
        ({"vary": ["e=1,2", "e=3,4"]}, "already varied by --vary e=1,2"),
        ({"random": ["e=gauss(0,1)"], "samples": 3}, "--random e=gauss(0,1): unknown distribution"),
        ({"random": ["e=uniform(2,1)"], "samples": 3}, "needs a < b"),
        ({"random": ["e=normal(1)"], "samples": 3}, "normal takes two numbers"),
        ({"random": ["e=normal(0,-1)"], "samples": 3}, "sigma > 0"),
        ({"random": ["e=uniform(0,1)"]}, "--samples"),
        ({"vary": ["e=1,2"], "samples": 0}, "--samples"),
        ({"seeds": 0}, "--seeds"),
        ({"seeds": 2, "base_overrides": ["meta.seed=3"]}, "--set meta.seed=3"),
        ({}, "nothing to vary"),
    ],
)
def test_bad_spec_is_refused_naming_the_argument(kw, named):
    with pytest.raises(SweepSpecError) as info:
        Study.build(SCENE, **kw)
    assert named in str(info.value)


def test_a_bad_case_fails_before_anything_runs(tmp_path, monkeypatch):
    monkeypatch.setattr(runner, "run_case", lambda *a: pytest.fail("ran"))
    with pytest.raises(ScenarioError, match=r"--vary design.pinion.teeth=29,3: case-0001 .*teeth = 3"):
        run_study(SCENE, vary=["design.pinion.teeth=29,3"], out_dir=tmp_path / "s", progress=False)
    with pytest.raises(ScenarioError, match=r"--vary production.error_mode.e_uum=1,2: .*did you mean"):
        run_study(SCENE, vary=["production.error_mode.e_uum=1,2"], out_dir=tmp_path / "s", progress=False)
    assert not (tmp_path / "s").exists()


# --- files, resume, failures ------------------------------------------------------------------------


def test_a_grid_writes_every_case_the_csv_and_the_plot(serial):
    out, res = serial
    assert res.all_ok and res.ran == 2 and res.skipped == 0 and res.keys == [E_UM]
    for cid, e in (("case-0000", 5), ("case-0001", 15)):
        d = out / "cases" / cid
        assert sorted(p.name for p in d.iterdir()) == ["result.npz", "scenario.toml", "summary.json"]
        summary = json.loads((d / "summary.json").read_text())
        assert summary["status"] == "ok" and summary["overrides"] == [*T_END, f"{E_UM}={e}"]
        assert summary["kd_max"] > 1 and summary["wall_time_s"] > 0 and summary["simulated_time_s"] == 0.02
        assert load_scenario(d / "scenario.toml").stages[0].error_mode.e_um == e
    spec = json.loads((out / "study.json").read_text())
    assert spec["spec"]["vary"] == {E_UM: ["5", "15"]} and len(spec["cases"]) == 2
    with open(out / "summary.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["id"] for r in rows] == ["case-0000", "case-0001"] and [r[E_UM] for r in rows] == ["5", "15"]
    for col in ("status", "kd_max", "kd_max_final", "separation_fraction", "wall_time_s"):
        assert col in rows[0]
    assert float(rows[1]["kd_max_final"]) > float(rows[0]["kd_max_final"])  # larger error, larger K_d
    assert (out / f"kd_max_final_vs_{E_UM}.png").stat().st_size > 10_000
    assert "case-0001" in res.table() and "2 ok, 0 failed" in res.table()


def test_writes_are_atomic(tmp_path):
    target = tmp_path / "summary.json"
    store.write_json(target, {"a": 1})

    def broken(path):
        path.write_text('{"a": 2, "b"')
        raise OSError("disk full")

    with pytest.raises(OSError):
        store.atomic_write(target, broken)
    assert json.loads(target.read_text()) == {"a": 1} and [p.name for p in tmp_path.iterdir()] == [
        target.name
    ]


def test_rerun_resumes_only_unfinished_cases_and_refuses_another_spec(serial, tmp_path, monkeypatch):
    out = tmp_path / "study"
    shutil.copytree(serial[0], out)
    (out / "cases" / "case-0001" / "summary.json").unlink()
    kept = (out / "cases" / "case-0000" / "summary.json").stat().st_mtime_ns
    ran = []
    monkeypatch.setattr(
        runner, "run_case", lambda base, ov, keep: ran.append(ov) or _real_run_case(base, ov, keep)
    )
    res = _run(out)
    assert ran == [(*T_END, f"{E_UM}=15")] and res.ran == 1 and res.skipped == 1 and res.all_ok
    assert (out / "cases" / "case-0000" / "summary.json").stat().st_mtime_ns == kept
    assert np.array_equal(_force(out, "case-0001"), _force(serial[0], "case-0001"))
    ran.clear()
    assert _run(out).ran == 0 and ran == []
    with pytest.raises(SweepSpecError, match=r"holds a different study \(vary: "):
        run_study(SCENE, out_dir=out, vary=[f"{E_UM}=5,20"], base_overrides=T_END, progress=False)


def test_a_failing_case_is_recorded_and_the_study_goes_on(tmp_path, monkeypatch):
    out = tmp_path / "fail"
    res = run_study(
        SCENE,
        out_dir=out,
        vary=[OVERLOAD],
        base_overrides=T_END,
        workers=1,
        progress=False,
        save_results=False,
    )
    assert [r["status"] for r in res.rows] == ["ok", "failed"] and not res.all_ok
    error = json.loads((out / "cases" / "case-0001" / "error.json").read_text())
    assert error["error_type"] == "InputError" and "breakdown torque" in error["message"]
    assert error["overrides"][-1] == "operation.load_profile={time_s=[0.0],fraction=[5.0]}"
    assert not (out / "cases" / "case-0001" / "summary.json").exists()
    assert not (out / "cases" / "case-0000" / "result.npz").exists()  # save_results=False
    with open(out / "summary.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert rows[1]["status"] == "failed" and "breakdown torque" in rows[1]["error"]
    # resume skips the failed case unless asked to retry it; an exception in a worker is recorded too
    calls = []
    monkeypatch.setattr(runner, "run_case", lambda *a: calls.append(a) or _real_run_case(*a))
    kw = {"vary": [OVERLOAD], "base_overrides": T_END, "workers": 1, "progress": False, "save_results": False}
    assert run_study(SCENE, out_dir=out, **kw).ran == 0 and not calls
    monkeypatch.setattr(runner, "run_case", lambda *a: executors.failure(RuntimeError("boom")))
    again = run_study(SCENE, out_dir=out, retry_failed=True, **kw)
    assert again.ran == 1 and again.n_failed == 1
    assert json.loads((out / "cases" / "case-0001" / "error.json").read_text())["message"] == "boom"


# --- executors ------------------------------------------------------------------------------------


def test_a_process_pool_gives_the_serial_results_bit_for_bit(serial, tmp_path):
    out = tmp_path / "pool"
    res = _run(out, workers=2)
    assert res.all_ok and res.ran == 2
    for cid in ("case-0000", "case-0001"):
        assert np.array_equal(_force(out, cid), _force(serial[0], cid))


@pytest.mark.slow
def test_a_dask_cluster_gives_the_serial_results_bit_for_bit(serial, tmp_path):
    from dask.distributed import LocalCluster

    out = tmp_path / "dask"
    with LocalCluster(
        n_workers=2, processes=True, threads_per_worker=1, host="127.0.0.1", dashboard_address=":0"
    ) as cluster:
        res = run_study(
            SCENE,
            out_dir=out,
            vary=[f"{E_UM}=5,15"],
            base_overrides=T_END,
            scheduler=cluster.scheduler_address,
            progress=False,
        )
    assert res.all_ok and res.ran == 2
    for cid in ("case-0000", "case-0001"):
        assert np.array_equal(_force(out, cid), _force(serial[0], cid))


def test_without_dask_the_error_says_what_to_install(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "dask", None)
    with pytest.raises(ImportError, match=r"pip install gearbody\[sweep\]"):
        run_study(SCENE, out_dir=tmp_path, seeds=2, scheduler="tcp://127.0.0.1:8786", progress=False)


# --- command line ---------------------------------------------------------------------------------


def test_cli_exit_codes_and_table(tmp_path, capsys):
    out = tmp_path / "cli"
    base = ["sweep", SCENE, "--t-end", "0.02", "--workers", "1", "--quiet"]
    assert main([*base, "--seeds", "2", "--no-results", "--plot-value", "kd_max", "--out", str(out)]) == 0
    assert (out / "kd_max_vs_meta.seed.png").exists() and not (out / "cases/case-0000/result.npz").exists()
    assert main([*base[:-1], "--seeds", "2", "--out", str(out)]) == 0  # resumed: nothing to run
    assert "0 run now, 2 done before" in capsys.readouterr().out
    assert main([*base, "--vary", OVERLOAD, "--no-results", "--out", str(tmp_path / "f")]) == 1
    assert (tmp_path / "f" / "summary.csv").exists()
    capsys.readouterr()
    assert main([*base, "--vary", f"{E_UM}=0:20", "--out", str(tmp_path / "bad")]) == 2
    assert f"--vary {E_UM}=0:20" in capsys.readouterr().err
    assert main([*base, "--vary", "design.pinion.teeth=3,29", "--out", str(tmp_path / "bad")]) == 2
    assert "--vary design.pinion.teeth=3,29: case-0000" in capsys.readouterr().err
    assert main([*base, "--seeds", "2", "--plot-key", "x", "--out", str(tmp_path / "bad")]) == 2
    assert "--plot-key x" in capsys.readouterr().err
    assert not (tmp_path / "bad").exists()
