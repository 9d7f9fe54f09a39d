"""Studies survive interruption and failure: Ctrl-C stops a study (exit 130, finished cases kept, the
others unrecorded), a killed pool worker fails only its own case, a resume runs every case exactly once,
and the results are bit-identical to an uninterrupted study; SIGTERM stops a command as Ctrl-C does;
studies are bounded in size.

The outcome does not depend on how pytest was started: a process started with SIGINT ignored (``nohup
pytest &`` from a script) passes SIG_IGN on to its children, and Python then raises no
KeyboardInterrupt. The tests set the disposition of what they interrupt: Python's own Ctrl-C handling
(:func:`_ctrl_c_raises`) in this process, and in the commands they start (:func:`_start`), and SIGINT
ignored where that is the point (:func:`test_sigterm_stops_a_sweep_that_ignores_ctrl_c`)."""

import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

from gearbody.cli import main
from gearbody.cli import sweep as sweep_cli
from gearbody.engine import simulate
from gearbody.model import load_scenario
from gearbody.studies import MAX_CASES, Study, SweepSpecError, executors, run_study

SCENE = "two-wheel"
E_UM = "production.error_mode.e_um"
VARY = f"{E_UM}=1:8:8"
T_END = "0.2"  # ~0.2 s wall per case: long enough to be interrupted or killed inside a case
ROOT = Path(__file__).resolve().parents[1]
MESSAGE = re.compile(r"^interrupted: (\d+) of 8 cases done; rerun the same command to resume$")


@contextmanager
def _sigint(handler):
    """SIGINT set to ``handler`` in this process (main thread) for the block, then restored."""
    previous = signal.signal(signal.SIGINT, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _ctrl_c_raises():
    """Python's own Ctrl-C handling (KeyboardInterrupt), whatever this process inherited."""
    return _sigint(signal.default_int_handler)


@pytest.fixture
def started_by_nohup():
    """SIGINT ignored in this process for the test, as ``nohup pytest &`` from a script leaves it: the
    interruption tests run in that condition every time, so none of them can come to depend on it."""
    with _sigint(signal.SIG_IGN):
        yield


def _start(cmd: list[str], sigint=signal.default_int_handler, **kwargs) -> subprocess.Popen:
    """Start ``cmd`` in its own process group (a signal to the group reaches it and its workers only)
    with SIGINT handled as ``sigint`` gives it: a Python handler becomes the default action across exec
    (and the child's Python then raises KeyboardInterrupt), SIG_IGN stays ignored."""
    with _sigint(sigint):
        return subprocess.Popen(
            cmd, env={**os.environ, "PYTHONPATH": str(ROOT)}, start_new_session=True, **kwargs
        )


# --- the engine -----------------------------------------------------------------------------------


def test_ctrl_c_inside_the_solver_is_a_keyboard_interrupt_not_a_simulation_error(started_by_nohup):
    simulate(load_scenario(SCENE, ["operation.t_end_s=0.01"]))  # compiled and warm
    scenario = load_scenario(SCENE, ["operation.t_end_s=5.0"])  # ~5 s wall uninterrupted
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    before = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)
    t0 = time.perf_counter()
    timer.start()
    with _ctrl_c_raises(), pytest.raises(KeyboardInterrupt):
        simulate(scenario)
    assert time.perf_counter() - t0 < 2.0  # promptly
    timer.join()
    assert (signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)) == before  # hooks gone


# --- failure marking of the executors ---------------------------------------------------------------


def _task(what: str) -> dict:
    """A job that succeeds, is killed by SIGKILL, or exits (as a crashed worker would)."""
    if what == "kill":
        time.sleep(0.2)  # the other jobs are under way
        os.kill(os.getpid(), signal.SIGKILL)
    if what == "exit":
        os._exit(3)
    time.sleep(0.05)
    return {"ok": True, "value": what, "pid": os.getpid()}


def test_a_dead_pool_worker_fails_only_its_own_job_and_the_pool_restarts():
    jobs = [(f"job-{i}", (w,)) for i, w in enumerate(["a", "kill", "b", "c", "exit", "d", "e", "f"])]
    outcomes = list(executors.run_pool(_task, jobs, workers=2))
    ids = [jid for jid, _ in outcomes]
    assert sorted(ids) == sorted(jid for jid, _ in jobs)  # every job exactly once
    by_id = dict(outcomes)
    assert by_id["job-1"]["ok"] is False and by_id["job-1"]["error_type"] == "WorkerDied"
    assert by_id["job-1"]["message"] == "worker process died (signal 9, SIGKILL) while running this case"
    assert by_id["job-4"]["message"] == "worker process exited with code 3 while running this case"
    ok = {jid: o for jid, o in outcomes if jid not in ("job-1", "job-4")}
    # a broken ProcessPoolExecutor runs nothing more: the jobs after a death ran on a restarted pool
    assert all(o["ok"] and o["value"] == dict(jobs)[jid][0] for jid, o in ok.items())


def _nap(seconds: float) -> dict:
    time.sleep(seconds)
    return {"ok": True, "pid": os.getpid()}


def test_a_pool_shutdown_that_sticks_is_bounded_and_its_workers_killed(monkeypatch):
    """Python 3.11's pool can deadlock in the shutdown after its workers were stopped (gh-125451): the
    study goes on after SHUTDOWN_GRACE_S, with the workers killed and the stuck pool noted."""
    from concurrent.futures import ProcessPoolExecutor

    monkeypatch.setattr(executors, "SHUTDOWN_GRACE_S", 0.5)
    monkeypatch.setattr(executors, "STUCK_POOLS", [])
    release = threading.Event()
    real = ProcessPoolExecutor.shutdown

    def stuck(self, wait=True, *, cancel_futures=False):
        if threading.current_thread().name == "gearbody-pool-stop":
            release.wait(60)  # as the deadlocked manager thread would hold it
        return real(self, wait=wait, cancel_futures=cancel_futures)

    monkeypatch.setattr(ProcessPoolExecutor, "shutdown", stuck)
    jobs = [("quick", (0.0,)), ("slow", (60.0,))]
    pool = executors.run_pool(_nap, jobs, workers=2)
    jid, outcome = next(pool)
    assert jid == "quick" and outcome["ok"]
    t0 = time.monotonic()
    pool.close()  # closed early: the slow job's worker is stopped, the shutdown sticks
    try:
        assert time.monotonic() - t0 < 10
        assert executors.STUCK_POOLS == ["pool of 2 workers: shutdown still waiting after 0.5 s"]
    finally:
        release.set()


def test_the_command_line_leaves_when_a_stuck_pool_would_hold_its_exit():
    """A thread that never ends (as a deadlocked pool's manager thread) would keep the interpreter from
    exiting: gearbody.cli.run leaves with the command's code, saying why."""
    code = (
        "import sys, threading\n"
        "from gearbody.studies import executors\n"
        "threading.Thread(target=threading.Event().wait).start()\n"
        "executors.STUCK_POOLS.append('pool of 2 workers: shutdown still waiting')\n"
        "sys.argv = ['gearbody', 'list']\n"
        "from gearbody.cli import run\n"
        "run()\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0
    assert "one-stage" in done.stdout
    assert done.stderr.strip().splitlines() == [
        "gearbody: pool of 2 workers: shutdown still waiting; leaving without waiting for it"
    ]


def test_death_causes_name_the_signal_or_the_exit_code():
    assert executors.death_cause(-signal.SIGSEGV) == "worker process died (signal 11, SIGSEGV)"
    assert executors.death_cause(1) == "worker process exited with code 1"


# --- size of a study -------------------------------------------------------------------------------


def test_a_study_too_big_is_refused_before_anything_is_made(tmp_path, capsys):
    t0 = time.perf_counter()
    with pytest.raises(SweepSpecError, match=rf"count 1000000000 is more than the {MAX_CASES} cases"):
        Study.build(SCENE, vary=[f"{E_UM}=0:20:1000000000"])
    with pytest.raises(
        SweepSpecError,
        match=r"has 1000000000000 cases \(1000000 \(--samples 1000000\) "
        rf"x 1000000 \(--seeds 1000000\)\), more than the limit of {MAX_CASES}",
    ):
        Study.build(SCENE, random=[f"{E_UM}=uniform(5,15)"], samples=10**6, seeds=10**6)
    with pytest.raises(SweepSpecError, match=r"has 10100 cases .*--max-cases 10100"):
        Study.build(SCENE, vary=[f"{E_UM}=0:20:101"], seeds=100)
    assert time.perf_counter() - t0 < 5.0
    assert len(Study.build(SCENE, vary=[f"{E_UM}=0:20:101"], seeds=100, max_cases=10100).cases()) == 10100
    with pytest.raises(SweepSpecError, match=r"--max-cases must be a whole number >= 1, got 0"):
        Study.build(SCENE, seeds=2, max_cases=0)
    with pytest.raises(SweepSpecError, match=r"20 values, more than the limit of 10 cases"):
        Study.build(SCENE, vary={E_UM: list(range(20))}, max_cases=10)
    base = ["sweep", SCENE, "--workers", "1", "--quiet", "--out", str(tmp_path / "big")]
    assert main([*base, "--seeds", "20", "--max-cases", "10"]) == 2
    assert "the study has 20 cases (20 (--seeds 20)), more than the limit of 10" in capsys.readouterr().err
    assert not (tmp_path / "big").exists()
    assert sweep_cli.MAX_CASES == MAX_CASES


# --- the command line: interrupt, kill a worker, resume ----------------------------------------------


def _sweep(out: Path, *extra: str, t_end: str = T_END, sigint=signal.default_int_handler) -> subprocess.Popen:
    cmd = [sys.executable, "-m", "gearbody.cli", "sweep", SCENE, "--vary", VARY, "--t-end", t_end]
    return _start(
        [*cmd, *extra, "--out", str(out)], sigint, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )


def test_a_started_command_handles_ctrl_c_even_where_this_process_ignores_it():
    """The guard of the tests below: run under ``nohup pytest &`` they would otherwise send SIGINT to a
    command that ignores it."""
    probe = [sys.executable, "-c", "import signal; print(repr(signal.getsignal(signal.SIGINT)))"]
    with _sigint(signal.SIG_IGN):
        proc = _start(probe, stdout=subprocess.PIPE, text=True)
    assert "default_int_handler" in proc.communicate(timeout=30)[0]
    proc = _start(probe, signal.SIG_IGN, stdout=subprocess.PIPE, text=True)
    assert "SIG_IGN" in proc.communicate(timeout=30)[0]


def _wait(until, proc: subprocess.Popen, timeout_s: float = 60.0):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout_s:
        got = until()
        if got:
            return got
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.01)
    raise AssertionError("timed out")


def _without_wall_times(data):
    """JSON data without its wall-clock entries (``*wall_s``, ``wall_time_s``): all else is compared."""
    if isinstance(data, dict):
        return {k: _without_wall_times(v) for k, v in data.items() if "wall" not in k}
    return data


def _records(out: Path) -> dict[str, tuple[str, int]]:
    """case id -> (state, mtime_ns of its record)."""
    recs = {}
    for name, state in (("summary.json", "ok"), ("error.json", "failed")):
        for f in out.glob(f"cases/*/{name}"):
            recs[f.parent.name] = (state, f.stat().st_mtime_ns)
    return recs


def test_an_interrupted_and_worker_killed_study_resumes_to_the_uninterrupted_results(
    tmp_path, started_by_nohup
):
    out = tmp_path / "study"
    # 1. Ctrl-C during a serial study, once some cases are recorded
    proc = _sweep(out, "--workers", "1")
    _wait(lambda: len(_records(out)) >= 2, proc)
    time.sleep(0.07)  # into the next case's solver (~0.01 s build, ~0.14 s solve)
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == 130, err
    assert "Traceback" not in err
    done = int(MESSAGE.match(err.strip().splitlines()[-1]).group(1))
    first = _records(out)
    assert 2 <= done < 8 and len(first) == done and {s for s, _ in first.values()} == {"ok"}
    assert not list(out.glob("cases/*/error.json"))  # the interrupted case is not recorded as failed

    # 2. resume on a process pool, kill -9 the worker of a running case
    proc = _sweep(out, "--workers", "2")
    running = out / ".running"

    def busy_worker():
        for mark in running.glob("*") if running.exists() else ():
            try:
                case = mark.read_text()
            except FileNotFoundError:
                continue
            if case and not (out / "cases" / case / "summary.json").exists():
                return int(mark.name), case
        return None

    pid, killed = _wait(busy_worker, proc)
    os.kill(pid, signal.SIGKILL)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 1, err  # some case failed: the killed one
    assert f"resuming {out}: {done} of 8 cases already done" in err and "Traceback" not in err
    second = _records(out)
    assert [c for c, (s, _) in second.items() if s == "failed"] == [killed]
    error = json.loads((out / "cases" / killed / "error.json").read_text())
    assert error["message"] == "worker process died (signal 9, SIGKILL) while running this case"
    assert len(second) == 8 and all(second[c] == first[c] for c in first)  # phase 1 untouched

    # 3. rerun the killed case
    proc = _sweep(out, "--workers", "2", "--retry-failed")
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, err
    third = _records(out)
    assert {c for c in third if third[c] != second[c]} == {killed}  # only the killed case ran again
    assert {s for s, _ in third.values()} == {"ok"} and not running.exists()

    # every case was recorded by exactly one run, and all match an uninterrupted study bit for bit
    runs = [set(first), set(second) - set(first) - {killed}, {killed}]
    assert sum(len(r) for r in runs) == 8 and set().union(*runs) == set(third)
    _assert_uninterrupted(tmp_path, out, third)


def _assert_uninterrupted(tmp_path: Path, out: Path, records: dict) -> None:
    """Every case of ``records`` in ``out`` equals that of an uninterrupted serial study bit for bit
    (wall-clock entries aside)."""
    assert len(records) == 8 and {s for s, _ in records.values()} == {"ok"}
    ref = tmp_path / "ref"
    run_study(
        SCENE,
        out_dir=ref,
        vary=[VARY],
        base_overrides=[f"operation.t_end_s={float(T_END)!r}"],
        workers=1,
        progress=False,
    )
    for case in sorted(records):
        with (
            np.load(out / "cases" / case / "result.npz") as a,
            np.load(ref / "cases" / case / "result.npz") as b,
        ):
            assert sorted(a.files) == sorted(b.files)
            for name in a.files:
                if name == "meta_json":
                    same = _without_wall_times(json.loads(str(a[name]))) == _without_wall_times(
                        json.loads(str(b[name]))
                    )
                else:
                    same = np.array_equal(a[name], b[name]) and a[name].dtype == b[name].dtype
                assert same, (case, name)
        sa, sb = (json.loads((d / "cases" / case / "summary.json").read_text()) for d in (out, ref))
        assert _without_wall_times(sa) == _without_wall_times(sb), case


def _dask_task(what: str) -> dict:
    if what == "kill":
        os.kill(os.getpid(), signal.SIGKILL)  # the worker process dies; its nanny starts a new one
    return {"ok": True, "value": what}


@pytest.mark.slow
def test_a_case_whose_dask_workers_die_is_failed_once_with_the_cause_and_the_others_run():
    import cloudpickle
    import dask
    from dask.distributed import LocalCluster

    cloudpickle.register_pickle_by_value(sys.modules[__name__])  # workers need not import the tests
    jobs = [(f"job-{i}", (w,)) for i, w in enumerate(["a", "kill", "b", "c"])]
    # worker-saturation 1: a worker holds only the task it runs (Dask counts a death against every task
    # the worker holds: with queued tasks, an innocent neighbour of the killer can fail too)
    config = {"distributed.scheduler.allowed-failures": 1, "distributed.scheduler.worker-saturation": 1.0}
    with (
        dask.config.set(config),
        LocalCluster(
            n_workers=2, processes=True, threads_per_worker=1, host="127.0.0.1", dashboard_address=":0"
        ) as cluster,
    ):
        outcomes = list(executors.run_dask(_dask_task, jobs, cluster.scheduler_address))
    assert sorted(jid for jid, _ in outcomes) == [jid for jid, _ in jobs]  # each job once
    by_id = dict(outcomes)
    assert by_id["job-1"]["ok"] is False and by_id["job-1"]["error_type"] == "KilledWorker"
    assert by_id["job-1"]["message"].startswith("the Dask workers running this case died repeatedly: ")
    assert all(by_id[j]["ok"] for j in ("job-0", "job-2", "job-3")), by_id


@pytest.mark.parametrize("how", ["ctrl-c", "sigterm"])
def test_an_interrupted_run_prints_one_line_and_exits_130_or_143(tmp_path, started_by_nohup, how):
    """Ctrl-C (to the group) or SIGTERM (to the process, as ``kill PID``) inside the solver: one line, no
    result, and the progress bar left where the run stopped (it used to be drawn full)."""
    out = tmp_path / "run"
    cmd = [sys.executable, "-m", "gearbody.cli", "run", SCENE, "--t-end", "20", "--no-plots"]
    cmd += ["--out", str(out)]
    proc = _start(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    seen = b""
    while b"simulating" not in seen:  # the progress bar: the solver has run for 2 s
        chunk = proc.stderr.read1(4096)
        assert chunk, (seen, proc.wait())
        seen += chunk
    if how == "ctrl-c":
        os.killpg(proc.pid, signal.SIGINT)
    else:
        proc.send_signal(signal.SIGTERM)
    rest = proc.stderr.read().decode()
    assert proc.wait(timeout=30) == (130 if how == "ctrl-c" else 143)
    assert rest.strip().splitlines()[-1] == "interrupted: gearbody run stopped" and "Traceback" not in rest
    assert not (out / "result.npz").exists()
    assert "20.000/20.000" not in rest


def test_sigterm_stops_a_sweep_that_ignores_ctrl_c(tmp_path):
    """Started as ``cmd &`` from a script starts it (SIGINT ignored, which gearbody keeps), a sweep is
    stopped by ``kill PID``: one line, exit 143, the finished cases recorded, its pool workers gone (they
    used to be left behind, idle, for ever)."""
    out = tmp_path / "study"
    proc = _sweep(out, "--workers", "2", t_end="1.0", sigint=signal.SIG_IGN)
    running = out / ".running"
    workers = _wait(lambda: len(_records(out)) >= 1 and running.exists() and list(running.glob("*")), proc)
    worker_pids = {int(mark.name) for mark in workers}
    try:
        proc.send_signal(signal.SIGTERM)  # the parent only, as kill PID does
        _, err = proc.communicate(timeout=30)  # (left-behind workers would hold its pipes open)
        assert proc.returncode == 143, err
        assert "Traceback" not in err
        done = int(MESSAGE.match(err.strip().splitlines()[-1]).group(1))
        assert 1 <= done < 8 and len(_records(out)) == done
        t0 = time.monotonic()
        while any(map(_running, worker_pids)) and time.monotonic() - t0 < 10:
            time.sleep(0.05)
        assert not any(map(_running, worker_pids))
    finally:
        try:  # whatever failed, leave nothing of it running
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


def _running(pid: int) -> bool:
    """The process exists and is not a zombie (Linux /proc)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except (FileNotFoundError, ProcessLookupError):
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


# --- no process outlives its study ------------------------------------------------------------------


def _children(pid: int) -> set[int]:
    """Pids of the live processes whose parent is ``pid`` (Linux /proc)."""
    found = set()
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (FileNotFoundError, ProcessLookupError, IndexError):
            continue
        if int(fields[1]) == pid and fields[0] != "Z":
            found.add(int(stat.parent.name))
    return found


def _gone_within(pids: set[int], timeout_s: float) -> set[int]:
    """The pids still running after ``timeout_s`` (empty: all gone)."""
    t0 = time.monotonic()
    while any(map(_running, pids)) and time.monotonic() - t0 < timeout_s:
        time.sleep(0.05)
    return {p for p in pids if _running(p)}


def _kill_all(pids):
    for pid in pids:
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="finds the workers in Linux /proc")
def test_a_study_killed_with_sigkill_takes_its_workers_with_it_and_resumes(tmp_path, started_by_nohup):
    """kill -9 of a sweep's main process, while its pool workers simulate: the workers go within a few
    seconds (they used to run on, then wait for work for ever); the same command then resumes the study
    and ends as an uninterrupted one."""
    out = tmp_path / "study"
    proc = _sweep(out, "--workers", "2", "--quiet")
    running = out / ".running"
    _wait(lambda: len(_records(out)) >= 1 and running.exists() and list(running.glob("*")), proc)
    workers = _children(proc.pid)
    try:
        assert len(workers) == 2, workers
        os.kill(proc.pid, signal.SIGKILL)  # the main process only: nothing can clean up after it
        assert proc.wait(timeout=30) == -signal.SIGKILL  # (not communicate: live workers hold its pipes)
        assert not _gone_within(workers, 5.0)
        proc.stdout.close(), proc.stderr.close()
        done = len(_records(out))
        assert 1 <= done < 8
    finally:
        _kill_all(workers)
    proc = _sweep(out, "--workers", "2")
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    assert "cases already done" in err and "Traceback" not in err
    _assert_uninterrupted(tmp_path, out, _records(out))


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="finds the workers in Linux /proc")
def test_without_the_kernels_death_signal_workers_still_follow_their_parent(tmp_path):
    """The fallback where PR_SET_PDEATHSIG is missing (other platforms): a thread in each worker polls
    its parent. Idle and busy workers of a pool whose parent is killed with SIGKILL are gone within a few
    polls."""
    script = tmp_path / "pool.py"
    script.write_text(
        "import os, sys, time\n"
        "from concurrent.futures import ProcessPoolExecutor\n"
        "from gearbody.studies import executors\n"
        "pool = ProcessPoolExecutor(3, initializer=executors._worker_init, initargs=(os.getpid(), False))\n"
        "busy = [pool.submit(time.sleep, 600) for _ in range(2)]\n"  # 2 busy, 1 idle
        "print(' '.join(str(p) for p in pool._processes), flush=True)\n"
        "time.sleep(600)\n"
    )
    proc = subprocess.Popen(
        [sys.executable, str(script)],
        stdout=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    workers = {int(p) for p in proc.stdout.readline().split()}
    try:
        assert len(workers) == 3 and workers == _children(proc.pid)
        time.sleep(0.2)  # every worker's initializer has run
        proc.kill()
        proc.wait(timeout=30)
        assert not _gone_within(workers, 5 * executors.PARENT_POLL_S + 2.0)
    finally:
        _kill_all(workers)


def test_a_stop_that_arrives_while_workers_are_forked_is_not_lost(tmp_path):
    """A SIGTERM (or Ctrl-C) delivered while the pool forks its workers used to be raised inside the
    fork's hooks (logging's lock release), printed as 'Exception ignored' and lost: the study ran on
    to its end and exited 0, or stopped before its workers were told to end and waited for them for ever
    at exit (found by the SIGTERM test of calibrate, which forks a pool per round). Here the signal is
    sent from inside such a hook, every time, with another thread there to take it."""
    script = tmp_path / "fork.py"
    script.write_text(
        "import os, signal, sys, threading, time\n"
        "from gearbody.cli import _sigterm_stops\n"
        "from gearbody.studies import executors\n"
        "sent = []\n"
        "def kill_once():\n"
        "    if not sent:\n"
        "        sent.append(1)\n"
        "        os.kill(os.getpid(), signal.SIGTERM)\n"
        "os.register_at_fork(after_in_parent=kill_once)\n"
        "threading.Thread(target=time.sleep, args=(60,), daemon=True).start()\n"  # another thread
        "with _sigterm_stops() as received:\n"
        "    try:\n"
        "        for _ in executors.run_pool(time.sleep, [(str(i), (2,)) for i in range(4)], workers=2):\n"
        "            pass\n"
        "    except KeyboardInterrupt:\n"
        "        print('stopped', received, flush=True)\n"
        "        sys.exit(0)\n"
        "print('ran to the end', flush=True)\n"
    )
    done = subprocess.run(
        [sys.executable, str(script)],
        capture_output=True,
        text=True,
        timeout=60,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    assert done.stdout == f"stopped [{int(signal.SIGTERM)}]\n", (done.stdout, done.stderr)
    assert "Exception ignored" not in done.stderr


def test_a_worker_whose_parent_is_gone_before_it_starts_stops_at_once():
    """The parent can die between the fork and the worker's initializer: the worker notices then."""
    pid = os.fork()
    if pid == 0:  # the "worker": its parent pid is not the one it was started for
        try:
            executors._worker_init(os.getppid() + 1_000_000)
            time.sleep(30)
        finally:
            os._exit(0)
    _, status = os.waitpid(pid, 0)
    assert os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGTERM


@pytest.mark.slow
def test_a_dask_study_killed_with_sigkill_leaves_no_work_on_the_cluster(tmp_path, started_by_nohup):
    """Dask workers belong to their cluster and stay; the study's tasks do not: the scheduler forgets them
    once the killed study's connection closes, and a task already running ends with its case."""
    from dask.distributed import Client, LocalCluster

    with (
        LocalCluster(
            n_workers=2, processes=True, threads_per_worker=1, host="127.0.0.1", dashboard_address=":0"
        ) as cluster,
        Client(cluster) as client,
    ):

        def tasks() -> int:
            return client.run_on_scheduler(lambda dask_scheduler: len(dask_scheduler.tasks))

        def executing() -> int:
            return sum(client.run(lambda dask_worker: dask_worker.state.executing_count).values())

        out = tmp_path / "study"
        proc = _sweep(out, "--scheduler", cluster.scheduler_address, "--quiet", t_end="1.0")
        try:
            _wait(lambda: tasks() == 8 and executing() == 2, proc)
            os.kill(proc.pid, signal.SIGKILL)
            assert proc.wait(timeout=30) == -signal.SIGKILL
        finally:
            if proc.poll() is None:
                proc.kill()
            proc.communicate()
        t0 = time.monotonic()
        while tasks() and time.monotonic() - t0 < 10:
            time.sleep(0.1)
        assert tasks() == 0
        while executing() and time.monotonic() - t0 < 60:  # the running cases end (~1 s each)
            time.sleep(0.2)
        assert executing() == 0 and len(client.scheduler_info()["workers"]) == 2


STEADY_SET = [
    "--set", 'operation.initial_state="steady"',
    "--set", "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "--set", "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
]  # fmt: skip
RESUMABLE = {
    "calibrate": (
        [
            "calibrate", "two-wheel", "--t-end", "0.3", *STEADY_SET, "--param", f"{E_UM}=5:15",
            "--target", "kd_max", "1.3", "0.05", "--budget", "6", "--batch", "2",
            "--polish-evaluations", "0", "--workers", "2", "--quiet",
        ],
        "evaluations.jsonl",
        "calibration.json",
    ),
    "sensitivity": (
        [
            "sensitivity", "two-wheel", "--t-end", "0.3", *STEADY_SET, "--key", f"{E_UM}=5:15",
            "--feature", "kd_max", "--samples", "4", "--seed", "1", "--workers", "2", "--quiet",
        ],
        "evaluations",
        "indices.json",
    ),
}  # fmt: skip


@pytest.mark.slow
@pytest.mark.parametrize("command", sorted(RESUMABLE))
def test_sigterm_stops_calibrate_and_sensitivity_and_the_rerun_ends_as_an_uninterrupted_one(
    tmp_path, command
):
    """``kill PID`` of a calibration or sensitivity analysis started in the background (SIGINT ignored):
    exit 143, one line, its pool workers gone; the same command then finishes it, with the result an
    uninterrupted run gives."""
    args, record, result = RESUMABLE[command]

    def start(out: Path) -> subprocess.Popen:
        cmd = [sys.executable, "-m", "gearbody.cli", *args, "--out", str(out)]
        return _start(cmd, signal.SIG_IGN, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    def recorded(out: Path) -> int:
        path = out / record
        if path.is_dir():
            return len(list(path.glob("*.json")))
        return max(0, len(path.read_text().splitlines()) - 1) if path.exists() else 0

    cut = tmp_path / "cut"
    proc = start(cut)
    _wait(lambda: recorded(cut) >= 2 and _children(proc.pid), proc)
    workers = _children(proc.pid)
    try:
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
        assert proc.returncode == 143, err
        last = err.strip().splitlines()
        assert len(last) == 1 and last[0].startswith("interrupted: ") and "Traceback" not in err
        assert not _gone_within(workers, 5.0)
    finally:
        _kill_all(workers)
    assert not (cut / result).exists()
    proc = start(cut)
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 0, err
    whole = tmp_path / "whole"
    proc = start(whole)
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 0, err
    a, b = (json.loads((d / result).read_text()) for d in (cut, whole))
    if command == "calibrate":
        assert a["replayed"] >= 2 and a["simulations"] < b["simulations"]
        assert a["parameters"] == b["parameters"] and a["history"] == b["history"]
    else:
        assert _without_wall_times(a) == _without_wall_times(b)


def _term_once(flag: str) -> dict:
    """A job whose first attempt is stopped by SIGTERM from outside (as ``kill PID`` of a worker)."""
    if not os.path.exists(flag):
        Path(flag).touch()
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(5)
    return {"ok": True, "pid": os.getpid()}


def test_a_worker_stopped_by_sigterm_has_its_job_run_again(tmp_path):
    """SIGTERM is how the pool stops its own workers, so a worker ended by it is not charged with its
    job: the job runs again on the restarted pool (a SIGKILL or a crash fails it, above)."""
    jobs = [("a", (str(tmp_path / "a"),)), ("b", (str(tmp_path / "b-done"),))]
    (tmp_path / "b-done").touch()
    outcomes = dict(executors.run_pool(_term_once, jobs, workers=2))
    assert sorted(outcomes) == ["a", "b"] and all(o["ok"] for o in outcomes.values())
    assert (tmp_path / "a").exists()  # its first attempt was stopped


def test_a_ctrl_c_inside_a_compiled_call_interrupts_the_case_instead_of_failing_it(monkeypatch):
    """A KeyboardInterrupt that lands inside a numba call surfaces as a SystemError with the interrupt as
    its context (seen in a loaded CI run): run_case raises it as the interrupt it is."""
    from gearbody.studies import tasks

    def interrupted_in_numba(*args, **kwargs):
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt:
            raise SystemError("CPUDispatcher(...) returned a result with an exception set") from None

    def plain_failure(*args, **kwargs):
        raise SystemError("a genuine failure")

    import gearbody.engine
    import gearbody.model

    monkeypatch.setattr(gearbody.model, "load_scenario", lambda *args: None)
    monkeypatch.setattr(gearbody.engine, "simulate", interrupted_in_numba)
    with pytest.raises(KeyboardInterrupt):
        tasks.run_case({}, [])
    monkeypatch.setattr(gearbody.engine, "simulate", plain_failure)
    assert tasks.run_case({}, [])["ok"] is False
