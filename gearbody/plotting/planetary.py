"""The standard PNG plots of a run with planetary stages (``gearbody run``): every planet's mesh K_d over
time, the load sharing, and the ring-sensor spectrum with the stage's kinematic lines labelled (carrier,
planet pass, mesh harmonics and their carrier sidebands, tooth fault frequencies)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from gearbody.analysis import amplitude_spectrum, label_peaks
from gearbody.analysis.planetary_lines import PlanetarySources, planetary_lines

from .figure import new_figure, save_figure, set_title
from .result import plot_signals
from .spectrum import plot_labelled_spectrum

if TYPE_CHECKING:
    from gearbody.result import Result

__all__ = ["planetary_sources", "write_planetary_plots"]


def planetary_sources(result: Result, stage: int) -> PlanetarySources:
    """The stage's teeth, planets and mean member speeds over the final window (Hz, signed)."""
    meta = result.meta["stages"][stage]
    prefix = "" if stage == 0 else f"stage_{stage + 1}_"
    win = result.final_window()
    hz = {
        m: float(np.mean(result[f"{prefix}{m}_speed_rad_s"][win])) / (2 * np.pi)
        for m in ("sun", "ring", "carrier")
    }
    planet = float(np.mean(result[f"{prefix}planet_1_speed_rad_s"][win])) / (2 * np.pi)
    return PlanetarySources(
        z_sun=meta["sun_teeth"],
        z_planet=meta["planet_teeth"],
        z_ring=meta["ring_teeth"],
        n_planets=meta["planets"],
        carrier_hz=hz["carrier"],
        sun_hz=hz["sun"],
        ring_hz=hz["ring"],
        planet_hz=planet,
        rtol=1e-3,  # mean speeds of a vibrating run
    )


def write_planetary_plots(result: Result, out_dir: str | Path) -> list[Path]:
    """Per planetary stage: planet mesh K_d over time, mean planet mesh forces (sharing), and the
    ring-sensor spectrum over the final window with its labelled peaks."""
    out = Path(out_dir)
    title = result.meta.get("title", result.meta.get("scene", ""))
    paths = []
    win = result.final_window()
    for k, meta in enumerate(result.meta["stages"]):
        if meta.get("type") != "planetary":
            continue
        prefix = "" if k == 0 else f"stage_{k + 1}_"
        tag = "" if k == 0 else f"_stage_{k + 1}"
        n = meta["planets"]
        kd = {
            f"planet {p} {mesh}": result[f"{prefix}planet_{p}_{mesh}_mesh_kd"]
            for p in range(1, n + 1)
            for mesh in ("sun", "ring")
        }
        paths.append(
            plot_signals(
                result.time_s,
                kd,
                out / f"planet_kd_time{tag}.png",
                title=f"{title}: planet mesh K_d = F(t)/F_rated, stage {k + 1}",
                ylabel="dynamic factor K_d [-]",
            )
        )
        fig = new_figure((800, 450))
        ax = fig.add_subplot()
        x = np.arange(1, n + 1)
        for offset, mesh in ((-0.2, "sun"), (0.2, "ring")):
            mean = [float(np.mean(result[f"{prefix}planet_{p}_{mesh}_mesh_kd"][win])) for p in x]
            ax.bar(x + offset, mean, width=0.4, label=f"{mesh} mesh")
        ax.axhline(1.0, color="0.4", linestyle=":", linewidth=1.0)
        ax.set_xticks(x)
        ax.set_xlabel("planet")
        ax.set_ylabel(f"mean K_d, last {result.FINAL_FRACTION:.0%} of run [-]")
        ax.legend(loc="lower right")
        set_title(ax, f"{title}: load sharing, stage {k + 1}")
        paths.append(save_figure(fig, out / f"load_sharing{tag}.png"))
        sensor = result[f"{prefix}ring_sensor_N"][win]
        spec = amplitude_spectrum(sensor, result.sample_rate_hz)
        sources = planetary_sources(result, k)
        f_max = min(result.sample_rate_hz / 2, 3.5 * sources.mesh_hz)
        lines = planetary_lines(sources, f_max, harmonics=3)
        peaks = label_peaks(spec, lines, f_max_hz=f_max, max_peaks=30)
        ax = plot_labelled_spectrum(
            spec,
            peaks,
            title=f"{title}: ring sensor, stage {k + 1} (last {result.FINAL_FRACTION:.0%} of run)",
            unit="N",
            f_max_hz=f_max,
        )
        paths.append(save_figure(ax.figure, out / f"ring_sensor_spectrum{tag}.png"))
    return paths
