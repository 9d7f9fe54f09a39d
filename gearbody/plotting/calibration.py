"""The convergence plot of a calibration (``OUT/convergence.png`` of ``gearbody calibrate``): the cost
chi^2 / 2 of every evaluation in the order made, coloured by stage (global search, least-squares polish,
Jacobian), and the best cost so far."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .figure import new_figure, save_figure

__all__ = ["plot_convergence"]

_STAGES = {
    "global": ("tab:blue", "global search (nevergrad)"),
    "polish": ("tab:orange", "least-squares polish"),
    "jacobian": ("tab:green", "Jacobian at the optimum"),
}


def plot_convergence(history: Sequence[tuple[int, str, float]], path: Path, title: str = "") -> Path:
    """Cost per evaluation (log scale; failed evaluations at their penalty) and the best so far."""
    fig = new_figure((900, 450), 100)
    ax = fig.add_subplot(1, 1, 1)
    n = np.array([h[0] for h in history], dtype=float)
    cost = np.array([h[2] for h in history], dtype=float)
    floor = max(float(np.min(cost[cost > 0])) * 0.5, 1e-300) if np.any(cost > 0) else 1e-12
    shown = np.maximum(cost, floor)  # a cost of exactly 0 on the log axis
    for stage, (colour, label) in _STAGES.items():
        sel = np.array([h[1] == stage for h in history], dtype=bool)
        if sel.any():
            ax.semilogy(n[sel], shown[sel], "o", ms=3, color=colour, label=label)
    if len(shown):
        ax.semilogy(n, np.minimum.accumulate(shown), "-", color="black", lw=1.2, label="best so far")
    ax.set_xlabel("evaluation (each: one simulation per case)")
    ax.set_ylabel("cost = sum(((feature - target) / sigma)^2) / 2")
    ax.xaxis.get_major_locator().set_params(integer=True)
    ax.set_title(title or "calibration convergence", fontsize=10)
    ax.grid(True, which="both", lw=0.3, alpha=0.5)
    ax.legend(fontsize=8, loc="upper right")
    return save_figure(fig, path, 100)
