"""Files written whole or not at all (:mod:`gearbody.folders`): :func:`atomic_write` writes a temporary
file in the same folder and renames it; an ``OSError`` on the way (a full disk) removes the temporary
file and becomes :class:`~gearbody.errors.OutputError`, one line naming the file."""

from __future__ import annotations

import contextlib
import errno
import os
import uuid
from collections.abc import Callable
from pathlib import Path
from typing import Any

from .errors import OutputError

__all__ = ["atomic_write", "output_error", "write_text"]


def atomic_write(path: str | Path, write: Callable[[Path], Any]) -> Path:
    """``write(tmp)`` to a temporary file in ``path``'s folder, then ``os.replace`` it onto ``path``:
    a reader never sees a part, and a failed write leaves ``path`` as it was. An ``OSError`` (a full
    disk, a lost permission) removes the temporary file and is raised as :class:`OutputError` naming
    ``path`` (also an ``OSError``, with the original ``errno``)."""
    path = Path(path)
    tmp = path.with_name(f".{path.stem}.{os.getpid()}.{uuid.uuid4().hex[:8]}.tmp{path.suffix}")
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            tmp.unlink(missing_ok=True)
        if isinstance(exc, OSError) and not isinstance(exc, OutputError):
            raise output_error(path, exc) from None
        raise
    return path


def write_text(path: str | Path, text: str) -> Path:
    """``text`` to ``path`` atomically (:func:`atomic_write`), as UTF-8: a path quoted in it that is not
    UTF-8 (its bytes kept as surrogates) gets U+FFFD in their place."""
    text = text.encode("utf-8", "surrogateescape").decode("utf-8", "replace")
    return atomic_write(path, lambda p: p.write_text(text))


def output_error(path: str | Path, exc: OSError) -> OutputError:
    """``cannot write PATH: <reason>`` as an :class:`OutputError` with ``exc``'s errno."""
    reason = exc.strerror or str(exc) or type(exc).__name__
    if exc.errno == errno.ENOSPC:
        reason += " (the disk is full)"
    error = OutputError(f"cannot write {path}: {reason}")
    error.errno = exc.errno
    return error
