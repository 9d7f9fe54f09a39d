"""What the commands share: the ``--set`` and ``--out`` options, the check of an output folder, the
types of numeric options (ranges checked when the command line is read), scenario loading with the
overrides, the default output folder ``runs/<scene>/...`` and the exit codes."""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

__all__ = [
    "EXIT_FAILED",
    "EXIT_INTERRUPTED",
    "OutOfRange",
    "EXIT_OK",
    "EXIT_SIMULATION",
    "EXIT_TERMINATED",
    "EXIT_USAGE",
    "add_executor",
    "add_out",
    "add_overwrite",
    "add_set",
    "add_wall_limit",
    "check_options",
    "check_wall_time",
    "check_out",
    "default_out",
    "load",
    "number",
    "scenario_labels",
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
EXIT_TERMINATED = 143
"""Stopped by SIGTERM (``kill PID``), with the same clean stop as Ctrl-C (128 + 15)."""


def add_set(parser: argparse.ArgumentParser, help: str) -> None:
    """``--set KEY=VALUE`` (repeatable) into ``args.overrides``."""
    parser.add_argument(
        "--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE", help=help
    )


MAX_WORKERS = 256
"""Largest --workers of a study command."""


def add_executor(parser: argparse.ArgumentParser) -> None:
    """``--workers N`` and ``--scheduler ADDRESS``: where a study runs (gearbody.studies.executors)."""
    parser.add_argument(
        "--workers",
        type=number(whole=True, ge=1, le=MAX_WORKERS),
        metavar="N",
        help="local processes (default: all cores; 1: serial)",
    )
    parser.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on a Dask cluster, e.g. tcp://host:8786 (needs: pip install gearbody[sweep])",
    )


DEFAULT_MAX_WALL_MINUTES = 30.0
"""The command line refuses a run or study estimated above this many minutes of wall time unless
--max-wall-minutes allows more (gearbody.assembly.wall_time): 100x the longest shipped scene at its
own t_end (planetary, 15 s), above every documented example, and below the 60 s of the planetary scene
(estimated ~53 min) that used to start unannounced; an estimate above a minute is printed. Within the
estimate's factor of ~2 a run of 15-60 min may be refused or let through."""


def add_wall_limit(parser: argparse.ArgumentParser, what: str) -> None:
    """``--max-wall-minutes MIN`` into ``args.max_wall_minutes`` (default DEFAULT_MAX_WALL_MINUTES)."""
    parser.add_argument(
        "--max-wall-minutes",
        type=number(gt=0),
        default=DEFAULT_MAX_WALL_MINUTES,
        metavar="MIN",
        help=f"refuse {what} estimated to take more than MIN minutes of wall time, before anything runs "
        f"(default {DEFAULT_MAX_WALL_MINUTES:g}; an estimate above a minute is printed; a run can also "
        "be stopped while it runs at solver.wall_time_limit_s)",
    )


def check_wall_time(scenario, args) -> None:
    """Before a run: its estimated wall time (gearbody.assembly.wall_time) printed on stderr when above
    a minute (unless ``args.quiet``), and an InputError above ``args.max_wall_minutes``."""
    from gearbody.assembly.stiff_modes import check_resolved_modes
    from gearbody.assembly.wall_time import duration_text, estimate_wall_time, refusal
    from gearbody.errors import InputError

    check_resolved_modes(scenario)  # an absurdly stiff coordinate is named as the cause, not the time
    est = estimate_wall_time(scenario)
    detail = (
        f"{est.simulated_s:g} s simulated at {duration_text(est.wall_per_simulated_s)} per simulated second"
    )
    message = refusal(est.wall_s, args.max_wall_minutes, "the run", "shorten operation.t_end_s (--t-end)")
    if message:
        raise InputError(f"{message} ({detail})")
    if est.wall_s > 60 and not args.quiet:
        print(f"estimated wall time {duration_text(est.wall_s)} ({detail})", file=sys.stderr)


def add_out(parser: argparse.ArgumentParser, help: str, required: bool = False) -> None:
    """``--out DIR`` into ``args.out`` (a Path)."""
    parser.add_argument("--out", type=Path, required=required, metavar="DIR", help=help)


def add_overwrite(parser: argparse.ArgumentParser, same: str) -> None:
    """``--overwrite`` into ``args.overwrite``; ``same`` says what makes a folder hold "the same run"."""
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="replace what DIR holds: its gearbody outputs are removed first (files other programs wrote "
        f"stay). Without it DIR must be empty, or hold the same {same}; anything else is refused",
    )


def scenario_overrides(args) -> list[str]:
    """The --set overrides, plus operation.t_end_s from --t-end when given."""
    overrides = list(args.overrides)
    if getattr(args, "t_end", None) is not None:
        overrides.append(f"operation.t_end_s={args.t_end!r}")
    return overrides


def scenario_labels(args) -> list[str]:
    """How the user typed each of :func:`scenario_overrides` (``--set KEY=VALUE``, ``--t-end X``)."""
    from gearbody.model.io import override_label

    labels = [override_label(o) for o in args.overrides]
    if getattr(args, "t_end", None) is not None:
        labels.append(f"--t-end {args.t_end!r}")
    return labels


def load(scene: str, overrides: list[str], labels: list[str] | None = None):
    """The scenario of a scene name or TOML path with the overrides (ScenarioError if invalid, naming
    the override as typed: ``labels``, one per override, default ``--set KEY=VALUE``)."""
    from gearbody.model import load_scenario

    return load_scenario(scene, overrides, labels)


def default_out(scene: str, *parts: str) -> Path:
    """``runs/<scene name or TOML file stem>/<parts>``."""
    name = Path(scene).stem if scene.endswith(".toml") else scene
    return Path("runs", name, *parts)


def usage_error(command: str, message: str) -> int:
    """Print ``gearbody <command>: <message>`` on stderr; returns EXIT_USAGE."""
    print(f"gearbody {command}: {message}", file=sys.stderr)
    return EXIT_USAGE


def check_out(path: Path, option: str = "--out") -> Path:
    """``path`` if it is a folder this process can write in, or one it can create; else an InputError
    naming the option, the path and the reason (before any work is done).

    Writability is tried, not read from permission bits (root ignores those): a probe folder is made
    and removed in ``path`` or in its nearest existing parent. Nothing else is created.
    """
    from gearbody.errors import InputError

    path = Path(path)
    shown = f"{option} {path}"
    try:  # a name the system cannot even look up (too long) is refused with its reason
        if path.is_symlink() and not path.exists():
            raise InputError(f"{shown}: a broken symbolic link, not a folder")
        if path.exists() and not path.is_dir():
            raise InputError(f"{shown}: is a file, not a folder")
        base = path
        while not base.exists() and not base.is_symlink() and base.parent != base:
            base = base.parent
        if not base.is_dir():
            raise InputError(f"{shown}: {base} is a file, not a folder")
    except OSError as exc:
        raise InputError(f"{shown}: cannot be used: {exc.strerror or exc}") from None
    try:
        os.rmdir(tempfile.mkdtemp(prefix=".gearbody-probe-", dir=base))
    except OSError as exc:
        where = "in it" if base == path else f"in {base}"
        raise InputError(f"{shown}: cannot write {where}: {exc.strerror or exc}") from None
    return path


@dataclass(frozen=True)
class OutOfRange:
    """An option's value that parsed but lies outside its range (refused by :func:`check_options`)."""

    text: str
    allowed: str


def number(
    *,
    whole: bool = False,
    ge: float | None = None,
    gt: float | None = None,
    le: float | None = None,
) -> Callable[[str], float | OutOfRange]:
    """An argparse ``type``: the option's text as a finite float (or an int with ``whole``) in the
    range. Text that is no number is argparse's usage error; a number out of range (NaN and
    infinities included) is kept as :class:`OutOfRange` and refused by :func:`check_options`, before
    the command runs, as ``--option = value: must be ...`` (exit 2)."""
    parts = [f">= {ge:g}" if ge is not None else "", f"> {gt:g}" if gt is not None else ""]
    parts.append(f"<= {le:g}" if le is not None else "")
    bounds = " and ".join(p for p in parts if p)
    what = ("a whole number" if whole else "a finite number") + (f" {bounds}" if bounds else "")

    def convert(text: str) -> float | OutOfRange:
        try:
            value = int(text) if whole else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be {what}, got {text!r}") from None
        ok = math.isfinite(value) and (ge is None or value >= ge) and (gt is None or value > gt)
        return value if ok and (le is None or value <= le) else OutOfRange(text.strip(), what)

    convert.__name__ = "whole number" if whole else "number"  # argparse names the type in messages
    return convert


def check_options(args: argparse.Namespace) -> None:
    """InputError naming the first option whose value is out of its range (see :func:`number`)."""
    from gearbody.errors import InputError

    for dest, value in vars(args).items():
        if isinstance(value, OutOfRange):
            option = "--" + dest.replace("_", "-")
            raise InputError(f"{option} = {value.text}: must be {value.allowed}")


def warn_if_backwards(result) -> None:
    """One line on stderr when a rotation of the run turned against its driven direction (an overrunning
    load is never silent; the summary carries the details: ``turned_backwards*``, ``*_driven_speed_min``)."""
    line = result.rotation_directions().message()
    if line:
        print(f"gearbody: warning: {line}", file=sys.stderr)
