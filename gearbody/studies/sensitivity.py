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

This module is the driver; the methods (problem, sample, SALib analysis) are in
:mod:`.sensitivity_methods`, the record in OUT and the indices written in :mod:`.sensitivity_record`, the
scene's checks before anything runs in :mod:`.sensitivity_scene`; their public names are also here.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from gearbody.errors import OutputError
from gearbody.folders import claim, output_error

from .executors import check_options, failure, run_jobs
from .sensitivity_methods import (  # INDEX_NAMES, MAX_LEVELS: this module's names before the split
    INDEX_NAMES,  # noqa: F401
    MAX_LEVELS,  # noqa: F401
    METHODS,
    check_outputs,
    check_sampling,
    check_seed_batch_conf,
    checked_run_count,
    make_problem,
    parse_key_range,
    run_count,
    salib,
    sample_matrix,
)
from .sensitivity_record import (
    FORMAT,
    MissingRowsError,
    SensitivityResult,
    analysis_spec,
    job_id,
    pending_rows,
    prepare_out,
    record_indices,
    recorded_rows,
    write_outputs,
)
from .sensitivity_scene import (  # PROBE_S, check_feature_windows: this module's names before the split
    PROBE_S,  # noqa: F401
    check_feature_signals,
    check_feature_windows,  # noqa: F401
    check_sample,
    check_scene_inputs,
    read_scene,
)
from .store import write_json

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

MAX_RUNS = 2000
"""Default bound on the simulations of one :func:`sensitivity` (``force`` / ``--force`` lifts it, up to
:data:`gearbody.studies.parse.MOST_CASES`: the sample matrix is made before anything runs)."""


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
    problem = make_problem(keys)
    outputs = check_outputs(method, outputs)
    samples, levels = check_sampling(method, samples, levels, exclude_failed)
    seed, batch = check_seed_batch_conf(seed, batch, conf_level)
    n_rows = checked_run_count(method, samples, len(problem), second_order, max_runs, force)
    check_options(workers, scheduler)
    salib()
    sampling = (samples, seed, levels, second_order, num_resamples, conf_level, batch)
    spec = analysis_spec(model, problem, outputs, method, sampling, model_args, describe)
    X = sample_matrix(problem, spec)
    if check is not None:
        check(X)
    out = Path(out)
    with claim(out, "sensitivity", overwrite=overwrite) as folder:  # locked while it writes
        folder.begin()
        prepare_out(out, spec, X)
        run = (workers, scheduler, progress)
        return _evaluate_and_analyse(
            out, spec, X, n_rows, model, model_args, retry_failed, exclude_failed, run, title
        )


def _evaluate_and_analyse(
    out: Path,
    spec: dict[str, Any],
    X: np.ndarray,
    n_rows: int,
    model: Callable[..., Mapping[str, float]],
    model_args: Sequence[Any],
    retry_failed: bool,
    exclude_failed: bool,
    run: tuple,
    title: str,
) -> SensitivityResult:
    """In the claimed ``out`` holding sensitivity.json: evaluate the rows not recorded yet (``run``:
    workers, scheduler, progress), then compute the indices and write them."""
    workers, scheduler, progress = run
    try:
        (out / "evaluations").mkdir(exist_ok=True)
    except OSError as exc:
        raise output_error(out / "evaluations", exc) from None

    pending = pending_rows(recorded_rows(out), n_rows, retry_failed)
    skipped = n_rows - len(pending)
    if progress and skipped:
        print(f"resuming {out}: {skipped} of {n_rows} rows already recorded", file=sys.stderr)
    keys, outputs = tuple(spec["keys"]), tuple(spec["outputs"])
    jobs, by_id = _jobs(model, pending, spec["batch"], X, keys, outputs, model_args)
    try:
        _run(jobs, by_id, out, workers, scheduler, progress)
    except KeyboardInterrupt:  # Ctrl-C or SIGTERM: the rows written so far stay recorded
        done = sum(1 for r in range(n_rows) if r in recorded_rows(out))
        raise KeyboardInterrupt(
            f"interrupted: {done} of {n_rows} runs recorded in {out / 'evaluations'}; rerun the same "
            "command to resume"
        ) from None

    indices, excluded = record_indices(out, spec, X, n_rows, outputs, exclude_failed)
    ran = len(pending)
    res = SensitivityResult(out, spec["method"], keys, outputs, indices, n_rows, ran, skipped, excluded)
    write_outputs(res, title or f"{spec['method']} sensitivity indices")
    return res


def _jobs(
    model: Callable[..., Mapping[str, float]],
    pending: Sequence[int],
    batch: int,
    X: np.ndarray,
    keys: tuple[str, ...],
    outputs: tuple[str, ...],
    model_args: Sequence[Any],
) -> tuple[list, dict[str, list[int]]]:
    """``(jobs for run_jobs, {job id: rows})``: the pending rows in jobs of ``batch`` rows."""
    chunks = [pending[i : i + batch] for i in range(0, len(pending), batch)]
    by_id = {job_id(c): c for c in chunks}
    Xl = X.tolist()
    jobs = [
        (jid, (model, c, [Xl[r] for r in c], keys, outputs, tuple(model_args))) for jid, c in by_id.items()
    ]
    return jobs, by_id


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
    problem = make_problem(keys)
    overrides = tuple(overrides)
    specs, parsed, label, base, sha = check_scene_inputs(scene, problem, features, overrides)

    def check(X: np.ndarray) -> None:  # after the options are checked, before anything is written
        check_sample(
            X, problem, base, overrides, parsed, Path(out), options, workers, scheduler, max_wall_minutes
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
