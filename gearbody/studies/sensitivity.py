"""Sensitivity analysis (``gearbody sensitivity``): which scenario keys move which features, by Morris
screening (elementary effects) or Sobol variance indices, on SALib, evaluated on the study executors.

The path is the same for a gearbody scene and for any picklable model function
``model(values: dict[key, float], *model_args) -> {output: float}``:

1. the problem: keys with ranges ``(low, high)`` (uniform, continuous);
2. the sample matrix (SALib: Morris trajectories, ``samples x (D + 1)`` rows; Saltelli/Sobol,
   ``samples x (2 D + 2)`` rows with second-order indices, ``samples x (D + 2)`` without);
3. jobs of ``batch`` rows run by :func:`~gearbody.studies.executors.run_jobs` (serial, process pool,
   Dask) on :func:`evaluate_rows`, which never raises;
4. the record in ``OUT``: ``sensitivity.json`` (format, spec, sample matrix; a rerun must match it)
   and ``evaluations/<job>.json`` per job, written atomically as it finishes: a rerun skips the rows
   done (an interrupted run resumes), reruns failed ones only with ``retry_failed``;
5. the analysis per output (SALib): Morris ``mu``, ``mu_star``, ``mu_star_conf``, ``sigma`` (in the
   output's unit: the elementary effect of a step of the level grid, scaled to the full range);
   Sobol ``S1``, ``S1_conf``, ``ST``, ``ST_conf``, ``S2``, ``S2_conf``. Indices are computed only when
   every row has a finite value: otherwise :class:`MissingRowsError` names the rows. For Morris only,
   ``exclude_failed`` drops the trajectories holding a failed row (Sobol's estimators need every row);
6. ``OUT/indices.csv``, ``indices.md``, ``indices.json`` (with S2) and the bar plot ``indices.png``.

:func:`sensitivity` is the gearbody entry point (a scene, ``--key KEY=low:high``, ``--feature`` specs of
:mod:`gearbody.analysis.features`); :func:`analyse_model` the generic one. :func:`ishigami` is the
classic test function with known indices (for checking the machinery).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gearbody.errors import OutputError, StudyError
from gearbody.folders import claim, output_error
from gearbody.version import __version__

from .executors import check_options, failure, run_jobs
from .parse import MOST_CASES, SweepSpecError, check_key
from .store import read_json, write_json, write_text
from .wall import check_study_wall_time, run_estimates_s

__all__ = [
    "FORMAT",
    "MAX_RUNS",
    "METHODS",
    "MissingRowsError",
    "SensitivityResult",
    "analyse_model",
    "check_feature_signals",
    "evaluate_rows",
    "ishigami",
    "parse_key_range",
    "read_scene",
    "run_count",
    "salib",
    "scene_features",
    "sensitivity",
]

FORMAT = "gearbody-sensitivity/1"
METHODS = ("morris", "sobol")
MAX_RUNS = 2000
"""Default bound on the simulations of one :func:`sensitivity` (``force`` / ``--force`` lifts it, up to
:data:`gearbody.studies.parse.MOST_CASES`: the sample matrix is made before anything runs)."""
MAX_LEVELS = 1000
"""Most Morris grid levels (``--levels``; 4-10 are usual): SALib allocates per level, and 2**63 levels
raised numpy's 'array is too big'."""
INDEX_NAMES = {
    "morris": ("mu_star", "mu_star_conf", "sigma", "mu"),
    "sobol": ("S1", "S1_conf", "ST", "ST_conf"),
}
_NUMBER = re.compile(r"^\s*[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?\s*$")


class MissingRowsError(StudyError):
    """Indices cannot be computed: some rows failed or have no finite value (exit code 1). Every
    evaluation is recorded; the message names the rows and the first causes."""

    exit_code = 1


def salib():
    """The SALib package, or an ImportError saying what to install."""
    try:
        import SALib  # noqa: F401
        import SALib.analyze.morris
        import SALib.analyze.sobol
        import SALib.sample.morris
        import SALib.sample.sobol
    except ImportError as exc:
        raise ImportError("sensitivity analysis needs SALib: pip install gearbody[calibrate]") from exc
    return SALib


# -- the problem and its sample ------------------------------------------------------------------------
def parse_key_range(text: str, label: str | None = None) -> tuple[str, float, float]:
    """``KEY=low:high`` -> (key, low, high); low < high, both finite."""
    label = label or f"--key {text}"
    if "=" not in text:
        raise SweepSpecError(f"{label}: expected KEY=low:high, e.g. design.mesh.damping_Ns_per_m=3000:12000")
    key, spec = (s.strip() for s in text.split("=", 1))
    check_key(key, label)
    parts = spec.split(":")
    if len(parts) != 2 or not all(_NUMBER.match(p) for p in parts):
        raise SweepSpecError(f"{label}: the range must be low:high (two numbers), got {spec!r}")
    return (key, *_check_bounds(key, float(parts[0]), float(parts[1]), label))


def _check_bounds(key: str, low: Any, high: Any, label: str) -> tuple[float, float]:
    try:
        lo, hi = float(low), float(high)
    except (TypeError, ValueError):
        raise SweepSpecError(
            f"{label}: the range of {key} must be two numbers, got {low!r}, {high!r}"
        ) from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise SweepSpecError(f"{label}: the range of {key} needs finite low < high, got {lo!r}:{hi!r}")
    return lo, hi


def _problem(keys: Mapping[str, tuple[float, float]] | Sequence[str]) -> dict[str, tuple[float, float]]:
    """Ordered ``{key: (low, high)}`` from a mapping or ``["KEY=low:high", ...]``."""
    if isinstance(keys, Mapping):
        items = []
        for k, bounds in keys.items():
            check_key(k, f"key {k}")
            if isinstance(bounds, str) or np.shape(bounds) != (2,):
                raise SweepSpecError(f"key {k}: give the range as (low, high), got {bounds!r}")
            items.append((k, *_check_bounds(k, bounds[0], bounds[1], f"key {k}")))
    else:
        items = [parse_key_range(str(t)) for t in keys]
    if not items:
        raise SweepSpecError("nothing to analyse: give at least one --key KEY=low:high")
    problem: dict[str, tuple[float, float]] = {}
    for k, lo, hi in items:
        if k in problem:
            raise SweepSpecError(f"--key {k}: given twice")
        problem[k] = (lo, hi)
    return problem


def _whole(value: Any, name: str, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise SweepSpecError(f"{name} must be a whole number >= {minimum}, got {value!r}")
    return int(value)


def run_count(method: str, samples: int, n_keys: int, second_order: bool = True) -> int:
    """Rows of the sample matrix (model evaluations) of a method."""
    if method == "morris":
        return samples * (n_keys + 1)
    return samples * (2 * n_keys + 2 if second_order else n_keys + 2)


def _sample(problem: Mapping[str, tuple[float, float]], spec: Mapping[str, Any]) -> np.ndarray:
    salib()
    from SALib.sample import morris, sobol

    sp = {"num_vars": len(problem), "names": list(problem), "bounds": [list(b) for b in problem.values()]}
    if spec["method"] == "morris":
        return morris.sample(sp, spec["samples"], num_levels=spec["levels"], seed=spec["seed"])
    return sobol.sample(sp, spec["samples"], calc_second_order=spec["second_order"], seed=spec["seed"])


# -- evaluation: the task the executors run ------------------------------------------------------------
def evaluate_rows(
    model: Callable[..., Mapping[str, float]],
    rows: Sequence[int],
    values: Sequence[Sequence[float]],
    keys: Sequence[str],
    outputs: Sequence[str],
    model_args: Sequence[Any] = (),
) -> dict[str, Any]:
    """Evaluate ``model`` on some rows of the sample; never raises (a row that raises or gives a
    non-finite output is recorded failed with its cause). Returns ``{"ok": True, "rows": [{"row",
    "ok", "values" | "error_type", "message", "traceback", "wall_time_s"}, ...]}``."""
    done = []
    for row, x in zip(rows, values, strict=True):
        t0 = time.perf_counter()
        try:
            y = model(dict(zip(keys, (float(v) for v in x), strict=True)), *model_args)
            out = {name: float(y[name]) for name in outputs}
            bad = [f"{k} = {v!r}" for k, v in out.items() if not math.isfinite(v)]
            if bad:
                raise ValueError(f"not finite: {', '.join(bad)}")
            done.append({"row": int(row), "ok": True, "values": out, "wall_time_s": time.perf_counter() - t0})
        except Exception as exc:  # recorded for this row; the analysis goes on
            done.append({"row": int(row), **failure(exc, time.perf_counter() - t0)})
    return {"ok": True, "rows": done}


def ishigami(values: Mapping[str, float], a: float = 7.0, b: float = 0.1) -> dict[str, float]:
    """The Ishigami function ``y = sin x1 + a sin^2 x2 + b x3^4 sin x1`` (keys x1, x2, x3 on
    [-pi, pi]); for a = 7, b = 0.1: S1 = 0.3139, 0.4424, 0; ST = 0.5576, 0.4424, 0.2437; S13 = 0.2437."""
    x1, x2, x3 = values["x1"], values["x2"], values["x3"]
    return {"y": math.sin(x1) + a * math.sin(x2) ** 2 + b * x3**4 * math.sin(x1)}


# -- the record in OUT ---------------------------------------------------------------------------------
_ADVICE = "give --overwrite to replace it, or choose another --out"


def _prepare_out(out: Path, spec: dict[str, Any], X: np.ndarray) -> None:
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


def _recorded(out: Path) -> dict[int, dict[str, Any]]:
    """Every recorded row: ``{row: entry}``; a row recorded ok anywhere counts as ok."""
    rows: dict[int, dict[str, Any]] = {}
    for path in sorted((out / "evaluations").glob("*.json")):
        data = read_json(path)
        for entry in (data or {}).get("rows", []):
            row = entry.get("row")
            if isinstance(row, int) and (row not in rows or entry.get("ok")):
                rows[row] = entry
    return rows


def _job_id(rows: Sequence[int]) -> str:
    return f"row-{rows[0]:06d}" if len(rows) == 1 else f"rows-{rows[0]:06d}-{rows[-1]:06d}"


# -- the analysis --------------------------------------------------------------------------------------
def _analyse(
    spec: Mapping[str, Any], X: np.ndarray, Y: np.ndarray, keep: np.ndarray | None
) -> dict[str, np.ndarray]:
    from SALib.analyze import morris, sobol

    problem = {"num_vars": len(spec["keys"]), "names": list(spec["keys"]), "bounds": spec["bounds"]}
    common = {"num_resamples": spec["num_resamples"], "conf_level": spec["conf_level"], "seed": spec["seed"]}
    if spec["method"] == "morris":
        x, y = (X, Y) if keep is None else (X[keep], Y[keep])
        res = morris.analyze(problem, x, y, num_levels=spec["levels"], **common)
        return {k: np.asarray(res[k], dtype=float) for k in ("mu", "mu_star", "mu_star_conf", "sigma")}
    res = sobol.analyze(problem, Y, calc_second_order=spec["second_order"], **common)
    names = ("S1", "S1_conf", "ST", "ST_conf") + (("S2", "S2_conf") if spec["second_order"] else ())
    return {k: np.asarray(res[k], dtype=float) for k in names}


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
                f"(Morris trajectories with failed rows excluded: rows {_rows_text(self.excluded_rows)})",
            ]
        return "\n".join(lines)


def _rows_text(rows: Sequence[int], limit: int = 20) -> str:
    shown = ", ".join(map(str, rows[:limit]))
    return shown + (f", ... ({len(rows)} in all)" if len(rows) > limit else "")


def _write_outputs(res: SensitivityResult, title: str) -> None:
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


# -- the generic entry point ---------------------------------------------------------------------------
def analyse_model(
    model: Callable[..., Mapping[str, float]],
    keys: Mapping[str, tuple[float, float]] | Sequence[str],
    outputs: Sequence[str],
    *,
    out: str | Path,
    method: str = "morris",
    samples: int = 8,
    seed: int = 0,
    model_args: Sequence[Any] = (),
    describe: Mapping[str, Any] | None = None,
    levels: int = 4,
    second_order: bool = True,
    batch: int = 1,
    num_resamples: int = 1000,
    conf_level: float = 0.95,
    workers: int | None = None,
    scheduler: Any | None = None,
    max_runs: int | None = None,
    force: bool = False,
    retry_failed: bool = False,
    exclude_failed: bool = False,
    progress: bool = True,
    title: str = "",
    check: Callable[[np.ndarray], None] | None = None,
    overwrite: bool = False,
) -> SensitivityResult:
    """Sensitivity indices of ``model``'s ``outputs`` to ``keys`` over their ranges, resuming whatever
    ``out`` holds of the same analysis.

    Args:
        model: picklable module-level ``model(values: {key: float}, *model_args) -> {output: float}``.
        keys: ``{key: (low, high)}`` or ``["KEY=low:high", ...]``.
        outputs: names of the model's outputs to analyse.
        out: output folder (``sensitivity.json``, ``evaluations/``, ``indices.*``).
        method: ``"morris"`` (``samples`` trajectories of ``levels`` levels) or ``"sobol"`` (Saltelli
            base sample ``samples``, a power of 2; ``second_order`` for S2).
        seed: seed of the sample and of the bootstrap confidence intervals.
        model_args: extra arguments of ``model`` (shipped to the workers).
        describe: what defines ``model_args`` for the resume check (default: ``model_args`` as text).
        batch: rows per job (1 for simulations; more for a cheap model).
        num_resamples, conf_level: bootstrap of the confidence intervals (``*_conf``: half-widths).
        workers, scheduler: the executor, as for studies (default all cores; 1 serial; a Dask address).
        max_runs: refuse more rows than this unless ``force``.
        retry_failed: on resume, evaluate again the rows that failed.
        exclude_failed: Morris only: drop the trajectories holding failed rows instead of refusing.
        title: of the plot.
        check: called with the sample matrix before anything runs or is written (raises on a bad row).
        overwrite: replace what ``out`` holds (its gearbody outputs removed first) instead of resuming.
    Raises:
        SweepSpecError: bad input (before anything runs), or ``out`` holds something else than this
            analysis (see ``overwrite``).
        FolderInUse: another command is writing in ``out`` (its lock, :mod:`gearbody.folders`).
        OutputError: a file could not be written (a full disk); the rows written stay recorded.
        MissingRowsError: rows failed (all recorded); names them.
        ImportError: SALib (or dask.distributed for a scheduler) missing.
    """
    problem = _problem(keys)
    if method not in METHODS:
        raise SweepSpecError(f"--method {method!r}: valid are {', '.join(METHODS)}")
    outputs = tuple(str(o) for o in outputs)
    if not outputs or len(set(outputs)) != len(outputs):
        raise SweepSpecError(f"give one or more distinct features, got {list(outputs)}")
    if method == "morris":
        samples = _whole(samples, "--samples (Morris trajectories)", 2)
        levels = _whole(levels, "--levels", 2)
        if levels % 2 or levels > MAX_LEVELS:
            raise SweepSpecError(
                f"--levels must be even (a grid jump of levels/(2 (levels-1))) and <= {MAX_LEVELS}, got "
                f"{levels}"
            )
    else:
        samples = _whole(samples, "--samples (Sobol base sample)", 2)
        if samples & (samples - 1):
            raise SweepSpecError(f"--samples must be a power of 2 for Sobol (Sobol sequence), got {samples}")
        if exclude_failed:
            raise SweepSpecError("--exclude-failed is for Morris only: Sobol's estimators need every row")
    seed = _whole(seed, "--seed", 0)
    batch = _whole(batch, "batch", 1)
    if not 0 < conf_level < 1:
        raise SweepSpecError(f"conf_level must be in (0, 1), got {conf_level!r}")
    n_rows = run_count(method, samples, len(problem), second_order)
    if n_rows > MOST_CASES:  # even with --force: the sample matrix is made in memory first
        raise SweepSpecError(
            f"{method} with --samples {samples} over {len(problem)} keys is {n_rows} runs, above the most "
            f"any analysis may have ({MOST_CASES}, --force included); lower --samples"
        )
    if max_runs is not None and n_rows > max_runs and not force:
        raise SweepSpecError(
            f"{method} with --samples {samples} over {len(problem)} keys is {n_rows} runs, above the limit "
            f"of {max_runs}; lower --samples or give --force"
        )
    check_options(workers, scheduler)
    salib()

    spec = {
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
    X = _sample(problem, spec)
    if check is not None:
        check(X)
    out = Path(out)
    with claim(out, "sensitivity", overwrite=overwrite) as folder:  # locked while it writes
        folder.begin()
        _prepare_out(out, spec, X)
        try:
            (out / "evaluations").mkdir(exist_ok=True)
        except OSError as exc:
            raise output_error(out / "evaluations", exc) from None

        recorded = _recorded(out)
        pending = [
            r for r in range(n_rows) if r not in recorded or (retry_failed and not recorded[r].get("ok"))
        ]
        skipped = n_rows - len(pending)
        if progress and skipped:
            print(f"resuming {out}: {skipped} of {n_rows} rows already recorded", file=sys.stderr)
        chunks = [pending[i : i + batch] for i in range(0, len(pending), batch)]
        by_id = {_job_id(c): c for c in chunks}
        keys_t, Xl = tuple(problem), X.tolist()
        jobs = [
            (jid, (model, c, [Xl[r] for r in c], keys_t, outputs, tuple(model_args)))
            for jid, c in by_id.items()
        ]
        try:
            _run(jobs, by_id, out, workers, scheduler, progress)
        except KeyboardInterrupt:  # Ctrl-C or SIGTERM: the rows written so far stay recorded
            done = sum(1 for r in range(n_rows) if r in _recorded(out))
            raise KeyboardInterrupt(
                f"interrupted: {done} of {n_rows} runs recorded in {out / 'evaluations'}; rerun the same "
                "command to resume"
            ) from None

        recorded = _recorded(out)
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
                    f"{_rows_text(failed)}; {causes}); every evaluation is in {out / 'evaluations'}; fix "
                    f"the cause and rerun with retry_failed / --retry-failed{hint}"
                )
            size = len(problem) + 1
            bad = {r // size for r in failed}
            keep = np.array([r // size not in bad for r in range(n_rows)])
            if (n_rows // size) - len(bad) < 2:
                raise MissingRowsError(
                    f"{out}: fewer than 2 Morris trajectories without failed rows "
                    f"(rows {_rows_text(failed)}; {causes})"
                )
        values = {
            o: np.array([recorded[r]["values"][o] if r not in failed_set else np.nan for r in range(n_rows)])
            for o in outputs
        }
        indices = {o: _analyse(spec, X, values[o], keep) for o in outputs}
        excluded = tuple(int(r) for r in range(n_rows) if keep is not None and not keep[r])
        res = SensitivityResult(
            out, method, keys_t, outputs, indices, n_rows, len(pending), skipped, excluded
        )
        _write_outputs(res, title or f"{method} sensitivity indices")
        return res


def _run(jobs, by_id, out: Path, workers, scheduler, progress: bool) -> None:
    """Run the jobs; each finished job's rows written at once to ``OUT/evaluations/<job>.json``."""
    if not jobs:
        return
    from tqdm import tqdm

    runner = run_jobs(evaluate_rows, jobs, workers=workers, scheduler=scheduler, name="gearbody-sensitivity")
    total = sum(len(c) for c in by_id.values())
    bar, failed, written = None, 0, 0
    try:
        for jid, outcome in runner:
            if bar is None:  # created after the pool has started its processes
                bar = tqdm(total=total, desc="sensitivity", unit="run", disable=not progress, file=sys.stderr)
            if outcome.get("rows") is None:  # the worker died: every row of the job failed with its cause
                outcome = {"rows": [{"row": r, **outcome} for r in by_id[jid]]}
            write_json(out / "evaluations" / f"{jid}.json", {"job": jid, "rows": outcome["rows"]})
            written += len(outcome["rows"])
            failed += sum(not e.get("ok") for e in outcome["rows"])
            bar.set_postfix_str(f"{failed} failed", refresh=False)
            bar.update(len(outcome["rows"]))
    except OutputError as exc:  # a full disk: what is recorded is whole; the rest runs on a resume
        raise OutputError(
            f"{exc}; {written} of the {total} runs of this call recorded: make room and rerun the same "
            "command to resume"
        ) from None
    finally:
        if bar is not None:
            bar.close()
        close = getattr(runner, "close", None)
        if close:
            close()


# -- gearbody: a scene's features ----------------------------------------------------------------------
def scene_features(
    values: Mapping[str, float], base: Mapping[str, Any], overrides: Sequence[str], features: Sequence[str]
) -> dict[str, float]:
    """The ``features`` of the scene ``base`` (TOML data) with ``overrides`` and ``values`` set: a
    simulation, and the modes when a natural frequency is asked (only the modes when nothing else is)."""
    from gearbody.analysis.features import evaluate_features, natural_frequency_hz, parse_feature
    from gearbody.engine import scene_modes, simulate
    from gearbody.model import load_scenario

    scenario = load_scenario(dict(base), [*overrides, *(f"{k}={float(v)!r}" for k, v in values.items())])
    specs = [parse_feature(f) for f in features]
    modal = [s for s in specs if s.name == "natural_frequency_hz"]
    freqs = tuple(float(f) for f in scene_modes(scenario).frequencies_hz) if modal else ()
    if len(modal) == len(specs):
        return {str(s): natural_frequency_hz(freqs, int(s.options.get("mode", 1))) for s in specs}
    return evaluate_features(specs, simulate(scenario).record(freqs))


def read_scene(scene: str | Path) -> tuple[str, dict[str, Any], str]:
    """(label stored in the spec, TOML data, sha256 of the file) of a scene name or TOML path."""
    from gearbody.model import scene_path
    from gearbody.model.io import names_a_file, parse_scenario_bytes, read_scenario_bytes

    path = Path(scene)
    if not path.suffix and not names_a_file(path):
        label, path = str(scene), scene_path(str(scene))
    else:  # realpath: a symbolic-link loop is the reader's one-line refusal below, not a RuntimeError
        label = os.path.realpath(path)
    data = read_scenario_bytes(path)  # refuses a missing file, a folder, a FIFO, a device, a huge file
    base = parse_scenario_bytes(data, path)
    if isinstance(base.get("meta"), dict):
        base["meta"].setdefault("name", path.stem)
    return label, base, hashlib.sha256(data).hexdigest()


def sensitivity(
    scene: str | Path,
    keys: Mapping[str, tuple[float, float]] | Sequence[str],
    features: Sequence[str],
    *,
    out: str | Path,
    method: str = "morris",
    samples: int = 8,
    seed: int = 0,
    overrides: Sequence[str] = (),
    workers: int | None = None,
    scheduler: Any | None = None,
    max_runs: int = MAX_RUNS,
    force: bool = False,
    max_wall_minutes: float | None = None,
    **options: Any,
) -> SensitivityResult:
    """Sensitivity of a scene's ``features`` (specs of :mod:`gearbody.analysis.features`, e.g.
    ``kd_max``, ``line_amplitude:signal=pinion_accel_rad_s2,mesh=1``) to scenario ``keys`` over their
    ranges, e.g. ``{"design.mesh.damping_Ns_per_m": (3000, 12000)}``; ``overrides``: fixed
    ``KEY=VALUE`` of every run (``--set``). Before anything runs: every key, range end and sample row
    is checked (its scenario loaded), every feature parsed, and the signals the features read looked
    up in a probe run of :data:`PROBE_S`. More than ``max_runs`` simulations are
    refused unless ``force``, and so are runs still to do estimated above ``max_wall_minutes`` of wall
    time (default None: no limit; :mod:`gearbody.studies.wall`). Other options as for
    :func:`analyse_model` (levels, second_order, retry_failed, exclude_failed, progress, ...)."""
    from gearbody.analysis.features import FeatureError, parse_feature
    from gearbody.model import ScenarioError, load_scenario, parse_override

    problem = _problem(keys)
    specs = []
    for f in features:
        try:
            specs.append(str(parse_feature(f)))
        except FeatureError as exc:
            raise SweepSpecError(f"--feature {f}: {exc}") from None
    if not specs:
        raise SweepSpecError("give one or more --feature specs, e.g. --feature kd_max")
    overrides = tuple(overrides)
    for o in overrides:
        if parse_override(o)[0] in problem:
            raise SweepSpecError(f"--set {o}: {parse_override(o)[0]} is also a --key; give it in one place")
    label, base, sha = read_scene(scene)
    parsed = [parse_feature(f) for f in specs]
    fixed = load_scenario(dict(base), list(overrides))  # the fixed overrides alone
    check_feature_windows(fixed, parsed)  # a window the run cannot hold, before the sample is drawn
    for k, (lo, hi) in problem.items():
        for v in (lo, hi):
            try:
                load_scenario(dict(base), [*overrides, f"{k}={v!r}"])
            except ScenarioError as exc:
                raise SweepSpecError(f"--key {k}={lo!r}:{hi!r}: at {k} = {v!r}: {exc}") from None

    def check(X: np.ndarray) -> None:  # after the options are checked, before anything is written
        scenarios = _check_rows(problem, base, overrides, X, parsed)
        check_feature_signals(base, overrides, parsed)
        if all(spec.name == "natural_frequency_hz" for spec in parsed):
            return  # the modes only: no simulation
        recorded = _recorded(Path(out))  # read only: a resume runs the rest
        retry = options.get("retry_failed", False)
        pending = [r for r in range(len(X)) if r not in recorded or (retry and not recorded[r].get("ok"))]
        check_study_wall_time(
            run_estimates_s([scenarios[r] for r in pending]),
            workers=workers,
            scheduler=scheduler,
            max_wall_minutes=max_wall_minutes,
            progress=options.get("progress", True),
            what=f"the analysis ({len(pending)} of {len(X)} runs to do)",
            remedy="shorten operation.t_end_s (--t-end), lower --samples or give more --workers",
        )

    return analyse_model(
        scene_features,
        problem,
        specs,
        out=out,
        method=method,
        samples=samples,
        seed=seed,
        model_args=(base, overrides, tuple(specs)),
        describe={"scene": label, "scene_sha256": sha, "overrides": list(overrides)},
        workers=workers,
        scheduler=scheduler,
        max_runs=max_runs,
        force=force,
        title=f"{Path(label).name if len(label) > 40 else label}: {method} sensitivity indices",
        check=check,
        **options,
    )


PROBE_S = 0.002
"""Simulated time of the probe run that finds the signals a scene records (a few hundredths of a second)."""


def check_feature_windows(scenario, specs, where: str = "", option: str = "--feature") -> None:
    """Every feature's window exists in a run of ``scenario``: its operating ``period``, its
    ``from_s``..``to_s`` or ``fraction`` holding 2 samples or more of the run's output grid. Needs no run:
    SweepSpecError naming the feature (given by ``option``), the run's length and its operating periods
    (``where``: which scenario)."""
    from gearbody.analysis.features import WINDOW_OPTIONS, FeatureError, Record, operating_periods_s
    from gearbody.model.budget import output_samples

    op, rate = scenario.operation, scenario.solver.output_rate_hz
    t = np.arange(output_samples(scenario)) / rate
    edges = operating_periods_s(t[0], t[-1], [*op.speed_profile.time_s, *op.load_profile.time_s])
    grid = Record(time_s=t, signals={}, period_boundaries_s=edges)
    for spec in specs:
        try:
            grid.window({k: v for k, v in spec.options.items() if k in WINDOW_OPTIONS})
        except FeatureError as exc:
            bounds = ", ".join(f"{e:g}" for e in edges)
            raise SweepSpecError(
                f"{option} {spec}: {exc} in a run of operation.t_end_s = {op.t_end_s:g} s{where} ({t.size} "
                f"samples; operating periods 1..{len(edges) - 1}, boundaries {bounds} s); nothing was run"
            ) from None


def check_feature_signals(base: Mapping[str, Any], overrides: Sequence[str], specs) -> None:
    """Every signal the features read is one the scene records: a probe run of PROBE_S finds them."""
    from gearbody.analysis.features import FeatureError, feature_signals

    if all(spec.name == "natural_frequency_hz" for spec in specs):
        return
    from gearbody.engine import simulate
    from gearbody.errors import SimulationError
    from gearbody.model import load_scenario

    try:
        record = simulate(load_scenario(dict(base), [*overrides, f"operation.t_end_s={PROBE_S}"])).record()
    except SimulationError:
        return  # the runs will say why
    for spec in specs:
        try:
            names = feature_signals(spec, record)
        except FeatureError as exc:  # the feature does not apply to the stage it names
            raise SweepSpecError(f"--feature {spec}: {str(exc).removeprefix(f'feature {spec}: ')}") from None
        for name in names:
            if name not in record.signals:
                raise SweepSpecError(
                    f"--feature {spec}: the scene records no signal {name!r}; it records "
                    f"{', '.join(sorted(record.signals))}"
                )


def _check_rows(problem, base, overrides, X: np.ndarray, specs=()) -> list:
    """Every row's scenario, each valid (keys that are valid alone may be refused together) and holding
    every feature's window (:func:`check_feature_windows`)."""
    from gearbody.model import ScenarioError, load_scenario

    scenarios = []
    for r, x in enumerate(X):
        row = [f"{k}={float(v)!r}" for k, v in zip(problem, x, strict=True)]
        try:
            scenario = load_scenario(dict(base), [*overrides, *row])
            scenarios.append(scenario)
        except ScenarioError as exc:
            raise SweepSpecError(
                f"sample row {r} ({', '.join(row)}) is not a valid scenario: {exc}"
            ) from None
        check_feature_windows(scenario, specs, f" (sample row {r}: {', '.join(row)})")
    return scenarios
