"""Speed at equal accuracy: gearbody vs the scipy reference vs a compiled equation-level integrator.

Not a test. In one process and one sitting, on the same scenario (steady rated running, E(0.5, 10, 0.3),
mu = 0.05, output without anti-aliasing so that every run is compared on exact samples):

1. a tight-tolerance gearbody run (rtol 1e-13, atol 1e-12) is the accuracy yardstick;
2. gearbody at its default solver settings, and with ``design.mesh.transition_width`` = 0.01;
3. the independent scipy reference (validation/), at its own tight tolerances;
4. benchmarks/numba_integrator.py (one-stage only): a numba Dormand-Prince loop of the same equations,
   at the loosest tolerance that still meets max |dF| / F_rated <= 0.5 %.

Each run reports wall seconds per simulated second, steps and rejected steps, max |dF|/F_rated against
the yardstick, and the peak resident memory of a fresh process that ran it. Then the build times
(fresh process, empty and warm numba cache), and the speed-up of a 16-case study on 2 workers vs 1.
``--write`` appends the tables to benchmarks/RESULTS.md.

    python benchmarks/bench_speed.py [--t-end 1.0] [--scenes one-stage,lateral-8dof,two-stage] [--write]
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from datetime import date
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
TARGETS_S_PER_S = {"one-stage": 0.6, "lateral-8dof": 1.5, "two-stage": 1.0}  # issue 16, at the defaults
NUMBA_RATIO_TARGET = 3.5  # one-stage: gearbody defaults / numba loop at <= 0.5 %
ACCURACY_PERCENT = 0.5
RATED = [
    'operation.initial_state="steady"',
    "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
    "condition.friction_coefficient=0.05",
    "solver.anti_aliasing=false",
]
ERROR_MODE = "production.error_mode={a=0.5,e_um=10.0,r=0.3}"  # trains: their own per-stage modes
TIGHT = ["solver.relative_tolerance=1e-13", "solver.absolute_tolerance=1e-12"]


def overrides(scene: str, t_end: float, extra=()) -> list[str]:
    out = [*RATED, f"operation.t_end_s={t_end}", *extra]
    return out if scene == "two-stage" else [ERROR_MODE, *out]


def _peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _job(kind: str, scene: str, t_end: float, extra: list[str], arg: float | None):
    """One timed run in a fresh worker process: (wall_s, steps, rejected, time, force, peak MB)."""
    from gearbody.model import load_scenario, scenario_to_dict

    sc = load_scenario(scene, overrides(scene, t_end, extra))
    warm = load_scenario(scene, overrides(scene, 0.002, extra))
    if kind == "gearbody":
        from gearbody.engine import simulate

        simulate(warm)  # compiled kernels loaded, not counted
        t0 = time.perf_counter()
        r = simulate(sc)
        wall = time.perf_counter() - t0
        st = r.meta["solver_statistics"]
        out = (wall, st["steps"], st["rejected_steps"], r.time_s, r.mesh_force)
    elif kind in ("floor", "python-floor"):  # the same system, constant mesh stiffness, no force law
        # python-floor: plus one Python user function on every node that returns zeros, the cost of
        # Exudyn calling Python once per right-hand side (what gearbody's one force function costs
        # before it computes anything)
        import exudyn as exu
        import exudyn.solver

        from gearbody.assembly import initial_state, static_lateral_displacements_m, torsional_layout
        from gearbody.assembly.topology import torsional_coordinates, torsional_system
        from gearbody.engine.build import build
        from gearbody.engine.simulate import SOLVER_TYPES, solver_settings

        q0, v0 = initial_state(sc)
        layout, u0 = torsional_layout(sc), static_lateral_displacements_m(sc)
        k_mesh = [1.25e9] * len(layout.meshes)
        system = torsional_system(layout, lateral_u0=u0, modal_mesh_stiffness_N_per_m=k_mesh)
        built = build(system, *torsional_coordinates(layout, q0, v0, u0))
        if kind == "python-floor":
            from exudyn.itemInterface import ObjectGenericODE2

            size = len(built.dof_names)
            zeros = [0.0] * size

            def no_force(mbs, t, itemNumber, q, q_t):
                return zeros

            built.user_functions.append(no_force)
            built.mbs.AddObject(ObjectGenericODE2(nodeNumbers=built.nodes, massMatrix=np.zeros((size, size)),
                                                  forceUserFunction=no_force))
            built.mbs.Assemble()
        settings = solver_settings(sc)
        exudyn.solver.solverCheckMemoryAllocationsThreshold = 2**62  # the zeros list is Python's
        t0 = time.perf_counter()
        exu.SolveDynamic(built.mbs, settings, solverType=SOLVER_TYPES[sc.solver.method], storeSolver=True,
                         showHints=False)
        wall = time.perf_counter() - t0
        it = built.mbs.sys["dynamicSolver"].it
        steps = int(it.currentStepIndex)
        out = (wall, steps, int(it.rejectedAutomaticStepSizeSteps), None, None)
    elif kind == "reference":
        if sc.is_lateral:
            from gearbody_validation.reference_lateral import simulate_reference_lateral as ref
        else:
            from gearbody_validation.reference import simulate_reference as ref
        t = np.arange(round(t_end * sc.solver.output_rate_hz) + 1) / sc.solver.output_rate_hz
        t0 = time.perf_counter()
        r = ref(scenario_to_dict(sc), t_eval=t)
        wall = time.perf_counter() - t0
        out = (wall, -1, -1, t, np.asarray(r["mesh_force_N"]))
    else:  # numba equation-level integrator, tolerance arg
        sys.path.insert(0, str(HERE))
        from numba_integrator import simulate_numba

        t = np.arange(round(t_end * sc.solver.output_rate_hz) + 1) / sc.solver.output_rate_hz
        rtol, atol, land = arg
        simulate_numba(warm, rtol=rtol, atol=atol, t_eval=t[t <= 0.002], stop_at_mesh_jumps=land)
        t0 = time.perf_counter()
        r = simulate_numba(sc, rtol=rtol, atol=atol, t_eval=t, stop_at_mesh_jumps=land)
        wall = time.perf_counter() - t0
        out = (wall, int(r["steps"]), int(r["rejected"]), t, np.asarray(r["mesh_force_N"]))
    return (*out, _peak_rss_mb())


def run_fresh(kind: str, scene: str, t_end: float, extra=(), arg=None):
    with ProcessPoolExecutor(max_workers=1) as pool:
        return pool.submit(_job, kind, scene, t_end, list(extra), arg).result()


def bench_scene(scene: str, t_end: float) -> list[str]:
    from gearbody.model import load_scenario

    F_rated = load_scenario(scene, overrides(scene, t_end)).rated_mesh_force_N
    tight = run_fresh("gearbody", scene, t_end, TIGHT)
    rows = []

    def row(label, res, note=""):
        wall, steps, rej, t, F, mb = res
        err = np.nan if F is None else np.max(np.abs(F - tight[4])) / F_rated * 100
        rows.append((label, wall / t_end, steps, rej, err, mb, note))
        print(f"  {label}: {wall / t_end:.3f} s/s, max dF {err:.4f} %", flush=True)
        return wall / t_end, err

    row("gearbody, tight yardstick (rtol 1e-13, atol 1e-12)", tight)
    g, _ = row(
        "**gearbody, defaults** (accuracy default: DOPRI5, atol 1e-8)", run_fresh("gearbody", scene, t_end)
    )
    for level, what in (("draft", "ODE23, atol 3e-5"), ("tight", "DOPRI5, atol 1e-10")):
        row(f"gearbody, accuracy {level} ({what})",
            run_fresh("gearbody", scene, t_end, [f'solver.accuracy="{level}"']))
    width = ["design.mesh.transition_width=0.01"] if scene != "two-stage" else []
    if width:
        row(
            "gearbody, transition_width 0.01, accuracy draft",
            run_fresh("gearbody", scene, t_end, [*width, 'solver.accuracy="draft"']),
            "vs the sharp yardstick: includes the model change",
        )
    row(
        "Exudyn floor: the same system, no user function (constant mesh stiffness, no motor/load law)",
        run_fresh("floor", scene, t_end),
        "what Exudyn costs without gearbody's Python force function",
    )
    row(
        "Exudyn floor + one Python user function returning zeros (the same system)",
        run_fresh("python-floor", scene, t_end),
        "the cost of one Python call per right-hand side, before any force is computed",
    )
    ref_s, _ = row("scipy reference (validation/)", run_fresh("reference", scene, t_end))
    numba_s = None
    if scene == "one-stage" and (HERE / "numba_integrator.py").exists():
        for rtol, atol in ((1e-6, 1e-9), (1e-6, 3e-10), (1e-6, 1e-11)):
            s, err = row(
                f"numba DOPRI5 (benchmarks/numba_integrator.py), rtol {rtol:g}, atol {atol:g} (angles "
                "by atol)",
                run_fresh("numba", scene, t_end, (), (rtol, atol, False)),
            )
            if err <= ACCURACY_PERCENT:
                numba_s = s
                break
        row(
            "numba DOPRI5, steps ending on the mesh jumps, tol 5e-6",
            run_fresh("numba", scene, t_end, (), (5e-6, 5e-6, True)),
            "beyond Exudyn's means (no event location); for reference",
        )
    lines = [
        f"### {scene}: {t_end} s simulated, steady rated, E(0.5,10,0.3), mu 0.05",
        "",
        "| run | wall s per simulated s | steps | rejected | us per step attempt | max dF % of F_rated vs "
        "tight | peak RSS MB | note |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for label, sps, steps, rej, err, mb, note in rows:
        st = "-" if steps < 0 else str(steps)
        rj = "-" if rej < 0 else str(rej)
        per = "-" if steps < 0 else f"{sps * t_end / max(steps + rej, 1) * 1e6:.2f}"
        e = "-" if np.isnan(err) else f"{err:.4f}"
        lines.append(f"| {label} | {sps:.3f} | {st} | {rj} | {per} | {e} | {mb:.0f} | {note} |")
    target = TARGETS_S_PER_S.get(scene)
    lines += [
        "",
        f"- gearbody defaults: {g:.3f} s per simulated s (target {target}: "
        f"{'met' if target and g <= target else 'MISSED'}); reference / gearbody = {ref_s / g:.1f}",
    ]
    if numba_s:
        lines.append(
            f"- gearbody defaults / numba integrator at <= 0.5 %: {g / numba_s:.1f} (target <= "
            f"{NUMBA_RATIO_TARGET})"
        )
    return lines


def build_times() -> list[str]:
    """Fresh interpreter: import + first simulate of 1 ms (build, compile or cache load), with an empty
    and with a warm numba cache."""
    code = (
        "import time; t0 = time.perf_counter(); import gearbody.engine as e, gearbody.model as m; "
        "t1 = time.perf_counter(); sc = m.load_scenario('one-stage', ['operation.t_end_s=0.001']); "
        "t2 = time.perf_counter(); b = e.build(sc); t3 = time.perf_counter(); e.simulate(sc); "
        "t4 = time.perf_counter(); "
        "print(f'{t1 - t0:.3f} {t3 - t2:.3f} {t4 - t3:.3f}')"
    )
    out = []
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        for label in ("empty numba cache (first time)", "warm numba cache"):
            cmd = [sys.executable, "-c", code]
            r = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
            imp, build, first = (float(x) for x in r.stdout.split()[-3:])
            out.append(f"| {label} | {imp:.2f} | {build:.2f} | {first:.2f} |")
            print(" ", label, imp, build, first, flush=True)
    return [
        "### Building a model (one-stage, fresh interpreter)",
        "",
        "| numba cache | import gearbody s | build() s | first simulate of 1 ms s (build + kernels) |",
        "|---|---|---|---|",
        *out,
    ]


def study_speedup(cases: int = 16, t_end: float = 0.1) -> list[str]:
    from gearbody.studies import run_study

    walls = {}
    for workers in (1, 2):
        with tempfile.TemporaryDirectory() as out:
            t0 = time.perf_counter()
            res = run_study(
                "one-stage",
                out_dir=out,
                vary={"production.error_mode.e_um": list(np.linspace(0.0, 15.0, cases))},
                base_overrides=[*RATED, f"operation.t_end_s={t_end}"],
                workers=workers,
                progress=False,
                save_results=False,
            )
            walls[workers] = time.perf_counter() - t0
            assert res.n_ok == cases, res.table()
    child_mb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0
    print(" ", walls, flush=True)
    return [
        f"### Parameter study: {cases} cases of one-stage ({t_end} s each), process pool",
        "",
        "| workers | wall s | speed-up |",
        "|---|---|---|",
        f"| 1 | {walls[1]:.1f} | 1.00 |",
        f"| 2 | {walls[2]:.1f} | {walls[1] / walls[2]:.2f} (target >= 1.8) |",
        "",
        f"- peak resident memory of the largest worker process: {child_mb:.0f} MB; CPUs: {os.cpu_count()}",
    ]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--t-end", type=float, default=1.0)
    ap.add_argument("--scenes", default="one-stage,lateral-8dof,two-stage")
    ap.add_argument("--no-build", action="store_true")
    ap.add_argument("--no-study", action="store_true")
    ap.add_argument("--write", action="store_true", help="append the tables to benchmarks/RESULTS.md")
    args = ap.parse_args()
    import gearbody

    lines = [
        f"## Speed at equal accuracy ({date.today()}, {platform.machine()}, {os.cpu_count()} CPUs, "
        f"gearbody {gearbody.__version__}; benchmarks/bench_speed.py)",
        "",
    ]
    for scene in args.scenes.split(","):
        print(scene, flush=True)
        lines += bench_scene(scene, args.t_end) + [""]
    if not args.no_build:
        lines += build_times() + [""]
    if not args.no_study:
        lines += study_speedup() + [""]
    text = "\n".join(lines)
    print(text)
    if args.write:
        out = HERE / "RESULTS.md"
        out.write_text(out.read_text() + "\n" + text)


if __name__ == "__main__":
    main()
