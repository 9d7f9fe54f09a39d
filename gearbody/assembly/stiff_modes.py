"""A check relative to the model before a run: no coordinate so light against its stiffness that its
natural frequency lies far above what the run resolves (docs/scenario.md, "Resource limits").

An inertia has no fixed lower bound (1e-6 kg m^2 is a fine pinion of a small drive and absurd for a
motor on a soft coupling); what matters is its natural frequency against the rest of the model. For
every coordinate i, ``f_i = sqrt(K_ii / M_ii) / 2 pi`` (K the stiffness matrix at the mean mesh
stiffness with the bearings, M the diagonal mass matrix) is a lower bound of the model's highest natural
frequency (Rayleigh quotient of the unit vector e_i). A bearing law enters with its tangent stiffness
where it carries the rated mesh forces, as the modes linearise it (a Hertzian bearing with clearance
is stiff only in contact). Damping makes a coordinate stiff too: with C_ii its damping (shafts, meshes,
bearings, and the slope 2 M_b / (s_b w_s) of the motor's Kloss characteristic), the
coordinate's own root of M_ii s^2 + C_ii s + K_ii = 0 has |s| >= max(sqrt(K_ii / M_ii), C_ii / (2 M_ii)),
and the explicit solver's stable step shrinks as 1 / |s| whether the root is oscillatory or real. The
rate of a coordinate is that |s| / 2 pi (for the damping part an estimate of the model's fastest root,
close when one light coordinate dominates, as in the cases it refuses, not a proven bound). A run is
refused when some rate exceeds MODE_RATE_FACTOR times the highest rate it resolves,
max(solver.output_rate_hz, 1 / solver.max_step_s): the solver must take steps of ~1 / (pi rate) to
stay stable there, and the output cannot show it. A drive with planetary stages (or stage kinds
registered from outside) has its rates from :mod:`gearbody.assembly.stiff_modes_compound`.
"""

from __future__ import annotations

import math

from ..model import Scenario, ScenarioError
from ..model.params import stage_key
from ..physics import mean_stiffness_N_per_m, viscous_equivalent_Nms
from ..physics.bearings import tangent_stiffness_damping
from .coordinate_rates import CoordinateFrequency, add, largest
from .parameters import mesh_parameters_from_scenario
from .stiff_modes_compound import compound_frequencies
from .topology import gear_names, reduced_mass_kg, torsional_layout

__all__ = ["MODE_RATE_FACTOR", "CoordinateFrequency", "check_resolved_modes", "coordinate_frequencies"]

MODE_RATE_FACTOR = 10.0
"""Largest coordinate frequency accepted, as a multiple of max(output rate, 1 / max step); the scenes'
highest natural frequencies lie at 0.02-0.18 of their 20 kHz output rate (tests/test_engine.py)."""


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


def _bearing_keys(law, gear_key: str, direction: int) -> tuple[str, str]:
    """The scenario keys of a bearing law's stiffness and damping in ``direction`` (0 = x, 1 = y): its
    parameters' names when the law states them, else its parameters table."""
    k = getattr(law, "STIFFNESS_PARAMETERS", None)
    c = getattr(law, "DAMPING_PARAMETERS", None)
    base = f"{gear_key}.bearing.parameters"
    return (f"{base}.{k[direction]}" if k else base, f"{base}.{c[direction]}" if c else base)


def _rated_bearing_states(scenario: Scenario) -> dict[str, object]:
    """Where each lateral gear's bearing carries the rated mesh forces (the modes linearise there); none
    when a law cannot carry them (the run says so)."""
    from ..errors import InputError
    from .operating_point import static_lateral_displacements_m

    try:
        return static_lateral_displacements_m(scenario, 1.0)
    except InputError:
        return {}


def coordinate_frequencies(scenario: Scenario) -> list[CoordinateFrequency]:
    """``sqrt(K_ii / M_ii) / 2 pi`` of every coordinate, its damping C_ii, and the scenario keys that
    contribute most to K_ii and C_ii (bearings included, a law at its tangent where it carries the rated
    mesh forces)."""
    if scenario.meta.topology == "muller":
        return [_muller_frequency(scenario)]
    if scenario.has_planetary:
        return compound_frequencies(scenario)
    return _train_frequencies(scenario)


def _muller_frequency(scenario: Scenario) -> CoordinateFrequency:
    """Muller's one coordinate, the deflection of the reduced mass on the mean mesh stiffness."""
    k = mean_stiffness_N_per_m(mesh_parameters_from_scenario(scenario))
    m = reduced_mass_kg(scenario)
    return CoordinateFrequency(
        "deflection",
        math.sqrt(k / m) / (2 * math.pi),
        "the reduced mass m = 1 / (r1^2 / I_pinion + r2^2 / I_wheel) of "
        "design.pinion.inertia_kg_m2 and design.wheel.inertia_kg_m2",
        m,
        k,
        scenario.stages[0].mesh.damping_Ns_per_m,
        "design.mesh.damping_Ns_per_m",
        "the mean mesh stiffness of design.mesh",
    )


def _train_frequencies(scenario: Scenario) -> list[CoordinateFrequency]:
    """The coordinates of a drive of parallel stages (train, two-wheel): every inertia's rotation, then
    every free lateral direction of a gear on bearings."""
    layout = torsional_layout(scenario)
    keys = _inertia_keys(scenario)
    n = len(layout.inertias)
    stiffness: list[dict[str, float]] = [{} for _ in range(n)]  # K_ii by contributing key
    damping: list[dict[str, float]] = [{} for _ in range(n)]  # C_ii by contributing key
    lateral: dict[tuple[int, int], dict[str, float]] = {}
    lateral_damping: dict[tuple[int, int], dict[str, float]] = {}

    for s, sh in enumerate(layout.shafts):
        for i in (sh.i, sh.j):
            add(stiffness[i], f"design.shafts.{s + 1}.stiffness_Nm_per_rad", sh.stiffness_Nm_per_rad)
            add(damping[i], f"design.shafts.{s + 1}.damping_Nms_per_rad", sh.damping_Nms_per_rad)
    for s, m in enumerate(layout.meshes):
        k = mean_stiffness_N_per_m(m.parameters)
        c = scenario.stages[s].mesh.damping_Ns_per_m
        mesh_key = stage_key(s, "mesh") + ".damping_Ns_per_m"
        mesh_k_key = f"the mean mesh stiffness of {stage_key(s, 'mesh')}"
        for body, r in ((m.pinion, m.r_pinion_m), (m.wheel, m.r_wheel_m)):
            add(stiffness[body], mesh_k_key, k * r**2)
            add(damping[body], mesh_key, c * r**2)
            support = layout.inertias[body].lateral
            for d in support.free_directions if support else ():
                add(lateral.setdefault((body, d), {}), mesh_k_key, k * m.line_of_action[d] ** 2)
                add(lateral_damping.setdefault((body, d), {}), mesh_key, c * m.line_of_action[d] ** 2)
    _add_bearings(scenario, layout, lateral, lateral_damping)
    if layout.motor_at is not None:
        mo = scenario.design.motor
        slope = viscous_equivalent_Nms(mo.breakdown_torque_Nm, mo.breakdown_slip, mo.synchronous_speed_rad_s)
        add(
            damping[layout.motor_at],
            "the motor's slip characteristic, slope 2 M_b / (s_b w_s) of design.motor.breakdown_torque_Nm, "
            "breakdown_slip and synchronous_speed_rad_s",
            slope,
        )

    def coordinate(name: str, key: str, mass: float, k_by_key: dict[str, float], c_by_key: dict[str, float]):
        k, c = sum(k_by_key.values()), sum(c_by_key.values())
        return CoordinateFrequency(
            name, math.sqrt(k / mass) / (2 * math.pi), key, mass, k, c, largest(c_by_key), largest(k_by_key)
        )

    out = [
        coordinate(body.name, keys[body.name], body.inertia_kg_m2, stiffness[i], damping[i])
        for i, body in enumerate(layout.inertias)
    ]
    for (i, d), k_by_key in lateral.items():
        body = layout.inertias[i]
        name = f"{body.name}_{'xy'[d]}"
        out.append(coordinate(name, keys[name], body.lateral.mass_kg, k_by_key, lateral_damping[i, d]))
    return out


def _add_bearings(scenario: Scenario, layout, lateral: dict, lateral_damping: dict) -> None:
    """Each lateral gear's bearing in its free directions: a law at its tangent stiffness and damping
    where it carries the rated mesh forces (as the modes linearise it)."""
    states = _rated_bearing_states(scenario)
    gear_keys = {
        name: stage_key(k, gear)
        for k in range(len(scenario.stages))
        for name, gear in zip(gear_names(k), ("pinion", "wheel"), strict=True)
    }
    for i, body in enumerate(layout.inertias):
        support = body.lateral
        if support is None:
            continue
        k_b, c_b = tangent_stiffness_damping(support.bearing, states.get(body.name, (0.0, 0.0)))
        for d in support.free_directions:
            k_key, c_key = _bearing_keys(support.bearing, gear_keys[body.name], d)
            add(lateral.setdefault((i, d), {}), k_key, max(float(k_b[d]), 0.0))
            add(lateral_damping.setdefault((i, d), {}), c_key, max(float(c_b[d]), 0.0))


def check_resolved_modes(scenario: Scenario) -> None:
    """Refuse a scenario with a coordinate whose rate (natural frequency or damping rate) lies above
    MODE_RATE_FACTOR times max(solver.output_rate_hz, 1 / solver.max_step_s), naming its mass key and the
    stiffness or damping that contributes most (ScenarioError, exit 2)."""
    sv = scenario.solver
    resolved_hz = max(sv.output_rate_hz, 1.0 / sv.max_step_s)
    limit_hz = MODE_RATE_FACTOR * resolved_hz
    freqs = coordinate_frequencies(scenario)
    worst = max(freqs, key=lambda c: c.rate_hz)
    if worst.rate_hz <= limit_hz:
        return
    rest = [c.rate_hz for c in freqs if c.key != worst.key]
    rest_text = f"; the model's other coordinates reach {max(rest):.3g} Hz" if rest else ""
    translation = worst.name.endswith(("_x", "_y")) or worst.name == "deflection"
    unit, k_unit, c_unit = ("kg", "N/m", "N s/m") if translation else ("kg m^2", "N m/rad", "N m s/rad")
    steps = scenario.operation.t_end_s * math.pi * worst.rate_hz
    if worst.damping_rate_hz > worst.frequency_hz:
        cause = (
            f"against its damping ({worst.damping:.3g} {c_unit}, mostly from {worst.damping_source}) this "
            f"gives a damping rate C / (2 M) / 2 pi of at least {worst.damping_rate_hz:.3g} Hz"
        )
        remedy = "raise the inertia or mass or lower that damping"
    else:
        cause = (
            f"against its stiffness ({worst.stiffness:.3g} {k_unit}, mostly from {worst.stiffness_source}) "
            f"this gives a natural frequency of at least {worst.frequency_hz:.3g} Hz"
        )
        remedy = "raise the inertia or mass or lower that stiffness"
    raise ScenarioError(
        f"{worst.key} = {worst.mass:g} {unit}: {cause}, more than {MODE_RATE_FACTOR:g} x the highest rate "
        f"the run resolves, max(solver.output_rate_hz, 1 / solver.max_step_s) = {resolved_hz:.3g} Hz "
        f"(limit {limit_hz:.3g} Hz){rest_text}. An explicit solver needs ~{steps:.2g} steps to stay stable "
        f"there and the output cannot show it: {remedy}, or to resolve it raise solver.output_rate_hz or "
        "lower solver.max_step_s"
    )
