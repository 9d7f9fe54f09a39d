"""Wall seconds per simulated second of a scene at rated load (not a test; default scene one-stage).

Runs gearbody on the scene, steady rated running with E(0.5, 10, 0.3) (train scenes: their own
per-stage error modes, E(0.5, 10, 0.3) in the shipped ones) and friction mu = 0.05,
1 s simulated, after a warm-up run (numba compilation is cached and not counted); optionally also
the independent scipy reference for the ratio. Prints a table and appends it to benchmarks/RESULTS.md
with --write.

    python benchmarks/bench_scene.py [--scene NAME] [--t-end 1.0] [--repeat 3] [--reference] [--write]
"""

from __future__ import annotations

import argparse
import platform
import time
from datetime import date
from pathlib import Path

import numpy as np

import gearbody
from gearbody.engine import simulate
from gearbody.model import load_scenario, scenario_to_dict

RATED = [
    'operation.initial_state="steady"',
    "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
    "production.error_mode={a=0.5,e_um=10.0,r=0.3}",
    "condition.friction_coefficient=0.05",
]


def _reference(scenario):
    """The independent reference for the scene: torsional, or with gears on bearings."""
    if scenario.is_lateral:
        from gearbody_validation.reference_lateral import simulate_reference_lateral

        return simulate_reference_lateral
    from gearbody_validation.reference import simulate_reference

    return simulate_reference


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", default="one-stage")
    ap.add_argument("--t-end", type=float, default=1.0)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--reference", action="store_true", help="also time the scipy reference")
    ap.add_argument("--write", action="store_true", help="append the table to benchmarks/RESULTS.md")
    ap.add_argument(
        "--sweep",
        action="store_true",
        help="also run tolerances 1e-9..1e-12 and give each one's max |dF|/F_rated vs the reference",
    )
    args = ap.parse_args()
    sc = load_scenario(args.scene, [*RATED, f"operation.t_end_s={args.t_end}"])
    t0 = time.perf_counter()
    simulate(load_scenario(args.scene, [*RATED, "operation.t_end_s=0.01"]))  # warm-up (numba cache)
    first_build = time.perf_counter() - t0
    walls, res = [], None
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        res = simulate(sc)
        walls.append(time.perf_counter() - t0)
    stats = res.meta["solver_statistics"]
    wall = min(walls)
    lines = [
        f"## {args.scene}, rated, E(0.5,10,0.3), mu 0.05, {args.t_end} s simulated ({date.today()}, "
        f"{platform.processor() or platform.machine()}, gearbody {gearbody.__version__})",
        "",
        "| run | wall s per simulated s | steps | rejected | notes |",
        "|---|---|---|---|---|",
        f"| gearbody (Exudyn {sc.solver.method}, rtol {sc.solver.relative_tolerance:g}, "
        f"atol {sc.solver.absolute_tolerance:g}) | {wall / args.t_end:.3f} | {stats['steps']} | "
        f"{stats['rejected_steps']} | best of {args.repeat}; warm-up incl. numba load {first_build:.2f} s |",
    ]
    simulate_reference = _reference(sc)
    if args.reference:
        t0 = time.perf_counter()
        ref = simulate_reference(scenario_to_dict(sc), t_eval=res.time_s)
        wref = time.perf_counter() - t0
        err = np.max(np.abs(ref["mesh_force_N"] - res.mesh_force)) / sc.rated_mesh_force_N * 100
        lines.append(
            f"| scipy reference ({simulate_reference.__module__}) | {wref / args.t_end:.3f} | - | - | "
            f"max dF {err:.3f} % of F_rated vs gearbody; ratio reference/gearbody {wref / wall:.1f} |"
        )
    if args.sweep:
        ref = simulate_reference(scenario_to_dict(sc), t_eval=res.time_s)
        lines += [
            "",
            "| rtol = atol | wall s per simulated s | steps | rejected | max dF % of F_rated vs reference |",
            "|---|---|---|---|---|",
        ]
        for tol in (1e-9, 1e-10, 1e-11, 1e-12):
            sct = load_scenario(
                args.scene,
                [
                    *RATED,
                    f"operation.t_end_s={args.t_end}",
                    f"solver.relative_tolerance={tol}",
                    f"solver.absolute_tolerance={tol}",
                ],
            )
            t0 = time.perf_counter()
            rt = simulate(sct)
            wt = time.perf_counter() - t0
            err = np.max(np.abs(rt.mesh_force - ref["mesh_force_N"])) / sc.rated_mesh_force_N * 100
            st = rt.meta["solver_statistics"]
            lines.append(
                f"| {tol:g} | {wt / args.t_end:.3f} | {st['steps']} | {st['rejected_steps']} | {err:.4f} |"
            )
    text = "\n".join(lines) + "\n"
    print(text)
    if args.write:
        out = Path(__file__).with_name("RESULTS.md")
        head = "" if out.exists() else "# Benchmark results\n\nMeasured by the scripts in this folder.\n\n"
        out.write_text((out.read_text() if out.exists() else head) + "\n" + text)


if __name__ == "__main__":
    main()
