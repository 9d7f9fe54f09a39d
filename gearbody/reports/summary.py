"""What a diagnostician reads first about a run: K_d, separation, mesh frequency, speed. Engine-free.

"Final" values are taken over the last quarter of the simulated time (the steady, rated-load
period in the scenes' four-period operation); whole-run values say so in their name. The run's PNG
plots are :func:`gearbody.plotting.run.write_plots`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gearbody.analysis import separation_stats
from gearbody.result import Result

FINAL_FRACTION = 0.25


def final_window(result: Result, fraction: float = FINAL_FRACTION) -> np.ndarray:
    """Boolean mask of the last ``fraction`` of the simulated time."""
    t = result.time_s
    return t >= t[-1] - fraction * (t[-1] - t[0])


def pinion_angle(result: Result) -> np.ndarray:
    return result["pinion_angle_rad"]


def vibration_signal(result: Result) -> tuple[str, np.ndarray]:
    """The acceleration signal whose spectrum is shown: the housing acceleration at the first lateral
    gear's bearing along the line of action's dominant axis (what an accelerometer there reads);
    otherwise the pinion's angular acceleration (Muller: the deflection's)."""
    for name in ("pinion_housing_accel_y_m_s2", "wheel_housing_accel_y_m_s2"):
        if name in result and f"{name.split('_housing')[0]}_y_m" in result:
            return name, result[name]
    name = "pinion_accel_rad_s2" if "pinion_accel_rad_s2" in result else "deflection_accel_m_s2"
    return name, result[name]


def bearing_gears(result: Result) -> list[str]:
    """Names of the gears with bearing-force signals (lateral gears)."""
    return sorted({k.split("_bearing_force_")[0] for k in result.signals if "_bearing_force_" in k})


def summarize(result: Result) -> dict[str, Any]:
    """Summary values of a run (see module docstring for the windows)."""
    win = final_window(result)
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
            for gear in bearing_gears(result)
            for axis in "xy"
        },
        **{
            f"{gear}_housing_accel_{axis}_rms_final_m_s2": float(
                np.std(result[f"{gear}_housing_accel_{axis}_m_s2"][win])
            )
            for gear in bearing_gears(result)
            for axis in "xy"
        },
    }
