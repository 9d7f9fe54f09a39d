"""Command line: ``gearbody list | new | run | analyze | compare | modes | mesh | validate | sweep |
sensitivity | calibrate | render | info``.

One module per command (``register(sub)`` adds its parser, ``execute(args)`` runs it; heavy imports
happen inside ``execute``), the shared options and exit codes in :mod:`.common`. Exit codes: 0 ok,
1 something failed (validation, sweep cases, a file that cannot be written: a full disk, named in one
line), 2 bad input (invalid scenario or option, an output folder holding another run or in use by
another command), 3 simulation failed, 130 interrupted (Ctrl-C: one line, no traceback), 143 stopped by
SIGTERM (the same clean stop).

Signals: an inherited SIGINT disposition is kept (a job started with ``cmd &`` from a script ignores
Ctrl-C on purpose, and so does gearbody); SIGTERM, the way to stop such a job (``kill PID``), stops a
command as Ctrl-C does: finished cases and evaluations stay recorded and pool workers are stopped.
Pool workers also die with the command when it is killed outright (SIGKILL;
:mod:`gearbody.studies.executors`).

Time: a run or study estimates its wall time before it starts (``--max-wall-minutes``,
:func:`.common.check_wall_time`, :mod:`gearbody.studies.wall`).
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager

from . import (
    analyze,
    calibrate,
    compare,
    info,
    listing,
    mesh,
    modes,
    new,
    render,
    run,
    sensitivity,
    sweep,
    validate,
)
from .common import EXIT_FAILED, EXIT_INTERRUPTED, EXIT_TERMINATED

__all__ = ["main"]

EPILOG = """examples:
  gearbody list
  gearbody run one-stage --out runs/one-stage
  gearbody run one-stage --set production.error_mode.e_um=15 --out runs/one-stage-e15
  gearbody new one-stage --out my-drive.toml     (a commented starting scenario for your drive)
  gearbody run my-drive.toml --t-end 1.0 --out runs/mine
  gearbody modes one-stage
  gearbody mesh one-stage-geometry --set 'condition.damaged_teeth=[{gear="pinion",tooth=0,crack_depth_mm=2}]'
  gearbody validate one-stage
  gearbody render industrial-two-stage --frames 100 --out runs/pictures
  gearbody render one-stage --result runs/one-stage --view front --frame gears
  gearbody analyze logger.wav --scene one-stage --tacho tacho --out runs/measured
  gearbody compare runs/one-stage logger.wav --scene one-stage --tacho tacho
  gearbody info                                  (versions, and whether the force laws run compiled)
"""

COMMANDS = (
    listing,
    new,
    run,
    analyze,
    compare,
    modes,
    mesh,
    validate,
    sweep,
    sensitivity,
    calibrate,
    render,
    info,
)
"""In the order of ``gearbody --help``."""


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="gearbody",
        description="Gearbox vibration simulation for diagnostics (Exudyn multibody engine).",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for command in COMMANDS:
        command.register(sub)
    return p


@contextmanager
def _sigterm_stops() -> Iterator[list[int]]:
    """While the command runs, SIGTERM raises KeyboardInterrupt (the list yielded gets the signal), so
    ``kill PID`` stops it as Ctrl-C does; a SIGTERM disposition set by the caller (ignored, a handler) is
    kept, and the previous one comes back afterwards."""
    received: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield received
        return
    previous = signal.getsignal(signal.SIGTERM)
    if previous is not signal.SIG_DFL:
        yield received
        return

    def stop(signum, frame):
        received.append(signum)
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, stop)
    try:
        yield received
    finally:
        signal.signal(signal.SIGTERM, previous)


def _printable_paths() -> None:
    """A file name that is not UTF-8 (its bytes kept as surrogates by Python) is printed with backslash
    escapes: under a UTF-8 locale stdout would raise UnicodeEncodeError on it, after the work was done."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.reconfigure(errors="backslashreplace")
        except (AttributeError, ValueError):  # not a text stream of its own (a test's capture, closed)
            pass


@contextmanager
def _notes_in_one_line() -> Iterator[None]:
    """gearbody's PerformanceWarning (the force laws run through Python, slower) as one line on stderr,
    ``gearbody: note: ...``, instead of Python's warning with a file and a source line."""
    import warnings

    previous = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if category.__name__ == "PerformanceWarning":
            print(f"gearbody: note: {message}", file=sys.stderr)
        else:
            previous(message, category, filename, lineno, file, line)

    warnings.showwarning = show
    try:
        yield
    finally:
        warnings.showwarning = previous


def run() -> None:
    """The ``gearbody`` script and ``python -m gearbody.cli``: :func:`main`, then exit with its code. A
    process pool whose shutdown stuck (gearbody.studies.executors.STUCK_POOLS) would hold the
    interpreter's exit for ever: then the streams are flushed and the process leaves at once."""
    code = main()
    from gearbody.studies.executors import STUCK_POOLS

    if STUCK_POOLS:
        print(f"gearbody: {STUCK_POOLS[0]}; leaving without waiting for it", file=sys.stderr)
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    sys.exit(code)


def main(argv: list[str] | None = None) -> int:
    from gearbody.errors import GearbodyError, ScenarioError, SimulationError

    from .common import check_options

    _printable_paths()
    args = _parser().parse_args(argv)
    with _sigterm_stops() as terminated, _notes_in_one_line():
        try:
            check_options(args)
            return args.handler(args)
        except GearbodyError as exc:  # recognised by type: each error class carries its exit code
            kind = (
                "invalid scenario"
                if isinstance(exc, ScenarioError)
                else "simulation failed"
                if isinstance(exc, SimulationError)
                else "invalid input"
                if exc.exit_code == 2
                else "failed"
            )
            print(f"gearbody: {kind}: {exc}", file=sys.stderr)
            return exc.exit_code
        except OSError as exc:  # a file gearbody's writers do not name themselves: one line all the same
            where = f"{exc.filename}: " if exc.filename else ""
            print(f"gearbody: failed: {where}{exc.strerror or exc}", file=sys.stderr)
            return EXIT_FAILED
        except KeyboardInterrupt as exc:  # a study says how far it got (StudyInterrupted)
            print(str(exc) or f"interrupted: gearbody {args.command} stopped", file=sys.stderr)
            return EXIT_TERMINATED if terminated else EXIT_INTERRUPTED
