"""The compiled path against the Python path, side by side in one process and one sitting (not a test).

For each scene (steady rated running, E(0.5, 10, 0.3), mu = 0.05 where the scene takes the error mode, no
anti-aliasing so that every run is compared on exact samples): gearbody at the accuracy levels draft,
default and tight on both force paths (``solver.force_path``), alternated in this process after a warm
run; wall seconds of the solve per simulated second, steps, rejected steps, microseconds per step attempt
and max |dF| / F_rated against a tight yardstick (rtol 1e-13, atol 1e-12, compiled path) over every mesh.
Then, in fresh processes (benchmarks/bench_speed.py's jobs), Exudyn's floor (the same system with constant
mesh stiffness and no user function; planetary scenes: their linearised system), the numba Dormand-Prince
loop (one-stage; the loop implements the torsional trains only) and the independent scipy reference.
Then a study of 64 one-stage cases on 2 local workers and on a local Dask cluster of 2 workers, on both
paths, and the wall of ``gearbody run one-stage``.

    python benchmarks/bench_force_path.py [--t-end 0.5] [--t-planetary 0.1] [--scenes ...] [--write]
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import tempfile
import time
from datetime import date
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from bench_planetary import errors as planetary_errors  # noqa: E402
from bench_planetary import force_names  # noqa: E402
from bench_speed import ACCURACY_PERCENT, RATED, TIGHT, overrides, run_fresh  # noqa: E402

SCENES = ("one-stage", "two-stage", "lateral-8dof", "planetary", "planetary-conveyor")
PLANETARY = ("planetary", "planetary-conveyor")
LEVELS = ("draft", "default", "tight")
TARGETS = {  # issue 28, s/s of the solve at the defaults on the compiled path
    "one-stage": 0.5,
    "two-stage": 0.8,
    "lateral-8dof": 1.2,
}
DRAFT_TARGET = 0.2  # one-stage, draft, s/s (and <= 1.5x the numba loop at <= 0.5 %)


def scene_overrides(scene: str, t_end: float, extra=()) -> list[str]:
    if scene in PLANETARY:
        return [*RATED, *planetary_errors(scene), f"operation.t_end_s={t_end}", *extra]
    return overrides(scene, t_end, extra)


def forces(result, sc) -> list[tuple[np.ndarray, float]]:
    """(mesh force, its rated force) of every mesh of the run."""
    return [(result[name], sc.stage_rated_force_N(k)) for name, k in force_names(sc)]


def timed(scene: str, t_end: float, extra=()):
    from gearbody import simulate
    from gearbody.model import load_scenario

    sc = load_scenario(scene, scene_overrides(scene, t_end, extra))
    r = simulate(sc)
    st = r.meta["solver_statistics"]
    attempts = st["steps"] + st["rejected_steps"]
    return (
        sc,
        r,
        st["solve_wall_s"] / t_end,
        st["steps"],
        st["rejected_steps"],
        st["solve_wall_s"] / attempts * 1e6,
    )


def max_error_percent(sc, r, yard) -> float:
    return max(
        float(np.max(np.abs(f - g)) / rated * 100)
        for (f, rated), (g, _) in zip(forces(r, sc), forces(yard, sc), strict=True)
    )


def bench_scene(scene: str, t_end: float) -> tuple[list[str], dict]:
    from gearbody import simulate
    from gearbody.model import load_scenario

    for path in ("python", "compiled"):  # kernels compiled or loaded, not counted
        simulate(load_scenario(scene, scene_overrides(scene, 0.002, [f'solver.force_path="{path}"'])))
    _, yard, *_ = timed(scene, t_end, TIGHT)
    rows, measured = [], {}
    for level in LEVELS:
        for path in ("python", "compiled"):
            extra = [f'solver.accuracy="{level}"', f'solver.force_path="{path}"']
            sc, r, sps, steps, rej, us = timed(scene, t_end, extra)
            err = max_error_percent(sc, r, yard)
            measured[(level, path)] = sps
            rows.append((f"{level}, {path} path", sps, steps, rej, us, err))
            print(f"  {scene} {level} {path}: {sps:.3f} s/s, {us:.2f} us/attempt, {err:.4f} %", flush=True)
    lines = [
        f"### {scene}: {t_end} s simulated, steady rated",
        "",
        "| run | solve s per simulated s | steps | rejected | us per attempt | max dF % of F_rated vs tight "
        "yardstick | python / compiled |",
        "|---|---|---|---|---|---|---|",
    ]
    for label, sps, steps, rej, us, err in rows:
        level, path = label.split(", ")[0], label.split(", ")[1].split()[0]
        ratio = measured[(level, "python")] / measured[(level, "compiled")] if path == "compiled" else None
        lines.append(
            f"| {label} | {sps:.3f} | {steps} | {rej} | {us:.2f} | {err:.4f} | "
            f"{'' if ratio is None else f'{ratio:.2f}'} |"
        )
    if scene not in PLANETARY:
        for kind, label in (
            ("floor", "Exudyn floor: the same system, constant mesh stiffness, no user function"),
            ("reference", "scipy reference (validation/)"),
        ):
            wall, steps, rej, t, F, _ = run_fresh(kind, scene, t_end)
            sps = wall / t_end
            us = "-" if steps < 0 else f"{wall / max(steps + rej, 1) * 1e6:.2f}"
            lines.append(
                f"| {label} | {sps:.3f} | {max(steps, 0) or '-'} | {'-' if rej < 0 else rej} | {us} | - | |"
            )
            measured[kind] = sps
            print(f"  {scene} {kind}: {sps:.3f} s/s", flush=True)
    if scene == "one-stage":
        for rtol, atol in ((1e-6, 1e-9), (1e-6, 3e-10), (1e-6, 1e-11)):
            wall, steps, rej, t, F, _ = run_fresh("numba", scene, t_end, (), (rtol, atol, False))
            err = float(np.max(np.abs(F - yard.mesh_force))) / load_scenario(scene).rated_mesh_force_N * 100
            lines.append(
                f"| numba DOPRI5 loop (benchmarks/numba_integrator.py), rtol {rtol:g}, atol {atol:g} | "
                f"{wall / t_end:.3f} | {steps} | {rej} | {wall / (steps + rej) * 1e6:.2f} | {err:.4f} | |"
            )
            print(f"  numba {atol:g}: {wall / t_end:.3f} s/s, {err:.4f} %", flush=True)
            if err <= ACCURACY_PERCENT:
                measured["numba"] = wall / t_end
                break
    return lines, measured


def _planetary_floor(scene: str, t_end: float):
    """Exudyn alone on a planetary drive's bodies (fresh process): the linearised system (meshes as
    constant stiffness matrices at their mean, compound_system(..., modal=True) with its constraints
    kept), from the run's initial state, no user function. (wall s, steps, rejected)."""
    import dataclasses

    import exudyn as exu

    from gearbody.assembly.compound import compound_layout
    from gearbody.assembly.compound_system import compound_system
    from gearbody.assembly.layouts import drive_system
    from gearbody.engine.build import build
    from gearbody.engine.simulate import SOLVER_TYPES, solver_settings
    from gearbody.model import load_scenario

    sc = load_scenario(scene, scene_overrides(scene, t_end))
    _, q0, v0 = drive_system(sc)
    linear = dataclasses.replace(compound_system(compound_layout(sc, modal=True), modal=True), modal=False)
    built = build(linear, q0, v0)
    t0 = time.perf_counter()
    exu.SolveDynamic(
        built.mbs, solver_settings(sc), solverType=SOLVER_TYPES[sc.solver.method], storeSolver=True
    )
    wall = time.perf_counter() - t0
    it = built.mbs.sys["dynamicSolver"].it
    return wall, int(it.currentStepIndex), int(it.rejectedAutomaticStepSizeSteps)


def planetary_floor(scene: str, t_end: float) -> str:
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(max_workers=1) as pool:
        wall, steps, rej = pool.submit(_planetary_floor, scene, t_end).result()
    print(f"  {scene} floor: {wall / t_end:.3f} s/s", flush=True)
    return (
        "| Exudyn floor: the same bodies, meshes as constant stiffness matrices (linearised), no user "
        f"function | {wall / t_end:.3f} | {steps} | {rej} | {wall / max(steps + rej, 1) * 1e6:.2f} | - | |"
    )


def planetary_reference(scene: str, t_ref: float) -> str:
    from gearbody_validation.reference.planetary_drive import simulate_reference_drive

    from gearbody.model import load_scenario, scenario_to_dict

    sc = load_scenario(scene, scene_overrides(scene, t_ref))
    t0 = time.perf_counter()
    simulate_reference_drive(scenario_to_dict(sc), np.arange(int(t_ref * 20000) + 1) / 20000)
    sps = (time.perf_counter() - t0) / t_ref
    print(f"  {scene} reference: {sps:.1f} s/s", flush=True)
    return f"| scipy reference (validation/), first {t_ref} s | {sps:.2f} | - | - | - | - | |"


def study(cases: int = 64, t_end: float = 0.1) -> list[str]:
    from gearbody.studies import run_study

    walls = {}
    for path in ("python", "compiled"):
        for where in ("2 local workers", "local Dask cluster, 2 workers"):
            base = [*RATED, f"operation.t_end_s={t_end}", f'solver.force_path="{path}"']
            kwargs = {"workers": 2}
            cluster = client = None
            if where.startswith("local Dask"):
                from dask.distributed import Client, LocalCluster

                cluster = LocalCluster(
                    n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
                )
                client = Client(cluster)
                kwargs = {"scheduler": client}
            try:
                with tempfile.TemporaryDirectory() as out:
                    t0 = time.perf_counter()
                    res = run_study(
                        "one-stage",
                        out_dir=out,
                        vary={"production.error_mode.e_um": list(np.linspace(0.0, 15.0, cases))},
                        base_overrides=base,
                        progress=False,
                        save_results=False,
                        **kwargs,
                    )
                    walls[(path, where)] = time.perf_counter() - t0
                    assert res.n_ok == cases, res.table()
            finally:
                if client is not None:
                    client.close()
                    cluster.close()
            print(f"  study {path} {where}: {walls[(path, where)]:.1f} s", flush=True)
    lines = [
        f"### A study of {cases} one-stage cases ({t_end} s each, steady rated)",
        "",
        "| where | python path wall s | compiled path wall s | python / compiled |",
        "|---|---|---|---|",
    ]
    for where in ("2 local workers", "local Dask cluster, 2 workers"):
        p, c = walls[("python", where)], walls[("compiled", where)]
        lines.append(f"| {where} | {p:.1f} | {c:.1f} | {p / c:.2f} |")
    return lines


def run_command_wall() -> str:
    with tempfile.TemporaryDirectory() as out:
        script = Path(sys.executable).with_name("gearbody")  # the installed command, as a user runs it
        start = [str(script)] if script.exists() else [sys.executable, "-m", "gearbody.cli"]
        cmd = [*start, "run", "one-stage", "--out", str(Path(out) / "r")]
        subprocess.run(cmd, check=True, capture_output=True)  # warm caches
        t0 = time.perf_counter()
        subprocess.run([*cmd[:-1], str(Path(out) / "r2")], check=True, capture_output=True)
        wall = time.perf_counter() - t0
    print(f"  gearbody run one-stage: {wall:.2f} s", flush=True)
    what = "`gearbody run one-stage` (2 s simulated, plots written; warm caches)"
    return f"- {what}: {wall:.2f} s wall (target <= 3.5)"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--t-end", type=float, default=0.5)
    ap.add_argument("--t-planetary", type=float, default=0.1)
    ap.add_argument("--t-ref", type=float, default=0.02, help="planetary reference span, s")
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--no-study", action="store_true")
    ap.add_argument("--write", action="store_true", help="append the tables to benchmarks/RESULTS.md")
    args = ap.parse_args()
    import gearbody
    from gearbody.engine.compiled_path import compiled_path_status

    works, why = compiled_path_status()
    if not works:
        raise SystemExit(f"the compiled path does not work here: {why}")
    lines = [
        f"## Compiled path vs Python path ({date.today()}, {platform.machine()}, {os.cpu_count()} CPUs, "
        f"gearbody {gearbody.__version__}; `python benchmarks/bench_force_path.py --t-end {args.t_end} "
        f"--t-planetary {args.t_planetary}`)",
        "",
    ]
    summary = []
    for scene in args.scenes.split(","):
        t_end = args.t_planetary if scene in PLANETARY else args.t_end
        print(scene, flush=True)
        block, m = bench_scene(scene, t_end)
        if scene in PLANETARY:
            block.append(planetary_floor(scene, t_end))
            block.append(planetary_reference(scene, args.t_ref))
        lines += block + [""]
        c, p = m[("default", "compiled")], m[("default", "python")]
        target = TARGETS.get(scene)
        verdict = (
            f"target {target}: {'met' if c <= target else 'MISSED'}" if target else "target >= 3x faster"
        )
        if scene in PLANETARY:
            verdict += f": {'met' if p / c >= 3 else 'MISSED'}"
        summary.append(f"- {scene}: defaults {p:.3f} -> {c:.3f} s/s ({p / c:.2f}x; {verdict})")
        if scene == "one-stage":
            d = m[("draft", "compiled")]
            summary.append(
                f"- one-stage draft: {m[('draft', 'python')]:.3f} -> {d:.3f} s/s (target {DRAFT_TARGET}: "
                f"{'met' if d <= DRAFT_TARGET else 'MISSED'}); Exudyn floor {m['floor']:.3f} s/s"
                + (
                    f"; draft / numba loop at <= 0.5 %: {d / m['numba']:.2f} (target <= 1.5)"
                    if "numba" in m
                    else ""
                )
            )
    if not args.no_study:
        lines += study() + [""]
    summary.append(run_command_wall())
    lines += ["### Against the targets", "", *summary, ""]
    text = "\n".join(lines)
    print(text)
    if args.write:
        out = HERE / "RESULTS.md"
        out.write_text(out.read_text() + "\n" + text)


if __name__ == "__main__":
    main()
