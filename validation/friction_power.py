"""Friction power of every mesh in forward motoring, generator mode and backward rotation
(docs/scenario.md, "Friction"): the share of samples where friction feeds energy in (P_f = T v_sl > 0)
and the mean P_f, for gearbody's law and, on the same states, for the phase-only law of earlier versions
(T = mu |F| s(p): + before the pitch point, - after).

    python -m validation.friction_power            # one-stage, lateral-8dof, planetary-conveyor, planetary
    python -m validation.friction_power one-stage --t-end 0.5
"""

from __future__ import annotations

import argparse

import numpy as np

from gearbody import simulate
from gearbody.model import load_scenario

MU = 0.05
CASES = {
    "forward": [
        'operation.initial_state="steady"',
        "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
        "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
    ],
    "generator": [
        'operation.initial_state="steady"',
        "operation.speed_profile={time_s=[0.0,0.01,0.3],fraction=[1.0,1.0,0.2]}",
        "operation.load_profile={time_s=[0.0],fraction=[0.0]}",
    ],
    "backward": [
        'operation.initial_state="rest"',
        "operation.speed_profile={time_s=[0.0],fraction=[0.0]}",
        "operation.load_profile={time_s=[0.0],fraction=[2.0]}",
    ],
}
T_END = {"one-stage": 0.5, "lateral-8dof": 0.5, "planetary-conveyor": 0.2, "planetary": 0.1}


def mesh_rows(scenario, result):
    """(mesh label, T, v_sl, F, phase, pitch) of every mesh of the run."""
    for k, st in enumerate(scenario.stages):
        prefix = "" if k == 0 else f"stage_{k + 1}_"
        if hasattr(st, "planets"):
            for n in range(1, st.planets + 1):
                for m, mesh in (("sun", st.sun_mesh), ("ring", st.ring_mesh)):
                    key = f"{prefix}planet_{n}_{m}_mesh_"
                    yield (
                        key[:-1],
                        result[key + "friction_force_N"],
                        result[key + "sliding_velocity_m_s"],
                        result[key + "force_N"],
                        result[key + "phase"],
                        mesh.pitch_point_phase,
                    )
        else:
            yield (
                f"stage {k + 1}",
                result[prefix + "friction_force_N"],
                result[prefix + "sliding_velocity_m_s"],
                result[prefix + "mesh_force_N"],
                result[prefix + "mesh_phase"],
                st.mesh.pitch_point_phase,
            )


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scenes", nargs="*", default=list(T_END))
    p.add_argument("--t-end", type=float, default=None, help="simulated time (default per scene)")
    args = p.parse_args(argv)
    print(
        "scene               case       mesh                       speed rad/s        P_f>0   mean P_f W  "
        "| phase-only law: P_f>0  mean W"
    )
    for scene in args.scenes:
        for case, sets in CASES.items():
            t_end = args.t_end or T_END.get(scene, 0.2)
            sc = load_scenario(
                scene, [*sets, f"condition.friction_coefficient={MU}", f"operation.t_end_s={t_end}"]
            )
            res = simulate(sc)
            name = "pinion" if "pinion_speed_rad_s" in res else "sun"
            w = res[f"{name}_speed_rad_s"][res.time_s > 0.5 * t_end]
            rows = list(mesh_rows(sc, res))
            if len(rows) > 4:  # planetary: the first planet's two meshes and the parallel stages
                rows = [r for r in rows if "planet_" not in r[0] or r[0].split("planet_")[1].startswith("1_")]
            for label, T, v, F, phase, pitch in rows:
                P = T * v
                old = MU * np.abs(F) * np.where(phase < pitch, 1.0, -1.0) * v
                print(
                    f"{scene:19s} {case:10s} {label:26s} {w.min():+7.2f}..{w.max():+7.2f}  "
                    f"{np.mean(P > 0):6.1%} {P.mean():+11.2f}  | {np.mean(old > 0):20.1%} {old.mean():+7.2f}"
                )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
