"""Solver settings against the independent reference on every full-length validation case.

Not a test. The reference runs once per case (scipy at its own tight tolerances, cached in --cache);
gearbody runs the same case at each setting (method, absolute tolerance of rotations; Muller's deflection
coordinate gets MULLER_TOLERANCE_SCALE times it, as solver.accuracy does). Prints a markdown table of
max |dF|/F_rated (%), the worst bearing force error (% of its peak) and gearbody's wall s per simulated s.

    python benchmarks/bench_accuracy.py [--cache DIR] [--settings DOPRI5:1e-8,ODE23:3e-5] [--scenes ...]
"""

from __future__ import annotations

import argparse
import pickle
import time
from pathlib import Path

import numpy as np

SETTINGS = "DOPRI5:1e-8,DOPRI5:1e-7,DOPRI5:1e-6,ODE23:1e-5,ODE23:3e-5"


def main() -> None:
    from gearbody_validation.compare import (
        VALIDATED_SCENES,
        bearing_force_errors_percent,
        case_scenario,
        cases,
        reference_input,
    )
    from gearbody_validation.reference import simulate_reference
    from gearbody_validation.reference_lateral import simulate_reference_lateral

    from gearbody.engine import simulate
    from gearbody.model.scenario import MULLER_TOLERANCE_SCALE

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cache", type=Path, default=Path("runs/bench-accuracy"))
    ap.add_argument("--settings", default=SETTINGS)
    ap.add_argument("--scenes", default=",".join(VALIDATED_SCENES))
    args = ap.parse_args()
    args.cache.mkdir(parents=True, exist_ok=True)
    settings = [(m, float(a)) for m, a in (s.split(":") for s in args.settings.split(","))]
    head = [f"{m} {a:g}" for m, a in settings]
    print("| scene | case | " + " | ".join(head) + " |")
    print("|---|---|" + "---|" * len(settings))
    for scene in args.scenes.split(","):
        for case in cases(scene):
            base = case_scenario(scene, case)
            cached = args.cache / f"ref_{scene}_{case.name}.pkl"
            if cached.exists():
                ref = pickle.loads(cached.read_bytes())
            else:
                times = simulate(base).time_s
                law = simulate_reference_lateral if base.is_lateral else simulate_reference
                ref = law(reference_input(base), t_eval=times)
                cached.write_bytes(pickle.dumps(ref))
            cells = []
            for method, atol in settings:
                scale = MULLER_TOLERANCE_SCALE if base.meta.topology == "muller" else 1.0
                sc = base.replace(solver=base.solver.replace(method=method, absolute_tolerance=atol * scale))
                t0 = time.perf_counter()
                res = simulate(sc)
                wall = time.perf_counter() - t0
                err = max(
                    float(np.max(np.abs(res.stage_signal("mesh_force_N", k) - ref["stage_mesh_force_N"][k])))
                    / sc.stage_rated_force_N(k)
                    * 100.0
                    for k in range(len(sc.stages))
                )
                bearing = bearing_force_errors_percent(res, ref)
                b = f", b {max(bearing.values()):.3f}" if bearing else ""
                cells.append(f"{err:.4f}{b} ({wall / sc.operation.t_end_s:.2f} s/s)")
            print(f"| {scene} | {case.name} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
