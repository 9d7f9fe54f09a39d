"""Friction transition speed v_0 (docs/scenario.md, "Friction"), not a test: what the regularisation of
the friction direction near zero sliding costs in accuracy and saves in steps. Forward motoring (steady
rated running, mu 0.05): max |dK_d| of each v_0 against the smallest, in % of F_rated, and the solver's
steps; backward rotation (converter at 0 Hz, twice the rated load, from rest): steps, where the sliding
stays slow and a small v_0 makes friction a stiff viscous force.

    python benchmarks/bench_friction_speed.py [--write]
"""

from __future__ import annotations

import argparse
import platform
from datetime import date
from pathlib import Path

import numpy as np

from gearbody.engine import simulate
from gearbody.model import load_scenario

V0 = (1e-4, 1e-3, 1e-2, 3e-2, 1e-1)
SCENES = {"one-stage": (0.2, 0.3), "lateral-8dof": (0.1, 0.3), "planetary-conveyor": (0.02, 0.1)}
FORWARD = [
    'operation.initial_state="steady"',
    "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
]
BACKWARD = [
    'operation.initial_state="rest"',
    "operation.speed_profile={time_s=[0.0],fraction=[0.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[2.0]}",
]


def run(scene: str, sets: list[str], t_end: float, v0: float):
    sc = load_scenario(
        scene,
        [
            *sets,
            "condition.friction_coefficient=0.05",
            f"condition.friction_transition_speed_m_s={v0}",
            f"operation.t_end_s={t_end}",
        ],
    )
    return simulate(sc)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--write", action="store_true", help="append the table to benchmarks/RESULTS.md")
    args = p.parse_args()
    lines = [
        f"## Friction transition speed v_0 ({date.today()}, {platform.machine()}, "
        "`python benchmarks/bench_friction_speed.py`)",
        "",
        "mu 0.05. Forward: steady rated running, max |dK_d| over every mesh against v_0 = 1e-4 m/s (% of "
        "F_rated) and solver steps; backward: converter at 0 Hz, twice the rated load from rest, solver "
        "steps.",
        "",
        "| scene | v_0 m/s | forward dK_d % | forward steps | backward steps |",
        "|---|---|---|---|---|",
    ]
    for scene, (t_fwd, t_bwd) in SCENES.items():
        ref = None
        for v0 in V0:
            fwd = run(scene, FORWARD, t_fwd, v0)
            bwd = run(scene, BACKWARD, t_bwd, v0)
            kd = {k: fwd[k] for k in fwd.names if k.endswith("kd")}
            ref = ref or kd
            d = max(float(np.max(np.abs(kd[k] - ref[k]))) for k in kd) * 100
            steps = (fwd.meta["solver_statistics"]["steps"], bwd.meta["solver_statistics"]["steps"])
            lines.append(f"| {scene} | {v0:g} | {d:.4f} | {steps[0]} | {steps[1]} |")
            print(lines[-1], flush=True)
    text = "\n".join(lines) + "\n"
    if args.write:
        path = Path(__file__).with_name("RESULTS.md")
        path.write_text(path.read_text().rstrip("\n") + "\n\n" + text)
    print(text)


if __name__ == "__main__":
    main()
