"""Mesh report of a scenario's gear stages (``gearbody mesh SCENE``): geometry table, k_z over the mesh
cycle (healthy, and around each damaged tooth) and the static transmission error under load.

Engine-free (no Exudyn): everything is evaluated with the mesh law of :mod:`gearbody.physics.mesh` and the
scenario's packed parameters, so the curves are exactly what the solver uses. The data are plain
dataclasses, arrays and rows (testable): :mod:`.stage` (a stage's parameters), :mod:`.table` (geometry
and stiffness rows), :mod:`.curves` (k_z and static TE), :mod:`.text` (the printed summary);
:func:`.figure.plot_stage` draws them, one PNG per stage. docs/mesh.md describes the output.

Coordinates: ``u = phi_p z1 / (2 pi)`` counts mesh periods along the pinion angle phi_p; period
``n = floor(u)`` is the pair of pinion tooth ``n mod z1`` and wheel tooth ``n mod z2``, at mesh phase
``p = u - n`` (docs/scenario.md, "Phase convention").
"""

from .curves import (
    DamageWindow,
    StaticTransmissionError,
    StiffnessCycle,
    damage_windows,
    static_transmission_error,
    stiffness_cycle,
)
from .stage import stage_label
from .table import geometry_table, table_value
from .text import format_table, summary_text

__all__ = [
    "DamageWindow",
    "StaticTransmissionError",
    "StiffnessCycle",
    "damage_windows",
    "format_table",
    "geometry_table",
    "stage_label",
    "static_transmission_error",
    "stiffness_cycle",
    "summary_text",
    "table_value",
]
