"""The standard PNG plots of a run with planetary stages (``gearbody run``): every planet's mesh K_d over
time, the load sharing, and the ring-sensor spectrum with the stage's kinematic lines labelled (carrier,
planet pass, mesh harmonics and their carrier sidebands, tooth fault frequencies).

The ring-sensor spectrum is taken over whole carrier revolutions relative to the ring at the end of the
run's steady part (:mod:`gearbody.analysis.ring_sensor`); lines that McFadden and Smith's rule cancels
for equally spaced planets are marked "(cancelled)" and drawn grey."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from gearbody.analysis.ring_sensor import equally_spaced, ring_sensor_spectrum

from ..signals import stage_file_tag, stage_prefix
from .figure import new_figure, save_figure, set_title
from .result import plot_signals
from .spectrum import mark_lines, plot_labelled_spectrum

if TYPE_CHECKING:
    from gearbody.result import Result

__all__ = ["write_planetary_plots"]

CANCELLED_CAPTION = (
    'open grey markers, "(cancelled)": lines McFadden & Smith\'s rule cancels for equally spaced identical '
    "planets; grey frequencies: peaks no line explains"
)


def write_planetary_plots(result: Result, out_dir: str | Path, marks=()) -> list[Path]:
    """Per planetary stage: planet mesh K_d over time, mean planet mesh forces (sharing), and the
    ring-sensor spectrum over its window of whole carrier revolutions with its labelled peaks (and
    ``marks``, lines such as bearing defect frequencies)."""
    out = Path(out_dir)
    title = result.meta.get("title", result.meta.get("scene", ""))
    paths = []
    win = result.final_window()
    for k in result.planetary_stages:
        meta = result.stages[k]
        prefix = stage_prefix(k)
        tag = stage_file_tag(k)
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
        ring = ring_sensor_spectrum(result, k)
        ax = plot_labelled_spectrum(
            ring.spectrum,
            ring.peaks(max_peaks=30),
            title=ring.title(f"{title}: ring sensor, stage {k + 1}"),
            unit="N",
            f_max_hz=ring.f_max_hz,
        )
        if equally_spaced(result, k):
            ax.text(0.01, 0.98, CANCELLED_CAPTION, transform=ax.transAxes, fontsize=7, color="0.4", va="top")
        mark_lines(ax, marks, ring.f_max_hz)
        paths.append(save_figure(ax.figure, out / f"ring_sensor_spectrum{tag}.png"))
    return paths
