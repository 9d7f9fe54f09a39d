"""The mesh report as printed by ``gearbody mesh``: the table as aligned text, and one stage's summary
(table, damaged teeth, static transmission error)."""

from __future__ import annotations

import numpy as np

from .curves import (
    DamageWindow,
    StaticTransmissionError,
    StiffnessCycle,
    load_label,
    stage_data,
    tooth_label,
)
from .stage import stage_label
from .table import Row, geometry_table

__all__ = ["format_table", "summary_text"]


def _format_value(value) -> str:
    if isinstance(value, bool | str):
        return str(value)
    if isinstance(value, int | np.integer):
        return str(int(value))
    v = float(value)
    if v != 0.0 and (abs(v) >= 1e6 or abs(v) < 1e-3):
        return f"{v:.5e}"
    return f"{v:.6g}"


def format_table(rows: list[Row], title: str = "") -> str:
    """The rows as aligned text: name, value, unit; headings on their own lines."""
    width = max((len(n) for n, v, _ in rows if v is not None), default=10) + 2
    lines = [title] if title else []
    for name, value, unit in rows:
        if value is None:
            lines.append(f"  {name}")
        else:
            lines.append(f"    {name:<{width}}{_format_value(value):>14}  {unit}".rstrip())
    return "\n".join(lines)


def _stats(x: np.ndarray) -> str:
    finite = x[np.isfinite(x)]
    lost = x.size - finite.size
    text = (
        f"mean {finite.mean():.3f}, min {finite.min():.3f}, max {finite.max():.3f}, "
        f"peak-to-peak {finite.max() - finite.min():.3f} µm"
    )
    return text + (f" ({lost} samples with k_z = 0: no contact)" if lost else "")


def summary_text(
    scenario,
    stage: int = 0,
    load_fraction: float = 1.0,
    cycle: StiffnessCycle | None = None,
    windows: list[DamageWindow] | None = None,
    te: StaticTransmissionError | None = None,
) -> str:
    """Printed summary of one stage: the geometry table, k_z over the cycle, the damaged teeth and the
    static TE (computed here unless passed in)."""
    cycle, windows, te = stage_data(scenario, stage, load_fraction, cycle, windows, te)
    lines = [format_table(geometry_table(scenario, stage), stage_label(scenario, stage))]
    lines.append("  damaged teeth" if windows else "  damaged teeth: none")
    for w in windows:
        lines.append(
            f"    {tooth_label(w)} ({w.description}): min k_z/k_z,healthy {w.min_ratio:.4f}, "
            f"acts over u = {w.contact[0]:.3f} .. {w.contact[1]:.3f} mesh periods"
        )
    inv_mean = float(np.mean(1.0 / te.healthy_stiffness_N_per_m))
    lines.append(
        f"  static transmission error at F = {te.force_N:.6g} N ({load_label(te)} "
        f"{te.rated_force_N:.6g} N), l_u = {te.backlash_um:.4g} µm, over {te.pinion_turns} pinion turn(s)"
    )
    lines.append(
        f"    F/k_mean {te.force_N / cycle.mean_N_per_m * 1e6:.3f} µm, "
        f"mean F/k {te.force_N * inv_mean * 1e6:.3f} µm (healthy)"
    )
    lines.append(f"    healthy:  {_stats(te.healthy_te_um)}")
    lines.append(f"    as given: {_stats(te.te_um)}")
    return "\n".join(lines)
