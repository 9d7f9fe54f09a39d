"""The standard PNG plots of a run (``gearbody run``): per parallel stage K_d over time and K_d folded over
its mesh period, the spectrum of the vibration signal and, for lateral gears, the bearing forces. A
drive's planetary stages add their own plots (:mod:`gearbody.plotting.planetary`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from gearbody.analysis import fold_over_mesh_period

from ..signals import stage_file_tag

if TYPE_CHECKING:  # Result.plot() calls this module
    from gearbody.result import Result

from .result import plot_kd_folded, plot_kd_time, plot_signals, plot_spectrum

__all__ = ["MIN_PLOT_SAMPLES", "parallel_stage_plot_names", "write_plots"]

MIN_PLOT_SAMPLES = 64
"""Fewest output samples a run's plots and report are drawn from: they analyse its final window (the last
25 %, :meth:`Result.final_window`), which then holds 16 samples, a spectrum of 9 lines. With 3 samples
(``--t-end 1e-4``) the spectrum had a single one; all scenes plot from 41."""


def parallel_stage_plot_names(result: Result) -> list[str]:
    """The file names :func:`write_plots` gives the K_d plots of the result's parallel stages: stage 1
    ``kd_time.png``, ``kd_folded.png``; stage k > 1 ``kd_time_stage_k.png``, ``kd_folded_stage_k.png``."""
    names = []
    for k, st in enumerate(result.stages):
        if st.has_kd_plots:
            tag = stage_file_tag(k)
            names += [f"kd_time{tag}.png", f"kd_folded{tag}.png"]
    return names


def write_plots(result: Result, out_dir: str | Path, marks=()) -> list[Path]:
    """Per parallel stage: K_d over time and folded over its mesh period (final window); when the first
    stage is parallel, the spectrum of the vibration signal (``spectrum.png``, ``marks`` drawn on it:
    lines such as bearing defect frequencies); bearing forces of lateral gears. A drive without parallel
    stages gets none of these."""
    out = Path(out_dir)
    title = result.meta.get("title", result.meta.get("scene", ""))
    paths: list[Path] = []
    for k, st in enumerate(result.stages):
        if st.has_kd_plots:
            paths += _stage_kd_plots(result, k, out, title)
    if result.stages[0].gear_pair() is not None:
        paths.append(_spectrum_plot(result, out, title, marks))
    # parallel gears on lateral bearings (a drive with planetary stages has none: its bearing forces are
    # the planetary members')
    gears = [] if result.planetary_stages else result.bearing_gears
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


def _stage_kd_plots(result: Result, stage: int, out: Path, title: str) -> list[Path]:
    """K_d of parallel stage ``stage`` (0-based) over time and folded over its mesh period."""
    tag = stage_file_tag(stage)
    which = f", stage {stage + 1}" if result.n_stages > 1 else ""
    kd = result.stage_signal("kd", stage)
    paths = [
        plot_kd_time(
            result.time_s, kd, out / f"kd_time{tag}.png", title=f"{title}: K_d = F(t)/F_rated{which}"
        )
    ]
    win = result.final_window()  # the steady end of the run (Result.FINAL_FRACTION)
    f_mesh = float(np.mean(result.stage_signal("mesh_frequency_hz", stage)[win]))
    # at most one bin per sample of a mesh period, so that every bin is filled
    bins = int(np.clip(result.sample_rate_hz / max(f_mesh, 1e-9), 10, 100))
    folded = fold_over_mesh_period(
        kd[win], result.stage_signal("pinion_angle_rad", stage)[win], result.teeth(stage)[0], bins=bins
    )
    paths.append(
        plot_kd_folded(
            folded,
            out / f"kd_folded{tag}.png",
            title=f"{title}: K_d over the mesh period{which} (last {result.FINAL_FRACTION:.0%} of run)",
        )
    )
    return paths


def _spectrum_plot(result: Result, out: Path, title: str, marks=()) -> Path:
    """Spectrum of the vibration signal over the final window, first stage's mesh harmonics and shafts."""
    win = result.final_window()
    f_mesh = float(np.mean(result["mesh_frequency_hz"][win]))
    name = result.vibration_signal_name
    t_win = result.time_s[win]
    spec = result.spectrum(name).spectrum  # Result.spectrum's: the one composition (labels in the report)
    z1, z2 = result.teeth(0)
    shafts = {"f_1": f_mesh / z1, "f_2": f_mesh / z2} if f_mesh > 0 else {}
    unit = "rad/s²" if name.endswith("rad_s2") else "m/s²"
    return plot_spectrum(
        spec,
        out / "spectrum.png",
        mesh_frequency_hz=f_mesh if f_mesh > 0 else None,
        shaft_frequencies_hz=shafts,
        title=f"{title}: spectrum of {name}, t = {t_win[0]:.3g}-{t_win[-1]:.3g} s"
        f" (last {result.FINAL_FRACTION:.0%} of the run, run-up left out)",
        fmax_hz=min(result.sample_rate_hz / 2, 8.5 * f_mesh if f_mesh > 0 else 1e9),
        ylabel=f"amplitude [{unit}]",
        log_amplitude=True,
        marks=marks,
    )
