"""What the fuzzers share (tests/test_fuzz_*.py): Hypothesis settings whose draws do not depend on how
pytest is invoked, the scale, the outcome report, and a bounded runner of ``gearbody`` command lines.

Determinism: every fuzzer runs with ``derandomize=True`` (the seed is a digest of the test function)
and no example database, and Hypothesis's mining of constants from the local source code is switched
off (:func:`switch_off_local_constants`): since Hypothesis 6.131 a draw may pick a number or string
found in any local module imported so far, so the draws changed with the test files collected before
(``pytest tests/test_fuzz_cli.py`` and ``pytest`` drew different inputs).

Scale: ``GEARBODY_FUZZ_SCALE`` (default 1, what CI runs) multiplies every fuzzer's example count.
``GEARBODY_FUZZ_REPORT=path``: the outcome counts of every fuzzer run are merged into that JSON file
(one row per fuzzer, input kind and outcome); ``GEARBODY_FUZZ_LOG=path``: every command line run, its
outcome and the last line it printed, appended there as JSON lines.

Command lines run in :class:`CommandRunner`: one Python process that calls ``gearbody.cli.main`` on
each command line in a fresh folder, its stdout and stderr caught at the file descriptors, bounded in
time (a command that has not answered within its bound is a hang: the process group is killed) and in
memory. Every failure message carries the command line that reproduces it (:func:`reproduce`).
"""

from __future__ import annotations

import json
import os
import re
import resource
import select
import shlex
import shutil
import signal
import subprocess
import sys
from collections import Counter
from pathlib import Path
from typing import Any

from hypothesis import HealthCheck, Phase, settings

ROOT = Path(__file__).resolve().parents[1]
SCALE = float(os.environ.get("GEARBODY_FUZZ_SCALE", "1"))
MEMORY_BYTES = 3 * 2**30
"""Address-space cap of a runner process (a command that would allocate without bound dies instead)."""


def switch_off_local_constants() -> bool:
    """Stop Hypothesis from drawing constants mined from local modules (those imported so far differ with
    the tests collected); returns whether this Hypothesis has the mining. Its global constants (0, 1,
    NaN, ...) stay: they are the same on every invocation."""
    try:
        from hypothesis.internal.conjecture import providers
    except ImportError:  # pragma: no cover - an older Hypothesis: no mining
        return False
    if not hasattr(providers, "_get_local_constants"):
        return False
    global ORIGINAL_LOCAL_CONSTANTS
    ORIGINAL_LOCAL_CONSTANTS = providers._get_local_constants
    empty = providers.Constants()
    providers._get_local_constants = lambda: empty
    cache = getattr(providers, "CONSTANTS_CACHE", None)
    if cache is not None and hasattr(cache, "cache"):
        cache.cache.clear()
    return True


ORIGINAL_LOCAL_CONSTANTS = None
"""Hypothesis's own mining function (the control of tests/test_fuzz_determinism.py)."""
LOCAL_CONSTANTS_SWITCHED_OFF = switch_off_local_constants()


def leaves(data: Any, prefix: str = "") -> dict[str, Any]:
    """Dotted key -> value of every number (not bool) in a nested dict, list items numbered from 1."""
    out = {}
    items = data.items() if isinstance(data, dict) else ((str(i + 1), v) for i, v in enumerate(data))
    for k, v in items:
        if isinstance(v, (dict, list)):
            out.update(leaves(v, f"{prefix}{k}."))
        elif isinstance(v, (int, float)) and not isinstance(v, bool):
            out[f"{prefix}{k}"] = v
    return out


def examples(count: int) -> int:
    """``count`` examples at GEARBODY_FUZZ_SCALE (at least 1)."""
    return max(1, round(count * SCALE))


def fuzz_settings(count: int, *, shrink: bool = True):
    """Hypothesis settings of a fuzzer: ``count`` examples (scaled), derandomized, no database, no
    deadline; ``shrink=False`` for examples that each run a command or a simulation (a shrink step is
    another run: the first failure is reported as drawn, with its reproducing command line)."""
    phases = list(Phase) if shrink else [Phase.explicit, Phase.reuse, Phase.generate]
    return settings(
        max_examples=examples(count),
        deadline=None,
        derandomize=True,
        database=None,
        phases=phases,
        suppress_health_check=list(HealthCheck),
    )


class Report:
    """Outcome counts of one fuzzer, merged into GEARBODY_FUZZ_REPORT by :meth:`write`."""

    def __init__(self, fuzzer: str) -> None:
        self.fuzzer = fuzzer
        self.counts: Counter[tuple[str, str]] = Counter()

    def add(self, kind: str, outcome: str) -> None:
        self.counts[kind, outcome] += 1

    def write(self) -> None:
        path = os.environ.get("GEARBODY_FUZZ_REPORT")
        if not path or not self.counts:
            return
        try:
            rows = json.loads(Path(path).read_text())
        except (OSError, ValueError):
            rows = []
        rows = [r for r in rows if r.get("fuzzer") != self.fuzzer]
        rows += [
            {"fuzzer": self.fuzzer, "input": k, "outcome": o, "examples": n}
            for (k, o), n in sorted(self.counts.items())
        ]
        Path(path).write_text(json.dumps(rows, indent=1) + "\n")

    def line(self) -> str:
        by_outcome: Counter[str] = Counter()
        for (_, o), n in self.counts.items():
            by_outcome[o] += n
        return f"{self.fuzzer}: {sum(by_outcome.values())} inputs, {dict(sorted(by_outcome.items()))}"


def print_line(request, text: str) -> None:
    """``text`` on the terminal, past pytest's capture (the counts of a fuzzer run)."""
    reporter = request.config.pluginmanager.get_plugin("terminalreporter")
    capture = request.config.pluginmanager.get_plugin("capturemanager")
    if reporter is not None and capture is not None:
        with capture.global_and_fixture_disabled():
            reporter.write_line(text)


# -- command lines -----------------------------------------------------------------------------------

WORKER = r"""
import json, os, signal, sys, time, traceback
reply = os.fdopen(os.dup(1), "w")
os.environ.setdefault("MPLBACKEND", "Agg")
from gearbody.cli import main
for fd in (0,):
    null = os.open(os.devnull, os.O_RDONLY)
    os.dup2(null, fd)
# stdout as a UTF-8 locale other than C gives it: strict (a C locale would escape what it cannot encode)
sys.stdout.reconfigure(errors="strict")
reply.write("ready\n"); reply.flush()
home = os.getcwd()
for line in open(int(sys.argv[1])):
    case = json.loads(line)
    os.chdir(case["cwd"])
    saved = [os.dup(1), os.dup(2)]
    out = os.open("stdout.txt", os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    err = os.open("stderr.txt", os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    os.dup2(out, 1); os.dup2(err, 2); os.close(out); os.close(err)
    argv = [a.encode("utf-8", "surrogateescape").decode("utf-8", "surrogateescape") for a in case["argv"]]
    t0 = time.perf_counter()
    crash = None
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse
        code = exc.code if isinstance(exc.code, int) else 1
    except BaseException:  # noqa: BLE001 - a traceback a user would see
        code = "traceback"
        crash = traceback.format_exc()
    wall = time.perf_counter() - t0
    sys.stdout.flush(); sys.stderr.flush()
    os.dup2(saved[0], 1); os.dup2(saved[1], 2); os.close(saved[0]); os.close(saved[1])
    children = []
    deadline = time.monotonic() + 5.0
    while True:  # processes the command started and left behind (pool workers)
        children = []
        for task in os.listdir(f"/proc/{os.getpid()}/task"):
            try:
                with open(f"/proc/{os.getpid()}/task/{task}/children") as f:
                    children += [int(p) for p in f.read().split()]
            except OSError:
                pass
        alive = []
        for pid in children:
            try:
                pid_done, _ = os.waitpid(pid, os.WNOHANG)
            except ChildProcessError:
                pid_done = pid
            if not pid_done:
                alive.append(pid)
        if not alive or time.monotonic() > deadline:
            break
        time.sleep(0.05)
    for pid in alive:
        os.kill(pid, signal.SIGKILL)
    os.chdir(home)
    reply.write(json.dumps({"code": code, "wall_s": wall, "crash": crash, "left": alive}) + "\n")
    reply.flush()
"""


def _limit_memory() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_BYTES, MEMORY_BYTES))


class CommandRunner:
    """A process that runs ``gearbody`` command lines (``gearbody.cli.main``) one after another, each in
    its own folder and within ``timeout_s``; it is restarted after a hang, a crash of the interpreter
    or ``restart_every`` commands (state a command might leave behind does not pile up)."""

    def __init__(self, sandbox: Path, timeout_s: float = 120.0, restart_every: int = 150) -> None:
        self.sandbox = Path(sandbox)
        self.timeout_s = timeout_s
        self.restart_every = restart_every
        self.proc: subprocess.Popen | None = None
        self.served = 0
        self.count = 0

    def _start(self) -> None:
        read_end, self._send = os.pipe()
        env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg", "COLUMNS": "100"}
        env.pop("DISPLAY", None)
        self.proc = subprocess.Popen(
            [sys.executable, "-c", WORKER, str(read_end)],
            stdout=subprocess.PIPE,
            stderr=open(self.sandbox / "runner-stderr.txt", "a"),  # noqa: SIM115 - lives with the process
            text=True,
            env=env,
            cwd=self.sandbox,
            pass_fds=(read_end,),
            preexec_fn=_limit_memory,
            start_new_session=True,  # its pool workers are in its process group: killed with it
        )
        os.close(read_end)
        self.served = 0
        line = self._read(300.0)
        if line != "ready":
            self.stop()
            raise RuntimeError(f"the command runner did not start: {line!r}")

    def _read(self, timeout_s: float) -> str | None:
        ready, _, _ = select.select([self.proc.stdout], [], [], timeout_s)
        return self.proc.stdout.readline().strip() if ready else None

    def stop(self) -> None:
        if self.proc is not None:
            try:
                os.killpg(self.proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            self.proc.wait()
            os.close(self._send)
            self.proc = None

    def folder(self) -> Path:
        """A fresh empty folder for the next command (its working directory)."""
        self.count += 1
        path = self.sandbox / f"case-{self.count:05d}"
        if path.exists():
            shutil.rmtree(path)
        path.mkdir()
        return path

    def run(self, argv: list[str], cwd: Path, timeout_s: float | None = None) -> Outcome:
        """Run ``gearbody *argv`` in ``cwd``; its :class:`Outcome`."""
        if self.proc is None or self.proc.poll() is not None or self.served >= self.restart_every:
            self.stop()
            self._start()
        self.served += 1
        os.write(self._send, (json.dumps({"argv": argv, "cwd": str(cwd)}) + "\n").encode())
        bound = timeout_s or self.timeout_s
        line = self._read(bound)
        if not line:
            died = self.proc.poll()
            self.stop()
            kind = "hang" if died is None else "died"
            answer = {"code": kind, "wall_s": bound, "crash": f"no answer ({kind}, exit {died})", "left": []}
        else:
            answer = json.loads(line)
        read = lambda name: (cwd / name).read_text(errors="replace") if (cwd / name).exists() else ""  # noqa: E731
        return Outcome(argv, cwd, answer["code"], read("stdout.txt"), read("stderr.txt"), answer)


ONE_LINE_CODES = {2: "refused", 3: "numerical failure", 1: "failed"}
USAGE_ERROR = re.compile(r"^gearbody(?: [\w-]+)?: error: .+")
PROGRESS = re.compile(r"\d+%\||it/s\]|s/it\]|sim(?: |$)|\d+/\d+ \[")
PYTHON_WARNING = re.compile(r"^\S+\.py:\d+: \w*Warning: ")


def reproduce(argv: list[str], cwd: Path | None = None, setup: str = "") -> str:
    """The shell command line that reproduces a run: ``cd DIR && gearbody ARGS`` (and how its files
    were made)."""
    line = "gearbody " + " ".join(shlex.quote(a) for a in argv)
    where = f"cd {shlex.quote(str(cwd))} && " if cwd is not None else ""
    return where + line + (f"   [files: {setup}]" if setup else "")


class Outcome:
    """What a command line did: its exit code (or 'traceback', 'hang', 'died'), stdout, stderr."""

    def __init__(self, argv, cwd, code, stdout: str, stderr: str, answer: dict) -> None:
        self.argv, self.cwd, self.code = argv, cwd, code
        self.stdout, self.stderr = stdout, stderr
        self.wall_s = answer.get("wall_s", 0.0)
        self.crash = answer.get("crash")
        self.left = answer.get("left", [])

    def lines(self) -> list[str]:
        """stderr's lines, progress-bar redraws and blank lines left out."""
        out = []
        for raw in self.stderr.splitlines():
            last = raw.split("\r")[-1].strip()
            if last and not PROGRESS.search(last):
                out.append(last)
        return out

    def kind(self) -> str:
        """ok | usage | refused | numerical failure | failed, or what is wrong: traceback, hang, died,
        left processes, several lines, a Python warning, exit code N."""
        if self.code in ("traceback", "hang", "died"):
            return self.code
        if "Traceback (most recent call last)" in self.stderr + self.stdout:
            return "traceback"
        if self.left:
            return "left processes"
        lines = self.lines()
        if any(PYTHON_WARNING.match(line) for line in lines):
            return "python warning"
        if self.code == 0:
            return "ok"
        if self.code == 2 and self.stderr.startswith("usage: "):  # argparse: usage, then its error
            errors = [line for line in self.stderr.splitlines() if USAGE_ERROR.match(line)]
            return "usage" if len(errors) == 1 else "several lines"  # (its text may echo a newline typed)
        if self.code in ONE_LINE_CODES:
            gearbody = [line for line in lines if not line.startswith("gearbody: warning: ")]
            if self.code == 1 and self.argv[:1] in (["validate"], ["sweep"], ["sensitivity"], ["calibrate"]):
                return "failed" if len(gearbody) <= 1 else "several lines"  # a table on stdout
            if len(gearbody) == 1 and gearbody[0].startswith("gearbody"):
                return ONE_LINE_CODES[self.code]
            return "several lines"
        return f"exit code {self.code}"

    def log(self, setup: str = "") -> None:
        """With GEARBODY_FUZZ_LOG=path: one JSON line per command line appended there (for reading)."""
        path = os.environ.get("GEARBODY_FUZZ_LOG")
        if path:
            lines = self.lines()
            row = {
                "kind": self.kind(),
                "code": self.code,
                "wall_s": round(self.wall_s, 3),
                "argv": reproduce(self.argv, None, setup),
                "last": lines[-1][:300] if lines else "",
            }
            with open(path, "a") as f:
                f.write(json.dumps(row) + "\n")

    def describe(self, setup: str = "") -> str:
        tail = (self.crash or self.stderr)[-3000:]
        return f"{reproduce(self.argv, self.cwd, setup)}\n-> {self.kind()} (exit {self.code}):\n{tail}"


GOOD = {"ok", "usage", "refused", "numerical failure", "failed"}
"""The outcome kinds a command line may end in (exit 0, 2 with argparse's usage or one line, 3 with one
line, 1 where documented); anything else is a finding."""


def runner_fixture(name: str, report: Report):
    """A module-scoped ``runner`` fixture: a :class:`CommandRunner` in a fresh folder ``name``, stopped
    at the module's end, when ``report``'s counts are written and printed."""
    import pytest

    @pytest.fixture(scope="module")
    def runner(tmp_path_factory, request):
        r = CommandRunner(tmp_path_factory.mktemp(name))
        yield r
        r.stop()
        report.write()
        print_line(request, "\n" + report.line())

    return runner
