"""Output folders: a results folder is one run, written whole or not at all.

A command that writes a folder (``run``, ``render``, ``mesh``, ``sweep``, ``sensitivity``,
``calibrate``) writes into it only if it is empty, holds the same run, or the user asks to replace it
(``overwrite``, ``--overwrite``); then the old outputs are removed first. "Empty" sets aside
subfolders (``runs/SCENE/render`` lives in the run folder ``runs/SCENE``) and hidden files; "the old
outputs" are the files gearbody commands write (:data:`KINDS`), never a file of another program.

- **The same run**: a study holds its spec (``study.json``, ``sensitivity.json``, the fingerprint in
  ``evaluations.jsonl``): the same command resumes it. A ``run``, ``render`` or ``mesh`` folder holds
  ``.gearbody.json`` (:data:`MANIFEST`): the command and its *identity* (``run`` and ``mesh``: the
  resolved scenario; ``render``: the resolved scenario and where the motion comes from). The same
  command with the same identity writes the folder again (its old outputs removed first).
- **A lock**: a command holds ``flock`` on ``DIR/.gearbody.lock`` (:data:`LOCK`) while it writes;
  a second one on the same folder is refused in one line naming the first one's pid
  (:class:`~gearbody.errors.FolderInUse`). The kernel releases the lock when its process dies
  (SIGKILL included): a killed command never blocks the next one.
- **Nothing half-written**: :func:`atomic_write` writes a temporary file in the same folder and renames
  it; an ``OSError`` on the way (a full disk) removes the temporary file and becomes
  :class:`~gearbody.errors.OutputError`, one line naming the file.

The writing of files is :mod:`gearbody.atomic_files` and the lock :mod:`gearbody.folder_lock`; their
names are also here.
"""

from __future__ import annotations

import fnmatch
import json
import time
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

from .atomic_files import atomic_write, output_error, write_text  # noqa: F401 (output_error: as before)
from .errors import InputError, OutputError
from .folder_lock import LOCK, FolderLock
from .version import __version__

__all__ = [
    "KINDS",
    "LOCK",
    "MANIFEST",
    "Claim",
    "FolderLock",
    "FolderState",
    "Kind",
    "atomic_write",
    "claim",
    "identity_differences",
    "inspect",
    "read_manifest",
    "write_text",
]

MANIFEST = ".gearbody.json"
"""What wrote a run, render or mesh folder: ``{"format", "command", "identity", "complete", ...}``."""
FORMAT = "gearbody-folder/1"
TEMPORARY = ".*.tmp*"
"""Temporary files of :func:`atomic_write` (``.<stem>.<pid>.<random>.tmp<suffix>``)."""


class Kind(NamedTuple):
    """What a command writes in its folder: ``outputs`` (patterns of files or folders, removed before
    the folder is written again) and ``markers`` (the files that tell such a folder without a
    manifest, in the order they are looked for)."""

    command: str
    what: str
    outputs: tuple[str, ...]
    markers: tuple[str, ...]


RUN_PLOTS = (
    "kd_time*.png",
    "kd_folded*.png",
    "spectrum.png",
    "bearing_forces.png",
    "planet_kd_time*.png",
    "load_sharing*.png",
    "ring_sensor_spectrum*.png",
)

ANALYSIS_OUTPUTS = ("report.html", "features.json", "spectrum_*.png", "orders_*.png", "tsa_*.png",
                    "kurtogram_*.png", "envelope_*.png", "rpm_orders_*.png")  # fmt: skip
COMPARE_OUTPUTS = ("comparison.html", "comparison.json", "comparison.csv", "overlay_*.png")

KINDS: dict[str, Kind] = {  # studies first: their spec files mark them
    "sweep": Kind(
        "sweep",
        "a 'gearbody sweep' study",
        ("study.json", "cases", "summary.csv", "*_vs_*.png", ".running"),
        ("study.json", "cases"),
    ),
    "sensitivity": Kind(
        "sensitivity",
        "a 'gearbody sensitivity' analysis",
        ("sensitivity.json", "evaluations", "indices.csv", "indices.md", "indices.json", "indices.png"),
        ("sensitivity.json", "evaluations"),
    ),
    "calibrate": Kind(
        "calibrate",
        "a 'gearbody calibrate' calibration",
        ("evaluations.jsonl", "calibration.json", "calibration.md", "convergence.png", "calibrated.toml"),
        ("evaluations.jsonl", "calibration.json", "calibrated.toml"),
    ),
    "render": Kind(
        "render",
        "a 'gearbody render' animation",
        ("frame_*.png", "animation.gif", "animation.mp4", "result.npz", "scenario.toml"),
        ("frame_*.png", "animation.gif", "animation.mp4"),
    ),
    "mesh": Kind("mesh", "'gearbody mesh' plots", ("mesh_stage*.png",), ("mesh_stage*.png",)),
    "analyze": Kind("analyze", "a 'gearbody analyze' report", ANALYSIS_OUTPUTS, ("features.json",)),
    "compare": Kind("compare", "a 'gearbody compare' comparison", COMPARE_OUTPUTS, ("comparison.json",)),
    "run": Kind(
        "run",
        "a 'gearbody run' result",
        ("result.npz", "scenario.toml", "summary.json", "report.html", "instruments.mat", *RUN_PLOTS),
        ("result.npz", "summary.json", "scenario.toml", "report.html", *RUN_PLOTS),
    ),
}
STUDIES = ("sweep", "sensitivity", "calibrate")


# -- what a folder holds -------------------------------------------------------------------------------
@dataclass(frozen=True)
class FolderState:
    """What an output folder holds: the ``kind`` of gearbody outputs there (a command of :data:`KINDS`,
    None: none), the manifest of a run / render / mesh folder (None: none or unreadable), the
    gearbody ``outputs`` there and the ``foreign`` files (top level, not hidden, written by no
    gearbody command)."""

    path: Path
    kind: str | None = None
    manifest: dict[str, Any] | None = None
    outputs: tuple[Path, ...] = ()
    foreign: tuple[str, ...] = ()

    @property
    def empty(self) -> bool:
        return not self.outputs and not self.foreign

    def describe(self) -> str:
        """``a 'gearbody run' result (result.npz, scenario.toml, summary.json and 3 more)``."""
        if self.kind is None:
            return f"files gearbody did not write ({_names(self.foreign)})"
        return f"{KINDS[self.kind].what} ({_names([p.name for p in self.outputs])})"


def _names(names, shown: int = 3) -> str:
    names = sorted(names)
    more = f" and {len(names) - shown} more" if len(names) > shown else ""
    return ", ".join(names[:shown]) + more


def _matches(name: str, patterns) -> bool:
    return any(fnmatch.fnmatchcase(name, p) for p in patterns)


def read_manifest(folder: Path) -> dict[str, Any] | None:
    """The folder's manifest, or None (none, unreadable, not gearbody's)."""
    try:
        data = json.loads((folder / MANIFEST).read_text())
    except (OSError, ValueError):
        return None
    ok = isinstance(data, dict) and data.get("format") == FORMAT and data.get("command") in KINDS
    return data if ok else None


def inspect(path: str | Path) -> FolderState:
    """What ``path`` holds (an empty state if it does not exist)."""
    folder = Path(path)
    if not folder.is_dir():
        return FolderState(folder)
    entries = sorted(folder.iterdir())
    manifest = read_manifest(folder)
    kind = manifest["command"] if manifest else None
    if kind is None:  # written without a manifest: a study, or an earlier gearbody
        for name, k in KINDS.items():
            if any(_matches(e.name, k.markers) for e in entries):
                kind = name
                break
    own = KINDS[kind].outputs if kind else ()
    # in a gearbody folder, a file another command writes is gearbody's too (an earlier gearbody let
    # render write into a run folder); a folder is only its own command's (cases/, evaluations/)
    other = [p for k in KINDS.values() if k.command != kind for p in k.outputs] if kind else []
    outputs, foreign = [], []
    for entry in entries:
        if _matches(entry.name, own) or (not entry.is_dir() and _matches(entry.name, other)):
            outputs.append(entry)
        elif not entry.name.startswith(".") and not entry.is_dir():
            foreign.append(entry.name)
    return FolderState(folder, kind, manifest, tuple(outputs), tuple(foreign))


def remove_outputs(state: FolderState, keep: Iterable[Path] = ()) -> None:
    """Remove the gearbody outputs of ``state`` but ``keep`` (and stale temporary files); foreign files
    stay."""
    import shutil

    kept = {Path(p).resolve() for p in keep}
    doomed = [*state.outputs, *state.path.glob(TEMPORARY), state.path / MANIFEST]
    for entry in doomed:
        if entry.resolve() in kept:
            continue
        try:
            if entry.is_dir() and not entry.is_symlink():
                shutil.rmtree(entry)
            else:
                entry.unlink(missing_ok=True)
        except OSError as exc:
            raise OutputError(f"cannot remove {entry}: {exc.strerror or exc}") from None


# -- identity ------------------------------------------------------------------------------------------
def _canonical(identity: Mapping[str, Any]) -> str:
    return json.dumps(identity, sort_keys=True, default=str)


def _flat(data: Any, prefix: str = "") -> dict[str, Any]:
    """Dotted keys; a list of tables numbered from 1, as in scenario keys (``design.stages.2.mesh``)."""
    if isinstance(data, Mapping) and data:
        items = data.items()
    elif isinstance(data, list) and data and all(isinstance(v, Mapping) for v in data):
        items = ((str(i), v) for i, v in enumerate(data, start=1))
    else:
        return {prefix[:-1]: data}
    out: dict[str, Any] = {}
    for k, v in items:
        out.update(_flat(v, f"{prefix}{k}."))
    return out


def identity_differences(old: Mapping[str, Any], new: Mapping[str, Any], shown: int = 3) -> str:
    """``operation.t_end_s: 0.02 there, 0.05 now; ...`` (the first ``shown`` differing keys)."""
    a = _flat(json.loads(_canonical(old)))
    b = _flat(json.loads(_canonical(new)))
    keys = [k for k in sorted(set(a) | set(b)) if a.get(k, "(unset)") != b.get(k, "(unset)")]
    keys.sort(key=lambda k: not k.endswith("meta.name"))  # which scene first

    def text(v: Any) -> str:
        s = "unset" if v == "(unset)" else repr(v)
        return s if len(s) <= 40 else s[:37] + "..."

    parts = [
        f"{k.removeprefix('scenario.')}: {text(a.get(k, '(unset)'))} there, {text(b.get(k, '(unset)'))} now"
        for k in keys[:shown]
    ]
    more = f"; and {len(keys) - shown} more" if len(keys) > shown else ""
    return "; ".join(parts) + more


# -- claiming a folder ---------------------------------------------------------------------------------
@dataclass
class Claim:
    """A folder this process may write: locked, checked. ``mode``: ``"new"`` (empty), ``"same"``
    (holds the same run: a study resumes), ``"replace"`` (``overwrite``: the old outputs go).
    :meth:`begin` removes the old outputs (a study: only when replacing) and records the run as
    incomplete; :meth:`finish` records it complete; :meth:`release` (or the ``with`` block) unlocks."""

    path: Path
    command: str
    identity: dict[str, Any] | None
    state: FolderState
    mode: str
    lock: FolderLock
    option: str = "--out"
    created: bool = False
    """The folder did not exist before: a command that fails before writing anything leaves none."""
    created_parents: tuple[Path, ...] = ()
    """Folders made above it (innermost first; ``runs/SCENE`` of ``runs/SCENE/render``): removed too
    when such a command leaves them empty."""

    def begin(self, keep: Iterable[Path] = ()) -> None:
        """Just before the first output is written: the old outputs go (but ``keep``: an input read
        from the folder)."""
        if self.command in STUDIES:
            if self.mode == "replace":
                remove_outputs(self.state)
            self.state = inspect(self.path)
            return
        remove_outputs(self.state, keep)
        self._record(complete=False)

    def finish(self) -> None:
        """Record the run complete (run, render, mesh)."""
        if self.command not in STUDIES:
            self._record(complete=True)

    def _record(self, complete: bool) -> None:
        data = {
            "format": FORMAT,
            "command": self.command,
            "complete": complete,
            "gearbody_version": __version__,
            "written": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "identity": self.identity,
        }
        write_text(self.path / MANIFEST, json.dumps(data, indent=1, default=str) + "\n")

    def release(self) -> None:
        self.lock.release()

    def __enter__(self) -> Claim:
        return self

    def __exit__(self, exc_type, *exc) -> None:
        self.release()
        if exc_type is not None and self.created and _remove_if_unused(self.path):
            for parent in self.created_parents:
                try:
                    parent.rmdir()  # only if empty: another command may have written in it since
                except OSError:
                    break


def _remove_if_unused(folder: Path) -> bool:
    """Remove a folder a failed command created, if it holds nothing but the lock file; whether it did."""
    try:
        if {p.name for p in folder.iterdir()} <= {LOCK}:
            (folder / LOCK).unlink(missing_ok=True)
            folder.rmdir()
            return True
    except OSError:
        pass  # someone else's by now, or not ours to remove
    return False


def claim(
    path: str | Path,
    command: str,
    identity: Mapping[str, Any] | None = None,
    *,
    overwrite: bool = False,
    option: str = "--out",
) -> Claim:
    """Lock ``path`` (created if missing) for ``command`` and check what it holds: empty, the same
    run (``identity`` equal to the manifest's; a study: its own kind, whose spec the study checks),
    or, with ``overwrite``, anything; else :class:`~gearbody.errors.InputError` in one line naming
    ``option``, the folder and what it holds. Nothing is removed here (see :meth:`Claim.begin`).

    Call it after every input is checked and before anything runs, as ``with claim(...) as folder:``
    (the lock is released at the end of the block)."""
    if command not in KINDS:
        raise ValueError(f"command {command!r}: one of {', '.join(KINDS)}")
    folder = Path(path)
    created = not folder.exists()
    parents = []
    for parent in folder.parents:  # the missing ones, innermost first
        if parent.exists() or parent.is_symlink():
            break
        parents.append(parent)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"{option} {folder}: cannot create it: {exc.strerror or exc}") from None
    lock = FolderLock(folder, command).acquire(option)
    try:
        state = inspect(folder)
        identity = dict(identity) if identity is not None else None
        if state.empty:
            mode = "new"
        elif overwrite:
            mode = "replace"
        elif state.kind == command and _same(command, state, identity):
            mode = "same"
        else:
            raise InputError(_refusal(folder, command, state, identity, option))
    except BaseException:
        lock.release()
        raise
    return Claim(folder, command, identity, state, mode, lock, option, created, tuple(parents))


def _same(command: str, state: FolderState, identity: dict[str, Any] | None) -> bool:
    if command in STUDIES:
        return True  # the study compares its spec file
    recorded = (state.manifest or {}).get("identity")
    return recorded is not None and identity is not None and _canonical(recorded) == _canonical(identity)


def _refusal(folder: Path, command: str, state: FolderState, identity, option: str) -> str:
    shown = f"{option} {folder}"
    advice = f"give --overwrite to replace it, or choose another {option}"
    if state.kind is None:
        return (
            f"{shown} is not empty: it holds {state.describe()}; choose an empty or new folder, or give "
            "--overwrite to write beside them (they are kept)"
        )
    if state.kind == command and state.manifest and identity is not None:
        differences = identity_differences(state.manifest.get("identity") or {}, identity)
        return f"{shown} holds another {command} ({differences}); {advice}"
    if state.kind == command:
        return f"{shown} holds {state.describe()} written by an earlier gearbody (no {MANIFEST}); {advice}"
    return f"{shown} holds {state.describe()}; {advice}"
