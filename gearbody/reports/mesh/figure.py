"""Figure of the mesh report (``gearbody mesh SCENE``): one PNG per gear stage with k_z over the mesh
cycle (healthy), k_z around each damaged tooth and the static transmission error under load.

Draws the data of :mod:`gearbody.reports.mesh` with :func:`gearbody.plotting.figure.new_figure` (no
pyplot; matplotlib is imported only when a figure is drawn). Engine-free. It lives with the data it
draws, which come from the scenario: the plotting package below draws what it is given and imports
nothing of the model. docs/mesh.md describes the figure.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from gearbody.plotting.figure import PathLike, new_figure, save_figure

from .curves import (
    DamageWindow,
    StaticTransmissionError,
    StiffnessCycle,
    load_label,
    stage_data,
    tooth_label,
)
from .stage import stage_label

__all__ = ["plot_planetary_stage", "plot_stage"]

MAX_WINDOWS_PLOTTED = 4
_PERIODS_LABEL = "Mesh periods u = phi_p z1 / 2 pi [-]"


def _gn(k_N_per_m):
    """Stiffness in 1e9 N/m (the unit of the k_z axes)."""
    return k_N_per_m / 1e9


def _has_double_zone(cycle: StiffnessCycle) -> bool:
    return cycle.profile != "table" and cycle.half_double > 0


def _shade_double(ax, cycle: StiffnessCycle) -> None:
    if not _has_double_zone(cycle):
        return
    h = cycle.half_double
    end = math.ceil(cycle.periods[-1])
    for n in range(end + 1):
        a, b = max(n - h, 0.0), min(n + h, float(end))
        if b > a:
            ax.axvspan(a, b, color="0.85", linewidth=0, zorder=0)


def _finish(ax, xlabel: str, ylabel: str, title: str, legend_loc: str) -> None:
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.legend(loc=legend_loc, fontsize="small")
    ax.grid(True, alpha=0.3)


def _plot_cycle(ax, cycle: StiffnessCycle) -> None:
    _shade_double(ax, cycle)
    ax.plot(
        cycle.periods, _gn(cycle.stiffness_N_per_m), color="tab:blue", linewidth=1.5, label="k_z (healthy)"
    )
    ax.axhline(_gn(cycle.mean_N_per_m), color="tab:green", linestyle="--", linewidth=1.0, label="mean")
    for n in range(math.ceil(cycle.periods[-1])):
        ax.axvline(n + cycle.pitch_point_phase, color="tab:red", linestyle=":", linewidth=1.0)
    ax.plot([], [], color="tab:red", linestyle=":", label="pitch point")
    if _has_double_zone(cycle):
        ax.fill_between([], [], color="0.85", label="double contact")
    ax.set_xlim(cycle.periods[0], cycle.periods[-1])
    ax.set_ylim(bottom=0)
    _finish(
        ax,
        _PERIODS_LABEL,
        "Mesh stiffness k_z [1e9 N/m]",
        "k_z over the mesh cycle, healthy teeth",
        "lower right",
    )


def _plot_window(ax, w: DamageWindow) -> None:
    ax.axvspan(*w.contact, color="tab:red", alpha=0.08, linewidth=0, label="tooth's pair acts")
    ax.plot(
        w.periods,
        _gn(w.healthy_stiffness_N_per_m),
        color="0.4",
        linestyle="--",
        linewidth=1.0,
        label="healthy",
    )
    ax.plot(w.periods, _gn(w.stiffness_N_per_m), color="tab:red", linewidth=1.5, label="as given")
    ax.set_xlim(w.periods[0], w.periods[-1])
    ax.set_ylim(bottom=0)
    title = f"{tooth_label(w)}: {w.description} (min k_z / healthy = {w.min_ratio:.3f})"
    _finish(ax, _PERIODS_LABEL, "k_z [1e9 N/m]", title, "lower right")


def _plot_te(ax, te: StaticTransmissionError) -> None:
    ax.plot(te.periods, te.healthy_te_um, color="0.4", linestyle="--", linewidth=1.0, label="perfect gears")
    ax.plot(
        te.periods,
        np.where(np.isfinite(te.te_um), te.te_um, np.nan),
        color="tab:blue",
        linewidth=0.9,
        label="as given",
    )
    ax.axhline(te.backlash_um, color="tab:green", linestyle=":", linewidth=1.0, label="l_u (backlash)")
    ax.set_xlim(0.0, te.periods[-1] + 0.5 * (te.periods[1] - te.periods[0]))
    title = f"Static transmission error F/k - E + l_u at F = {te.force_N:.5g} N ({load_label(te)})"
    _finish(ax, _PERIODS_LABEL + " (pinion turn = z1 periods)", "Static TE [µm]", title, "upper right")


def plot_stage(
    scenario,
    stage: int,
    path: PathLike,
    cycle: StiffnessCycle | None = None,
    windows: list[DamageWindow] | None = None,
    te: StaticTransmissionError | None = None,
    load_fraction: float = 1.0,
    width_px: int = 1100,
    dpi: int = 100,
) -> Path:
    """One PNG of a stage: k_z over the mesh cycle (healthy), k_z around each damaged tooth (at most
    MAX_WINDOWS_PLOTTED panels), and the static transmission error over the pinion turn(s). The data
    not passed in is computed with :mod:`gearbody.reports.mesh`'s defaults."""
    cycle, windows, te = stage_data(scenario, stage, load_fraction, cycle, windows, te)
    shown = windows[:MAX_WINDOWS_PLOTTED]
    rows = 2 + len(shown)
    fig = new_figure((width_px, 330 * rows), dpi)
    axes = fig.subplots(rows, 1, squeeze=False)[:, 0]
    st = scenario.stages[stage]
    fig.suptitle(
        f"{scenario.meta.title}\n{stage_label(scenario, stage)}: z = {st.pinion.teeth}/{st.wheel.teeth}, "
        f"{st.mesh.stiffness_profile}",
        fontsize=10,
    )
    _plot_cycle(axes[0], cycle)
    for ax, w in zip(axes[1 : 1 + len(shown)], shown, strict=True):
        _plot_window(ax, w)
    _plot_te(axes[-1], te)
    if len(windows) > len(shown):
        fig.text(0.01, 0.005, f"{len(windows) - len(shown)} more damaged teeth not shown", fontsize=8)
    return save_figure(fig, path, dpi)


def plot_planetary_stage(
    scenario,
    stage: int,
    path: PathLike,
    cycles: dict[str, StiffnessCycle] | None = None,
    windows: list[DamageWindow] | None = None,
    tes: dict[str, StaticTransmissionError] | None = None,
    load_fraction: float = 1.0,
    width_px: int = 1100,
    dpi: int = 100,
) -> Path:
    """One PNG of a planetary stage: k_z of the sun-planet and the ring-planet law over the mesh cycle
    (healthy), k_z around each damaged tooth (at most MAX_WINDOWS_PLOTTED panels) and planet 1's static
    transmission error in each mesh over one revolution of the sun (ring) relative to its line of
    centres. Data not passed in is computed with :mod:`gearbody.reports.mesh.planetary`'s defaults."""
    from .planetary import (
        PLANET_MESHES,
        planetary_damage_windows,
        planetary_static_transmission_errors,
        planetary_stiffness_cycles,
    )

    cycles = planetary_stiffness_cycles(scenario, stage) if cycles is None else cycles
    windows = planetary_damage_windows(scenario, stage) if windows is None else windows
    tes = planetary_static_transmission_errors(scenario, stage, load_fraction) if tes is None else tes
    shown = windows[:MAX_WINDOWS_PLOTTED]
    rows = 4 + len(shown)
    fig = new_figure((width_px, 330 * rows), dpi)
    axes = fig.subplots(rows, 1, squeeze=False)[:, 0]
    st = scenario.stages[stage]
    fig.suptitle(
        f"{scenario.meta.title}\n{stage_label(scenario, stage)}: planetary, z_s/z_p/z_r = "
        f"{st.sun.teeth}/{st.planet.teeth}/{st.ring.teeth}, {st.planets} planets",
        fontsize=10,
    )
    for ax, mesh in zip(axes[:2], PLANET_MESHES, strict=True):
        _plot_cycle(ax, cycles[mesh])
        ax.set_title(f"{mesh}-planet mesh: k_z over the mesh cycle, healthy teeth", fontsize=10)
        ax.set_xlabel(f"Mesh periods u = (law angle) z_{mesh[0]} / 2 pi [-]")
    for ax, w in zip(axes[2 : 2 + len(shown)], shown, strict=True):
        _plot_window(ax, w)
        ax.set_xlabel("Mesh periods u = (law angle) z1 / 2 pi [-]")
    for ax, mesh in zip(axes[-2:], PLANET_MESHES, strict=True):
        te = tes[mesh]
        _plot_te(ax, te)
        ax.set_title(
            f"{mesh}-planet mesh, planet 1: static TE F/k - E + l_u at F = {te.force_N:.5g} N "
            f"({load_label(te)})",
            fontsize=10,
        )
        ax.set_xlabel(f"Mesh periods u (one {mesh} revolution relative to the line of centres)")
    if len(windows) > len(shown):
        fig.text(0.01, 0.005, f"{len(windows) - len(shown)} more damaged teeth not shown", fontsize=8)
    return save_figure(fig, path, dpi)
