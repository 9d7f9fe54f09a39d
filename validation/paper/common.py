"""Shared pieces of the reproduction scripts: claims, the results files and where they are written.

Each script ``figs_*.py`` checks the paper's claims for one figure group with ONE documented
parameter set per system (the shipped scenes; nothing is tuned per claim) and writes
``results/<name>.md`` (claims table) and its figures next to it, in the output folder
(:func:`resolve_output_dir`). ``python -m gearbody_validation.paper.run_all`` runs them all and
regenerates RESULTS.md there.

The checkout's ``validation/paper`` is the record (RESULTS.md is committed): it takes full runs only,
``--quick`` is refused there (exit 2) and allowed with ``--out DIR``, where what it writes says
"QUICK". Outside a checkout the default output folder is ``./paper-validation``: an installed package
is never written into.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

DEFAULT_OUT = "paper-validation"
"""Output folder (in the current directory) when the command runs outside a checkout."""

QUICK_LABEL = "QUICK run, fewer points or a shorter record: not the reproduction"


class OutputRefused(Exception):
    """An output the record may not take (``--quick`` into the checkout's validation/paper)."""


def checkout_paper_dir(root: Path) -> Path | None:
    """``root/validation/paper`` if ``root`` is a gearbody checkout (pyproject.toml and the scripts)."""
    here = Path(root) / "validation" / "paper"
    if (Path(root) / "pyproject.toml").is_file() and (here / "run_all.py").is_file():
        return here
    return None


def is_record(folder: Path) -> bool:
    """Is ``folder`` a checkout's validation/paper (the committed record)?"""
    folder = Path(folder).resolve()
    found = checkout_paper_dir(folder.parents[1]) if len(folder.parents) > 1 else None
    return found is not None and found.resolve() == folder


def resolve_output_dir(out: str | Path | None = None, cwd: str | Path | None = None) -> Path:
    """Where the scripts write: ``out`` if given; else validation/paper of the checkout the command runs
    in (``cwd``, default the current directory); else ``cwd/paper-validation``. Never into the installed
    package (site-packages), nor into a checkout the command does not run in."""
    if out is not None:
        return Path(out)
    cwd = Path.cwd() if cwd is None else Path(cwd)
    found = checkout_paper_dir(cwd)
    return found if found is not None else cwd / DEFAULT_OUT


_OUTPUT: dict[str, Path] = {}


def output_dir() -> Path:
    """The output folder: the one :func:`configure` set, else :func:`resolve_output_dir`'s default."""
    if "dir" not in _OUTPUT:
        _OUTPUT["dir"] = resolve_output_dir()
    return _OUTPUT["dir"]


def results_dir() -> Path:
    """``results/`` of the output folder (each script's claims table, JSON and figures)."""
    return output_dir() / "results"


def configure(out: str | Path | None = None, quick: bool = False) -> Path:
    """Set the output folder (``--out``, else the default); refuse ``quick`` into the record."""
    previous = _OUTPUT.get("dir")
    _OUTPUT["dir"] = resolve_output_dir(out)
    try:
        check_quick(quick)
    except OutputRefused:
        _OUTPUT.pop("dir") if previous is None else _OUTPUT.update(dir=previous)
        raise
    return _OUTPUT["dir"]


def check_quick(quick: bool) -> None:
    """Raise OutputRefused if a quick run would write into the record (called before a script runs, and
    again before anything is written)."""
    if quick and is_record(output_dir()):
        raise OutputRefused(
            f"--quick results are not the reproduction and {output_dir()} holds full runs only; "
            "give --out DIR for a quick run"
        )


def parser(doc: str, quick_help: str | None = None) -> argparse.ArgumentParser:
    """A script's command line: ``--out DIR`` and, for a script with a quick mode, ``--quick``."""
    p = argparse.ArgumentParser(description=doc.splitlines()[0])
    if quick_help:
        p.add_argument(
            "--quick", action="store_true", help=f"{quick_help} (refused into a checkout: give --out DIR)"
        )
    p.add_argument(
        "--out",
        metavar="DIR",
        help=f"write results/ (and RESULTS.md) into DIR (default: validation/paper of the checkout the "
        f"command runs in, else ./{DEFAULT_OUT})",
    )
    return p


def start(script: str, args: argparse.Namespace) -> None:
    """Set the output folder from the parsed ``args`` and say where it is; a refused output exits 2 with
    one line on stderr, before anything runs."""
    try:
        folder = configure(args.out, getattr(args, "quick", False))
    except OutputRefused as exc:
        print(f"{script}: {exc}", file=sys.stderr)
        raise SystemExit(2) from None
    print(f"{script}: writing into {folder}")


@dataclass
class Claim:
    """One claim of the paper, checked: PASS if the measured figure supports it."""

    figure: str
    claim: str
    measured: str
    passed: bool
    note: str = ""

    def __post_init__(self):
        self.passed = bool(self.passed)  # numpy bools are not JSON


def write_results(
    name: str,
    title: str,
    claims: list[Claim],
    notes: list[str],
    figures: list[Path],
    wall_s: float,
    quick: bool = False,
) -> Path:
    """Write results/<name>.md (claims table, figures, notes) and results/<name>.json; a quick run is
    labelled in both (title, every result, ``"quick": true``); never into the record."""
    check_quick(quick)
    folder = results_dir()
    folder.mkdir(parents=True, exist_ok=True)
    heading = f"{title} ({QUICK_LABEL})" if quick else title
    lines = [f"## {heading}", "", f"Script `validation/paper/{name}.py`, {wall_s:.0f} s wall.", ""]
    lines += ["| figure | claim | measured | result |", "|---|---|---|---|"]
    for c in claims:
        result = ("PASS" if c.passed else "FAIL") + (" (quick)" if quick else "")
        note = f" ({c.note})" if c.note else ""
        lines.append(f"| {c.figure} | {c.claim} | {c.measured} | {result}{note} |")
    lines.append("")
    for note in notes:
        lines.append(f"- {note}")
    if notes:
        lines.append("")
    for fig in figures:
        lines.append(f"![{fig.stem}](results/{fig.name})")
    lines.append("")
    path = folder / f"{name}.md"
    path.write_text("\n".join(lines))
    (folder / f"{name}.json").write_text(
        json.dumps(
            {"title": title, "wall_s": wall_s, "quick": quick, "claims": [asdict(c) for c in claims]},
            indent=2,
        )
    )
    for c in claims:
        result = ("PASS" if c.passed else "FAIL") + (" (quick)" if quick else "")
        print(f"[{result}] {c.figure}: {c.claim} -- {c.measured}")
    return path


class Timer:
    def __enter__(self):
        self.t0 = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.s = time.perf_counter() - self.t0
