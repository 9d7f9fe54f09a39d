"""The wall-time estimate against measurement (not a test): for every shipped scene as shipped, and for
its validation cases (steady, separation, run-up; the short lengths of ``gearbody validate``) at the
default, draft and tight accuracy, the estimated and the measured solver step attempts (steps +
rejected: deterministic, machine-independent) and wall time of ``simulate`` (machine- and
load-dependent), and their ratios. The estimate is :func:`gearbody.assembly.wall_time.estimate_wall_time`.

    python benchmarks/bench_wall_estimate.py [--scenes one-stage,two-wheel] [--no-shipped]
        [--accuracy default,draft,tight] [--fit]

``--fit`` prints the least-squares (in log) values of ATTEMPTS_PER_MESH_PERIOD and ATTEMPTS_PER_RATE_HZ
over the steady default-accuracy cases, the data the constants come from.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import time

import numpy as np
from gearbody_validation.compare import cases

from gearbody.assembly import wall_time
from gearbody.assembly.stiff_modes import coordinate_frequencies
from gearbody.engine import simulate
from gearbody.model import list_scenes, load_scenario


def measure(scene: str, overrides: list[str]) -> dict:
    sc = load_scenario(scene, overrides)
    simulate(load_scenario(scene, [*overrides, "operation.t_end_s=0.002"]))  # compiled and warm
    est = wall_time.estimate_wall_time(sc)
    t0, c0 = time.perf_counter(), time.process_time()
    r = simulate(sc)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    s = r.meta["solver_statistics"]
    return {
        "attempts": s["steps"] + s["rejected_steps"],
        "wall_s": wall,
        "cpu_s": cpu,
        "est": est,
        "f_mesh_sum": wall_time.mesh_frequency_sum_hz(sc),
        "f_fastest": max(c.rate_hz for c in coordinate_frequencies(sc)),
        "t_end": sc.operation.t_end_s,
        "load": os.getloadavg()[0],
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default="", help="comma-separated (default: every shipped scene)")
    ap.add_argument("--no-shipped", action="store_true", help="skip the scenes as shipped (full t_end)")
    ap.add_argument("--accuracy", default="default,draft,tight", help="levels of the validation cases")
    ap.add_argument("--fit", action="store_true", help="fit the model's constants to these runs")
    args = ap.parse_args()
    scenes = args.scenes.split(",") if args.scenes else list_scenes()
    print(f"# {platform.machine()}, {os.cpu_count()} CPUs, {time.strftime('%Y-%m-%d')}")
    print(
        "| scene | case | accuracy | t_end s | attempts est / measured | us per attempt est / CPU "
        "| estimate s | CPU s | wall s | load |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    for scene in scenes:
        runs = [] if args.no_shipped else [("as shipped", "default", [])]
        for case in cases(scene, short=True):
            for level in args.accuracy.split(","):
                extra = [] if level == "default" else [f'solver.accuracy="{level}"']
                t_end = f"operation.t_end_s={case.t_end_short_s}"
                runs.append((case.name, level, [*case.overrides, t_end, *extra]))
        for name, level, overrides in runs:
            m = measure(scene, overrides)
            e = m["est"]
            m["ratios"] = (e.attempts / m["attempts"], e.wall_s / m["cpu_s"], e.wall_s / m["wall_s"])
            m["us_cpu"] = m["cpu_s"] / wall_time.OUTPUT_OVERHEAD / m["attempts"] * 1e6
            rows.append((scene, name, level, m))
            ra, rc, rw = m["ratios"]
            print(
                f"| {scene} | {name} | {level} | {m['t_end']:g} | {e.attempts:.3g} / {m['attempts']:.3g} "
                f"({ra:.2f}) | {e.us_per_attempt:.3g} / {m['us_cpu']:.3g} | {e.wall_s:.3g} | "
                f"{m['cpu_s']:.3g} ({rc:.2f}) | {m['wall_s']:.3g} ({rw:.2f}) | {m['load']:.1f} |",
                flush=True,
            )
    for k, what in enumerate(("step attempts", "wall time against CPU time", "wall time against wall time")):
        r = np.array([row[3]["ratios"][k] for row in rows])
        inside = np.mean((r >= 1 / 3) & (r <= 3))
        print(
            f"- {what}: estimate / measured {r.min():.2f}-{r.max():.2f} (median {np.median(r):.2f}) over "
            f"{len(r)} runs; within 3x: {100 * inside:.0f} %"
        )
    if args.fit:
        fit(rows)


def fit(rows) -> None:
    """Least squares in log: the two attempt constants over the steady default-accuracy cases, the cost
    of an evaluation per coordinate over every run (CPU time)."""
    from scipy.optimize import minimize

    steady = [row[3] for row in rows if row[1] == "steady" and row[2] == "default"]
    A = np.array([[m["f_mesh_sum"], m["f_fastest"]] for m in steady])
    y = np.array([m["attempts"] / m["t_end"] for m in steady])

    def cost(p):
        return np.sum(np.log((A @ np.exp(p)) / y) ** 2)

    p = minimize(cost, np.log([92.0, 34.0]), method="Nelder-Mead").x
    a, b = np.exp(p)
    print(
        f"- fit over {len(steady)} steady cases: ATTEMPTS_PER_MESH_PERIOD {a:.3g}, "
        f"ATTEMPTS_PER_RATE_HZ {b:.3g} (rms log error {math.sqrt(cost(p) / len(steady)):.3f})"
    )
    cost = np.array([m["us_cpu"] / m["est"].us_per_attempt for *_, m in rows])
    print(
        f"- cost of an attempt, CPU time / model: {cost.min():.2f}-{cost.max():.2f} "
        f"(median {np.median(cost):.2f})"
    )


if __name__ == "__main__":
    main()
