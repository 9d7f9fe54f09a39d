"""The plot of a sensitivity analysis (``OUT/indices.png`` of ``gearbody sensitivity``): one panel per
feature, one group of horizontal bars per key with the confidence half-widths as error bars. Morris:
mu* and sigma (in the feature's unit); Sobol: S1 and ST (fractions of the variance)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from .figure import new_figure, save_figure

__all__ = ["plot_indices"]

_BARS = {
    "morris": (("mu_star", "mu_star_conf", "mu*"), ("sigma", None, "sigma")),
    "sobol": (("S1", "S1_conf", "S1 (first order)"), ("ST", "ST_conf", "ST (total)")),
}


def plot_indices(
    method: str,
    keys: Sequence[str],
    indices: Mapping[str, Mapping[str, np.ndarray]],
    path: Path,
    title: str = "",
) -> Path:
    """Bar plot of the indices of every feature (``indices[feature][name]``, arrays over ``keys``)."""
    bars = _BARS[method]
    n_feat, n_keys = len(indices), len(keys)
    panel_px = 70 + 34 * n_keys * len(bars) // 2 + 20 * n_keys
    fig = new_figure((1000, min(max(300, 60 + panel_px * n_feat), 4000)), 100)
    axes = fig.subplots(n_feat, 1, squeeze=False)[:, 0]
    y = np.arange(n_keys)
    height = 0.8 / len(bars)
    for ax, (feature, ix) in zip(axes, indices.items(), strict=True):
        for b, (name, conf, label) in enumerate(bars):
            values = np.asarray(ix[name], dtype=float)
            err = np.abs(np.asarray(ix[conf], dtype=float)) if conf else None
            ax.barh(y + (b - (len(bars) - 1) / 2) * height, values, height, xerr=err, label=label, capsize=3)
        ax.set_yticks(y, list(keys))
        ax.invert_yaxis()
        ax.axvline(0.0, color="black", lw=0.8)
        ax.set_title(feature, fontsize=10, loc="left")
        ax.grid(axis="x", alpha=0.3)
        ax.set_xlabel("index [-]" if method == "sobol" else "elementary effect over the range [feature unit]")
    axes[0].legend(loc="lower right", fontsize=8)
    if title:
        fig.suptitle(title)
    return save_figure(fig, path)
