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
stay stable there, and the output cannot show it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np

from ..model import Scenario, ScenarioError
from ..model.params import stage_key
from ..physics import mean_stiffness_N_per_m, viscous_equivalent_Nms
from ..physics.bearings import tangent_stiffness_damping
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
    stiffness_source: str = ""  # what contributes most of K_ii, for the message

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


def _add(to: dict[str, float], key: str, value: float) -> None:
    to[key] = to.get(key, 0.0) + value


def _largest(by_key: dict[str, float]) -> str:
    """The key contributing most (empty when nothing contributes)."""
    return max(by_key, key=by_key.get) if sum(by_key.values()) > 0 else ""


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
                "the mean mesh stiffness of design.mesh",
            )
        ]
    if scenario.has_planetary:
        return _compound_frequencies(scenario)
    layout = torsional_layout(scenario)
    keys = _inertia_keys(scenario)
    n = len(layout.inertias)
    stiffness: list[dict[str, float]] = [{} for _ in range(n)]  # K_ii by contributing key
    damping: list[dict[str, float]] = [{} for _ in range(n)]  # C_ii by contributing key
    lateral: dict[tuple[int, int], dict[str, float]] = {}
    lateral_damping: dict[tuple[int, int], dict[str, float]] = {}

    for s, sh in enumerate(layout.shafts):
        for i in (sh.i, sh.j):
            _add(stiffness[i], f"design.shafts.{s + 1}.stiffness_Nm_per_rad", sh.stiffness_Nm_per_rad)
            _add(damping[i], f"design.shafts.{s + 1}.damping_Nms_per_rad", sh.damping_Nms_per_rad)
    for s, m in enumerate(layout.meshes):
        k = mean_stiffness_N_per_m(m.parameters)
        c = scenario.stages[s].mesh.damping_Ns_per_m
        mesh_key = stage_key(s, "mesh") + ".damping_Ns_per_m"
        mesh_k_key = f"the mean mesh stiffness of {stage_key(s, 'mesh')}"
        for body, r in ((m.pinion, m.r_pinion_m), (m.wheel, m.r_wheel_m)):
            _add(stiffness[body], mesh_k_key, k * r**2)
            _add(damping[body], mesh_key, c * r**2)
            support = layout.inertias[body].lateral
            for d in support.free_directions if support else ():
                _add(lateral.setdefault((body, d), {}), mesh_k_key, k * m.line_of_action[d] ** 2)
                _add(lateral_damping.setdefault((body, d), {}), mesh_key, c * m.line_of_action[d] ** 2)
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
            _add(lateral.setdefault((i, d), {}), k_key, max(float(k_b[d]), 0.0))
            _add(lateral_damping.setdefault((i, d), {}), c_key, max(float(c_b[d]), 0.0))
    if layout.motor_at is not None:
        mo = scenario.design.motor
        slope = viscous_equivalent_Nms(mo.breakdown_torque_Nm, mo.breakdown_slip, mo.synchronous_speed_rad_s)
        _add(
            damping[layout.motor_at],
            "the motor's slip characteristic, slope 2 M_b / (s_b w_s) of design.motor.breakdown_torque_Nm, "
            "breakdown_slip and synchronous_speed_rad_s",
            slope,
        )

    def coordinate(name: str, key: str, mass: float, k_by_key: dict[str, float], c_by_key: dict[str, float]):
        k, c = sum(k_by_key.values()), sum(c_by_key.values())
        return CoordinateFrequency(
            name, math.sqrt(k / mass) / (2 * math.pi), key, mass, k, c, _largest(c_by_key), _largest(k_by_key)
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


def _stage(G: np.ndarray, laws: tuple[np.ndarray, np.ndarray], q: np.ndarray, q_t: np.ndarray) -> np.ndarray:
    """A planetary stage's mesh and planet-bearing forces with geometry rows ``G`` (:func:`stage_forces
    <gearbody.physics.planetary_mesh.stage_forces>`)."""
    from ..physics.planetary_mesh import stage_forces

    return stage_forces(q, q_t, G, *laws)


def _slope(forces: Callable, at: np.ndarray, j: int, h: float, rate: bool = False) -> float:
    """-dF_j / dq_j (``rate``: -dF_j / dv_j) of ``forces(q, v)`` at ``at`` at rest, central differences of
    step ``h``."""
    e, zero = np.zeros(at.size), np.zeros(at.size)
    e[j] = h
    if rate:
        return float(-(forces(at, e)[j] - forces(at, -e)[j]) / (2 * h))
    return float(-(forces(at + e, zero)[j] - forces(at - e, zero)[j]) / (2 * h))


def _law_key(where: str, name: str, own_law: bool, planet_law: bool) -> str:
    """The bearing laws acting on a coordinate of member ``name``: its own, and on the carrier the
    planets' (their reaction at the pins)."""
    laws = [f"{name}.bearing.parameters"] if own_law and name != "planet" else []
    if planet_law and name in ("carrier", "planet"):
        laws.append("planet.bearing.parameters")
    return " and ".join(where + law for law in laws)


def _add_part_diagonal(part, K, C, mass, keys, step: float = 1e-7) -> None:
    """K_ii and C_ii of a stage part's drive terms by central differences at rest, and its bodies'
    masses (diagonal entries of the mass matrix)."""
    where = stage_key(part.stage)
    c = part.first
    for body in part.bodies():
        values = {"rotation": [body.inertia_kg_m2], "translation": [body.mass_kg]}.get(
            body.kind, [body.mass_kg, body.mass_kg, body.inertia_kg_m2]
        )
        for value in values:
            mass[c], keys[c] = value, where + "(its bodies)"
            c += 1
    for term in part.drive_terms():
        forces = term.factory()
        zero = np.zeros(term.size)
        for j in range(term.size):
            e = np.zeros(term.size)
            e[j] = step
            dk = -(forces(e, zero)[j] - forces(-e, zero)[j]) / (2 * step)
            dc = -(forces(zero, e)[j] - forces(zero, -e)[j]) / (2 * step)
            _add(K[term.first + j], where + "(its force terms)", dk)
            _add(C[term.first + j], where + "(its force terms)", dc)


def _compound_frequencies(scenario: Scenario) -> list[CoordinateFrequency]:
    """The coordinates of a drive with planetary stages: shafts and parallel meshes as for trains, a
    planetary stage's K_ii and C_ii from its force law at the nominal assembly (finite differences of
    :func:`gearbody.physics.planetary_mesh.stage_forces`: meshes and planet bearings, told apart by the
    same differences without the planet bearings), plus the supports of sun, ring and carrier and the
    bearing laws at the static state under the rated load (as the modes linearise them)."""
    from ..physics.planetary_mesh import G_BEARING_C, G_BEARING_K
    from .compound import bearing_law_forces, compound_layout, has_bearing_laws, stage_static_displacements

    layout = compound_layout(scenario)
    n = len(layout.dof_names)
    K: list[dict[str, float]] = [{} for _ in range(n)]  # K_ii by contributing key
    C: list[dict[str, float]] = [{} for _ in range(n)]  # C_ii by contributing key
    mass, keys = np.zeros(n), [""] * n
    mass[0], keys[0] = scenario.design.motor.inertia_kg_m2, "design.motor.inertia_kg_m2"
    mass[-1], keys[-1] = scenario.design.machine.inertia_kg_m2, "design.machine.inertia_kg_m2"
    mo = scenario.design.motor
    slope = viscous_equivalent_Nms(mo.breakdown_torque_Nm, mo.breakdown_slip, mo.synchronous_speed_rad_s)
    _add(C[0], "the motor's slip characteristic (design.motor)", slope)
    for s, sh in enumerate(layout.shafts):
        for i in (sh.i, sh.j):
            _add(K[i], f"design.shafts.{s + 1}.stiffness_Nm_per_rad", sh.stiffness_Nm_per_rad)
            _add(C[i], f"design.shafts.{s + 1}.damping_Nms_per_rad", sh.damping_Nms_per_rad)
    for m in layout.meshes:
        st = scenario.stages[m.stage]
        k, c = mean_stiffness_N_per_m(m.parameters), st.mesh.damping_Ns_per_m
        for i, gear in ((m.pinion, st.pinion), (m.wheel, st.wheel)):
            _add(K[i], f"the mean mesh stiffness of {stage_key(m.stage, 'mesh')}", k * gear.base_radius_m**2)
            _add(C[i], stage_key(m.stage, "mesh") + ".damping_Ns_per_m", c * gear.base_radius_m**2)
            mass[i], keys[i] = (
                gear.inertia_kg_m2,
                stage_key(m.stage, "pinion" if gear is st.pinion else "wheel") + ".inertia_kg_m2",
            )
    for link, modal in zip(layout.planetary, compound_layout(scenario, modal=True).planetary, strict=True):
        where = stage_key(link.stage)
        mesh_k, mesh_c = (
            where + "sun_mesh / ring_mesh (mean stiffness)",
            where + "sun_mesh / ring_mesh.damping_Ns_per_m",
        )
        planet = link.layout.planet
        planet_k = where + (
            "planet.bearing.parameters" if planet.bearing_law else "planet.bearing_stiffness_N_per_m"
        )
        planet_c = where + (
            "planet.bearing.parameters" if planet.bearing_law else "planet.bearing_damping_Ns_per_m"
        )
        ref = link.reference()
        G_k, G_c = modal.geometry_rows(), link.geometry_rows()
        meshes_k, meshes_c = G_k.copy(), G_c.copy()  # the same stage without its planet bearings
        meshes_k[:, [G_BEARING_K, G_BEARING_C]] = 0.0
        meshes_c[:, [G_BEARING_K, G_BEARING_C]] = 0.0
        Pk, Pc = modal.layout.mesh_arrays(), link.layout.mesh_arrays()
        state = None
        if has_bearing_laws(link):  # where the laws carry the rated load (a clearance closed), as the modes
            st, F = scenario.stages[link.stage], scenario.stage_rated_force_N(link.stage)
            try:
                state = stage_static_displacements(
                    modal, link.input_sense * F * st.input_arm_m, -link.output_sense * F * st.output_arm_m
                )
            except (ValueError, ArithmeticError, np.linalg.LinAlgError):  # the run will say why
                state = np.zeros(link.size)
        members = (*link.layout.members, *([planet] * (len(link.names) - 3)))
        whole_k, whole_c = partial(_stage, G_k, Pk), partial(_stage, G_c, Pc)
        bare_k, bare_c = partial(_stage, meshes_k, Pk), partial(_stage, meshes_c, Pc)
        for j in range(link.size):
            i = link.first + j
            h = 1e-7 if j % 3 < 2 else 1e-7 / link.layout.carrier_radius_m
            k_meshes, c_meshes = _slope(bare_k, ref, j, h), _slope(bare_c, ref, j, h, rate=True)
            _add(K[i], mesh_k, k_meshes)
            _add(C[i], mesh_c, c_meshes)
            _add(K[i], planet_k, _slope(whole_k, ref, j, h) - k_meshes)
            _add(C[i], planet_c, _slope(whole_c, ref, j, h, rate=True) - c_meshes)
            member = members[j // 3]
            name = member.name if j < 9 else "planet"
            translation = j % 3 < 2
            if state is not None:
                law_key = _law_key(
                    where, name, member.bearing_law is not None, planet.bearing_law is not None
                )
                _add(K[i], law_key, _slope(partial(bearing_law_forces, modal), state, j, h))
                _add(C[i], law_key, _slope(partial(bearing_law_forces, link), state, j, h, rate=True))
            keys[i] = stage_key(link.stage, name) + (".mass_kg" if translation else ".inertia_kg_m2")
            mass[i] = member.mass_kg if translation else member.inertia_kg_m2
            if j < 9:
                if translation:
                    _add(K[i], where + f"{name}.bearing_stiffness_N_per_m", member.bearing_stiffness_N_per_m)
                    _add(C[i], where + f"{name}.bearing_damping_Ns_per_m", member.bearing_damping_Ns_per_m)
                else:
                    _add(
                        K[i],
                        where + f"{name}.torsion_stiffness_Nm_per_rad",
                        member.torsion_stiffness_Nm_per_rad or 0.0,
                    )
                    _add(
                        C[i],
                        where + f"{name}.torsion_damping_Nms_per_rad",
                        member.torsion_damping_Nms_per_rad,
                    )
    known = {id(p) for p in (*layout.meshes, *layout.planetary)}
    for part in layout.parts:
        if id(part) not in known:  # a stage kind registered from outside: its bodies and force terms
            _add_part_diagonal(part, K, C, mass, keys)
    out = []
    for i in range(n):
        k, c = sum(K[i].values()), sum(C[i].values())
        out.append(
            CoordinateFrequency(
                layout.dof_names[i],
                math.sqrt(max(k, 0.0) / mass[i]) / (2 * math.pi),
                keys[i],
                float(mass[i]),
                float(k),
                float(c),
                _largest(C[i]),
                _largest(K[i]),
            )
        )
    return out


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
