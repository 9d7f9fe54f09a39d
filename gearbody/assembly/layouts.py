"""A scenario's system layout (:class:`~gearbody.assembly.system.SystemLayout`) and initial state, for the
run and for the modes: the one place that picks the layout of a drive."""

from __future__ import annotations

import numpy as np

from ..model import Scenario
from .compound import compound_initial_state, compound_layout
from .compound_system import compound_system
from .operating_point import initial_state, static_lateral_displacements_m
from .system import SystemLayout
from .topology import muller_system, torsional_coordinates, torsional_layout, torsional_system

__all__ = ["drive_system"]


def drive_system(scenario: Scenario) -> tuple[SystemLayout, np.ndarray, np.ndarray]:
    """The system of a scenario and its initial coordinates and velocities (one per coordinate; an
    infeasible start raises InputError)."""
    if scenario.has_planetary:
        layout = compound_layout(scenario)
        q0, v0 = compound_initial_state(scenario, layout)
        return compound_system(layout), q0, v0
    q0, v0 = initial_state(scenario)
    if scenario.meta.topology == "muller":
        return muller_system(scenario), q0, v0
    lateral_u0 = static_lateral_displacements_m(scenario)
    layout = torsional_layout(scenario)
    q, v = torsional_coordinates(layout, q0, v0, lateral_u0)
    return torsional_system(layout, lateral_u0=lateral_u0), q, v
