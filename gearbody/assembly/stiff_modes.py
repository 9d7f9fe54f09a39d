"""A check relative to the model before a run: no coordinate so light against its stiffness that its
natural frequency lies far above what the run resolves (docs/scenario.md, "Resource limits").

An inertia has no fixed lower bound (1e-6 kg m^2 is a fine pinion of a small drive and absurd for a
motor on a soft coupling); what matters is its natural frequency against the rest of the model. For
every coordinate i, ``f_i = sqrt(K_ii / M_ii) / 2 pi`` (K the stiffness matrix at the mean mesh
stiffness, M the diagonal mass matrix) is a lower bound of the model's highest natural frequency
(Rayleigh quotient of the unit vector e_i). Damping makes a coordinate stiff too: with C_ii its
damping (shafts, meshes, and the slope 2 M_b / (s_b w_s) of the motor's Kloss characteristic), the
coordinate's own root of M_ii s^2 + C_ii s + K_ii = 0 has |s| >= max(sqrt(K_ii / M_ii), C_ii / (2 M_ii)),
and the explicit solver's stable step shrinks as 1 / |s| whether the root is oscillatory or real. The
rate of a coordinate is that |s| / 2 pi (for the damping part an estimate of the model's fastest root,
close when one light coordinate dominates, as in the cases it refuses, not a proven bound). A run is
refused when some rate exceeds MODE_RATE_FACTOR times the highest rate it resolves,
max(solver.output_rate_hz, 1 / solver.max_step_s): the solver must take steps of ~1 / (pi rate) to
stay stable there, and the output cannot show it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..model import Scenario, ScenarioError
from ..model.params import stage_key
from ..physics import mean_stiffness_N_per_m, viscous_equivalent_Nms
from .parameters import mesh_parameters_from_scenario
from .topology import gear_names, reduced_mass_kg, torsional_layout

__all__ = ["MODE_RATE_FACTOR", "CoordinateFrequency", "check_resolved_modes", "coordinate_frequencies"]

MODE_RATE_FACTOR = 10.0
"""Largest coordinate frequency accepted, as a multiple of max(output rate, 1 / max step); the scenes'
highest natural frequencies lie at 0.02-0.18 of their 20 kHz output rate (tests/test_engine.py)."""


@dataclass(frozen=True)
class CoordinateFrequency:
    """sqrt(K_ii / M_ii) / 2 pi of one coordinate, its damping C_ii, and the scenario key of its mass."""

    name: str
    frequency_hz: float
    key: str
    mass: float  # kg m^2 (rotation) or kg (translation)
    stiffness: float  # N m / rad or N / m
    damping: float = 0.0  # N m s / rad or N s / m
    damping_source: str = ""  # what contributes most of C_ii, for the message

    @property
    def damping_rate_hz(self) -> float:
        """C_ii / (2 M_ii) / 2 pi: the coordinate's decay rate when overdamped, Hz."""
        return self.damping / (2.0 * self.mass) / (2 * math.pi)

    @property
    def rate_hz(self) -> float:
        """max(natural frequency, damping rate), Hz: the coordinate's own largest |root| / 2 pi is at
        least this."""
        return max(self.frequency_hz, self.damping_rate_hz)


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
                scenario.stages[0].mesh.damping_Ns_per_m,
                "design.mesh.damping_Ns_per_m",
            )
        ]
    if scenario.has_planetary:
        return _compound_frequencies(scenario)
    layout = torsional_layout(scenario)
    keys = _inertia_keys(scenario)
    n = len(layout.inertias)
    stiffness = [0.0] * n
    damping: list[dict[str, float]] = [{} for _ in range(n)]  # C_ii by contributing key
    lateral: dict[tuple[int, int], float] = {}
    lateral_damping: dict[tuple[int, int], dict[str, float]] = {}

    def add(to: dict[str, float], key: str, c: float) -> None:
        to[key] = to.get(key, 0.0) + c

    for s, sh in enumerate(layout.shafts):
        stiffness[sh.i] += sh.stiffness_Nm_per_rad
        stiffness[sh.j] += sh.stiffness_Nm_per_rad
        for i in (sh.i, sh.j):
            add(damping[i], f"design.shafts.{s + 1}.damping_Nms_per_rad", sh.damping_Nms_per_rad)
    for s, m in enumerate(layout.meshes):
        k = mean_stiffness_N_per_m(m.parameters)
        c = scenario.stages[s].mesh.damping_Ns_per_m
        mesh_key = stage_key(s, "mesh") + ".damping_Ns_per_m"
        stiffness[m.pinion] += k * m.r_pinion_m**2
        stiffness[m.wheel] += k * m.r_wheel_m**2
        add(damping[m.pinion], mesh_key, c * m.r_pinion_m**2)
        add(damping[m.wheel], mesh_key, c * m.r_wheel_m**2)
        for body in (m.pinion, m.wheel):
            support = layout.inertias[body].lateral
            for d in support.free_directions if support else ():
                lateral[body, d] = lateral.get((body, d), 0.0) + k * m.line_of_action[d] ** 2
                add(lateral_damping.setdefault((body, d), {}), mesh_key, c * m.line_of_action[d] ** 2)
    if layout.motor_at is not None:
        mo = scenario.design.motor
        slope = viscous_equivalent_Nms(mo.breakdown_torque_Nm, mo.breakdown_slip, mo.synchronous_speed_rad_s)
        add(
            damping[layout.motor_at],
            "the motor's slip characteristic, slope 2 M_b / (s_b w_s) of design.motor.breakdown_torque_Nm, "
            "breakdown_slip and synchronous_speed_rad_s",
            slope,
        )

    def coordinate(name: str, key: str, mass: float, k: float, c_by_key: dict[str, float]):
        c = sum(c_by_key.values())
        source = max(c_by_key, key=c_by_key.get) if c > 0 else ""
        return CoordinateFrequency(name, math.sqrt(k / mass) / (2 * math.pi), key, mass, k, c, source)

    out = [
        coordinate(body.name, keys[body.name], body.inertia_kg_m2, stiffness[i], damping[i])
        for i, body in enumerate(layout.inertias)
    ]
    for (i, d), k in lateral.items():
        body = layout.inertias[i]
        name = f"{body.name}_{'xy'[d]}"
        out.append(coordinate(name, keys[name], body.lateral.mass_kg, k, lateral_damping[i, d]))
    return out


def _compound_frequencies(scenario: Scenario) -> list[CoordinateFrequency]:
    """The coordinates of a drive with planetary stages: shafts and parallel meshes as for trains, a
    planetary stage's K_ii and C_ii from its force law at the nominal assembly (finite differences of
    :func:`gearbody.physics.planetary_mesh.stage_forces` plus the supports)."""
    import numpy as np

    from ..physics.planetary_mesh import stage_forces
    from .compound import compound_layout, stage_stiffness_matrix

    layout = compound_layout(scenario)
    n = len(layout.dof_names)
    K, C = np.zeros(n), np.zeros(n)
    mass, keys = np.zeros(n), [""] * n
    sources: list[str] = ["" for _ in range(n)]
    mass[0], keys[0] = scenario.design.motor.inertia_kg_m2, "design.motor.inertia_kg_m2"
    mass[-1], keys[-1] = scenario.design.machine.inertia_kg_m2, "design.machine.inertia_kg_m2"
    mo = scenario.design.motor
    C[0] = viscous_equivalent_Nms(mo.breakdown_torque_Nm, mo.breakdown_slip, mo.synchronous_speed_rad_s)
    sources[0] = "the motor's slip characteristic (design.motor)"
    for s, sh in enumerate(layout.shafts):
        for i in (sh.i, sh.j):
            K[i] += sh.stiffness_Nm_per_rad
            C[i] += sh.damping_Nms_per_rad
            sources[i] = sources[i] or f"design.shafts.{s + 1}.damping_Nms_per_rad"
    for m in layout.meshes:
        st = scenario.stages[m.stage]
        k, c = mean_stiffness_N_per_m(m.parameters), st.mesh.damping_Ns_per_m
        for i, gear in ((m.pinion, st.pinion), (m.wheel, st.wheel)):
            K[i] += k * gear.base_radius_m**2
            C[i] += c * gear.base_radius_m**2
            mass[i], keys[i] = (
                gear.inertia_kg_m2,
                stage_key(m.stage, "pinion" if gear is st.pinion else "wheel"),
            )
            keys[i] += ".inertia_kg_m2"
            sources[i] = sources[i] or stage_key(m.stage, "mesh") + ".damping_Ns_per_m"
    for link, modal in zip(layout.planetary, compound_layout(scenario, modal=True).planetary, strict=True):
        K_stage = np.diag(stage_stiffness_matrix(modal))
        ref, G = link.reference(), link.geometry_rows()
        Ps, Pr = link.layout.mesh_arrays()
        members = (*link.layout.members, *([link.layout.planet] * (len(link.names) - 3)))
        for j in range(link.size):
            i, h = link.first + j, 1e-6
            e = np.zeros(link.size)
            e[j] = h
            K[i] += K_stage[j]
            C[i] -= (stage_forces(ref, e, G, Ps, Pr)[j] - stage_forces(ref, -e, G, Ps, Pr)[j]) / (2 * h)
            member = members[j // 3]
            name = member.name if j < 9 else "planet"
            translation = j % 3 < 2
            keys[i] = stage_key(link.stage, name) + (".mass_kg" if translation else ".inertia_kg_m2")
            mass[i] = member.mass_kg if translation else member.inertia_kg_m2
            if j < 9:
                K[i] += (
                    member.bearing_stiffness_N_per_m
                    if translation
                    else member.torsion_stiffness_Nm_per_rad or 0.0
                )
            sources[i] = sources[i] or stage_key(link.stage, "sun_mesh / ring_mesh") + ".damping_Ns_per_m"
    return [
        CoordinateFrequency(
            layout.dof_names[i],
            math.sqrt(max(K[i], 0.0) / mass[i]) / (2 * math.pi),
            keys[i],
            float(mass[i]),
            float(K[i]),
            float(C[i]),
            sources[i],
        )
        for i in range(n)
    ]


def check_resolved_modes(scenario: Scenario) -> None:
    """Refuse a scenario with a coordinate whose rate (natural frequency or damping rate) lies above
    MODE_RATE_FACTOR times max(solver.output_rate_hz, 1 / solver.max_step_s), naming its mass key and,
    for a damping rate, the damping that causes it (ScenarioError, exit 2)."""
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
            f"against its stiffness ({worst.stiffness:.3g} {k_unit}, from the model's shafts and meshes) "
            f"this gives a natural frequency of at least {worst.frequency_hz:.3g} Hz"
        )
        remedy = "raise the inertia or mass"
    raise ScenarioError(
        f"{worst.key} = {worst.mass:g} {unit}: {cause}, more than {MODE_RATE_FACTOR:g} x the highest rate "
        f"the run resolves, max(solver.output_rate_hz, 1 / solver.max_step_s) = {resolved_hz:.3g} Hz "
        f"(limit {limit_hz:.3g} Hz){rest_text}. An explicit solver needs ~{steps:.2g} steps to stay stable "
        f"there and the output cannot show it: {remedy}, or to resolve it raise solver.output_rate_hz or "
        "lower solver.max_step_s"
    )
