"""Speed of a run on ball-by-ball bearings with defects (not a test), side by side in one process.

lateral-8dof-ball steady at rated load for ``--t-end`` simulated seconds, in turn: its lumped Hertzian
bearings (the shipped scene), the same bearings ball by ball (``rolling-elements``, healthy), and ball by
ball with validate's bearing-defect case (an outer-race and a ball defect on the pinion's bearing, an
inner-race one on the wheel's); then phm2009 (four ball-by-ball bearings) healthy and with the README's
outer-race spall; each on the compiled and the Python force path, after a warm run (kernels compiled
and cached). Reported: wall seconds per simulated second (best of ``--repeat``), the
integrator's accepted and rejected steps, the accepted steps per pinion revolution, and the ratio to
the scene's first case on the same path.

    PYTHONPATH=. python benchmarks/bench_bearing_defect.py [--t-end 0.5] [--repeat 2]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from gearbody_validation.compare import BEARING_DEFECT

from gearbody.engine import simulate
from gearbody.model import load_scenario

STEADY = [
    'operation.initial_state="steady"',
    "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
]


PHM_DEFECT = (
    'design.stages.1.pinion.bearing.defects=[{race="outer",depth_m=5e-6,width_deg=8.0,angle_deg=110.0}]'
)


def cases() -> dict[str, tuple[str, list[str]]]:
    """label -> (scene, overrides); the first case of each scene is its ratios' reference."""
    defect = list(BEARING_DEFECT["lateral-8dof-ball"])
    return {
        "hertzian (lumped)": ("lateral-8dof-ball", []),
        "rolling-elements, healthy": ("lateral-8dof-ball", [o for o in defect if ".defects=" not in o]),
        "rolling-elements, 3 defects": ("lateral-8dof-ball", defect),
        "phm2009 (rolling-elements)": ("phm2009", []),
        "phm2009, outer-race spall": ("phm2009", [PHM_DEFECT]),
    }


def measure(
    scene: str, overrides: list[str], path: str, t_end: float, repeat: int
) -> tuple[float, dict, float]:
    """(best wall s per simulated s, solver statistics, input pinion revolutions)."""
    best, stats, revs = math.inf, {}, 0.0
    scenario = load_scenario(
        scene, [*STEADY, *overrides, f"operation.t_end_s={t_end}", f'solver.force_path="{path}"']
    )
    for _ in range(repeat):
        start = time.perf_counter()
        result = simulate(scenario)
        wall = time.perf_counter() - start
        if wall < best:
            best, stats = wall, result.meta["solver_statistics"]
            revs = float(np.ptp(result["pinion_angle_rad"])) / (2 * math.pi)
    return best / t_end, stats, revs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=0.5)
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args()
    for path in ("compiled", "python"):
        for scene, overrides in cases().values():  # warm: kernels compiled, caches loaded
            measure(scene, overrides, path, 0.01, 1)
        reference: dict[str, float] = {}
        for name, (scene, overrides) in cases().items():
            s_per_s, stats, revs = measure(scene, overrides, path, args.t_end, args.repeat)
            reference.setdefault(scene, s_per_s)
            steps = stats.get("steps", 0)
            rejected = stats.get("rejected_steps", 0)
            print(
                f"{path:8s} {name:30s} {s_per_s:7.3f} s/s  x{s_per_s / reference[scene]:5.2f}  steps {steps} "
                f"(+{rejected} rejected), {steps / revs:6.1f} per input pinion revolution ({revs:.2f} rev)"
            )


if __name__ == "__main__":
    main()
