"""Snapshots of short runs of every shipped scene, to show that a refactor keeps behaviour: every signal
bit for bit, and every metadata and summary value that existed before.

    python -m validation.snapshots save DIR [SCENE ...]      # every scene of `gearbody list` by default
    python -m validation.snapshots compare BEFORE AFTER      # exit 1 on any difference

A scene runs for ``T_END_S`` (planetary drives ``PLANETARY_T_END_S``) from its own initial state, with
its own solver settings. New signals or keys after the change are listed, not counted as differences.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

T_END_S = 0.05
PLANETARY_T_END_S = 0.01


def _t_end_s(scenario) -> float:
    planetary = any(getattr(st, "type", "") == "planetary" for st in scenario.stages)
    return PLANETARY_T_END_S if planetary else T_END_S


def save(folder: Path, scenes: list[str]) -> None:
    from gearbody import load_scenario, simulate
    from gearbody.model.scenes import list_scenes

    folder.mkdir(parents=True, exist_ok=True)
    for scene in scenes or list_scenes():
        t_end = _t_end_s(load_scenario(scene))
        result = simulate(load_scenario(scene, [f"operation.t_end_s={t_end}"]))
        result.save_npz(folder / f"{scene}.npz")
        (folder / f"{scene}.summary.json").write_text(json.dumps(result.summary(), indent=1, default=str))
        print(f"{scene}: {len(result.names)} signals, {result.time_s.size} samples", flush=True)


WALL_CLOCK = ("wall_time_s", "wall_s_per_simulated_s", "build_wall_s", "solve_wall_s")
"""Keys that time the run on the wall clock: never the same twice, left out of the comparison."""


def _differences(before, after, where: str) -> list[str]:
    """Every value of ``before`` that ``after`` lacks or holds differently (dicts and lists recursively;
    wall-clock times left out)."""
    if where.rsplit(".", 1)[-1] in WALL_CLOCK:
        return []
    if isinstance(before, dict):
        if not isinstance(after, dict):
            return [f"{where}: {type(after).__name__} instead of a dict"]
        out = []
        for k, v in before.items():
            out += [f"{where}.{k}: missing"] if k not in after else _differences(v, after[k], f"{where}.{k}")
        return out
    if isinstance(before, list) and isinstance(after, list) and len(before) == len(after):
        return [
            d
            for i, (x, y) in enumerate(zip(before, after, strict=True))
            for d in _differences(x, y, f"{where}[{i}]")
        ]
    if before != after and not (before != before and after != after):  # NaN == NaN here
        return [f"{where}: {before!r} -> {after!r}"]
    return []


def compare(a: Path, b: Path) -> int:
    bad = 0
    for path in sorted(a.glob("*.npz")):
        scene = path.stem
        with np.load(path) as A, np.load(b / path.name) as B:
            diffs, same = [], 0
            for k in A.files:
                if k == "meta_json":
                    diffs += _differences(json.loads(str(A[k])), json.loads(str(B[k])), "meta")
                elif k not in B.files:
                    diffs.append(f"{k}: missing")
                elif A[k].dtype != B[k].dtype or A[k].shape != B[k].shape:
                    diffs.append(f"{k}: {A[k].dtype}{A[k].shape} -> {B[k].dtype}{B[k].shape}")
                elif A[k].tobytes() != B[k].tobytes():
                    diffs.append(f"{k}: values differ (max |d| {np.nanmax(np.abs(A[k] - B[k])):.3g})")
                else:
                    same += 1
            new = sorted(set(B.files) - set(A.files))
        sa = json.loads((a / f"{scene}.summary.json").read_text())
        sb = json.loads((b / f"{scene}.summary.json").read_text())
        diffs += _differences(sa, sb, "summary")
        bad += bool(diffs)
        print(f"{scene}: {same} arrays bit-identical, {len(diffs)} differences, new arrays {new[:5]}")
        for d in diffs[:10]:
            print(f"    {d}")
    print("all bit-identical" if not bad else f"{bad} scene(s) differ")
    return 1 if bad else 0


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m validation.snapshots", description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser("save")
    s.add_argument("folder", type=Path)
    s.add_argument("scenes", nargs="*")
    c = sub.add_parser("compare")
    c.add_argument("before", type=Path)
    c.add_argument("after", type=Path)
    args = p.parse_args(argv)
    if args.command == "save":
        save(args.folder, args.scenes)
        return 0
    return compare(args.before, args.after)


if __name__ == "__main__":
    sys.exit(main())
