"""A gear stage of a scenario as the mesh report evaluates it: stage lookup, its packed mesh parameters as
given and with perfect gears, the double-contact half-width and the mesh-period coordinate.

Coordinates: ``u = phi_p z1 / (2 pi)`` counts mesh periods along the pinion angle phi_p; period
``n = floor(u)`` is the pair of pinion tooth ``n mod z1`` and wheel tooth ``n mod z2``, at mesh phase
``p = u - n`` (docs/scenario.md, "Phase convention").
"""

from __future__ import annotations

import math

import numpy as np

from gearbody.assembly import mesh_parameters_from_scenario

__all__ = [
    "angles",
    "get_stage",
    "half_double",
    "healthy_scenario",
    "parameter_pair",
    "parameters",
    "stage_label",
]


def healthy_scenario(scenario, stage: int):
    """The scenario with stage ``stage``'s gears perfect: no damaged or pitted teeth, no run-out, no
    tooth errors (e_um = 0), resolved and validated again."""
    st = scenario.stages[stage]
    return scenario.with_stage(
        stage,
        damaged_teeth=(),
        pitted_teeth=(),
        eccentricity=(),
        error_mode=st.error_mode.replace(e_um=0.0),
    )


def get_stage(scenario, stage: int):
    """The scenario's stage ``stage`` (0-based); IndexError if there is none."""
    n = len(scenario.stages)
    if not (isinstance(stage, int) and 0 <= stage < n):
        raise IndexError(f"stage = {stage!r}: the scenario has {n} stage(s) (0-based index 0..{n - 1})")
    return scenario.stages[stage]


def parameters(scenario, stage: int, healthy: bool = False) -> np.ndarray:
    """Packed mesh parameters (friction off: it does not enter k_z, E or the static TE)."""
    source = healthy_scenario(scenario, stage) if healthy else scenario
    return mesh_parameters_from_scenario(source, stage, friction=False)


def parameter_pair(scenario, stage: int) -> tuple[np.ndarray, np.ndarray]:
    """Packed mesh parameters as given and with perfect gears (:func:`healthy_scenario`)."""
    return parameters(scenario, stage), parameters(scenario, stage, healthy=True)


def half_double(mesh) -> float:
    """h = (eps_alpha - 1)/2: double contact for mesh phase p < h and p >= 1 - h."""
    return 0.5 * (mesh.contact_ratio - 1.0)


def angles(periods: np.ndarray, z1: int) -> np.ndarray:
    return np.ascontiguousarray(2.0 * math.pi * np.asarray(periods, float) / z1)


def stage_label(scenario, stage: int) -> str:
    """ "stage 1 of 2 (design.stages.1)"."""
    return f"stage {stage + 1} of {len(scenario.stages)} (design.stages.{stage + 1})"
