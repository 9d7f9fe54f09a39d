"""Calibration of a scene (``gearbody calibrate``): fit scenario keys within bounds to target features
of one or more *cases* of the scene, every evaluation a simulation on the study executors.

A case is a named set of extra overrides (for the paper's Fig. 12: the error mode and coupling damping of
run (a), of run (d), ...); a target is a feature of one case (``kd_max:period=4@a``; no ``@``: the scene
with the fixed overrides only). An evaluation of a parameter point runs every case the targets name, as
separate jobs of :func:`~gearbody.studies.executors.run_jobs` (serial, process pool or Dask), so the
cases of a point and the points of a batch run in parallel. The fit itself is
:func:`gearbody.studies.calibration.calibrate` (nevergrad, then scipy least squares, Jacobian
uncertainties).

The record in ``OUT``: ``evaluations.jsonl`` (every evaluation as it finishes: a rerun of the same
command replays them and resumes an interrupted calibration; the features of a point do not depend on
the targets' values, so a rerun with other target values or a larger budget reuses them),
``calibration.json`` and ``calibration.md`` (parameters, 1-sigma uncertainties, correlations, each
target's residual, the parameters that end on a bound or are not identified, evaluations and wall
time), ``convergence.png`` and ``calibrated.toml`` (the scene with the fitted values and the fixed
overrides set: ``gearbody run OUT/calibrated.toml`` reruns it).

The input specs and the checks before anything runs are in :mod:`.scene_calibration_checks`, the files
written in :mod:`.scene_calibration_output`.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from gearbody.errors import CalibrationFailed, OutputError
from gearbody.folders import claim

from .calibration import (
    CalibrationError,
    CalibrationResult,
    EvaluationCache,
    Parameter,
    Target,
    calibrate,
    fingerprint,
)
from .executors import run_jobs
from .parse import SweepSpecError
from .scene_calibration_checks import (
    MAX_SEED,  # noqa: F401 (this module's name before the split)
    check_cases,
    check_settings,
    check_targets,
    check_wall_time,
    parse_parameter,
    parse_target,
)
from .scene_calibration_output import write_outputs
from .sensitivity import evaluate_rows, read_scene, scene_features

__all__ = ["MAX_EVALUATIONS", "SceneCalibration", "calibrate_scene", "parse_parameter", "parse_target"]

MAX_EVALUATIONS = 2000
"""Largest budget + polish evaluations of one calibration (each a simulation per case) unless forced."""


@dataclass
class SceneCalibration:
    """A finished scene calibration: the fit and where its files are."""

    fit: CalibrationResult
    out: Path
    simulations: int  # run in this call (cases x evaluations not replayed)
    failed: int  # evaluations with a failed case (scored FAILED_RESIDUAL)
    wall_time_s: float
    scenario_file: Path

    def table(self) -> str:
        return self.fit.table()


def calibrate_scene(
    scene: str | Path,
    parameters: Sequence[Parameter],
    targets: Sequence[Target],
    *,
    out: str | Path,
    cases: Mapping[str, Sequence[str]] | None = None,
    overrides: Sequence[str] = (),
    workers: int | None = None,
    scheduler: Any | None = None,
    budget: int = 60,
    batch: int | None = None,
    polish: bool = True,
    polish_evaluations: int = 40,
    seed: int = 0,
    max_evaluations: int = MAX_EVALUATIONS,
    force: bool = False,
    progress: bool = True,
    overwrite: bool = False,
    max_wall_minutes: float | None = None,
) -> SceneCalibration:
    """Fit ``parameters`` (scenario keys with bounds) of ``scene`` (a name or TOML path) to ``targets``
    (features of its ``cases``: ``{name: [KEY=VALUE, ...]}``), every run with ``overrides``.

    ``budget`` global evaluations in rounds of ``batch`` points (default: 2, or the number of workers),
    then at most ``polish_evaluations`` of the least-squares polish, then the Jacobian (parameters + 1).
    Before anything runs: every key, bound and case is loaded as a scenario, every feature parsed and the
    signals it reads looked up in a probe run; more than ``max_evaluations`` are refused unless
    ``force``, and so are evaluations still to do estimated above ``max_wall_minutes`` of wall time
    (default None: no limit; :mod:`gearbody.studies.wall`: every case at the costlier end of each
    parameter's range). ``out`` resumes the same calibration (its ``evaluations.jsonl`` replayed);
    ``overwrite`` replaces what it holds instead (its gearbody outputs removed first).

    Raises SweepSpecError (bad input; ``out`` holds something else, or a record that is not this
    calibration's), FolderInUse (another command writes in ``out``), CalibrationFailed (every evaluation
    failed, exit 1), OutputError (a file cannot be written: a full disk; the evaluations recorded stay),
    ImportError (nevergrad or dask missing)."""
    t0 = time.perf_counter()
    parameters, targets = tuple(parameters), tuple(targets)
    cases = {str(k): tuple(v) for k, v in (cases or {}).items()}
    overrides = tuple(overrides)
    fit_options = {"budget": budget, "polish": polish, "polish_evaluations": polish_evaluations, "seed": seed}
    limits = (max_evaluations, force)
    batch, total = check_settings(parameters, targets, fit_options, batch, limits, workers, scheduler)
    used, keys = check_targets(parameters, targets, cases, overrides)
    label, base, sha = read_scene(scene)
    case_s = check_cases(base, overrides, used, parameters, targets)
    check_wall_time(Path(out), case_s, batch, total, workers, scheduler, max_wall_minutes, progress)

    features = {case: tuple(dict.fromkeys(t.feature for t in targets if t.case == case)) for case in used}
    out = Path(out)
    identity = fingerprint(
        "gearbody-calibration/1",
        sha,
        list(overrides),
        {c: list(v) for c, v in used.items()},
        {c: list(f) for c, f in features.items()},
        keys,
    )
    with claim(out, "calibrate", overwrite=overwrite) as folder:  # locked while it writes
        folder.begin()
        cache = _open_cache(out, identity)
        evaluate = _Evaluate(keys, used, features, (base, overrides), workers, scheduler, total, progress)
        if progress and cache.values:
            print(f"resuming {out}: {len(cache.values)} evaluations recorded", file=sys.stderr)
        fit = _fit(evaluate, parameters, targets, cache, batch=batch, **fit_options)
        if not any(math.isfinite(v) for v in fit.features.values()):
            raise CalibrationFailed(
                f"{out}: every evaluation failed (last cause: {evaluate.stats['cause'] or 'unknown'}); see "
                f"{cache.path}"
            )
        wall = time.perf_counter() - t0
        stats = evaluate.stats
        scenario_file = write_outputs(out, fit, label, base, overrides, used, stats, wall)
        return SceneCalibration(fit, out, stats["simulations"], stats["failed"], wall, scenario_file)


def _open_cache(out: Path, identity: str) -> EvaluationCache:
    """The evaluations record of ``out``, refused when it is another calibration's."""
    try:
        return EvaluationCache(out / "evaluations.jsonl", identity)
    except CalibrationError as exc:
        resume = "rerun with the same arguments to resume, " if "another calibration" in str(exc) else ""
        raise SweepSpecError(
            f"--out {out} holds a record that is not this calibration's: {exc}; {resume}give --overwrite "
            "to replace it, or choose another --out"
        ) from None


class _Evaluate:
    """``evaluate(points) -> [features | None]`` of :func:`~gearbody.studies.calibration.calibrate`: every
    case of every point a job of :func:`run_jobs` (None: a case of that point failed); counts the
    simulations and failures (``stats``) on a progress bar created at the first evaluation (after the
    pool has started)."""

    def __init__(self, keys, used, features, scene, workers, scheduler, total: int, progress: bool) -> None:
        self.keys, self.used, self.features, self.scene = keys, used, features, scene
        self.workers, self.scheduler, self.total, self.progress = workers, scheduler, total, progress
        self.stats = {"simulations": 0, "failed": 0, "cause": ""}
        self.bar: Any = None

    def jobs(self, points: list[dict[str, float]]) -> list:
        base, overrides = self.scene
        jobs = []
        for i, point in enumerate(points):
            values = [[point[k] for k in self.keys]]
            for c, extra in self.used.items():
                f = self.features[c]
                args = (scene_features, [i], values, tuple(self.keys), f, (base, (*overrides, *extra), f))
                jobs.append((f"{i}@{c}", args))
        return jobs

    def __call__(self, points: list[dict[str, float]]) -> list[dict[str, float] | None]:
        stats = self.stats
        results: list[dict[str, float] | None] = [{} for _ in points]
        runner = run_jobs(
            evaluate_rows,
            self.jobs(points),
            workers=self.workers,
            scheduler=self.scheduler,
            name="gearbody-calibrate",
        )
        try:
            for jid, outcome in runner:
                i, _, c = jid.partition("@")
                stats["simulations"] += 1
                row = (outcome.get("rows") or [outcome])[0]
                if not row.get("ok") or results[int(i)] is None:
                    if not row.get("ok"):
                        stats["cause"] = f"{row.get('error_type')}: {row.get('message', '')}"[:300]
                    results[int(i)] = None
                    continue
                suffix = f"@{c}" if c else ""
                results[int(i)].update({f"{f}{suffix}": v for f, v in row["values"].items()})
        finally:
            close = getattr(runner, "close", None)
            if close:
                close()
        stats["failed"] += sum(r is None for r in results)
        if self.bar is None:
            from tqdm import tqdm

            self.bar = tqdm(
                total=self.total, desc="calibrate", unit="eval", disable=not self.progress, file=sys.stderr
            )
        self.bar.update(len(points))
        self.bar.set_postfix_str(f"{stats['failed']} failed", refresh=False)
        return results


def _fit(
    evaluate: _Evaluate,
    parameters: tuple[Parameter, ...],
    targets: tuple[Target, ...],
    cache: EvaluationCache,
    **options: Any,
) -> CalibrationResult:
    """:func:`~gearbody.studies.calibration.calibrate` with ``options``; a full disk or an interruption
    said with what stays recorded; the progress bar closed."""
    try:
        return calibrate(evaluate, parameters, targets, cache=cache, **options)
    except OutputError as exc:  # a full disk: the record holds whole evaluations only
        raise OutputError(
            f"{exc}; the evaluations recorded in {cache.path} stay: make room and rerun the same "
            "command to resume"
        ) from None
    except KeyboardInterrupt:
        raise KeyboardInterrupt(
            f"interrupted: {len(cache.values)} evaluations recorded in {cache.path}; rerun the same "
            "command to resume"
        ) from None
    finally:
        if evaluate.bar is not None:
            evaluate.bar.close()
