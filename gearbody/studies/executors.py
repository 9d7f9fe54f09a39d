"""Where the runs of a study execute: in this process, on a local process pool, or on a Dask
distributed cluster; one set of executors for parameter sweeps and K_d-against-speed sweeps.

A job is ``(id, args)``; a task is a picklable module-level function ``task(*args) -> outcome`` that
never raises (it returns :func:`failure` instead). Exudyn systems cannot be pickled: the tasks rebuild
their model from plain TOML data and override strings. Every executor yields ``(id, outcome)`` as jobs
finish (the pool and Dask in completion order); a worker that dies or cannot unpickle yields a
:func:`failure` for its job.
"""

from __future__ import annotations

import math
import os
import traceback
import uuid
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Any

from .parse import SweepSpecError

__all__ = ["Job", "check_options", "dask", "failure", "run_dask", "run_jobs", "run_pool", "run_serial"]

Job = tuple[str, tuple]
Task = Callable[..., dict[str, Any]]


def failure(exc: BaseException, wall_s: float = math.nan) -> dict[str, Any]:
    """The outcome of a failed job: ``{"ok": False, "error_type", "message", "traceback", "wall_time_s"}``."""
    return {
        "ok": False,
        "error_type": type(exc).__name__,
        "message": str(exc) or repr(exc),
        "traceback": "".join(traceback.format_exception(type(exc), exc, exc.__traceback__)),
        "wall_time_s": wall_s,
    }


def run_serial(task: Task, jobs: Sequence[Job]) -> Iterator[tuple[str, dict]]:
    for jid, args in jobs:
        yield jid, task(*args)


def run_pool(task: Task, jobs: Sequence[Job], workers: int) -> Iterator[tuple[str, dict]]:
    pool = ProcessPoolExecutor(max_workers=workers)
    futures = {}
    try:
        futures = {pool.submit(task, *args): jid for jid, args in jobs}
        for fut in as_completed(futures):
            try:
                outcome = fut.result()
            except Exception as exc:  # the worker died (BrokenProcessPool) or could not unpickle
                outcome = failure(exc)
            yield futures[fut], outcome
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def dask():
    """The ``dask.distributed`` module, or an ImportError saying what to install."""
    try:
        from dask import distributed
    except ImportError as exc:
        raise ImportError(
            "running a study on a Dask cluster needs dask.distributed: pip install gearbody[sweep]"
        ) from exc
    return distributed


def run_dask(
    task: Task, jobs: Sequence[Job], scheduler: Any, name: str = "gearbody-sweep"
) -> Iterator[tuple[str, dict]]:
    """On a Dask cluster: ``scheduler`` is an address (a client is opened and closed here) or a
    ``dask.distributed.Client``. Task keys are ``<name>-<token>-<id>``."""
    distributed = dask()
    own = isinstance(scheduler, str)
    if own:
        try:
            client = distributed.Client(scheduler, timeout="20s")
        except (OSError, TimeoutError) as exc:
            raise SweepSpecError(f"--scheduler {scheduler}: cannot connect: {exc}") from None
    else:
        client = scheduler  # an existing dask.distributed.Client
    token = uuid.uuid4().hex[:8]
    futures: dict = {}
    try:
        for jid, args in jobs:
            fut = client.submit(task, *args, key=f"{name}-{token}-{jid}", pure=False)
            futures[fut] = jid
        for fut in distributed.as_completed(list(futures)):
            try:
                outcome = fut.result()
            except Exception as exc:  # KilledWorker, lost connection, ...
                outcome = failure(exc)
            yield futures[fut], outcome
            fut.release()
    finally:
        if futures:
            client.cancel(list(futures))
        if own:
            client.close()


def check_options(workers: int | None, scheduler: Any | None) -> None:
    """SweepSpecError for workers and scheduler together or a bad worker count; ImportError for a
    scheduler without dask.distributed. Call before anything runs."""
    if scheduler is not None and workers is not None:
        raise SweepSpecError("--workers and --scheduler exclude each other (the cluster has its workers)")
    if workers is not None and (isinstance(workers, bool) or int(workers) != workers or workers < 1):
        raise SweepSpecError(f"--workers must be a whole number >= 1, got {workers!r}")
    if scheduler is not None:
        dask()  # clear ImportError before anything runs


def run_jobs(
    task: Task,
    jobs: Sequence[Job],
    *,
    workers: int | None = None,
    scheduler: Any | None = None,
    name: str = "gearbody-sweep",
) -> Iterator[tuple[str, dict]]:
    """Run ``task`` on every job, on ``scheduler`` (Dask) if given, else on ``workers`` local processes
    (default ``os.cpu_count()``, at most one per job; 1: serially in this process)."""
    jobs = list(jobs)
    n_workers = min(workers or os.cpu_count() or 1, max(len(jobs), 1))
    if not jobs:
        return iter(())
    if scheduler is not None:
        return run_dask(task, jobs, scheduler, name)
    if n_workers == 1:
        return run_serial(task, jobs)
    return run_pool(task, jobs, n_workers)
