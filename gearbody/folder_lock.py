"""The lock of a folder being written (:mod:`gearbody.folders`): a command holds ``flock`` on
``DIR/.gearbody.lock`` (:data:`LOCK`) while it writes; a second one on the same folder is refused in one
line naming the first one's pid (:class:`~gearbody.errors.FolderInUse`). The kernel releases the lock
when its process dies (SIGKILL included): a killed command never blocks the next one."""

from __future__ import annotations

import contextlib
import fcntl
import os
from dataclasses import dataclass, field
from pathlib import Path

from .atomic_files import output_error
from .errors import FolderInUse

__all__ = ["LOCK", "FolderLock"]

LOCK = ".gearbody.lock"
"""The lock file of a folder being written (``flock``; removed when the command ends)."""

_HELD: dict[int, FolderLock] = {}  # fd -> lock held by this process (closed in forked children)


def _forget_locks_in_child() -> None:
    """In a forked child (a pool worker): close the inherited lock files without unlocking them (the
    parent holds the lock; closing a copy of the descriptor leaves it held)."""
    for fd in list(_HELD):
        with contextlib.suppress(OSError):
            os.close(fd)
        _HELD[fd].fd = None
    _HELD.clear()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_locks_in_child)


@dataclass
class FolderLock:
    """``flock`` on ``folder/.gearbody.lock`` for one command; the file holds ``<pid> <command>``."""

    folder: Path
    command: str
    fd: int | None = field(default=None, repr=False)

    @property
    def path(self) -> Path:
        return self.folder / LOCK

    def acquire(self, option: str = "--out") -> FolderLock:
        """Take the lock, or :class:`FolderInUse` naming the command and pid that hold it."""
        while True:
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
            except OSError as exc:
                raise output_error(self.path, exc) from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = _holder(fd)
                os.close(fd)
                raise FolderInUse(
                    f"{option} {self.folder}: another {holder} is writing in it; wait for it to end, or "
                    f"choose another {option}"
                ) from None
            except OSError:  # a filesystem without flock: no lock, as before
                os.close(fd)
                return self
            try:  # the file may have been removed by the holder it was taken from: lock the new one
                same = os.stat(self.path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                break
            os.close(fd)
        self.fd = fd
        _HELD[fd] = self
        with contextlib.suppress(OSError):  # who holds it: for the message of a second command
            os.ftruncate(fd, 0)
            os.write(fd, f"{os.getpid()} {self.command}\n".encode())
        return self

    def release(self) -> None:
        """Remove the lock file and release the lock (nothing if not held)."""
        fd, self.fd = self.fd, None
        if fd is None:
            return
        _HELD.pop(fd, None)
        with contextlib.suppress(OSError):
            if os.stat(self.path).st_ino == os.fstat(fd).st_ino:
                os.unlink(self.path)
        with contextlib.suppress(OSError):
            fcntl.flock(fd, fcntl.LOCK_UN)
        os.close(fd)

    def __enter__(self) -> FolderLock:
        return self.acquire() if self.fd is None else self

    def __exit__(self, *exc) -> None:
        self.release()


def _holder(fd: int) -> str:
    """``gearbody sweep (pid 1234)`` from a lock file's text."""
    with contextlib.suppress(OSError, ValueError):
        pid, command = os.pread(fd, 200, 0).decode().split()[:2]
        return f"gearbody {command} (pid {int(pid)})"
    return "gearbody command"
