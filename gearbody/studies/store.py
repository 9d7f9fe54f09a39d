"""The files of a study in its output folder, written atomically (readers never see a part):
``OUT/study.json`` (the spec and case list; a rerun must match it to resume) and one folder per case,
``OUT/cases/<id>/`` with ``result.npz``, ``scenario.toml`` and ``summary.json``, or ``error.json`` for a
failed case. A case is done when its ``summary.json`` (or ``error.json``) is there."""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Any

import numpy as np

from gearbody.folders import atomic_write, output_error, write_text
from gearbody.model import Scenario, dump_scenario
from gearbody.version import __version__

from .parse import SweepSpecError
from .spec import Case, Study

__all__ = [
    "STUDY_FORMAT",
    "atomic_write",
    "case_state",
    "prepare_out",
    "read_json",
    "write_case",
    "write_json",
    "write_text",
]

STUDY_FORMAT = "gearbody-sweep/1"


def write_json(path: Path, data: Any) -> Path:
    return write_text(path, json.dumps(data, indent=2, default=_jsonable) + "\n")


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, (np.ndarray, tuple)):
        return list(obj)
    return str(obj)


def read_json(path: Path) -> dict | None:
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def write_case(case_dir: Path, case: Case, scenario: Scenario, outcome: dict, save_results: bool) -> None:
    """A finished case's files; ``summary.json`` (or ``error.json``) last: it marks the case done. A file
    that cannot be written (a full disk) raises :class:`~gearbody.errors.OutputError` naming it, and
    the case stays pending: a resume runs it again."""
    try:
        case_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise output_error(case_dir, exc) from None
    for stale in case_dir.glob(".*.tmp*"):  # left by an interrupted run (the folder is locked: not live)
        stale.unlink(missing_ok=True)
    head = {"case": case.id, "values": case.texts, "overrides": list(case.overrides)}
    if outcome["ok"]:
        if save_results and outcome.get("result") is not None:
            atomic_write(case_dir / "result.npz", outcome["result"].save_npz)
        atomic_write(case_dir / "scenario.toml", lambda p: dump_scenario(scenario, p))
        write_json(case_dir / "summary.json", {**outcome["summary"], **head, "status": "ok"})
        (case_dir / "error.json").unlink(missing_ok=True)
    else:
        error = {k: outcome[k] for k in ("error_type", "message", "wall_time_s", "traceback")}
        write_json(case_dir / "error.json", {**head, "status": "failed", **error})


def case_state(case_dir: Path) -> tuple[str, dict | None]:
    """("ok", summary) | ("failed", error) | ("pending", None) from a case folder."""
    summary = read_json(case_dir / "summary.json")
    if summary is not None:
        return "ok", summary
    error = read_json(case_dir / "error.json")
    if error is not None:
        return "failed", error
    return "pending", None


def prepare_out(out: Path, study: Study, cases: list[Case]) -> None:
    """Create OUT/study.json, or check that the one there describes this study (call it on a claimed
    folder, :func:`gearbody.folders.claim`)."""
    path = out / "study.json"
    spec = study.spec()
    listing = [{"id": c.id, "overrides": list(c.overrides)} for c in cases]
    advice = "give --overwrite to replace it, or choose another --out"
    if path.exists():
        old = read_json(path)
        if old is None or old.get("format") != STUDY_FORMAT:
            raise SweepSpecError(f"--out {out}: {path} is not a gearbody study file; {advice}")
        diff = [k for k in spec if old.get("spec", {}).get(k) != spec[k]]
        if diff:
            shown = "; ".join(f"{k}: {old.get('spec', {}).get(k)!r} there, {spec[k]!r} now" for k in diff)
            raise SweepSpecError(
                f"--out {out} holds a different study ({shown}); rerun with the same arguments to resume, "
                f"{advice}"
            )
        if old.get("cases") != listing:
            raise SweepSpecError(
                f"--out {out}: same arguments but different cases (random draws changed with this numpy?); "
                f"{advice}"
            )
        return
    if (out / "cases").exists():
        raise SweepSpecError(f"--out {out} has a cases/ folder but no study.json; {advice}")
    out.mkdir(parents=True, exist_ok=True)
    write_json(
        path,
        {
            "format": STUDY_FORMAT,
            "gearbody_version": __version__,
            "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "keys": study.keys,
            "spec": spec,
            "cases": listing,
        },
    )
