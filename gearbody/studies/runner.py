"""Running a parameter study (``gearbody sweep``): check the whole spec and every case before anything
runs, resume what the output folder already holds, run the pending cases on an executor (serial,
process pool or Dask), write each finished case at once, then ``OUT/summary.csv`` and the plot.
Ctrl-C stops it promptly with :class:`StudyInterrupted`: the finished cases stay recorded, the running
and pending ones stay unrecorded, so the same call resumes them.

The package docstring (:mod:`gearbody.studies`) describes the study; docs/sweep.md the files.
"""

from __future__ import annotations

import shutil
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from gearbody.errors import OutputError
from gearbody.folders import claim
from gearbody.plotting.study import plot_study

from .executors import check_options, run_jobs
from .parse import SweepSpecError
from .spec import MAX_CASES, Case, Study
from .store import case_state, prepare_out, write_case
from .table import DEFAULT_PLOT_VALUE, StudyResult, check_plot_value, collect_rows, write_csv
from .tasks import run_case
from .wall import check_study_wall_time, run_estimates_s

__all__ = ["StudyInterrupted", "run_study"]


class StudyInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped a study: ``done`` of ``total`` cases are recorded; the same call resumes it."""

    def __init__(self, done: int, total: int) -> None:
        super().__init__(f"interrupted: {done} of {total} cases done; rerun the same command to resume")
        self.done, self.total = done, total


def run_study(
    scene: str | Path | Study,
    *,
    out_dir: str | Path,
    vary: Mapping[str, Sequence[Any] | str] | Sequence[str] | None = None,
    random: Mapping[str, str] | Sequence[str] | None = None,
    samples: int | None = None,
    study_seed: int = 0,
    seeds: int | None = None,
    base_overrides: Sequence[str] = (),
    workers: int | None = None,
    scheduler: str | Any | None = None,
    progress: bool = True,
    save_results: bool = True,
    retry_failed: bool = False,
    plot_value: str = DEFAULT_PLOT_VALUE,
    plot_key: str | None = None,
    max_cases: int = MAX_CASES,
    overwrite: bool = False,
    max_wall_minutes: float | None = None,
) -> StudyResult:
    """Run a parameter study, resuming whatever ``out_dir`` already holds of it.

    Args:
        scene: scene name, TOML path, or a prepared :class:`Study` (then leave the spec arguments out).
        out_dir: output folder (``study.json``, ``cases/<id>/``, ``summary.csv``, the plot).
        vary, random, samples, study_seed, seeds, base_overrides: the study, see :meth:`Study.build`.
        workers: local processes (default ``os.cpu_count()``); 1 runs the cases in this process.
        scheduler: a Dask scheduler address (``tcp://host:8786``) or a ``dask.distributed.Client``;
            the cases then run on that cluster (``workers`` must be left out).
        progress: show a progress bar (done, failed, time left) on stderr.
        save_results: write each case's ``result.npz`` (off for big studies: summaries only).
        retry_failed: rerun cases that have an ``error.json``.
        plot_value: summary value to plot (default ``kd_max_final``).
        plot_key: varied key on the x axis (default: the first one).
        max_cases: most cases the study may have (default :data:`~gearbody.studies.spec.MAX_CASES`).
        overwrite: replace what ``out_dir`` holds (its gearbody outputs are removed first) instead of
            resuming; without it, a folder holding anything but this study is refused.
        max_wall_minutes: refuse a study whose pending cases are estimated to take longer (default
            None: no limit; the command line's --max-wall-minutes). With ``progress`` an estimate above
            a minute is printed (:mod:`gearbody.studies.wall`).
    Raises:
        SweepSpecError, ScenarioError: bad input (also more than ``max_cases`` cases, or more than
            ``max_wall_minutes`` of estimated wall time), before anything runs; ``out_dir`` holds
            something else than this study (see ``overwrite``).
        FolderInUse: another command is writing in ``out_dir`` (its lock, :mod:`gearbody.folders`).
        OutputError: a file could not be written (a full disk); the cases written stay recorded.
        StudyInterrupted: Ctrl-C (a KeyboardInterrupt); the finished cases are recorded.
        ImportError: ``scheduler`` given but dask.distributed is not installed.
    """
    study = _study(scene, vary, random, samples, study_seed, seeds, base_overrides, max_cases)
    keys = study.keys
    plot_key = plot_key or keys[0]
    if plot_key not in keys:
        raise SweepSpecError(f"--plot-key {plot_key}: not a varied key; one of {', '.join(keys)}")
    check_plot_value(plot_value)
    check_options(workers, scheduler)

    cases = study.cases()
    scenarios = {c.id: study.load_case(c) for c in cases}  # every case valid before anything runs
    out = Path(out_dir)
    executor = (workers, scheduler, progress)
    _check_wall_time(out, cases, scenarios, overwrite, retry_failed, executor, max_wall_minutes)
    with claim(out, "sweep", overwrite=overwrite) as folder:  # locked while the study writes
        folder.begin()
        prepare_out(out, study, cases)

        pending = [c for c in cases if _still_to_run(out / "cases" / c.id, retry_failed)]
        skipped = len(cases) - len(pending)
        if progress and skipped:
            print(f"resuming {out}: {skipped} of {len(cases)} cases already done", file=sys.stderr)
        _run_cases(out, study, pending, scenarios, len(cases), skipped, save_results, executor)
        rows, csv_path, plot_path = _summarise(out, study, cases, plot_value, plot_key)
        return StudyResult(out, keys, rows, len(pending), skipped, csv_path, plot_path, plot_value)


def _study(scene, vary, random, samples, study_seed, seeds, base_overrides, max_cases) -> Study:
    """The study: ``scene`` if it is a prepared :class:`Study` (then no spec argument may be given),
    else built from the spec arguments (:meth:`Study.build`)."""
    if isinstance(scene, Study):
        if vary or random or samples is not None or seeds is not None or base_overrides or study_seed:
            raise SweepSpecError("give either a Study or the spec arguments (vary, random, ...), not both")
        return scene
    return Study.build(
        scene,
        vary=vary,
        random=random,
        samples=samples,
        study_seed=study_seed,
        seeds=seeds,
        base_overrides=base_overrides,
        max_cases=max_cases,
    )


def _check_wall_time(
    out: Path,
    cases: Sequence[Case],
    scenarios: Mapping[str, Any],
    overwrite: bool,
    retry_failed: bool,
    executor: tuple,
    max_wall_minutes: float | None,
) -> None:
    """Refuse a study whose cases still to run (read before anything is written; all of them if
    replaced) are estimated above ``max_wall_minutes`` (``executor``: workers, scheduler, progress)."""
    workers, scheduler, progress = executor
    estimate = [  # the cases still to run, read before anything is written (all of them if replaced)
        c for c in cases if overwrite or _still_to_run(out / "cases" / c.id, retry_failed)
    ]
    check_study_wall_time(
        run_estimates_s([scenarios[c.id] for c in estimate]),
        workers=workers,
        scheduler=scheduler,
        max_wall_minutes=max_wall_minutes,
        progress=progress,
        what=f"the study ({len(estimate)} of {len(cases)} cases to run)",
        remedy="shorten operation.t_end_s (--t-end), run fewer cases or more --workers",
    )


def _run_cases(
    out: Path,
    study: Study,
    pending: Sequence[Case],
    scenarios: Mapping[str, Any],
    n_cases: int,
    skipped: int,
    save_results: bool,
    executor: tuple,
) -> None:
    """Run the pending cases on the executor (``executor``: workers, scheduler, progress), each
    written to ``OUT/cases/<id>/`` as it finishes; Ctrl-C is :class:`StudyInterrupted`."""
    workers, scheduler, progress = executor
    by_id = {c.id: c for c in pending}
    jobs = [(c.id, (study.base, c.overrides, save_results)) for c in pending]
    running = out / ".running"  # pool workers' <pid> files naming their case, while it runs
    runner = run_jobs(run_case, jobs, workers=workers, scheduler=scheduler, mark_dir=running)

    from tqdm import tqdm

    failed = 0
    bar = None
    recorded: set[str] = set()
    try:
        for cid, outcome in runner:
            if cid in recorded:  # an executor never yields a case twice; never record one twice
                continue
            if bar is None:  # created after the pool has started its processes
                bar = tqdm(
                    total=len(jobs),
                    desc="sweep",
                    unit="case",
                    disable=not progress,
                    file=sys.stderr,
                    bar_format="{desc}: {n_fmt}/{total_fmt} cases done{postfix} |{bar}| "
                    "[{elapsed}<{remaining}]",
                )
                bar.set_postfix_str("0 failed", refresh=False)
            write_case(out / "cases" / cid, by_id[cid], scenarios[cid], outcome, save_results)
            recorded.add(cid)
            failed += not outcome["ok"]
            bar.set_postfix_str(f"{failed} failed", refresh=False)
            bar.update(1)
    except KeyboardInterrupt:
        raise StudyInterrupted(skipped + len(recorded), n_cases) from None
    except OutputError as exc:  # a full disk: what is recorded is whole; the rest runs on a resume
        raise OutputError(
            f"{exc}; {skipped + len(recorded)} of {n_cases} cases recorded: make room and rerun the "
            "same command to resume"
        ) from None
    finally:
        if bar is not None:
            bar.close()
        close = getattr(runner, "close", None)
        if close:
            close()
        shutil.rmtree(running, ignore_errors=True)


def _summarise(out: Path, study: Study, cases: Sequence[Case], plot_value: str, plot_key: str) -> tuple:
    """``(rows, summary.csv path, plot path)``: the summary of every case and the plot of ``plot_value``
    against ``plot_key``."""
    keys = study.keys
    rows, summary_cols = collect_rows(out, cases, keys)
    columns = ["id", *keys, "status", *summary_cols, "error"]
    csv_path = write_csv(out / "summary.csv", rows, columns)
    plot_path = plot_study(
        rows,
        keys,
        plot_value,
        plot_key,
        out / f"{plot_value}_vs_{plot_key}.png",
        title=f"{study.scene if len(study.scene) < 40 else Path(study.scene).name}: {plot_value} "
        f"against {plot_key}",
    )
    return rows, csv_path, plot_path


def _still_to_run(case_dir: Path, retry_failed: bool) -> bool:
    """A case not yet recorded, or recorded as failed when ``retry_failed``."""
    state, _ = case_state(case_dir)
    return state == "pending" or (state == "failed" and retry_failed)
