"""Command line: ``gearbody list | run | modes | mesh | validate | sweep | sensitivity | calibrate | render``.

One module per command (``register(sub)`` adds its parser, ``execute(args)`` runs it; heavy imports
happen inside ``execute``), the shared options and exit codes in :mod:`.common`. Exit codes: 0 ok,
1 something failed (validation, sweep cases), 2 bad input (invalid scenario or option), 3 simulation
failed, 130 interrupted (Ctrl-C: one line, no traceback).
"""

from __future__ import annotations

import argparse
import sys

from . import calibrate, listing, mesh, modes, render, run, sensitivity, sweep, validate
from .common import EXIT_INTERRUPTED

__all__ = ["main"]

EPILOG = """examples:
  gearbody list
  gearbody run one-stage --out runs/one-stage
  gearbody run one-stage --set production.error_mode.e_um=15 --out runs/one-stage-e15
  gearbody run my-drive.toml --t-end 1.0 --out runs/mine
  gearbody modes one-stage
  gearbody mesh one-stage-geometry --set 'condition.damaged_teeth=[{gear="pinion",tooth=0,crack_depth_mm=2}]'
  gearbody validate one-stage
  gearbody render industrial-two-stage --frames 100 --out runs/pictures
  gearbody render one-stage --result runs/one-stage --view front --frame gears
"""

COMMANDS = (listing, run, modes, mesh, validate, sweep, sensitivity, calibrate, render)
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


def main(argv: list[str] | None = None) -> int:
    from gearbody.errors import GearbodyError, ScenarioError, SimulationError

    from .common import check_options

    args = _parser().parse_args(argv)
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
    except KeyboardInterrupt as exc:  # a study says how far it got (StudyInterrupted)
        print(str(exc) or f"interrupted: gearbody {args.command} stopped", file=sys.stderr)
        return EXIT_INTERRUPTED
