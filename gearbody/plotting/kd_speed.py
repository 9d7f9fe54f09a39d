"""K_d against speed: the result of :func:`gearbody.studies.speed.kd_speed_sweep` over the mesh
frequency, with the natural frequencies marked (the paper's Figs. 5-8)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from gearbody.analysis.dynamic_factor import INSTABILITY_KD

from .figure import new_figure, save_figure

if TYPE_CHECKING:
    from gearbody.studies.speed import SpeedSweep

__all__ = ["plot_kd_against_speed"]


def plot_kd_against_speed(
    sweep: SpeedSweep, natural_frequencies_hz: Sequence[float], path: str | Path, title: str = ""
) -> Path:
    """K_d max / min against mesh frequency, with the natural frequencies as vertical lines."""
    fig = new_figure((900, 500), 100)
    ax = fig.add_subplot(1, 1, 1)
    ok = np.isfinite(sweep.kd_max)
    ax.plot(sweep.mesh_frequency_hz[ok], sweep.kd_max[ok], "o-", label="K_d max")
    ax.plot(sweep.mesh_frequency_hz[ok], sweep.kd_min[ok], "s--", label="K_d min")
    ax.axhline(INSTABILITY_KD, color="red", lw=0.8, ls=":", label=f"K_d = {INSTABILITY_KD:g}")
    lo, hi = ax.get_xlim()
    for f in natural_frequencies_hz:
        if f > 1.0 and lo <= f <= hi:
            ax.axvline(f, color="grey", lw=0.8, ls="--", label="natural frequency")
            ax.text(f, ax.get_ylim()[1], f" {f:.0f} Hz", rotation=90, va="top", fontsize=8, color="grey")
    handles, labels = ax.get_legend_handles_labels()
    seen = dict(zip(labels, handles, strict=True))
    ax.legend(seen.values(), seen.keys(), loc="best")
    ax.set_xlabel("mesh frequency f_z = z1 w / 2 pi [Hz]")
    ax.set_ylabel("K_d = F / F_rated [-]")
    ax.set_title(title or "K_d against speed (steady rated load)")
    ax.grid(alpha=0.3)
    return save_figure(fig, path, 100)
