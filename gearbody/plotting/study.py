"""The plot of a parameter study (``OUT/<value>_vs_<key>.png`` of ``gearbody sweep``): a summary value
against one varied key, one line per value of the next varied key, failed cases marked."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from .figure import new_figure, save_figure

__all__ = ["plot_study"]


def _numeric(values: list[Any]) -> bool:
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)


def plot_study(rows: list[dict], keys: list[str], value: str, key: str, path: Path, title: str = "") -> Path:
    """``value`` against ``key``; one line per value of the next varied key; failed cases marked."""
    fig = new_figure((900, 550), 100)
    ax = fig.add_subplot(1, 1, 1)
    xs_all = [r[key] for r in rows]
    numeric = _numeric(xs_all)
    categories = list(dict.fromkeys(map(str, xs_all)))

    def xpos(v: Any) -> float:
        return float(v) if numeric else float(categories.index(str(v)))

    others = [k for k in keys if k != key]
    group_key = others[0] if others else None
    groups: dict[str, list[dict]] = {}
    for r in rows:
        groups.setdefault(str(r[group_key]) if group_key else "", []).append(r)
    for name, members in groups.items():
        pts = sorted(
            (xpos(r[key]), float(r[value]))
            for r in members
            if r["status"] == "ok" and isinstance(r.get(value), (int, float)) and math.isfinite(r[value])
        )
        if not pts:
            continue
        x, y = zip(*pts, strict=True)
        style = "o-" if len(set(x)) == len(x) else "o"
        label = f"{group_key} = {name}" if group_key and len(groups) <= 12 else None
        ax.plot(x, y, style, label=label, ms=4)
    failed = [xpos(r[key]) for r in rows if r["status"] == "failed"]
    if failed:
        ax.plot(
            failed,
            [0.02] * len(failed),
            "x",
            color="red",
            ms=9,
            mew=2,
            transform=ax.get_xaxis_transform(),
            label=f"failed ({len(failed)})",
        )
    if not numeric:
        ax.set_xticks(range(len(categories)), categories, rotation=30 if len(categories) > 6 else 0)
    ax.set_xlabel(key)
    ax.set_ylabel(value)
    ax.set_title(title or f"{value} against {key}")
    ax.grid(alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="best", fontsize=8)
    return save_figure(fig, path, 100)
