"""The standard PNG plots of a run (``gearbody run``): K_d over time, K_d folded over the mesh period,
the spectrum of the vibration signal and, for lateral gears, the bearing forces."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from gearbody.analysis import amplitude_spectrum, fold_over_mesh_period

if TYPE_CHECKING:  # Result.plot() calls this module
    from gearbody.result import Result

from .result import plot_kd_folded, plot_kd_time, plot_signals, plot_spectrum

__all__ = ["write_plots"]


def write_plots(result: Result, out_dir: str | Path) -> list[Path]:
    """K_d over time, K_d folded over the mesh period (final window), spectrum of the acceleration."""
    out = Path(out_dir)
    title = result.meta.get("title", result.meta.get("scene", ""))
    paths = [
        plot_kd_time(result.time_s, result.kd, out / "kd_time.png", title=f"{title}: K_d = F(t)/F_rated")
    ]
    win = result.final_window()  # the steady end of the run (Result.FINAL_FRACTION)
    f_mesh = float(np.mean(result["mesh_frequency_hz"][win]))
    # at most one bin per sample of a mesh period, so that every bin is filled
    bins = int(np.clip(result.sample_rate_hz / max(f_mesh, 1e-9), 10, 100))
    folded = fold_over_mesh_period(
        result.kd[win], result["pinion_angle_rad"][win], result.teeth(0)[0], bins=bins
    )
    paths.append(
        plot_kd_folded(
            folded,
            out / "kd_folded.png",
            title=f"{title}: K_d over the mesh period (last {result.FINAL_FRACTION:.0%} of run)",
        )
    )
    name = result.vibration_signal_name
    t_win = result.time_s[win]
    spec = amplitude_spectrum(result[name][win], result.sample_rate_hz)
    z1, z2 = result.teeth(0)
    shafts = {"f_1": f_mesh / z1, "f_2": f_mesh / z2} if f_mesh > 0 else {}
    unit = "rad/s²" if name.endswith("rad_s2") else "m/s²"
    paths.append(
        plot_spectrum(
            spec,
            out / "spectrum.png",
            mesh_frequency_hz=f_mesh if f_mesh > 0 else None,
            shaft_frequencies_hz=shafts,
            title=f"{title}: spectrum of {name}, t = {t_win[0]:.3g}-{t_win[-1]:.3g} s"
            f" (last {result.FINAL_FRACTION:.0%} of the run, run-up left out)",
            fmax_hz=min(result.sample_rate_hz / 2, 8.5 * f_mesh if f_mesh > 0 else 1e9),
            ylabel=f"amplitude [{unit}]",
            log_amplitude=True,
        )
    )
    gears = result.bearing_gears
    if gears:
        paths.append(
            plot_signals(
                result.time_s,
                {
                    f"{gear} {axis}": result[f"{gear}_bearing_force_{axis}_N"]
                    for gear in gears
                    for axis in "xy"
                },
                out / "bearing_forces.png",
                title=f"{title}: forces on the housing at the bearings",
                ylabel="bearing force [N]",
            )
        )
    return paths
