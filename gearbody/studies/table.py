"""What a study produced, as a table: one row per case (id, varied values, status, summary values or
the error) for ``OUT/summary.csv``, the short text table of ``gearbody sweep``, and
:class:`StudyResult`."""

from __future__ import annotations

import csv
import io
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .parse import SweepSpecError
from .spec import Case
from .store import case_state, write_text

__all__ = [
    "DEFAULT_PLOT_VALUE",
    "SUMMARY_COLUMNS",
    "StudyResult",
    "check_plot_value",
    "collect_rows",
    "write_csv",
]

DEFAULT_PLOT_VALUE = "kd_max_final"
# Scalar summary values, in the order of summary.csv's columns (summarize() + the case wall time).
SUMMARY_COLUMNS = (
    "kd_max",
    "kd_min",
    "kd_max_final",
    "kd_mean_final",
    "kd_above_2",
    "separation_fraction",
    "contact_losses",
    "mesh_frequency_hz",
    "mean_speed_rad_s",
    "rated_mesh_force_N",
    "simulated_time_s",
    "solver_steps",
    "solver_rejected_steps",
    "wall_s_per_simulated_s",
    "wall_time_s",
)
_LATERAL_VALUE = re.compile(r"^\w+_(bearing_force_[xy]_max_N|housing_accel_[xy]_rms_final_m_s2)$")


@dataclass
class StudyResult:
    """What a study produced (everything is also on disk in ``out_dir``)."""

    out_dir: Path
    keys: list[str]
    """Varied keys, in column order."""
    rows: list[dict[str, Any]]
    """One per case, as in summary.csv: id, each key's value, status, summary values, error."""
    ran: int
    """Cases run by this call."""
    skipped: int
    """Cases found done on disk (resume)."""
    csv_path: Path
    plot_path: Path | None
    plot_value: str = DEFAULT_PLOT_VALUE

    @property
    def n_ok(self) -> int:
        return sum(r["status"] == "ok" for r in self.rows)

    @property
    def n_failed(self) -> int:
        return sum(r["status"] == "failed" for r in self.rows)

    @property
    def all_ok(self) -> bool:
        return self.n_ok == len(self.rows)

    def table(self, max_rows: int = 30) -> str:
        """A short text table: id, varied values, status and the plotted value."""
        cols = ["id", *self.keys, "status", self.plot_value]
        cells = [[_cell(r.get(c)) for c in cols] for r in self.rows[:max_rows]]
        widths = [max(len(c), *(len(row[i]) for row in cells)) for i, c in enumerate(cols)]
        lines = ["  ".join(c.ljust(w) for c, w in zip(cols, widths, strict=True))]
        lines += ["  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)) for row in cells]
        if len(self.rows) > max_rows:
            lines.append(f"... {len(self.rows) - max_rows} more cases in {self.csv_path}")
        lines.append(
            f"{self.n_ok} ok, {self.n_failed} failed of {len(self.rows)} cases "
            f"({self.ran} run now, {self.skipped} done before); {self.csv_path}"
            + (f", {self.plot_path}" if self.plot_path else "")
        )
        return "\n".join(lines)


def _cell(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def _csv_value(v: Any, text: str) -> Any:
    return v if isinstance(v, (bool, int, float, str)) else text


def collect_rows(out: Path, cases: list[Case], keys: list[str]) -> tuple[list[dict], list[str]]:
    rows, extra = [], []
    for case in cases:
        status, data = case_state(out / "cases" / case.id)
        row: dict[str, Any] = {"id": case.id}
        row.update({k: _csv_value(case.values[k], case.texts[k]) for k in keys})
        row["status"] = status if status != "pending" else "not run"
        if status == "ok":
            for k, v in data.items():
                if k in SUMMARY_COLUMNS or (_LATERAL_VALUE.match(k) and isinstance(v, (int, float))):
                    row[k] = v
                    if k not in SUMMARY_COLUMNS and k not in extra:
                        extra.append(k)
        elif status == "failed":
            row["error"] = f"{data.get('error_type')}: {data.get('message', '')}".splitlines()[0]
        rows.append(row)
    return rows, [*SUMMARY_COLUMNS, *sorted(extra)]


def write_csv(path: Path, rows: list[dict], columns: list[str]) -> Path:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=columns, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in row.items()})
    return write_text(path, buf.getvalue())


def check_plot_value(value: str) -> None:
    if value not in SUMMARY_COLUMNS and not _LATERAL_VALUE.match(value):
        raise SweepSpecError(
            f"--plot-value {value}: not a summary value; one of {', '.join(SUMMARY_COLUMNS)} "
            "(lateral scenes also <gear>_bearing_force_<x|y>_max_N, ...)"
        )
