"""Speed of the planetary scenes (not a test): wall seconds per simulated second of gearbody at its
accuracy levels and with a transition width, side by side in one process with the one-stage scene and the
independent scipy reference, and each variant's max |dF| / F_rated against the reference (every planet's
sun and ring mesh) over the reference's span. Steady rated running with E(0.5, 10, 0.3) on every mesh.

    python benchmarks/bench_planetary.py [--t-end 0.2] [--t-ref 0.02] [--write]
"""

from __future__ import annotations

import argparse
import platform
import time
from datetime import date
from pathlib import Path

import numpy as np

from gearbody.engine import simulate
from gearbody.model import load_scenario, scenario_to_dict

SCENES = ("planetary", "planetary-conveyor")
STEADY = [
    'operation.initial_state="steady"',
    "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
    "solver.anti_aliasing=false",
]


def errors(scene: str) -> list[str]:
    sc = load_scenario(scene)
    out = []
    for k, st in enumerate(sc.stages):
        keys = ("sun_", "ring_") if hasattr(st, "planets") else ("",)
        out += [f"design.stages.{k + 1}.{key}error_mode={{a=0.5,e_um=10.0,r=0.3}}" for key in keys]
    return out


def force_names(sc) -> list[tuple[str, int]]:
    out = []
    for k, st in enumerate(sc.stages):
        p = "" if k == 0 else f"stage_{k + 1}_"
        if hasattr(st, "planets"):
            out += [
                (f"{p}planet_{n + 1}_{m}_mesh_force_N", k) for n in range(st.planets) for m in ("sun", "ring")
            ]
        else:
            out.append((p + "mesh_force_N", k))
    return out


def timed(scene: str, t_end: float, extra=()) -> tuple[float, object]:
    sc = load_scenario(scene, [*STEADY, *errors(scene), f"operation.t_end_s={t_end}", *extra])
    simulate(load_scenario(scene, [*STEADY, *errors(scene), "operation.t_end_s=0.002", *extra]))  # warm
    t0 = time.perf_counter()
    r = simulate(sc)
    return (time.perf_counter() - t0) / t_end, r


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--t-end", type=float, default=0.2)
    ap.add_argument("--t-ref", type=float, default=0.02)
    ap.add_argument("--write", action="store_true", help="append the table to benchmarks/RESULTS.md")
    args = ap.parse_args()
    from gearbody_validation.reference.planetary_drive import simulate_reference_drive

    one_stage, _ = timed("one-stage", args.t_end)
    lines = [
        f"## Planetary scenes ({date.today()}, {platform.machine()}, `python benchmarks/bench_planetary.py "
        f"--t-end {args.t_end} --t-ref {args.t_ref}`)",
        "",
        f"Steady rated running, E(0.5, 10, 0.3) on every mesh; wall s per simulated s over {args.t_end} s; "
        f"error: max |dF| / F_rated over every mesh against the reference, first {args.t_ref} s. The "
        f"one-stage scene in the same process: {one_stage:.2f} s/s.",
        "",
        "| scene | variant | s/s | x one-stage | steps per mesh period | max dF % |",
        "|---|---|---|---|---|---|",
    ]
    for scene in SCENES:
        sc = load_scenario(scene, [*STEADY, *errors(scene), f"operation.t_end_s={args.t_ref}"])
        t0 = time.perf_counter()
        ref = simulate_reference_drive(scenario_to_dict(sc), np.arange(int(args.t_ref * 20000) + 1) / 20000)
        ref_s = (time.perf_counter() - t0) / args.t_ref
        names = force_names(sc)
        width = [
            f"design.stages.{k + 1}.{m}.transition_width=0.02"
            for k, st in enumerate(sc.stages)
            for m in (("sun_mesh", "ring_mesh") if hasattr(st, "planets") else ("mesh",))
        ]
        variants = {
            "default (DOPRI5, atol 1e-9)": [],
            "draft (ODE23, atol 3e-6)": ['solver.accuracy="draft"'],
            "default, transition_width 0.02": width,
            "tight (atol 1e-11)": ['solver.accuracy="tight"'],
        }
        for name, extra in variants.items():
            wall, r = timed(scene, args.t_end, extra)
            n = int(args.t_ref * 20000) + 1
            err = 0.0
            if not extra or extra == ['solver.accuracy="draft"'] or "tight" in name:
                for signal, k in names:
                    err = max(
                        err,
                        float(np.max(np.abs(r[signal][:n] - ref[signal])) / sc.stage_rated_force_N(k) * 100),
                    )
                err_text = f"{err:.4f}"
            else:
                err_text = "(law changed)"
            f_m = float(
                np.mean(
                    r["mesh_frequency_hz"] if "mesh_frequency_hz" in r else r["stage_2_mesh_frequency_hz"]
                )
            )
            steps = r.meta["solver_statistics"]["steps"] / (args.t_end * f_m)
            lines.append(
                f"| {scene} | {name} | {wall:.2f} | {wall / one_stage:.1f} | {steps:.0f} | {err_text} |"
            )
        lines.append(
            f"| {scene} | scipy reference (validation/) | {ref_s:.1f} | {ref_s / one_stage:.1f} | - | 0 |"
        )
    text = "\n".join(lines)
    print(text)
    if args.write:
        path = Path(__file__).with_name("RESULTS.md")
        path.write_text(path.read_text() + "\n" + text + "\n")


if __name__ == "__main__":
    main()
