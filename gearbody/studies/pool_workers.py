"""The workers of the local process pool (:func:`gearbody.studies.executors.run_pool`): what a worker
does when it starts (ignores Ctrl-C, dies with its parent), the mark naming the job it runs, how its
death is told, and the stop signals held around the forks."""

from __future__ import annotations

import ctypes
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

__all__ = ["PARENT_POLL_S", "STOP_SIGNALS", "death_cause"]

PARENT_POLL_S = 0.5
"""How often a pool worker without PR_SET_PDEATHSIG (not Linux) checks that its parent is alive, s."""

_PR_SET_PDEATHSIG = 1  # linux/prctl.h


def _parent_death_signal() -> bool:
    """Ask Linux to send this process SIGTERM when its parent dies (``prctl(PR_SET_PDEATHSIG)``);
    False where that is unavailable (another platform, no libc)."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGTERM), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _watch_parent(parent_pid: int, poll_s: float = PARENT_POLL_S) -> threading.Thread:
    """A daemon thread that sends this process SIGTERM once its parent is gone (POSIX reparents an
    orphan, so ``os.getppid()`` changes): the fallback of :func:`_parent_death_signal`."""

    def watch() -> None:
        while os.getppid() == parent_pid:
            time.sleep(poll_s)
        os.kill(os.getpid(), signal.SIGTERM)

    thread = threading.Thread(target=watch, name="gearbody-parent-watch", daemon=True)
    thread.start()
    return thread


STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
"""The signals that stop a study (Ctrl-C, and SIGTERM from the command line)."""


@contextmanager
def _stop_signals_held() -> Iterator[None]:
    """Hold Ctrl-C and SIGTERM for the block and deliver one that arrived meanwhile when it ends.

    Around a fork: Python runs the fork's hooks in the parent (logging's lock release), and a
    KeyboardInterrupt raised in one of them is printed and lost, so the study would run on to its end;
    raised between the forks and the pool's start it would leave the forked workers waiting for work
    for ever. So a Python handler of either signal is replaced by one that notes the signal (it runs in
    the main thread whichever thread the signal reached), and this thread blocks both: a signal noted
    or pending is handled when the block ends, by the handler it was meant for. A forked child
    inherits the blocked mask, so that a SIGTERM sent to it before :func:`_worker_init` releases the
    mask stays pending instead of running the parent's handler."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    noted: list[int] = []
    handlers = {s: signal.getsignal(s) for s in STOP_SIGNALS}
    for s, handler in handlers.items():
        if callable(handler):  # SIG_DFL and SIG_IGN run no Python code: nothing to lose
            signal.signal(s, lambda signum, frame: noted.append(signum))
    mask = (
        signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS) if hasattr(signal, "pthread_sigmask") else None
    )
    try:
        yield
    finally:
        for s, handler in handlers.items():
            if callable(handler):
                signal.signal(s, handler)
        if mask is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)  # a pending one is handled here
        if noted:
            handlers[noted[0]](noted[0], None)


def _worker_init(parent_pid: int, death_signal: bool = True) -> None:
    """Pool worker initializer. Ctrl-C reaches the whole process group and the parent stops the workers,
    so a worker ignores SIGINT; SIGTERM (how the parent stops them) gets its default action back, which a
    forked worker would otherwise inherit as the command line's clean-stop handler. The worker dies with
    its parent (``parent_pid``): SIGTERM when the parent dies, from the kernel (``death_signal`` and
    Linux) or from a thread that polls the parent; a parent already gone by now is noticed here.

    The kernel sends the death signal when the *thread* that forked the worker ends: the pool is
    created and fed by the thread that iterates :func:`run_pool`, which outlives its workers."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if hasattr(signal, "pthread_sigmask"):  # forked while the parent held them (_stop_signals_held)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, STOP_SIGNALS)
    if not (death_signal and _parent_death_signal()):
        _watch_parent(parent_pid)
    if os.getppid() != parent_pid:  # the parent died before the death signal was armed
        os.kill(os.getpid(), signal.SIGTERM)


def _marked(marks: str, task: Callable[..., dict[str, Any]], jid: str, args: tuple) -> dict[str, Any]:
    """Run ``task(*args)`` in a pool worker with ``marks/<pid>`` naming the job while it runs (so the
    parent can tell which job a dead worker was running)."""
    mark = Path(marks) / str(os.getpid())
    try:
        mark.write_text(jid)
    except OSError:  # a full disk: the job runs unmarked (and its record will say why it stopped)
        pass
    try:
        return task(*args)
    finally:
        mark.unlink(missing_ok=True)


def death_cause(exitcode: int | None) -> str:
    """``worker process died (signal 9, SIGKILL)`` or ``worker process exited with code 1``."""
    if exitcode is not None and exitcode < 0:
        try:
            name = f", {signal.Signals(-exitcode).name}"
        except ValueError:
            name = ""
        return f"worker process died (signal {-exitcode}{name})"
    return f"worker process exited with code {exitcode}"
