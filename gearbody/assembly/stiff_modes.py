"""A check relative to the model before a run: no coordinate so light against its stiffness that its
natural frequency lies far above what the run resolves (docs/scenario.md, "Resource limits").

An inertia has no fixed lower bound (1e-6 kg m^2 is a fine pinion of a small drive and absurd for a
motor on a soft coupling); what matters is its natural frequency against the rest of the model. For
every coordinate i, ``f_i = sqrt(K_ii / M_ii) / 2 pi`` (K the stiffness matrix at the mean mesh
stiffness, M the diagonal mass matrix) is a lower bound of the model's highest natural frequency
(Rayleigh quotient of the unit vector e_i). A run is refused when some f_i exceeds MODE_RATE_FACTOR times
the highest rate it resolves, max(solver.output_rate_hz, 1 / solver.max_step_s): an explicit solver
must take steps of ~1 / (pi f_i) to stay stable on such a mode, and the output cannot show it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..model import Scenario, ScenarioError
from ..model.params import stage_key
from ..physics import mean_stiffness_N_per_m
from .parameters import mesh_parameters_from_scenario
from .topology import gear_names, reduced_mass_kg, torsional_layout

__all__ = ["MODE_RATE_FACTOR", "CoordinateFrequency", "check_resolved_modes", "coordinate_frequencies"]

MODE_RATE_FACTOR = 10.0
"""Largest coordinate frequency accepted, as a multiple of max(output rate, 1 / max step); the scenes'
highest natural frequencies lie at 0.02-0.18 of their 20 kHz output rate (tests/test_engine.py)."""


@dataclass(frozen=True)
class CoordinateFrequency:
    """sqrt(K_ii / M_ii) / 2 pi of one coordinate, and the scenario key of its mass."""

    name: str
    frequency_hz: float
    key: str
    mass: float  # kg m^2 (rotation) or kg (translation)
    stiffness: float  # N m / rad or N / m


def _inertia_keys(scenario: Scenario) -> dict[str, str]:
    keys = {"motor": "design.motor.inertia_kg_m2", "machine": "design.machine.inertia_kg_m2"}
    for k in range(len(scenario.stages)):
        for name, gear in zip(gear_names(k), ("pinion", "wheel"), strict=True):
            keys[name] = stage_key(k, gear) + ".inertia_kg_m2"
            keys[name + "_x"] = keys[name + "_y"] = stage_key(k, gear) + ".mass_kg"
    if scenario.meta.topology == "two-wheel":  # motor and machine lumped on the gears
        keys["pinion"] += " (with design.motor.inertia_kg_m2)"
        keys["wheel"] += " (with design.machine.inertia_kg_m2)"
    return keys


def coordinate_frequencies(scenario: Scenario) -> list[CoordinateFrequency]:
    """``sqrt(K_ii / M_ii) / 2 pi`` of every coordinate (bearing stiffness left out: still a lower
    bound of the highest natural frequency)."""
    if scenario.meta.topology == "muller":
        k = mean_stiffness_N_per_m(mesh_parameters_from_scenario(scenario))
        m = reduced_mass_kg(scenario)
        return [
            CoordinateFrequency(
                "deflection",
                math.sqrt(k / m) / (2 * math.pi),
                "the reduced mass m = 1 / (r1^2 / I_pinion + r2^2 / I_wheel) of "
                "design.pinion.inertia_kg_m2 and design.wheel.inertia_kg_m2",
                m,
                k,
            )
        ]
    layout = torsional_layout(scenario)
    keys = _inertia_keys(scenario)
    stiffness = [0.0] * len(layout.inertias)
    lateral: dict[tuple[int, int], float] = {}
    for sh in layout.shafts:
        stiffness[sh.i] += sh.stiffness_Nm_per_rad
        stiffness[sh.j] += sh.stiffness_Nm_per_rad
    for m in layout.meshes:
        k = mean_stiffness_N_per_m(m.parameters)
        stiffness[m.pinion] += k * m.r_pinion_m**2
        stiffness[m.wheel] += k * m.r_wheel_m**2
        for body in (m.pinion, m.wheel):
            support = layout.inertias[body].lateral
            for d in support.free_directions if support else ():
                lateral[body, d] = lateral.get((body, d), 0.0) + k * m.line_of_action[d] ** 2
    out = []
    for i, body in enumerate(layout.inertias):
        J = body.inertia_kg_m2
        out.append(
            CoordinateFrequency(
                body.name, math.sqrt(stiffness[i] / J) / (2 * math.pi), keys[body.name], J, stiffness[i]
            )
        )
    for (i, d), k in lateral.items():
        body = layout.inertias[i]
        name = f"{body.name}_{'xy'[d]}"
        mass = body.lateral.mass_kg
        out.append(CoordinateFrequency(name, math.sqrt(k / mass) / (2 * math.pi), keys[name], mass, k))
    return out


def check_resolved_modes(scenario: Scenario) -> None:
    """Refuse a scenario with a coordinate whose natural frequency lies above MODE_RATE_FACTOR times
    max(solver.output_rate_hz, 1 / solver.max_step_s), naming its mass key (ScenarioError, exit 2)."""
    sv = scenario.solver
    resolved_hz = max(sv.output_rate_hz, 1.0 / sv.max_step_s)
    limit_hz = MODE_RATE_FACTOR * resolved_hz
    freqs = coordinate_frequencies(scenario)
    worst = max(freqs, key=lambda c: c.frequency_hz)
    if worst.frequency_hz <= limit_hz:
        return
    rest = [c.frequency_hz for c in freqs if c.key != worst.key]
    rest_text = f"; the model's other coordinates reach {max(rest):.3g} Hz" if rest else ""
    translation = worst.name.endswith(("_x", "_y")) or worst.name == "deflection"
    unit, k_unit = ("kg", "N/m") if translation else ("kg m^2", "N m/rad")
    steps = scenario.operation.t_end_s * math.pi * worst.frequency_hz
    raise ScenarioError(
        f"{worst.key} = {worst.mass:g} {unit}: against its stiffness ({worst.stiffness:.3g} {k_unit}, from "
        f"the model's shafts and meshes) this gives a natural frequency of at least "
        f"{worst.frequency_hz:.3g} Hz, more than {MODE_RATE_FACTOR:g} x the highest rate the run "
        f"resolves, max(solver.output_rate_hz, 1 / solver.max_step_s) = {resolved_hz:.3g} Hz "
        f"(limit {limit_hz:.3g} Hz){rest_text}. An explicit solver needs ~{steps:.2g} steps to stay stable "
        "on such a mode and the output cannot show it: raise the inertia or mass, or to resolve the "
        "mode raise solver.output_rate_hz or lower solver.max_step_s"
    )
