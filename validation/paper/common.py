"""Shared pieces of the reproduction scripts: claims and the results files.

Each script ``figs_*.py`` checks the paper's claims for one figure group with ONE documented
parameter set per system (the shipped scenes; nothing is tuned per claim) and writes
``validation/paper/results/<name>.md`` (claims table) and its figures next to it.
``python -m gearbody_validation.paper.run_all`` runs them all and regenerates RESULTS.md.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass
from pathlib import Path


def _output_dir() -> Path:
    """validation/paper of the checkout the command runs in (RESULTS.md belongs there), else this
    package's own folder (an editable install is the checkout)."""
    here = Path.cwd() / "validation" / "paper"
    if (Path.cwd() / "pyproject.toml").is_file() and (here / "run_all.py").is_file():
        return here
    return Path(__file__).resolve().parent


HERE = _output_dir()
RESULTS_DIR = HERE / "results"


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
    name: str, title: str, claims: list[Claim], notes: list[str], figures: list[Path], wall_s: float
) -> Path:
    """Write results/<name>.md (claims table, figures, notes) and results/<name>.json."""
    RESULTS_DIR.mkdir(parents=True, exist_ok=True)
    lines = [f"## {title}", "", f"Script `validation/paper/{name}.py`, {wall_s:.0f} s wall.", ""]
    lines += ["| figure | claim | measured | result |", "|---|---|---|---|"]
    for c in claims:
        result = "PASS" if c.passed else "FAIL"
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
    path = RESULTS_DIR / f"{name}.md"
    path.write_text("\n".join(lines))
    (RESULTS_DIR / f"{name}.json").write_text(
        json.dumps({"title": title, "wall_s": wall_s, "claims": [asdict(c) for c in claims]}, indent=2)
    )
    for c in claims:
        print(f"[{'PASS' if c.passed else 'FAIL'}] {c.figure}: {c.claim} -- {c.measured}")
    return path


class Timer:
    def __enter__(self):
        self.t0 = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.s = time.perf_counter() - self.t0
