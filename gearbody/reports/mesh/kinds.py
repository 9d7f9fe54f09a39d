"""``gearbody mesh``'s report of each stage kind (the kinds' ``mesh_report``): the parallel stage's
(:mod:`gearbody.reports.mesh`) and the planetary stage's (:mod:`gearbody.reports.mesh.planetary`), text and
figure, registered on import."""

from __future__ import annotations

from gearbody.model.kinds import register_stage_kind

from . import damage_windows, static_transmission_error, stiffness_cycle, summary_text
from .figure import plot_planetary_stage, plot_stage
from .planetary import (
    planetary_damage_windows,
    planetary_static_transmission_errors,
    planetary_stiffness_cycles,
    planetary_summary_text,
)

__all__: list[str] = []


def _parallel_mesh_report(scenario, k: int, load: float, path):
    """(the report's text, its plot or None) of parallel stage k at ``load`` (fraction of rated)."""
    cycle, windows = stiffness_cycle(scenario, k), damage_windows(scenario, k)
    te = static_transmission_error(scenario, k, load)
    text = summary_text(scenario, k, load, cycle=cycle, windows=windows, te=te)
    return text, None if path is None else plot_stage(scenario, k, path, cycle, windows, te)


def _planetary_mesh_report(scenario, k: int, load: float, path):
    """(the report's text, its plot or None) of planetary stage k at ``load`` (fraction of rated)."""
    cycles, windows = planetary_stiffness_cycles(scenario, k), planetary_damage_windows(scenario, k)
    tes = planetary_static_transmission_errors(scenario, k, load)
    text = planetary_summary_text(scenario, k, load, cycles=cycles, windows=windows, tes=tes)
    return text, None if path is None else plot_planetary_stage(scenario, k, path, cycles, windows, tes)


register_stage_kind("parallel", mesh_report=_parallel_mesh_report)
register_stage_kind("planetary", mesh_report=_planetary_mesh_report)
