"""What the fuzzers of issue 26 found (tests/test_fuzz_cli.py), each refused in one line before anything
runs (exit 2) or handled: the command lines as the fuzzer drew them, minimised."""

from __future__ import annotations

import os

import pytest

from gearbody.cli import main

KEY = "condition.friction_coefficient"
STUDY = ["--t-end", "0.003", "--workers", "1", "--quiet"]


def _one_line(capsys, argv: list[str], code: int = 2) -> str:
    assert main(argv) == code
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in err[0], err
    return err[0]


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (  # on main: SALib's ValueError 'array is too big'
            ["sensitivity", "two-wheel", "--key", f"{KEY}=0:0.05", "--feature", "kd_max", "--samples", "2"]
            + ["--levels", str(2**63)],
            f"--levels must be even (a grid jump of levels/(2 (levels-1))) and <= 1000, got {2**63}",
        ),
        (  # on main: Sobol's ValueError 'Maximum allowed dimension exceeded', --force let it through
            ["sensitivity", "two-wheel", "--key", f"{KEY}=0:0.05", "--feature", "kd_max", "--method", "sobol"]
            + ["--samples", str(2**63), "--force"],
            "above the most any analysis may have (100000, --force included); lower --samples",
        ),
        (  # on main: numpy's ValueError 'Seed must be between 0 and 2**32 - 1'
            ["calibrate", "two-wheel", "--param", f"{KEY}=0:0.05", "--target", "kd_max", "1.5", "0.5"]
            + ["--budget", "2", "--seed", str(2**64)],
            f"--seed must be a whole number >= 0 and <= 4294967295, got {2**64}",
        ),
        (  # on main: MemoryError while listing 2**41 cases
            ["sweep", "two-wheel", "--seeds", str(2**40), "--max-cases", str(2**63)],
            f"--max-cases = {2**63}: at most 100000 (a study's cases are listed in memory before any runs)",
        ),
    ],
)
def test_counts_and_seeds_beyond_what_a_study_can_hold_are_refused(tmp_path, capsys, argv, expected):
    out = tmp_path / "study"
    line = _one_line(capsys, [*argv, *STUDY, "--out", str(out)])
    assert expected in line
    assert not out.exists()


def test_the_largest_seed_a_calibration_takes_runs(tmp_path, capsys):
    argv = ["calibrate", "two-wheel", "--param", f"{KEY}=0:0.05", "--target", "kd_max", "1.5", "0.5"]
    argv += ["--budget", "2", "--polish-evaluations", "0", "--seed", str(2**32 - 1), *STUDY]
    assert main([*argv, "--out", str(tmp_path / "cal")]) == 0


def test_a_symlink_loop_as_the_scene_is_refused_by_every_study(tmp_path, capsys):
    """On main sensitivity and calibrate raised RuntimeError('Symlink loop') from Path.resolve, and sweep
    called the loop 'no such scenario file'."""
    loop = tmp_path / "loop.toml"
    (tmp_path / "other.toml").symlink_to(loop)
    loop.symlink_to(tmp_path / "other.toml")
    for argv in (
        ["sweep", str(loop), "--vary", f"{KEY}=0,0.05"],
        ["sensitivity", str(loop), "--key", f"{KEY}=0:0.05", "--feature", "kd_max", "--samples", "2"],
        ["calibrate", str(loop), "--param", f"{KEY}=0:0.05", "--target", "kd_max", "1.5", "0.5"],
    ):
        line = _one_line(capsys, [*argv, *STUDY, "--out", str(tmp_path / "study")])
        assert f"{loop}: cannot read the scenario file: Too many levels of symbolic links" in line


def test_names_too_long_for_the_system_are_refused_as_input(tmp_path, capsys, monkeypatch):
    """On main 'File name too long' escaped as exit 1 ('failed', as for a full disk) from Path.exists."""
    monkeypatch.chdir(tmp_path)
    long = "y" * 300
    line = _one_line(capsys, ["run", "two-wheel", "--t-end", "0.003", "--no-plots", "--out", long])
    assert line.endswith(f"--out {long}: cannot be used: File name too long")
    line = _one_line(capsys, ["sweep", f"{long}.toml", "--vary", f"{KEY}=0,0.05", *STUDY, "--out", "s"])
    assert line.endswith(f"{long}.toml: cannot read the scenario file: File name too long")
    line = _one_line(capsys, ["run", long, "--t-end", "0.003", "--no-plots", "--out", "r"])
    assert line.endswith(f"{long}: cannot read the scenario file: File name too long")
    assert sorted(os.listdir(tmp_path)) == []


def test_a_scenario_file_whose_name_is_not_utf8_runs_and_writes_utf8(tmp_path, capsys, monkeypatch):
    """On main: UnicodeEncodeError writing scenario.toml (the scenario named after the file)."""
    from gearbody.model import load_scenario
    from gearbody.model.scenes import scene_path

    monkeypatch.chdir(tmp_path)
    name = os.fsdecode(b"drive-\xff.toml")  # as Python gives a file name that is not UTF-8
    (tmp_path / name).write_bytes(scene_path("two-wheel").read_bytes())
    assert main(["run", name, "--t-end", "0.003", "--no-plots", "--quiet", "--out", "run"]) == 0
    written = (tmp_path / "run" / "scenario.toml").read_bytes().decode("utf-8")  # UTF-8, or this raises
    assert 'name = "drive-\ufffd"' in written
    assert load_scenario(tmp_path / "run" / "scenario.toml").meta.name == "drive-\ufffd"


def test_outputs_under_a_name_that_is_not_utf8_are_written_as_utf8(tmp_path, capsys, monkeypatch):
    """On main: UnicodeEncodeError writing calibrated.toml and new's file, which quote their paths."""
    monkeypatch.chdir(tmp_path)
    folder = os.fsdecode(b"out-\xfe")
    assert main(["new", "two-wheel", "--out", f"{folder}.toml"]) == 0
    assert "\ufffd" in (tmp_path / f"{folder}.toml").read_bytes().decode("utf-8")
    argv = ["calibrate", "two-wheel", "--param", f"{KEY}=0:0.05", "--target", "kd_max", "1.5", "0.5"]
    assert main([*argv, "--budget", "2", "--polish-evaluations", "0", *STUDY, "--out", folder]) == 0
    assert "\ufffd" in (tmp_path / folder / "calibrated.toml").read_bytes().decode("utf-8")


def test_a_scenario_file_with_a_byte_order_mark_is_read(tmp_path, capsys):
    """Windows editors write UTF-8 with a byte-order mark; on main: 'Invalid statement (at line 1,
    column 1)'."""
    from gearbody.model import load_scenario
    from gearbody.model.scenes import scene_path

    path, plain = tmp_path / "two-wheel.toml", scene_path("two-wheel")
    path.write_bytes(b"\xef\xbb\xbf" + plain.read_bytes())
    assert load_scenario(path) == load_scenario(plain)


@pytest.mark.parametrize("value", ["[]", "{}", "1", "true"])
def test_a_stage_type_that_is_no_string_is_refused_naming_it(value):
    """Drawn by the document fuzzer with its draws fixed; on main: TypeError 'unhashable type: list'."""
    from gearbody.errors import InputError
    from gearbody.model import load_scenario

    with pytest.raises(InputError, match=r"design\.stages\.2\.type = .*: must be a string"):
        load_scenario("planetary-conveyor", [f"design.stages.2.type={value}"])


@pytest.mark.parametrize(
    ("override", "named"),
    [  # on main: OverflowError (floor of an infinite sample count) in the memory budget's estimate
        ("operation.t_end_s=1.7976931348623157e308", "exceed the memory budget"),
        ("solver.output_rate_hz=1.7976931348623157e308", "output samples"),
        ("solver.output_rate_hz=1e308", "output samples"),
    ],
)
def test_a_run_of_more_samples_than_a_float_counts_is_refused_by_the_memory_budget(
    tmp_path, capsys, override, named
):
    out = tmp_path / "run"
    line = _one_line(capsys, ["run", "two-stage", "--set", override, "--no-plots", "--out", str(out)])
    assert named in line and "memory budget" in line
    assert not out.exists()


def test_a_batch_beyond_any_study_is_refused(tmp_path, capsys):
    """On main: OverflowError ('cannot fit int into an index-sized integer') in the wall-time estimate."""
    argv = ["calibrate", "lateral-6dof", "--param", f"{KEY}=0:0.05", "--target", "kd_max", "1.5", "0.5"]
    argv += ["--budget", "2", "--batch", "9" * 40, *STUDY, "--out", str(tmp_path / "cal")]
    assert _one_line(capsys, argv).endswith(f"--batch = {'9' * 40}: at most 100000 points per round")
    assert not (tmp_path / "cal").exists()


def test_a_refused_render_leaves_none_of_the_folders_it_made(tmp_path, capsys, monkeypatch):
    """On main the refused render removed runs/SCENE/render but left runs/SCENE and runs behind."""
    monkeypatch.chdir(tmp_path)
    argv = ["render", "lateral-8dof-ball", "--kinematic", "--frames", "1", "--format", "none", "--quiet"]
    line = _one_line(capsys, [*argv, "--width", "32", "--height", "24", "--end", "3.0"])
    assert "start_s = 2.94216: must lie in the result's time range" in line
    assert os.listdir(tmp_path) == []
    (tmp_path / "runs").mkdir()  # a folder that was there stays
    _one_line(capsys, [*argv, "--width", "32", "--height", "24", "--end", "3.0"])
    assert os.listdir(tmp_path) == ["runs"] and os.listdir(tmp_path / "runs") == []


def test_a_ring_too_small_for_its_pressure_angle_is_refused_naming_its_teeth():
    """Drawn by the planetary fuzzer (in-range teeth meeting the assembly condition); on main: ValueError
    'math domain error' in the contact ratio, the ring's tips inside its base circle."""
    from gearbody.errors import InputError
    from gearbody.model import load_scenario

    teeth = ["planets=1", "sun.teeth=6", "planet.teeth=6", "ring.teeth=18"]
    refusal = r"ring\.teeth = 18: the ring's tip circle .* allowed: ring\.teeth >= 23"
    with pytest.raises(InputError, match=refusal):
        load_scenario("planetary", [f"design.stages.1.{t}" for t in teeth])
    fewest = ["planets=1", "sun.teeth=7", "planet.teeth=8", "ring.teeth=23"]
    load_scenario("planetary", [f"design.stages.1.{t}" for t in fewest])


def _dies_once(flag: str, what: str) -> dict:
    """A job whose worker is killed the first time it runs (``flag`` marks that it has been)."""
    import signal

    if what == "kill" and not os.path.exists(flag):
        open(flag, "w").close()
        os.kill(os.getpid(), signal.SIGKILL)
    return {"ok": True, "value": what}


def test_a_worker_that_dies_while_the_jobs_are_handed_out_fails_no_other_job(tmp_path, monkeypatch):
    """Found by the interruption matrix (SIGKILL to a calibration's pool worker): the pool broke while
    run_pool was still submitting, and submit's BrokenProcessPool escaped as a traceback. Here the
    first job's worker dies and the next submit waits until the pool knows it (the race, made sure)."""
    import time
    from concurrent.futures import ProcessPoolExecutor

    from gearbody.studies import executors

    real_submit = ProcessPoolExecutor.submit
    held: list[bool] = []

    def submit_after_the_death(self, *args, **kwargs):
        future = real_submit(self, *args, **kwargs)
        if not held:  # the first pool only: wait until its first worker's death has broken it
            held.append(True)
            t0 = time.monotonic()
            while not self._broken and time.monotonic() - t0 < 30:
                time.sleep(0.01)
            assert self._broken
        return future

    monkeypatch.setattr(ProcessPoolExecutor, "submit", submit_after_the_death)
    flag = str(tmp_path / "killed")
    jobs = [(f"job-{i}", (flag, w)) for i, w in enumerate(["kill", "a", "b", "c", "d"])]
    outcomes = list(executors.run_pool(_dies_once, jobs, workers=2))
    assert sorted(jid for jid, _ in outcomes) == sorted(jid for jid, _ in jobs)  # each exactly once
    by_id = dict(outcomes)
    assert all(by_id[f"job-{i}"]["ok"] for i in range(1, 5))
    first = by_id["job-0"]  # charged with its worker's death, or (the pool let go of it) run again
    assert first["ok"] or first["message"].startswith("worker process died (signal 9, SIGKILL)")


def test_a_quiet_sweep_with_a_failed_case_says_so_in_one_line(tmp_path, capsys):
    """Found by the interruption matrix (SIGKILL to a sweep's pool worker, --quiet): exit 1 and nothing
    on stderr; the failed cases were only in summary.csv."""
    overload = "operation.load_profile={time_s=[0.0],fraction=[1.0]},{time_s=[0.0],fraction=[5.0]}"
    out = tmp_path / "study"
    line = _one_line(capsys, ["sweep", "two-wheel", "--vary", overload, *STUDY, "--out", str(out)], code=1)
    assert line.startswith("gearbody sweep: 1 of 2 cases failed (case-0001: ")
    assert line.endswith(
        f"each is recorded in {out / 'summary.csv'}; rerun with --retry-failed to run them again"
    )


def test_render_interactive_without_a_display_is_refused_before_it_simulates(tmp_path, capsys, monkeypatch):
    """On main the scene was simulated first (the whole run) and then refused, naming the Python API
    ('use render() for pictures')."""
    import gearbody.engine

    def no_simulation(*args, **kwargs):
        raise AssertionError("simulated for a viewer that cannot open")

    monkeypatch.setattr(gearbody.engine, "simulate", no_simulation)
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    line = _one_line(capsys, ["render", "two-wheel", "--interactive", "--out", str(tmp_path / "r")])
    assert line.startswith("gearbody render: --interactive: no display to open Exudyn's viewer on")
    assert "render()" not in line and not (tmp_path / "r").exists()


def test_a_run_that_creeps_is_stalled_relative_to_the_period_it_resolves():
    """The watchdog's threshold follows the shortest period the run resolves (STALL_FRACTION of it):
    2e-7 s per STALL_CALLS evaluations is a stall at the default 20 kHz output, progress at 100 MHz."""
    from gearbody.engine.user_functions import STALL_CALLS, StallError, StallWatchdog

    def creep(period_s: float) -> None:
        dog = StallWatchdog()
        dog.watch(1.0, 1e3, False, "motor speed", "rad/s", max_step_s=1e-4, resolved_period_s=period_s)
        for k in range(3 * STALL_CALLS):
            dog(2e-7 * k / STALL_CALLS, 100.0)

    with pytest.raises(StallError, match=r"200000 force evaluations advanced less than 5e-07 s"):
        creep(1 / 20000)
    creep(1e-8)  # 2e-7 s is ~20 periods of 100 MHz: progress


@pytest.mark.slow
def test_the_muller_run_that_crept_for_ever_is_a_numerical_failure(tmp_path, capsys):
    """Drawn by the simulation fuzzer: 0.01 s had not finished after 5 min (~1e-12 s per step at a jump
    of the mesh law); the absolute 1e-9 s per check never called it stalled. The wall-time limit is
    only this test's bound."""
    sets = [
        "operation.t_end_s=0.01",
        "design.motor.synchronous_speed_rad_s=14.113160201108897",
        "design.motor.inertia_kg_m2=0.011999723692969953",
        "operation.speed_profile={time_s = [0.0], fraction = [2.3279138811885858]}",
        "production.error_mode.e_um=88.26977995229572",
        "design.mesh.damping_Ns_per_m=1533475.9328450963",
        "solver.wall_time_limit_s=120",
    ]
    argv = ["run", "muller", *[a for s in sets for a in ("--set", s)], "--no-plots", "--quiet"]
    line = _one_line(capsys, [*argv, "--out", str(tmp_path / "run")], code=3)
    assert "the solver stalled at t = 0.0047" in line and "advanced less than 5e-07 s" in line
