"""The interruption matrix (issue 26): SIGINT, SIGTERM and SIGKILL, to the main process or to a pool
worker, of run, sweep, sensitivity and calibrate, each sent once the command is under way. Every cell
ends as the command line documents it:

- main process: SIGINT exit 130 and SIGTERM exit 143, each with one line on stderr; SIGKILL exit -9
  (nothing can be printed);
- pool worker: SIGINT is ignored (Ctrl-C reaches the whole process group and the main process stops
  the workers), SIGTERM is how the pool stops its workers (the job runs again), SIGKILL fails the job
  it was running (exit 1, one line) or, in a calibration, is scored as that evaluation's failure;

and in every cell no process of the command outlives it, and the same command run again (with
``--retry-failed`` where a case failed) completes with results bit-identical to an uninterrupted run
(wall times aside). ``run`` has no workers.

At the default scale one cell runs (CI's time); the whole matrix with
GEARBODY_FUZZ_SCALE >= 2 (21 cells, ~4 min on two cores). The outcome of every cell run is printed at
the end, and merged into GEARBODY_FUZZ_REPORT.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from fuzzing import ROOT, SCALE, Report, print_line

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="finds the workers in Linux /proc"),
]

E_UM = "production.error_mode.e_um"
STUDY = ["--t-end", "0.2", "--workers", "2", "--quiet"]  # ~0.2 s of wall per case: interrupted inside one
COMMANDS = {
    "run": ["run", "two-wheel", "--t-end", "6", "--no-plots"],
    "sweep": ["sweep", "two-wheel", "--vary", f"{E_UM}=1:8:8", *STUDY],
    "sensitivity": ["sensitivity", "two-wheel", "--key", f"{E_UM}=1:8", "--feature", "kd_max"]
    + ["--samples", "4", *STUDY],
    "calibrate": ["calibrate", "two-wheel", "--param", f"{E_UM}=1:8", "--target", "kd_max", "1.6", "0.1"]
    + ["--budget", "8", "--batch", "2", "--polish-evaluations", "0", *STUDY],
}
SIGNALS = ("SIGINT", "SIGTERM", "SIGKILL")
CELLS = [
    (c, p, s)
    for c in COMMANDS
    for p in ("main", "worker")
    for s in SIGNALS
    if not (c == "run" and p == "worker")
]
DEFAULT_CELLS = {("sensitivity", "main", "SIGTERM")}
"""The cell run at the default scale (CI; the others' cells of the signals are in
tests/test_study_interrupt.py)."""
EXPECTED_EXIT = {
    ("main", "SIGINT"): {130},
    ("main", "SIGTERM"): {143},
    ("main", "SIGKILL"): {-9},
    ("worker", "SIGINT"): {0},
    ("worker", "SIGTERM"): {0},
    ("worker", "SIGKILL"): {0, 1},  # 1: the case it ran failed; 0: a calibration scores it and goes on
}
REPORT = Report("interruption matrix")
TABLE: list[str] = []


def _start(argv: list[str], out: Path) -> subprocess.Popen:
    """The command in its own session, Ctrl-C handled as in a terminal (SIGINT's default action)."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)  # a child inherits SIG_IGN otherwise
    try:
        return subprocess.Popen(
            [sys.executable, "-m", "gearbody.cli", *argv, "--out", str(out)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            env={**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg", "PYTHONFAULTHANDLER": "1"},
            start_new_session=True,
        )
    finally:
        signal.signal(signal.SIGINT, previous)


def _children(pid: int) -> list[int]:
    kids = []
    try:
        for task in os.listdir(f"/proc/{pid}/task"):
            try:
                kids += [int(p) for p in Path(f"/proc/{pid}/task/{task}/children").read_text().split()]
            except OSError:
                pass
    except OSError:
        pass
    return kids


def _cmdline(pid: int) -> bytes:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return b""


def _alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def _workers(proc: subprocess.Popen) -> list[int]:
    """The pool workers: children forked from the main process (its command line; the resource tracker
    Python starts has another)."""
    me = _cmdline(proc.pid)
    return [c for c in _children(proc.pid) if _cmdline(c) == me]


def _records(command: str, out: Path) -> int:
    if command == "sweep":
        return len(list(out.glob("cases/*/summary.json")))
    if command == "sensitivity":
        return len(list(out.glob("evaluations/*.json")))
    if command == "calibrate":
        path = out / "evaluations.jsonl"
        return max(0, len(path.read_text().splitlines()) - 1) if path.exists() else 0
    return 0


def _under_way(command: str, process: str, proc: subprocess.Popen, out: Path, seen: bytearray):
    """Whether to send the signal now: a record written and a worker busy (studies), the solver running
    (run: its progress bar)."""
    if command == "run":
        os.set_blocking(proc.stderr.fileno(), False)
        chunk = proc.stderr.read()
        if chunk:
            seen += chunk
        return b"simulating" in seen
    return _records(command, out) >= 1 and bool(_workers(proc))


def _state(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return "gone"


def _stuck(proc: subprocess.Popen, pids: set[int]) -> str:
    """What holds a command that has not ended 3 minutes after its signal: the state of its main
    process and of every process seen, and the main process's Python stacks (faulthandler, on
    SIGABRT) if it is still there."""
    seen = {p: _state(p) for p in sorted({proc.pid, *pids, *_children(proc.pid)})}
    text = f"not ended; process states {seen}"
    if proc.poll() is None:
        os.kill(proc.pid, signal.SIGABRT)
        try:
            _, err = proc.communicate(timeout=10)
            text += "\n" + err.decode(errors="replace")[-4000:]
        except subprocess.TimeoutExpired:
            pass
    return text


def _interrupt(command: str, process: str, sig: str, out: Path) -> tuple[int, str, list[int]]:
    """Start the command, send the signal once it is under way; (exit code, stderr, pids seen)."""
    proc = _start(COMMANDS[command], out)
    seen = bytearray()
    pids: set[int] = set()
    t0 = time.monotonic()
    try:
        while not _under_way(command, process, proc, out, seen):
            assert proc.poll() is None, f"ended before it was interrupted: {proc.returncode} {bytes(seen)}"
            assert time.monotonic() - t0 < 120, "never under way"
            pids |= set(_workers(proc))
            time.sleep(0.02)
        workers = _workers(proc)
        pids |= set(workers)
        target = workers[0] if process == "worker" else proc.pid
        os.kill(target, getattr(signal, sig))
        deadline = time.monotonic() + 120
        while proc.poll() is None and time.monotonic() < deadline:
            pids |= set(_workers(proc))
            time.sleep(0.02)
        os.set_blocking(proc.stderr.fileno(), True)
        try:
            _, rest = proc.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            raise AssertionError(f"{sig} to the {process}: {_stuck(proc, pids)}") from None
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    return proc.returncode, (bytes(seen) + rest).decode(errors="replace"), sorted(pids)


def _resume(command: str, out: Path, retry: bool) -> tuple[int, str]:
    argv = COMMANDS[command] + (["--retry-failed"] if retry and command in ("sweep", "sensitivity") else [])
    proc = _start(argv, out)
    _, err = proc.communicate(timeout=300)
    return proc.returncode, err.decode(errors="replace")


def _without_wall(data):
    if isinstance(data, dict):
        return {k: _without_wall(v) for k, v in data.items() if "wall" not in k}
    if isinstance(data, list):
        return [_without_wall(v) for v in data]
    return data


def _npz(path: Path) -> dict:
    with np.load(path) as f:
        arrays = {k: f[k] for k in f.files}
    meta = arrays.pop("meta_json", None)
    return {
        **{k: (a.dtype.str, a.shape, a.tobytes()) for k, a in arrays.items()},
        "meta": _without_wall(json.loads(str(meta))) if meta is not None else None,
    }


def outputs(command: str, out: Path) -> dict:
    """What must be bit-identical to an uninterrupted run: arrays bit for bit, records without wall
    times."""
    if command == "run":
        return {
            "result": _npz(out / "result.npz"),
            "summary": _without_wall(json.loads((out / "summary.json").read_text())),
        }
    if command == "sweep":
        return {
            p.parent.name: (_npz(p.parent / "result.npz"), _without_wall(json.loads(p.read_text())))
            for p in sorted(out.glob("cases/*/summary.json"))
        }
    if command == "sensitivity":
        return {
            "evaluations": {
                p.name: _without_wall(json.loads(p.read_text()))
                for p in sorted(out.glob("evaluations/*.json"))
            },
            "indices": _without_wall(json.loads((out / "indices.json").read_text())),
        }
    lines = (out / "evaluations.jsonl").read_text().splitlines()
    calibration = _without_wall(json.loads((out / "calibration.json").read_text()))
    for bookkeeping in ("replayed", "simulations"):  # how many evaluations this run made or read back
        calibration.pop(bookkeeping, None)
    return {"evaluations": sorted(lines), "calibration": calibration}


@pytest.fixture(scope="module")
def reference(tmp_path_factory, request):
    """Uninterrupted runs, one per command (made when a cell first needs it)."""
    made: dict[str, dict] = {}

    def of(command: str) -> dict:
        if command not in made:
            out = tmp_path_factory.mktemp(f"reference-{command}") / "out"
            code, err = _resume(command, out, retry=False)
            assert code == 0, err
            made[command] = outputs(command, out)
        return made[command]

    yield of
    REPORT.write()
    if TABLE:
        print_line(request, "\ninterruption matrix (signal x process x command):\n" + "\n".join(TABLE))


def _last_line(err: str) -> list[str]:
    return [
        line for line in (s.split("\r")[-1].strip() for s in err.splitlines()) if line and "%|" not in line
    ]


@pytest.mark.parametrize(("command", "process", "sig"), CELLS)
def test_every_interruption_ends_cleanly_leaves_no_process_and_resumes_bit_identically(
    tmp_path, reference, command, process, sig
):
    if SCALE < 2 and (command, process, sig) not in DEFAULT_CELLS:
        pytest.skip("the whole matrix runs with GEARBODY_FUZZ_SCALE >= 2")
    out = tmp_path / "out"
    where = f"{sig} to the {process} process of: gearbody {' '.join(COMMANDS[command])} --out {out}"
    code, err, pids = _interrupt(command, process, sig, out)
    lines = _last_line(err)
    assert "Traceback" not in err, f"{where}\n{err}"
    assert code in EXPECTED_EXIT[process, sig], f"{where}: exit {code}\n{err}"
    if code in (130, 143):
        assert lines and lines[-1].startswith("interrupted: "), f"{where}\n{err}"
    if code == 1:
        assert lines and lines[-1].startswith("gearbody"), f"{where}\n{err}"
    t0 = time.monotonic()
    while any(map(_alive, pids)) and time.monotonic() - t0 < 15:
        time.sleep(0.05)
    left = [p for p in pids if _alive(p)]
    for p in left:
        os.kill(p, signal.SIGKILL)
    assert not left, f"{where}: processes left behind {left}"
    again, err2 = _resume(command, out, retry=code == 1)
    assert again == 0, f"{where}, then the same command again: exit {again}\n{err2}"
    same = outputs(command, out) == reference(command)
    outcome = f"exit {code}" + (f", {lines[-1][:60]}" if lines and code not in (0, -9) else "")
    REPORT.add(f"{command} {process} {sig}", "bit-identical" if same else "differs")
    TABLE.append(
        f"  {sig:7s} {process:6s} {command:11s} {outcome}; processes left: {len(left)}; "
        f"rerun: exit {again}, {'bit-identical' if same else 'DIFFERS'}"
    )
    assert same, f"{where}: the resumed outputs differ from an uninterrupted run's"
