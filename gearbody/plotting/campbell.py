"""Campbell diagram: mesh harmonics k z1 w / 2 pi against pinion speed, natural frequencies as
horizontal lines, their crossings (resonance speeds, :func:`gearbody.analysis.modal.campbell_lines`)
marked."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from gearbody.analysis.modal import campbell_lines

from .figure import new_figure, save_figure

__all__ = ["plot_campbell"]


def plot_campbell(
    natural_frequencies_hz: Sequence[float],
    pinion_teeth: int,
    max_speed_rad_s: float,
    path: str | Path,
    harmonics: int = 3,
    title: str = "",
    operating_speed_rad_s: float | None = None,
) -> Path:
    """Campbell diagram: mesh harmonics k z1 w / 2 pi against pinion speed, natural frequencies as
    horizontal lines; crossings (resonance speeds) marked."""
    fig = new_figure((900, 600), 100)
    ax = fig.add_subplot(1, 1, 1)
    w = np.linspace(0, max_speed_rad_s, 200)
    f_top = harmonics * pinion_teeth * max_speed_rad_s / (2 * math.pi)
    for k in range(1, harmonics + 1):
        ax.plot(w, k * pinion_teeth * w / (2 * math.pi), label=f"{k} f_z")
    crossings = campbell_lines(natural_frequencies_hz, pinion_teeth, harmonics)["speed_rad_s"]
    for j, f in enumerate(natural_frequencies_hz):
        if f < 1.0 or f > f_top:
            continue
        ax.axhline(f, color="grey", lw=0.8, ls="--")
        ax.text(max_speed_rad_s, f, f" {f:.0f} Hz", va="center", fontsize=8, color="grey")
        for k in range(harmonics):
            ws = crossings[k, j]
            if ws <= max_speed_rad_s:
                ax.plot(ws, f, "ko", ms=4)
    if operating_speed_rad_s:
        ax.axvline(operating_speed_rad_s, color="green", lw=1, label="operating speed")
    ax.set_xlim(0, max_speed_rad_s)
    ax.set_ylim(0, f_top)
    ax.set_xlabel("pinion speed w [rad/s]")
    ax.set_ylabel("frequency [Hz]")
    ax.set_title(title or "Campbell diagram")
    ax.legend(loc="upper left")
    ax.grid(alpha=0.3)
    return save_figure(fig, path, 100)
