"""Time is told before it is spent: a run's or a study's wall time is estimated before anything runs
(gearbody.assembly.wall_time), printed above a minute, and refused above --max-wall-minutes (default
30), which lifts it. Nothing here measures time: the estimate's step attempts are compared with the
solver's counted ones (deterministic); its wall time against measurement is the benchmark's
(benchmarks/bench_wall_estimate.py, benchmarks/RESULTS.md)."""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

import pytest

from gearbody.assembly import wall_time
from gearbody.cli import common, main
from gearbody.engine import simulate
from gearbody.model import list_scenes, load_scenario
from gearbody.studies import SweepSpecError, run_study
from gearbody.studies.wall import check_study_wall_time

ROOT = Path(__file__).resolve().parents[1]
E_UM = "production.error_mode.e_um"


def _gearbody(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    """A command in its own interpreter, bounded: the code before the estimate would start the run."""
    return subprocess.run(
        [sys.executable, "-m", "gearbody.cli", *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )


# --- the estimate ---------------------------------------------------------------------------------


def test_the_speed_profile_is_averaged_over_the_run():
    sc = load_scenario("one-stage")  # 0 -> 1 over 0.5 s, then held; 2 s
    assert wall_time.mean_speed_fraction(sc) == pytest.approx((0.5 * 0.5 + 1.5) / 2.0)
    short = load_scenario("one-stage", ["operation.t_end_s=0.25"])
    assert wall_time.mean_speed_fraction(short) == pytest.approx(0.25)


def test_the_estimate_grows_with_what_costs_steps(steady_overrides):
    base = load_scenario("one-stage", [*steady_overrides, "operation.t_end_s=1.0"])
    est = wall_time.estimate_wall_time(base)
    longer = wall_time.estimate_wall_time(
        load_scenario("one-stage", [*steady_overrides, "operation.t_end_s=4.0"])
    )
    assert longer.attempts == pytest.approx(4 * est.attempts)
    faster = load_scenario(
        "one-stage", ["operation.t_end_s=1.0", "operation.speed_profile={time_s=[0.0],fraction=[2.0]}"]
    )
    more = wall_time.estimate_wall_time(faster).attempts - est.attempts  # twice the mesh jumps
    f_mesh = base.stages[0].mesh_frequency_hz(base.design.motor.synchronous_speed_rad_s)
    assert more == pytest.approx(wall_time.ATTEMPTS_PER_MESH_PERIOD * f_mesh)
    tight, draft = (
        wall_time.estimate_wall_time(
            load_scenario("one-stage", ["operation.t_end_s=1.0", f'solver.accuracy="{a}"'])
        )
        for a in ("tight", "draft")
    )
    assert draft.wall_s < est.wall_s < tight.wall_s
    fine = load_scenario("one-stage", ["operation.t_end_s=0.01", "solver.max_step_s=1e-7"])
    assert wall_time.estimate_wall_time(fine).attempts == pytest.approx(1e5)  # max_step_s bounds the steps
    fixed = load_scenario("one-stage", ["operation.t_end_s=1.0", 'solver.method="RK44"'])
    assert wall_time.estimate_wall_time(fixed).attempts == pytest.approx(1e4)  # fixed steps of max_step_s
    planetary = wall_time.estimate_wall_time(load_scenario("planetary", ["operation.t_end_s=1.0"]))
    assert planetary.wall_s > 10 * est.wall_s  # 20 coordinates, 6 meshes, an 11 kHz sun


def _attempts_ratio(scene: str, t_end: float) -> float:
    sc = load_scenario(
        scene,
        [
            'operation.initial_state="steady"',
            "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
            "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
            f"operation.t_end_s={t_end}",
        ],
    )
    stats = simulate(sc).meta["solver_statistics"]
    return wall_time.estimate_wall_time(sc).attempts / (stats["steps"] + stats["rejected_steps"])


@pytest.mark.parametrize("scene", ["one-stage", "two-wheel"])
def test_estimated_step_attempts_match_the_solvers_within_2x(scene):
    assert 0.5 <= _attempts_ratio(scene, 0.05) <= 2.0


@pytest.mark.slow
@pytest.mark.parametrize("scene", list_scenes())
def test_estimated_step_attempts_match_the_solvers_within_2x_on_every_scene(scene):
    """The machine-independent half of the estimate (the other half, the cost of an attempt, is the
    benchmark's): every shipped scene in steady rated running."""
    assert 0.5 <= _attempts_ratio(scene, 0.02 if scene == "planetary" else 0.05) <= 2.0


def test_a_pool_takes_its_queue_in_order():
    assert wall_time.makespan_s([10, 10, 10, 10], 2) == 20
    assert wall_time.makespan_s([30, 10, 10, 10], 2) == 30
    assert wall_time.makespan_s([5, 5], 8) == 5
    assert wall_time.makespan_s([], 2) == 0


def test_durations_read_as_people_say_them():
    assert [wall_time.duration_text(s) for s in (42, 600, 4 * 3600, 3 * 86400)] == [
        "~42 s",
        "~10 min",
        "~4 h",
        "~3 days",
    ]


# --- a run: told above a minute, refused above the limit --------------------------------------------


def _args(limit: float = common.DEFAULT_MAX_WALL_MINUTES, quiet: bool = False) -> argparse.Namespace:
    return argparse.Namespace(max_wall_minutes=limit, quiet=quiet)


def test_a_run_above_a_minute_is_announced_and_a_shorter_one_is_not(capsys):
    long = load_scenario("planetary", ["operation.t_end_s=5.0"])
    est = wall_time.estimate_wall_time(long)
    assert 60 < est.wall_s < common.DEFAULT_MAX_WALL_MINUTES * 60
    common.check_wall_time(long, _args())
    err = capsys.readouterr().err
    assert err == (
        f"estimated wall time {wall_time.duration_text(est.wall_s)} (5 s simulated at "
        f"{wall_time.duration_text(est.wall_per_simulated_s)} per simulated second)\n"
    )
    common.check_wall_time(long, _args(quiet=True))
    assert capsys.readouterr().err == ""
    common.check_wall_time(load_scenario("one-stage", ["operation.t_end_s=0.5"]), _args())
    assert capsys.readouterr().err == ""


def test_long_planetary_runs_are_refused_before_anything_runs_and_the_option_lifts_the_limit(tmp_path):
    """The finding: 17 s of the planetary scene (~20 min) ran unannounced, and 60 s (~70 min) with the
    memory budget raised; now the run is refused in one line naming the option that lifts it."""
    out = tmp_path / "run"
    done = _gearbody(
        "run", "planetary", "--t-end", "60", "--set", "solver.memory_limit_MiB=100000", "--out", str(out)
    )
    assert done.returncode == 2, done.stderr
    line = done.stderr.strip()
    assert "\n" not in line and "Traceback" not in line
    assert line.startswith("gearbody: invalid input: the run is estimated to take ~")
    assert "above the limit of --max-wall-minutes 30; give --max-wall-minutes " in line
    assert "shorten operation.t_end_s (--t-end) (60 s simulated at " in line
    assert not out.exists()
    est = wall_time.estimate_wall_time(
        load_scenario("planetary", ["operation.t_end_s=60", "solver.memory_limit_MiB=100000"])
    )
    assert f"give --max-wall-minutes {int(-(-est.wall_s // 60))} to run it anyway" in line


def test_the_limit_is_an_option(tmp_path, capsys):
    out = tmp_path / "run"
    base = ["run", "two-wheel", "--t-end", "0.01", "--no-plots", "--quiet", "--out", str(out)]
    assert main([*base, "--max-wall-minutes", "1e-6"]) == 2
    err = capsys.readouterr().err
    assert "above the limit of --max-wall-minutes 1e-06; give --max-wall-minutes 1 to run it anyway" in err
    assert not out.exists()
    assert main(base) == 0 and (out / "result.npz").exists()  # the default limit: far above
    assert main(["run", "two-wheel", "--max-wall-minutes", "0"]) == 2
    assert "--max-wall-minutes = 0: must be a finite number > 0" in capsys.readouterr().err


def test_render_judges_what_it_would_simulate(tmp_path, capsys):
    out = tmp_path / "frames"
    code = main(
        ["render", "planetary", "--t-end", "5", "--max-wall-minutes", "1", "--frames", "2", "--out", str(out)]
    )
    assert code == 2
    assert "the run is estimated to take ~" in capsys.readouterr().err and not (out / "result.npz").exists()


def test_simulate_in_python_does_not_refuse():
    """The limit is the command line's: a script that simulates asked for it (solver.wall_time_limit_s
    bounds a run from inside)."""
    assert "max_wall" not in simulate.__code__.co_varnames


# --- studies: every pending run, over the workers -----------------------------------------------------


def test_a_study_is_its_runs_over_the_workers(capsys):
    wall = check_study_wall_time(
        [100.0] * 10, workers=2, scheduler=None, max_wall_minutes=None, progress=True, what="x", remedy="y"
    )
    assert wall == 500.0
    assert (
        capsys.readouterr().err == "estimated wall time ~8.3 min (10 simulations of ~1.7 min on 2 workers)\n"
    )
    with pytest.raises(SweepSpecError) as info:
        check_study_wall_time(
            [100.0] * 10,
            workers=1,
            scheduler=None,
            max_wall_minutes=10,
            progress=True,
            what="the study",
            remedy="run fewer cases",
        )
    assert str(info.value) == (
        "the study is estimated to take ~17 min of wall time, above the limit of --max-wall-minutes 10; give "
        "--max-wall-minutes 17 to run it anyway, or run fewer cases (10 simulations of ~1.7 min on 1 worker)"
    )
    wall = check_study_wall_time(
        [100.0, 700.0],
        workers=None,
        scheduler="tcp://x:1",
        max_wall_minutes=None,
        progress=True,
        what="x",
        remedy="y",
    )
    assert wall == 700.0  # a cluster of unknown size: its longest run
    assert capsys.readouterr().err == (
        "estimated wall time at least ~12 min (2 simulations of ~1.7 min to ~12 min, ~13 min of CPU time "
        "over the Dask cluster's workers; the longest simulation bounds the wall time from below)\n"
    )
    with pytest.raises(SweepSpecError, match=r"^x is estimated to take at least ~12 min of wall time, above"):
        check_study_wall_time(
            [100.0, 700.0],
            workers=None,
            scheduler="tcp://x:1",
            max_wall_minutes=10,
            progress=False,
            what="x",
            remedy="y",
        )
    assert (
        check_study_wall_time(
            [], workers=2, scheduler=None, max_wall_minutes=1, progress=True, what="x", remedy="y"
        )
        == 0.0
    )


def test_a_sweep_beyond_the_limit_is_refused_before_anything_is_written_and_a_resume_counts_what_is_left(
    tmp_path, capsys
):
    out = tmp_path / "study"
    base = ["sweep", "two-wheel", "--vary", f"{E_UM}=1,2", "--t-end", "0.01", "--workers", "1", "--quiet"]
    assert main([*base, "--max-wall-minutes", "1e-6", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("gearbody sweep: the study (2 of 2 cases to run) is estimated to take ~")
    assert "give --max-wall-minutes 1 to run it anyway" in err and not out.exists()
    assert main([*base, "--out", str(out)]) == 0
    capsys.readouterr()
    assert main([*base, "--max-wall-minutes", "1e-6", "--out", str(out)]) == 0  # nothing left to run


def test_python_studies_have_no_limit_unless_asked(tmp_path):
    kw = dict(vary=[f"{E_UM}=1,2"], base_overrides=["operation.t_end_s=0.01"], workers=1, progress=False)
    with pytest.raises(SweepSpecError, match=r"--max-wall-minutes 1e-06"):
        run_study("two-wheel", out_dir=tmp_path / "a", max_wall_minutes=1e-6, **kw)
    assert not (tmp_path / "a").exists()
    assert run_study("two-wheel", out_dir=tmp_path / "b", **kw).all_ok


def test_sensitivity_and_calibrate_beyond_the_limit_are_refused_before_anything_is_written(tmp_path, capsys):
    out = tmp_path / "sens"
    code = main(
        [
            "sensitivity",
            "two-wheel",
            "--key",
            f"{E_UM}=5:15",
            "--feature",
            "kd_max",
            "--samples",
            "2",
            "--t-end",
            "0.01",
            "--workers",
            "1",
            "--quiet",
            "--max-wall-minutes",
            "1e-6",
            "--out",
            str(out),
        ]
    )
    assert code == 2
    err = capsys.readouterr().err
    assert err.startswith("gearbody sensitivity: the analysis (4 of 4 runs to do) is estimated to take ~")
    assert "--max-wall-minutes" in err and not out.exists()
    out = tmp_path / "cal"
    code = main(
        [
            "calibrate",
            "two-wheel",
            "--param",
            f"{E_UM}=5:15",
            "--target",
            "kd_max",
            "1.5",
            "0.1",
            "--budget",
            "4",
            "--polish-evaluations",
            "0",
            "--t-end",
            "0.01",
            "--workers",
            "1",
            "--quiet",
            "--max-wall-minutes",
            "1e-6",
            "--out",
            str(out),
        ]
    )
    assert code == 2
    err = capsys.readouterr().err
    assert err.startswith("gearbody calibrate: the calibration (up to 7 of 7 evaluations to do) is estimated")
    assert "--max-wall-minutes" in err and not out.exists()
