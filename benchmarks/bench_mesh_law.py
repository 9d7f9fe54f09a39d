"""Cost of one mesh-law evaluation per stiffness profile (not a test): the compiled kernel
``gearbody.physics.mesh.mesh_contact`` over 2 million pinion angles, nanoseconds per call, for the
hand-given "contact-ratio" profile (one-stage), the ISO 6336 method B profile and the potential-energy
pair table (one-stage-geometry), healthy and with a cracked tooth. Prints a table and appends it to
benchmarks/RESULTS.md with --write.

    python benchmarks/bench_mesh_law.py [--calls 2000000] [--repeat 5] [--write]
"""

from __future__ import annotations

import argparse
import math
import platform
import time
from datetime import date
from pathlib import Path

import numpy as np

from gearbody.assembly import mesh_parameters_from_scenario
from gearbody.model import load_scenario
from gearbody.physics.mesh import mesh_contact_series

CASES = {
    "contact-ratio (one-stage)": ("one-stage", []),
    "iso-6336-b (one-stage-geometry)": ("one-stage-geometry", ["design.mesh.stiffness_profile='iso-6336-b'"]),
    "potential-energy pairs (one-stage-geometry)": ("one-stage-geometry", []),
    "pairs, cracked pinion tooth 2 mm": (
        "one-stage-geometry",
        ['condition.damaged_teeth=[{gear="pinion",tooth=3,crack_depth_mm=2.0}]'],
    ),
    "pairs, transition width 0.02": ("one-stage-geometry", ["design.mesh.transition_width=0.02"]),
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--calls", type=int, default=2_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--write", action="store_true")
    args = ap.parse_args()
    rng = np.random.default_rng(0)
    angles = rng.uniform(0.0, 40 * math.pi, args.calls)
    delta = 60e-6 + 10e-6 * rng.standard_normal(args.calls)
    rate = 1e-3 * rng.standard_normal(args.calls)
    rows = []
    for name, (scene, overrides) in CASES.items():
        P = mesh_parameters_from_scenario(load_scenario(scene, overrides))
        mesh_contact_series(angles[:10], delta[:10], rate[:10], P)  # compile / load
        best = math.inf
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            mesh_contact_series(angles, delta, rate, P)
            best = min(best, time.perf_counter() - t0)
        rows.append((name, best / args.calls * 1e9))
    base = rows[0][1]
    lines = [
        f"## mesh law per call, {args.calls} calls, best of {args.repeat} "
        f"({date.today()}, {platform.machine()})",
        "",
        "| stiffness profile | ns per call | ratio to contact-ratio |",
        "|---|---|---|",
        *[f"| {name} | {ns:.1f} | {ns / base:.2f} |" for name, ns in rows],
        "",
    ]
    print("\n".join(lines))
    if args.write:
        path = Path(__file__).with_name("RESULTS.md")
        path.write_text(path.read_text() + "\n" + "\n".join(lines))


if __name__ == "__main__":
    main()
