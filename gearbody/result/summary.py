"""The values of a run's summary.json (:meth:`gearbody.result.Result.summary`): K_d over the run and its
steady end, separations, mesh frequency, speed, solver statistics, bearing forces, which way each
rotation turned, and where the scene's values come from; a drive whose stages are not all gear pairs
adds each stage's own keys (its kind's ``summary``)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from . import Result

__all__ = ["run_summary"]


def run_summary(result: Result) -> dict[str, Any]:
    """:meth:`Result.summary <gearbody.result.Result.summary>` of ``result``."""
    sources = {"sources": list(result.meta.get("sources") or [])}
    if not result._gear_train:
        return {**_compound_summary(result), **_direction_summary(result), **sources}
    return {**_gear_train_summary(result), **_direction_summary(result), **sources}


def _gear_train_summary(result: Result) -> dict[str, Any]:
    """summary() of a drive of gear pairs: its first stage's K_d and separations, speed, solver
    statistics, and the lateral gears' bearing forces and housing accelerations."""
    from ..analysis import separation_stats

    win = result.final_window()
    sep = separation_stats(result.mesh_force, result.time_s, kd=result.kd)
    speed = (
        result["pinion_speed_rad_s"]
        if "pinion_speed_rad_s" in result
        else 2 * math.pi * result["mesh_frequency_hz"] / result.meta["pinion_teeth"]
    )
    stats = result.meta.get("solver_statistics", {})
    return {
        "scene": result.meta.get("scene"),
        "kd_max": float(np.max(result.kd)),
        "kd_min": float(np.min(result.kd)),
        "kd_max_final": float(np.max(result.kd[win])),
        "kd_mean_final": float(np.mean(result.kd[win])),
        "kd_above_2": bool(np.max(result.kd) > 2.0),
        "separation_fraction": float(sep.separated_fraction),
        "contact_losses": int(sep.contact_losses),
        "mesh_frequency_hz": float(np.mean(result["mesh_frequency_hz"][win])),
        "mean_speed_rad_s": float(np.mean(speed[win])),
        "rated_mesh_force_N": float(result.meta.get("rated_mesh_force_N", float("nan"))),
        "simulated_time_s": float(result.time_s[-1] - result.time_s[0]),
        "wall_time_s": float(stats.get("wall_time_s", float("nan"))),
        "wall_s_per_simulated_s": float(stats.get("wall_time_s", float("nan")))
        / max(float(result.time_s[-1] - result.time_s[0]), 1e-300),
        "solver_steps": int(stats.get("steps", 0)),
        "solver_rejected_steps": int(stats.get("rejected_steps", 0)),
        "seed": result.meta.get("seed"),
        **{
            f"{gear}_bearing_force_{axis}_max_N": float(
                np.max(np.abs(result[f"{gear}_bearing_force_{axis}_N"]))
            )
            for gear in result.bearing_gears
            for axis in "xy"
        },
        **{
            f"{gear}_housing_accel_{axis}_rms_final_m_s2": float(
                np.std(result[f"{gear}_housing_accel_{axis}_m_s2"][win])
            )
            for gear in result.bearing_gears
            for axis in "xy"
        },
    }


def _direction_summary(result: Result) -> dict[str, Any]:
    """summary() keys of :meth:`Result.rotation_directions`: ``<rotation>_driven_speed_min_rad_s`` and
    ``turned_backwards`` with the first rotation and time (NaN and '' when it never did)."""
    d = result.rotation_directions()
    first = d.first
    return {
        **{f"{name}_driven_speed_min_rad_s": v for name, v in d.driven_speed_min_rad_s.items()},
        "turned_backwards": d.turned_backwards,
        "turned_backwards_first": first[0] if first else "",
        "turned_backwards_at_s": first[1] if first else float("nan"),
    }


def _compound_summary(result: Result) -> dict[str, Any]:
    """summary() of a drive whose stages are not all gear pairs (planetary stages, say): the first
    stage's K_d over all its meshes (every planet's sun and ring mesh: the keys studies and
    calibrations read by default), then each stage's own keys (a planetary stage: per mesh type the
    planets' K_d, load sharing, separations; a later parallel stage: its K_d); speed and solver
    statistics."""
    from ..analysis import separation_stats

    win = result.final_window()
    stats = result.meta.get("solver_statistics", {})
    t = float(result.time_s[-1] - result.time_s[0])
    out: dict[str, Any] = {"scene": result.meta.get("scene")}
    first = result.stages[0].mesh_signals(0)
    if first:
        kd = np.array([result[kd_name] for kd_name, _ in first])
        seps = [
            separation_stats(result[force], result.time_s, kd=result[kd_name]) for kd_name, force in first
        ]
        out.update(
            {
                "kd_max": float(kd.max()),
                "kd_min": float(kd.min()),
                "kd_max_final": float(kd[:, win].max()),
                "kd_mean_final": float(kd[:, win].mean()),
                "kd_above_2": bool(kd.max() > 2.0),
                "separation_fraction": float(max(s.separated_fraction for s in seps)),
                "contact_losses": int(sum(s.contact_losses for s in seps)),
                "mesh_frequency_hz": float(np.mean(result["mesh_frequency_hz"][win])),
            }
        )
    for k, st in enumerate(result.stages):
        out.update(st.summary(result, k, win))
    out.update(
        {
            "mean_speed_rad_s": float(np.mean(result["motor_speed_rad_s"][win])),
            "simulated_time_s": t,
            "wall_time_s": float(stats.get("wall_time_s", float("nan"))),
            "wall_s_per_simulated_s": float(stats.get("wall_time_s", float("nan"))) / max(t, 1e-300),
            "solver_steps": int(stats.get("steps", 0)),
            "solver_rejected_steps": int(stats.get("rejected_steps", 0)),
            "seed": result.meta.get("seed"),
        }
    )
    return out
