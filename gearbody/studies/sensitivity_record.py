"""The record of a sensitivity analysis (:mod:`gearbody.studies.sensitivity`) in its ``OUT`` folder:
``sensitivity.json`` (format, spec, sample matrix), ``evaluations/<job>.json`` per job, the indices
computed from the recorded rows (:class:`SensitivityResult`) and the files they are written to
(``indices.csv``, ``indices.md``, ``indices.json``, ``indices.png``)."""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gearbody.errors import StudyError
from gearbody.version import __version__

from .parse import SweepSpecError
from .sensitivity_methods import INDEX_NAMES, analyse_rows
from .store import read_json, write_json, write_text

FORMAT = "gearbody-sensitivity/1"


class MissingRowsError(StudyError):
    """Indices cannot be computed: some rows failed or have no finite value (exit code 1). Every
    evaluation is recorded; the message names the rows and the first causes."""

    exit_code = 1


_ADVICE = "give --overwrite to replace it, or choose another --out"


def prepare_out(out: Path, spec: dict[str, Any], X: np.ndarray) -> None:
    """Create OUT/sensitivity.json, or check that the one there is this analysis (spec and sample)."""
    path = out / "sensitivity.json"
    if path.exists():
        old = read_json(path)
        if old is None or old.get("format") != FORMAT:
            raise SweepSpecError(f"--out {out}: {path} is not a gearbody sensitivity file; {_ADVICE}")
        old_spec = old.get("spec", {})
        diff = [k for k in sorted(set(spec) | set(old_spec)) if old_spec.get(k) != spec.get(k)]
        if diff:
            shown = "; ".join(f"{k}: {old_spec.get(k)!r} there, {spec.get(k)!r} now" for k in diff)
            raise SweepSpecError(
                f"--out {out} holds a different sensitivity analysis ({shown}); rerun with the same "
                f"arguments to resume, {_ADVICE}"
            )
        if not np.array_equal(np.asarray(old.get("sample", []), dtype=float), X):
            raise SweepSpecError(
                f"--out {out}: same arguments but a different sample matrix (another SALib or numpy "
                f"version?); {_ADVICE}"
            )
        return
    if (out / "evaluations").exists():
        raise SweepSpecError(f"--out {out} has an evaluations/ folder but no sensitivity.json; {_ADVICE}")
    out.mkdir(parents=True, exist_ok=True)
    write_json(
        path,
        {
            "format": FORMAT,
            "gearbody_version": __version__,
            "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "spec": spec,
            "rows": len(X),
            "sample": X.tolist(),
        },
    )


def recorded_rows(out: Path) -> dict[int, dict[str, Any]]:
    """Every recorded row: ``{row: entry}``; a row recorded ok anywhere counts as ok."""
    rows: dict[int, dict[str, Any]] = {}
    for path in sorted((out / "evaluations").glob("*.json")):
        data = read_json(path)
        for entry in (data or {}).get("rows", []):
            row = entry.get("row")
            if isinstance(row, int) and (row not in rows or entry.get("ok")):
                rows[row] = entry
    return rows


def job_id(rows: Sequence[int]) -> str:
    """The id of the job evaluating ``rows`` (consecutive), its evaluations file's name."""
    return f"row-{rows[0]:06d}" if len(rows) == 1 else f"rows-{rows[0]:06d}-{rows[-1]:06d}"


def pending_rows(recorded: Mapping[int, Mapping[str, Any]], n_rows: int, retry_failed: bool) -> list[int]:
    """The rows still to evaluate: not recorded, or recorded failed when ``retry_failed``."""
    return [r for r in range(n_rows) if r not in recorded or (retry_failed and not recorded[r].get("ok"))]


def analysis_spec(
    model: Callable[..., Mapping[str, float]],
    problem: Mapping[str, tuple[float, float]],
    outputs: tuple[str, ...],
    method: str,
    sampling: tuple,
    model_args: Sequence[Any],
    describe: Mapping[str, Any] | None,
) -> dict[str, Any]:
    """The analysis as recorded in sensitivity.json (a resume must match it); ``sampling``: samples,
    seed, levels, second_order, num_resamples, conf_level, batch."""
    samples, seed, levels, second_order, num_resamples, conf_level, batch = sampling
    return {
        "method": method,
        "keys": list(problem),
        "bounds": [list(b) for b in problem.values()],
        "outputs": list(outputs),
        "samples": samples,
        "seed": seed,
        "levels": levels if method == "morris" else None,
        "second_order": bool(second_order) if method == "sobol" else None,
        "num_resamples": int(num_resamples),
        "conf_level": float(conf_level),
        "batch": batch,
        "model": f"{getattr(model, '__module__', '?')}:{getattr(model, '__qualname__', repr(model))}",
        "model_args": dict(describe)
        if describe is not None
        else json.loads(json.dumps(list(model_args), default=str)),
    }


@dataclass
class SensitivityResult:
    """The indices of an analysis: ``indices[output][index]`` is an array over ``keys`` (``S2``,
    ``S2_conf``: ``len(keys) x len(keys)``, upper triangle)."""

    out: Path
    method: str
    keys: tuple[str, ...]
    outputs: tuple[str, ...]
    indices: dict[str, dict[str, np.ndarray]]
    rows: int
    ran: int
    skipped: int
    excluded_rows: tuple[int, ...] = ()
    files: dict[str, Path] = field(default_factory=dict)

    def index(self, output: str, name: str, key: str) -> float:
        """One index, e.g. ``result.index("kd_max", "mu_star", "design.mesh.damping_Ns_per_m")``."""
        return float(self.indices[output][name][self.keys.index(key)])

    def records(self) -> list[dict[str, Any]]:
        """One row per (output, key): the first-order table of indices.csv."""
        names = INDEX_NAMES[self.method]
        return [
            {"feature": o, "key": k, **{n: float(self.indices[o][n][i]) for n in names}}
            for o in self.outputs
            for i, k in enumerate(self.keys)
        ]

    def table(self) -> str:
        """The indices as a Markdown table (and the second-order Sobol indices when computed)."""
        names = INDEX_NAMES[self.method]
        lines = ["| feature | key | " + " | ".join(names) + " |", "|---|---|" + "---:|" * len(names)]
        lines += [
            f"| {r['feature']} | {r['key']} | " + " | ".join(f"{r[n]:.4g}" for n in names) + " |"
            for r in self.records()
        ]
        s2 = [
            f"| {o} | {self.keys[i]} | {self.keys[j]} | {v['S2'][i, j]:.4g} | {v['S2_conf'][i, j]:.4g} |"
            for o, v in self.indices.items()
            if "S2" in v
            for i in range(len(self.keys))
            for j in range(i + 1, len(self.keys))
        ]
        if s2:
            lines += ["", "| feature | key i | key j | S2 | S2_conf |", "|---|---|---|---:|---:|", *s2]
        if self.excluded_rows:
            lines += [
                "",
                f"(Morris trajectories with failed rows excluded: rows {rows_text(self.excluded_rows)})",
            ]
        return "\n".join(lines)


def rows_text(rows: Sequence[int], limit: int = 20) -> str:
    """Row numbers for a message: the first ``limit``, then how many in all."""
    shown = ", ".join(map(str, rows[:limit]))
    return shown + (f", ... ({len(rows)} in all)" if len(rows) > limit else "")


def record_indices(
    out: Path,
    spec: Mapping[str, Any],
    X: np.ndarray,
    n_rows: int,
    outputs: Sequence[str],
    exclude_failed: bool,
) -> tuple[dict[str, dict[str, np.ndarray]], tuple[int, ...]]:
    """``(indices per output, excluded rows)`` from the rows recorded in ``out``: MissingRowsError
    when a row failed or is missing, unless (Morris) ``exclude_failed`` drops its trajectory."""
    method = spec["method"]
    recorded = recorded_rows(out)
    failed = [r for r in range(n_rows) if not recorded.get(r, {}).get("ok")]
    failed_set = set(failed)
    keep = None
    if failed:
        causes = "; ".join(
            f"row {r}: {recorded[r].get('error_type')}: {recorded[r].get('message', '')}".strip()[:300]
            for r in failed[:3]
            if r in recorded
        )
        if not exclude_failed:
            hint = " or (Morris only) exclude_failed / --exclude-failed" if method == "morris" else ""
            raise MissingRowsError(
                f"{out}: no indices: {len(failed)} of {n_rows} rows failed or missing (rows "
                f"{rows_text(failed)}; {causes}); every evaluation is in {out / 'evaluations'}; fix "
                f"the cause and rerun with retry_failed / --retry-failed{hint}"
            )
        size = len(spec["keys"]) + 1
        bad = {r // size for r in failed}
        keep = np.array([r // size not in bad for r in range(n_rows)])
        if (n_rows // size) - len(bad) < 2:
            raise MissingRowsError(
                f"{out}: fewer than 2 Morris trajectories without failed rows "
                f"(rows {rows_text(failed)}; {causes})"
            )
    values = {
        o: np.array([recorded[r]["values"][o] if r not in failed_set else np.nan for r in range(n_rows)])
        for o in outputs
    }
    indices = {o: analyse_rows(spec, X, values[o], keep) for o in outputs}
    excluded = tuple(int(r) for r in range(n_rows) if keep is not None and not keep[r])
    return indices, excluded


def write_outputs(res: SensitivityResult, title: str) -> None:
    """Write ``indices.csv``, ``indices.md``, ``indices.json`` and the bar plot ``indices.png`` (titled
    ``title``) into ``res.out``; their paths in ``res.files``."""
    from gearbody.plotting.sensitivity import plot_indices

    from .table import write_csv

    names = list(INDEX_NAMES[res.method])
    res.files["csv"] = write_csv(res.out / "indices.csv", res.records(), ["feature", "key", *names])
    res.files["md"] = write_text(res.out / "indices.md", res.table() + "\n")
    res.files["json"] = write_json(
        res.out / "indices.json",
        {
            "method": res.method,
            "keys": list(res.keys),
            "excluded_rows": list(res.excluded_rows),
            "indices": {o: {n: v.tolist() for n, v in ix.items()} for o, ix in res.indices.items()},
        },
    )
    res.files["png"] = plot_indices(res.method, res.keys, res.indices, res.out / "indices.png", title=title)
