"""What the commands share: the ``--set`` and ``--out`` options, scenario loading with the overrides,
the default output folder ``runs/<scene>/...`` and the exit codes."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = [
    "EXIT_FAILED",
    "EXIT_INTERRUPTED",
    "EXIT_OK",
    "EXIT_SIMULATION",
    "EXIT_USAGE",
    "add_out",
    "add_set",
    "default_out",
    "load",
    "scenario_overrides",
    "usage_error",
]

EXIT_OK = 0
EXIT_FAILED = 1
"""Ran, but something failed: validation above tolerance, failed cases of a sweep."""
EXIT_USAGE = 2
"""Bad input: invalid scenario or option value (also argparse's own code)."""
EXIT_SIMULATION = 3
"""The simulation failed (SimulationError)."""
EXIT_INTERRUPTED = 130
"""Stopped by Ctrl-C (SIGINT), as a shell reports a process killed by SIGINT (128 + 2)."""


def add_set(parser: argparse.ArgumentParser, help: str) -> None:
    """``--set KEY=VALUE`` (repeatable) into ``args.overrides``."""
    parser.add_argument(
        "--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE", help=help
    )


def add_out(parser: argparse.ArgumentParser, help: str, required: bool = False) -> None:
    """``--out DIR`` into ``args.out`` (a Path)."""
    parser.add_argument("--out", type=Path, required=required, metavar="DIR", help=help)


def scenario_overrides(args) -> list[str]:
    """The --set overrides, plus operation.t_end_s from --t-end when given."""
    overrides = list(args.overrides)
    if args.t_end is not None:
        overrides.append(f"operation.t_end_s={args.t_end!r}")
    return overrides


def load(scene: str, overrides: list[str]):
    """The scenario of a scene name or TOML path with the overrides (ScenarioError if invalid)."""
    from gearbody.model import load_scenario

    return load_scenario(scene, overrides)


def default_out(scene: str, *parts: str) -> Path:
    """``runs/<scene name or TOML file stem>/<parts>``."""
    name = Path(scene).stem if scene.endswith(".toml") else scene
    return Path("runs", name, *parts)


def usage_error(command: str, message: str) -> int:
    """Print ``gearbody <command>: <message>`` on stderr; returns EXIT_USAGE."""
    print(f"gearbody {command}: {message}", file=sys.stderr)
    return EXIT_USAGE
