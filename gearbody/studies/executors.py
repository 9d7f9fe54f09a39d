"""Where the runs of a study execute: in this process, on a local process pool, or on a Dask
distributed cluster; one set of executors for parameter sweeps and K_d-against-speed sweeps.

A job is ``(id, args)``; a task is a picklable module-level function ``task(*args) -> outcome`` that
never raises (it returns :func:`failure` instead). Exudyn systems cannot be pickled: the tasks rebuild
their model from plain TOML data and override strings. Every executor yields ``(id, outcome)`` as jobs
finish (the pool and Dask in completion order).

Failures of the machinery are charged to the job that met them, and the others go on: a pool worker
that dies (killed, crashed) fails only the job it was running, with its signal or exit code, and the
pool is restarted for the rest; a Dask job whose workers died ``distributed.scheduler.allowed-failures``
times (Dask reschedules it until then) fails with that cause. Ctrl-C (KeyboardInterrupt in the calling
process) stops every executor promptly: pool workers ignore SIGINT and are terminated, Dask jobs are
cancelled, and the KeyboardInterrupt propagates; jobs not yielded yet are simply not done.

No pool worker outlives the process that started it: a worker gets SIGTERM when its parent dies,
however it died (SIGKILL included; Linux: ``prctl(PR_SET_PDEATHSIG)``, elsewhere a thread that polls
``os.getppid()``), so a killed study leaves nothing running. Dask workers belong to their cluster, not
to the study: a study that dies leaves them running, and the scheduler drops the study's tasks when its
client's connection closes (docs/sweep.md, "Interrupting and resuming"). What a pool worker does is in
:mod:`.pool_workers`.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import signal
import tempfile
import threading
import traceback
import uuid
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import Any

from gearbody.errors import GearbodyError

from .parse import SweepSpecError
from .pool_workers import (  # PARENT_POLL_S, STOP_SIGNALS: this module's names before the split
    PARENT_POLL_S,  # noqa: F401
    STOP_SIGNALS,  # noqa: F401
    _marked,
    _stop_signals_held,
    _worker_init,
    death_cause,
)

__all__ = [
    "Job",
    "WorkerDied",
    "check_options",
    "check_scheduler_address",
    "dask",
    "death_cause",
    "failure",
    "run_dask",
    "run_jobs",
    "run_pool",
    "run_serial",
]

Job = tuple[str, tuple]
Task = Callable[..., dict[str, Any]]


def failure(exc: BaseException, wall_s: float = math.nan, message: str | None = None) -> dict[str, Any]:
    """The outcome of a failed job: ``{"ok": False, "error_type", "message", "traceback", "wall_time_s"}``
    (``message`` defaults to the exception's text)."""
    return {
        "ok": False,
        "error_type": type(exc).__name__,
        "message": message or str(exc) or repr(exc),
        "traceback": "".join(traceback.format_exception(type(exc), exc, exc.__traceback__)),
        "wall_time_s": wall_s,
    }


def run_serial(task: Task, jobs: Sequence[Job]) -> Iterator[tuple[str, dict]]:
    for jid, args in jobs:
        yield jid, task(*args)


MAX_UNCHARGED_RESTARTS = 3
"""Pool restarts after a worker died between jobs (no job to charge) before the pending jobs fail."""


class WorkerDied(GearbodyError, RuntimeError):
    """A pool worker process died (killed by a signal, crashed, or exited) while running a job."""


SHUTDOWN_GRACE_S = 30.0
"""How long a pool whose workers were stopped (interrupted, closed early, broken) may take to shut down.
Python 3.11's ProcessPoolExecutor can deadlock in that shutdown (its manager thread joins the queue's
feeder thread while holding the lock the feeder waits for: CPython gh-125451, fixed in later 3.12 and
3.13 releases); an interrupted sweep on a busy machine once had not ended 3 minutes after Ctrl-C."""

STUCK_POOLS: list[str] = []
"""Pools whose shutdown did not end within SHUTDOWN_GRACE_S: their manager threads would hold the
interpreter's exit for ever, so the command line leaves with ``os._exit`` (gearbody.cli.run)."""


def _shutdown_stopped(pool: ProcessPoolExecutor, processes: list) -> None:
    """Shut down a pool whose workers were told to stop, within SHUTDOWN_GRACE_S: a worker still alive
    then is killed, and a shutdown that is still stuck is left to a daemon thread (noted in
    STUCK_POOLS)."""
    stopper = threading.Thread(
        target=pool.shutdown,
        kwargs={"wait": True, "cancel_futures": True},
        name="gearbody-pool-stop",
        daemon=True,
    )
    stopper.start()
    stopper.join(SHUTDOWN_GRACE_S)
    if not stopper.is_alive():
        return
    for p in processes:
        if p.is_alive():
            p.kill()
            p.join(5.0)
    STUCK_POOLS.append(
        f"pool of {len(processes)} workers: shutdown still waiting after {SHUTDOWN_GRACE_S:g} s"
    )


def _pool_processes(pool: ProcessPoolExecutor) -> list:
    """The pool's worker processes (none once a broken pool has let go of them)."""
    return list((getattr(pool, "_processes", None) or {}).values())


def run_pool(
    task: Task, jobs: Sequence[Job], workers: int, mark_dir: str | Path | None = None
) -> Iterator[tuple[str, dict]]:
    """On a local process pool of ``workers`` processes. A worker that dies fails the job it was
    running (:class:`WorkerDied`, the message names the signal or exit code); the pool is restarted
    for the other jobs. ``mark_dir`` holds ``<pid>`` files naming each worker's running job (default:
    a temporary folder)."""
    todo = dict(jobs)
    marks = Path(mark_dir) if mark_dir is not None else Path(tempfile.mkdtemp(prefix="gearbody-pool-"))
    marks.mkdir(parents=True, exist_ok=True)
    uncharged = 0
    try:
        while todo:
            pool = ProcessPoolExecutor(
                max_workers=min(workers, len(todo)), initializer=_worker_init, initargs=(os.getpid(),)
            )
            futures: dict = {}
            processes: list = []
            broken = done = False
            try:
                try:
                    with _stop_signals_held():  # the workers are forked in submit
                        for jid, args in todo.items():
                            futures[pool.submit(_marked, str(marks), task, jid, args)] = jid
                        processes = _pool_processes(pool)  # fork: all started by now
                except BrokenProcessPool:  # a worker died while the jobs were handed out: as below
                    broken = True
                    processes = _pool_processes(pool)
                for fut in [] if broken else as_completed(futures):
                    try:
                        outcome = fut.result()
                    except BrokenProcessPool:  # a worker died: which one, and running what, below
                        broken = True
                        break
                    except Exception as exc:  # a result that cannot be unpickled
                        outcome = failure(exc)
                    del todo[futures[fut]]
                    yield futures[fut], outcome
                done = not broken
            finally:
                if done:
                    pool.shutdown(wait=True, cancel_futures=True)
                else:  # interrupted, closed early or broken: stop every worker now
                    processes = processes or _pool_processes(pool)
                    for p in processes:
                        p.terminate()
                    _shutdown_stopped(pool, processes)
            if not broken:
                continue
            for fut, jid in futures.items():  # finished before the break but not yielded yet
                if jid in todo and fut.done() and not fut.cancelled() and fut.exception() is None:
                    del todo[jid]
                    yield jid, fut.result()
            charged = 0
            for p in processes:  # the pool terminated the survivors (SIGTERM) after one died
                mark = marks / str(p.pid)
                jid = mark.read_text() if mark.exists() else None
                mark.unlink(missing_ok=True)
                if p.exitcode in (None, 0, -signal.SIGTERM) or jid not in todo:
                    continue
                cause = death_cause(p.exitcode)
                del todo[jid]
                charged += 1
                yield jid, failure(WorkerDied(cause), message=f"{cause} while running this case")
            uncharged = 0 if charged else uncharged + 1
            if uncharged > MAX_UNCHARGED_RESTARTS:
                for jid in list(todo):
                    del todo[jid]
                    yield jid, failure(WorkerDied("the process pool broke repeatedly"))
    finally:
        if mark_dir is None:
            shutil.rmtree(marks, ignore_errors=True)


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
        check_scheduler_address(scheduler)
        try:
            client = distributed.Client(scheduler, timeout=f"{CONNECT_TIMEOUT_S:g}s")
        except (OSError, TimeoutError, ValueError) as exc:  # nothing answers, or Dask refuses the address
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
            except distributed.KilledWorker as exc:  # its workers died allowed-failures times
                outcome = failure(exc, message=f"the Dask workers running this case died repeatedly: {exc}")
            except Exception as exc:  # lost connection, a result that cannot be unpickled, ...
                outcome = failure(exc)
            yield futures[fut], outcome
            fut.release()
    finally:
        if futures:
            client.cancel(list(futures))
        if own:
            client.close()


CONNECT_TIMEOUT_S = 20.0
"""How long a study waits for the Dask scheduler of ``--scheduler`` before it gives up [s]: an address
that answers nothing (no scheduler there, a firewall) fails after this, in one line (exit 2)."""

DASK_SCHEMES = ("tcp", "tls", "ws", "wss", "ucx")
"""The address schemes of a Dask scheduler that gearbody accepts (``inproc://`` lives in one process
only: a command line cannot reach it)."""

_ADDRESS = re.compile(
    r"(?:(?P<scheme>[A-Za-z][A-Za-z0-9+.-]*)://)?(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9._-]+):(?P<port>[0-9]+)"
)


def check_scheduler_address(address: str) -> None:
    """SweepSpecError unless ``address`` is a Dask scheduler address, ``SCHEME://HOST:PORT`` with a
    scheme of DASK_SCHEMES and a port 1..65535, or ``HOST:PORT`` (Dask's default scheme, tcp); nothing is
    contacted."""
    allowed = (
        "allowed: SCHEME://HOST:PORT with SCHEME one of " + ", ".join(DASK_SCHEMES) + " and PORT 1..65535, "
        "e.g. tcp://head:8786, or HOST:PORT (tcp)"
    )
    shown = f"--scheduler = {address!r}"
    match = _ADDRESS.fullmatch(address) if isinstance(address, str) else None
    if match is None:
        raise SweepSpecError(f"{shown}: not a Dask scheduler address; {allowed}")
    if match["scheme"] is not None and match["scheme"] not in DASK_SCHEMES:
        raise SweepSpecError(
            f"{shown}: the scheme {match['scheme']}:// is not one a study reaches a Dask scheduler by; "
            + allowed
        )
    if not 1 <= int(match["port"]) <= 65535:
        raise SweepSpecError(f"{shown}: port {int(match['port'])} does not exist; {allowed}")


def check_options(workers: int | None, scheduler: Any | None) -> None:
    """SweepSpecError for workers and scheduler together, a bad worker count or a scheduler address that
    is malformed (:func:`check_scheduler_address`); ImportError for a scheduler without dask.distributed.
    Call before anything runs."""
    if scheduler is not None and workers is not None:
        raise SweepSpecError("--workers and --scheduler exclude each other (the cluster has its workers)")
    if workers is not None and (isinstance(workers, bool) or int(workers) != workers or workers < 1):
        raise SweepSpecError(f"--workers must be a whole number >= 1, got {workers!r}")
    if scheduler is not None:
        if isinstance(scheduler, str):
            check_scheduler_address(scheduler)
        dask()  # clear ImportError before anything runs


def run_jobs(
    task: Task,
    jobs: Sequence[Job],
    *,
    workers: int | None = None,
    scheduler: Any | None = None,
    name: str = "gearbody-sweep",
    mark_dir: str | Path | None = None,
) -> Iterator[tuple[str, dict]]:
    """Run ``task`` on every job, on ``scheduler`` (Dask) if given, else on ``workers`` local processes
    (default ``os.cpu_count()``, at most one per job; 1: serially in this process). ``mark_dir``: see
    :func:`run_pool`."""
    jobs = list(jobs)
    n_workers = min(workers or os.cpu_count() or 1, max(len(jobs), 1))
    if not jobs:
        return iter(())
    if scheduler is not None:
        return run_dask(task, jobs, scheduler, name)
    if n_workers == 1:
        return run_serial(task, jobs)
    return run_pool(task, jobs, n_workers, mark_dir)
