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
from gearbody.folders import atomic_write, claim
from gearbody.version import __version__

from .calibration import (
    CalibrationError,
    CalibrationResult,
    EvaluationCache,
    Parameter,
    Target,
    calibrate,
    fingerprint,
)
from .executors import check_options, run_jobs
from .parse import MOST_CASES, SweepSpecError, check_key
from .sensitivity import (
    check_feature_signals,
    check_feature_windows,
    evaluate_rows,
    read_scene,
    scene_features,
)
from .store import write_json, write_text
from .wall import check_study_wall_time, run_estimates_s

__all__ = ["MAX_EVALUATIONS", "SceneCalibration", "calibrate_scene", "parse_parameter", "parse_target"]

MAX_EVALUATIONS = 2000
"""Largest budget + polish evaluations of one calibration (each a simulation per case) unless forced."""
MAX_SEED = 2**32 - 1
"""Largest optimiser seed (``--seed``): the optimiser's random state takes 32 bits (2**64 raised numpy's
'Seed must be between 0 and 2**32 - 1')."""


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


def parse_parameter(text: str, start: float | None = None) -> Parameter:
    """``KEY=low:high`` or ``KEY=low:high:log`` -> :class:`Parameter` (``--param``)."""
    label = f"--param {text}"
    if "=" not in text:
        raise SweepSpecError(
            f"{label}: expected KEY=low:high[:log], e.g. design.mesh.damping_Ns_per_m=3000:12000:log"
        )
    key, spec = (s.strip() for s in text.split("=", 1))
    check_key(key, label)
    parts = spec.split(":")
    log = len(parts) == 3 and parts[2].strip() == "log"
    if len(parts) not in (2, 3) or (len(parts) == 3 and not log):
        raise SweepSpecError(f"{label}: the range must be low:high or low:high:log, got {spec!r}")
    try:
        lo, hi = float(parts[0]), float(parts[1])
    except ValueError:
        raise SweepSpecError(
            f"{label}: low and high must be numbers, got {parts[0]!r}, {parts[1]!r}"
        ) from None
    try:
        return Parameter(key, lo, hi, start, log)
    except CalibrationError as exc:
        raise SweepSpecError(f"{label}: {exc}") from None


def parse_target(feature: str, value: str, sigma: str) -> Target:
    """``FEATURE[@CASE] VALUE SIGMA`` -> :class:`Target` (``--target``)."""
    label = f"--target {feature} {value} {sigma}"
    spec, _, case = feature.partition("@")
    try:
        return Target(spec.strip(), float(value), float(sigma), case.strip())
    except ValueError as exc:
        raise SweepSpecError(f"{label}: {exc}") from None


def _recorded_evaluations(path: Path) -> int:
    """Evaluation lines of an evaluations.jsonl (0 when there is none or it cannot be read)."""
    try:
        with open(path, "rb") as f:
            return max(0, sum(1 for _ in f) - 1)  # the first line is the fingerprint
    except OSError:
        return 0


def _cases_used(targets: Sequence[Target], cases: Mapping[str, Sequence[str]]) -> dict[str, tuple[str, ...]]:
    """The cases the targets name, in first-use order, with their overrides ("" = no extra override)."""
    used: dict[str, tuple[str, ...]] = {}
    for t in targets:
        if t.case and t.case not in cases:
            known = ", ".join(sorted(cases)) or "none given"
            raise SweepSpecError(
                f"target {t.label}: no case {t.case!r} (cases: {known}; give --case {t.case} KEY=VALUE)"
            )
        used.setdefault(t.case, tuple(cases.get(t.case, ())))
    unused = [c for c in cases if c not in used]
    if unused:
        raise SweepSpecError(
            f"case {unused[0]!r} is read by no target (give --target FEATURE@{unused[0]} ...)"
        )
    return used


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
    from gearbody.analysis.features import FeatureError, parse_feature
    from gearbody.model import ScenarioError, load_scenario, parse_override
    from gearbody.model.io import override_label

    t0 = time.perf_counter()
    parameters, targets = tuple(parameters), tuple(targets)
    cases = {str(k): tuple(v) for k, v in (cases or {}).items()}
    overrides = tuple(overrides)
    if not parameters:
        raise SweepSpecError("nothing to fit: give one or more --param KEY=low:high")
    if not targets:
        raise SweepSpecError("nothing to fit to: give one or more --target FEATURE VALUE SIGMA")
    for n, v in (("budget", budget), ("polish_evaluations", polish_evaluations), ("seed", seed)):
        if isinstance(v, bool) or not isinstance(v, int) or v < (1 if n == "budget" else 0):
            raise SweepSpecError(
                f"--{n.replace('_', '-')} must be a whole number >= {1 if n == 'budget' else 0}, got {v!r}"
            )
    if seed > MAX_SEED:
        raise SweepSpecError(f"--seed must be a whole number >= 0 and <= {MAX_SEED}, got {seed!r}")
    check_options(workers, scheduler)
    if batch is None:
        batch = 2 if workers is None else max(1, workers)
    if isinstance(batch, bool) or not isinstance(batch, int) or batch < 1:
        raise SweepSpecError(f"--batch must be a whole number >= 1, got {batch!r}")
    if batch > MOST_CASES:  # points asked of the optimiser at once, and listed for the wall-time estimate
        raise SweepSpecError(f"--batch = {batch}: at most {MOST_CASES} points per round")
    total = budget + (polish_evaluations if polish else 0) + len(parameters) + 2
    if total > max_evaluations and not force:
        raise SweepSpecError(
            f"--budget {budget} + --polish-evaluations {polish_evaluations if polish else 0} is up to "
            f"{total} evaluations, above the limit of {max_evaluations}; lower them or give --force"
        )
    labels = [t.label for t in targets]
    if len(set(labels)) != len(labels):
        raise SweepSpecError(f"a target is given twice: {labels}")
    for t in targets:
        try:
            parse_feature(t.feature)
        except FeatureError as exc:
            raise SweepSpecError(f"--target {t.label}: {exc}") from None
    used = _cases_used(targets, cases)
    keys = [p.key for p in parameters]
    if len(set(keys)) != len(keys):
        raise SweepSpecError(f"a --param is given twice: {keys}")
    given = [(o, None) for o in overrides]
    given += [
        (o, f"--case {c} {override_label(o).removeprefix('--set ')}") for c, os in used.items() for o in os
    ]
    for o, typed in given:  # a case's override named as --case NAME KEY=VALUE
        key = parse_override(o, typed)[0]
        if key in keys:
            raise SweepSpecError(f"override {o}: {key} is also a --param; give it in one place")
    label, base, sha = read_scene(scene)
    case_s: list[float] = []  # estimated wall time of a simulation of each case, s
    for case, extra in used.items():
        where = f"case {case!r}" if case else "the fixed overrides"
        specs = [parse_feature(t.feature) for t in targets if t.case == case]
        try:
            scenario = load_scenario(dict(base), [*overrides, *extra])
            loaded = [scenario]
        except ScenarioError as exc:
            raise SweepSpecError(f"{where}: {exc}") from None
        check_feature_windows(scenario, specs, f" ({where})", "--target")
        for p in parameters:
            for v in (p.lower, p.upper, *(() if p.start is None else (p.start,))):
                try:
                    scenario = load_scenario(dict(base), [*overrides, *extra, f"{p.key}={v!r}"])
                    loaded.append(scenario)
                except ScenarioError as exc:
                    raise SweepSpecError(f"--param {p.key}: at {v!r} ({where}): {exc}") from None
                check_feature_windows(scenario, specs, f" (--param {p.key} at {v!r}, {where})", "--target")
        check_feature_signals(base, [*overrides, *extra], specs)
        if not all(spec.name == "natural_frequency_hz" for spec in specs):  # else the modes only
            case_s.append(max(run_estimates_s(loaded)))
    recorded = _recorded_evaluations(Path(out) / "evaluations.jsonl")  # read only: replayed on resume
    check_study_wall_time(
        case_s * batch,
        workers=workers,
        scheduler=scheduler,
        max_wall_minutes=max_wall_minutes,
        progress=progress,
        what=f"the calibration (up to {max(0, total - recorded)} of {total} evaluations to do)",
        remedy="shorten operation.t_end_s (--t-end), lower --budget / --polish-evaluations or give more "
        "--workers",
        parallel=batch * len(case_s),
        repeat=math.ceil(max(0, total - recorded) / batch),
    )

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
        try:
            cache = EvaluationCache(out / "evaluations.jsonl", identity)
        except CalibrationError as exc:
            resume = "rerun with the same arguments to resume, " if "another calibration" in str(exc) else ""
            raise SweepSpecError(
                f"--out {out} holds a record that is not this calibration's: {exc}; {resume}give --overwrite "
                "to replace it, or choose another --out"
            ) from None
        stats = {"simulations": 0, "failed": 0, "cause": ""}
        bar: dict[str, Any] = {"bar": None}  # created at the first evaluation (after the pool has started)

        def evaluate(points: list[dict[str, float]]) -> list[dict[str, float] | None]:
            jobs = []
            for i, point in enumerate(points):
                values = [[point[k] for k in keys]]
                for c, extra in used.items():
                    args = (
                        scene_features,
                        [i],
                        values,
                        tuple(keys),
                        features[c],
                        (base, (*overrides, *extra), features[c]),
                    )
                    jobs.append((f"{i}@{c}", args))
            results: list[dict[str, float] | None] = [{} for _ in points]
            runner = run_jobs(
                evaluate_rows, jobs, workers=workers, scheduler=scheduler, name="gearbody-calibrate"
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
            if bar["bar"] is None:
                from tqdm import tqdm

                bar["bar"] = tqdm(
                    total=total, desc="calibrate", unit="eval", disable=not progress, file=sys.stderr
                )
            bar["bar"].update(len(points))
            bar["bar"].set_postfix_str(f"{stats['failed']} failed", refresh=False)
            return results

        if progress and cache.values:
            print(f"resuming {out}: {len(cache.values)} evaluations recorded", file=sys.stderr)
        try:
            fit = calibrate(
                evaluate,
                parameters,
                targets,
                budget=budget,
                batch=batch,
                polish=polish,
                polish_evaluations=polish_evaluations,
                seed=seed,
                cache=cache,
            )
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
            if bar["bar"] is not None:
                bar["bar"].close()
        if not any(math.isfinite(v) for v in fit.features.values()):
            raise CalibrationFailed(
                f"{out}: every evaluation failed (last cause: {stats['cause'] or 'unknown'}); see "
                f"{cache.path}"
            )
        wall = time.perf_counter() - t0
        scenario_file = _write_outputs(out, fit, label, base, overrides, used, stats, wall)
        return SceneCalibration(fit, out, stats["simulations"], stats["failed"], wall, scenario_file)


def _write_outputs(
    out: Path, fit: CalibrationResult, label: str, base, overrides, cases, stats, wall: float
) -> Path:
    from gearbody.model import dump_scenario, load_scenario
    from gearbody.plotting.calibration import plot_convergence

    values = [f"{k}={v!r}" for k, v in fit.parameters.items()]
    sc = load_scenario(dict(base), [*overrides, *values])
    sources = (
        *sc.meta.sources,
        f"calibrated by gearbody {__version__} from {label}: {', '.join(values)} fitted to "
        + "; ".join(f"{t.label} = {t.value:g} +- {t.sigma:g}" for t in fit.targets)
        + f" (files in {out})",
    )
    sc = sc.replace(meta=sc.meta.replace(name=f"{sc.meta.name}-calibrated", sources=sources))
    scenario_file = atomic_write(out / "calibrated.toml", lambda p: dump_scenario(sc, p))
    write_json(
        out / "calibration.json",
        {
            "format": "gearbody-calibration/1",
            "gearbody": __version__,
            "scene": label,
            "overrides": list(overrides),
            "cases": {c: list(v) for c, v in cases.items()},
            "parameters": fit.parameters,
            **fit.uncertainty_record(),  # sigma (null: unidentified), correlation, flags, warnings
            "targets": [
                {"feature": t.feature, "case": t.case, "value": t.value, "sigma": t.sigma}
                for t in fit.targets
            ],
            "features": fit.features,
            "residuals": fit.residuals,
            "cost": fit.cost,
            "evaluations": fit.evaluations,
            "replayed": fit.replayed,
            "simulations": stats["simulations"],
            "failed_evaluations": stats["failed"],
            "wall_time_s": wall,
            "history": fit.history,
        },
    )
    warnings = "".join(f"- warning: {w}\n" for w in fit.warnings())
    text = (
        f"# Calibration of {label}\n\n```\n{fit.table()}\n```\n\n"
        + (f"{warnings}\n" if warnings else "")
        + f"{stats['simulations']} simulations in this run, {wall:.1f} s wall; "
        f"cases: {', '.join(repr(c) for c in cases if c) or 'the scene only'}. "
        f"Rerun the fitted scene: `gearbody run {out / 'calibrated.toml'}`.\n"
    )
    write_text(out / "calibration.md", text)
    plot_convergence(fit.history, out / "convergence.png", title=f"{Path(label).name}: calibration")
    return scenario_file
