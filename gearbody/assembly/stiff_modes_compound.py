"""The coordinate rates of a drive with planetary stages (or stage kinds registered from outside), for
the check of :mod:`gearbody.assembly.stiff_modes`: shafts and parallel meshes as for trains, a
planetary stage's K_ii and C_ii from its force law at the nominal assembly (finite differences of
:func:`gearbody.physics.planetary_mesh.stage_forces`), its members' supports, and the bearing laws at
the static state under the rated load (as the modes linearise them)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np

from ..model import Scenario
from ..model.params import stage_key
from ..physics import mean_stiffness_N_per_m, viscous_equivalent_Nms
from .coordinate_rates import CoordinateFrequency, add, largest

__all__ = ["compound_frequencies"]


@dataclass
class _Diagonal:
    """The diagonals of a drive's matrices: K_ii and C_ii by contributing key, M_ii, and the scenario
    key of each coordinate's mass."""

    K: list[dict[str, float]]
    C: list[dict[str, float]]
    mass: np.ndarray
    keys: list[str]

    @classmethod
    def empty(cls, n: int) -> _Diagonal:
        return cls([{} for _ in range(n)], [{} for _ in range(n)], np.zeros(n), [""] * n)


def compound_frequencies(scenario: Scenario) -> list[CoordinateFrequency]:
    """The coordinates of a drive with planetary stages: shafts and parallel meshes as for trains, a
    planetary stage's K_ii and C_ii from its force law at the nominal assembly (finite differences of
    :func:`gearbody.physics.planetary_mesh.stage_forces`: meshes and planet bearings, told apart by the
    same differences without the planet bearings), plus the supports of sun, ring and carrier and the
    bearing laws at the static state under the rated load (as the modes linearise them)."""
    from .compound import compound_layout

    layout = compound_layout(scenario)
    n = len(layout.dof_names)
    d = _Diagonal.empty(n)
    _add_chain(scenario, layout, d)
    for link, modal in zip(layout.planetary, compound_layout(scenario, modal=True).planetary, strict=True):
        _add_planetary_stage(scenario, link, modal, d)
    known = {id(p) for p in (*layout.meshes, *layout.planetary)}
    for part in layout.parts:
        if id(part) not in known:  # a stage kind registered from outside: its bodies and force terms
            _add_part_diagonal(part, d)
    out = []
    for i in range(n):
        k, c = sum(d.K[i].values()), sum(d.C[i].values())
        out.append(
            CoordinateFrequency(
                layout.dof_names[i],
                math.sqrt(max(k, 0.0) / d.mass[i]) / (2 * math.pi),
                d.keys[i],
                float(d.mass[i]),
                float(k),
                float(c),
                largest(d.C[i]),
                largest(d.K[i]),
            )
        )
    return out


def _add_chain(scenario: Scenario, layout, d: _Diagonal) -> None:
    """The chain around the stages: motor and machine (with the motor's slip characteristic), the
    shafts, and the parallel stages' meshes with their gears' inertias."""
    K, C, mass, keys = d.K, d.C, d.mass, d.keys
    mass[0], keys[0] = scenario.design.motor.inertia_kg_m2, "design.motor.inertia_kg_m2"
    mass[-1], keys[-1] = scenario.design.machine.inertia_kg_m2, "design.machine.inertia_kg_m2"
    mo = scenario.design.motor
    slope = viscous_equivalent_Nms(mo.breakdown_torque_Nm, mo.breakdown_slip, mo.synchronous_speed_rad_s)
    add(C[0], "the motor's slip characteristic (design.motor)", slope)
    for s, sh in enumerate(layout.shafts):
        for i in (sh.i, sh.j):
            add(K[i], f"design.shafts.{s + 1}.stiffness_Nm_per_rad", sh.stiffness_Nm_per_rad)
            add(C[i], f"design.shafts.{s + 1}.damping_Nms_per_rad", sh.damping_Nms_per_rad)
    for m in layout.meshes:
        st = scenario.stages[m.stage]
        k, c = mean_stiffness_N_per_m(m.parameters), st.mesh.damping_Ns_per_m
        for i, gear in ((m.pinion, st.pinion), (m.wheel, st.wheel)):
            add(K[i], f"the mean mesh stiffness of {stage_key(m.stage, 'mesh')}", k * gear.base_radius_m**2)
            add(C[i], stage_key(m.stage, "mesh") + ".damping_Ns_per_m", c * gear.base_radius_m**2)
            mass[i], keys[i] = (
                gear.inertia_kg_m2,
                stage_key(m.stage, "pinion" if gear is st.pinion else "wheel") + ".inertia_kg_m2",
            )


def _add_planetary_stage(scenario: Scenario, link, modal, d: _Diagonal) -> None:
    """A planetary stage's coordinates (``link`` as run, ``modal`` with its meshes at their mean
    stiffness): meshes and planet bearings from central differences of the stage's force law, told apart
    by the same differences without the planet bearings; its bearing laws at the rated static state;
    the supports of sun, ring and carrier; its members' masses and inertias."""
    from ..physics.planetary_mesh import G_BEARING_C, G_BEARING_K
    from .compound import bearing_law_forces

    K, C = d.K, d.C
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
    state = _rated_state(scenario, link, modal)
    members = (*link.layout.members, *([planet] * (len(link.names) - 3)))
    whole_k, whole_c = partial(_stage, G_k, Pk), partial(_stage, G_c, Pc)
    bare_k, bare_c = partial(_stage, meshes_k, Pk), partial(_stage, meshes_c, Pc)
    for j in range(link.size):
        i = link.first + j
        h = 1e-7 if j % 3 < 2 else 1e-7 / link.layout.carrier_radius_m
        k_meshes, c_meshes = _slope(bare_k, ref, j, h), _slope(bare_c, ref, j, h, rate=True)
        add(K[i], mesh_k, k_meshes)
        add(C[i], mesh_c, c_meshes)
        add(K[i], planet_k, _slope(whole_k, ref, j, h) - k_meshes)
        add(C[i], planet_c, _slope(whole_c, ref, j, h, rate=True) - c_meshes)
        member = members[j // 3]
        name = member.name if j < 9 else "planet"
        translation = j % 3 < 2
        if state is not None:
            law_key = _law_key(where, name, member.bearing_law is not None, planet.bearing_law is not None)
            add(K[i], law_key, _slope(partial(bearing_law_forces, modal), state, j, h))
            add(C[i], law_key, _slope(partial(bearing_law_forces, link), state, j, h, rate=True))
        d.keys[i] = stage_key(link.stage, name) + (".mass_kg" if translation else ".inertia_kg_m2")
        d.mass[i] = member.mass_kg if translation else member.inertia_kg_m2
        if j < 9:
            _add_support(d, i, where + name, member, translation)


def _rated_state(scenario: Scenario, link, modal) -> np.ndarray | None:
    """Where a stage's bearing laws carry the rated load (a clearance closed), as the modes linearise
    them: its static displacements under the rated torques (zeros when none is found: the run will say
    why); None for a stage without bearing laws."""
    from .compound import has_bearing_laws, stage_static_displacements

    if not has_bearing_laws(link):
        return None
    st, F = scenario.stages[link.stage], scenario.stage_rated_force_N(link.stage)
    try:
        return stage_static_displacements(
            modal, link.input_sense * F * st.input_arm_m, -link.output_sense * F * st.output_arm_m
        )
    except (ValueError, ArithmeticError, np.linalg.LinAlgError):  # the run will say why
        return np.zeros(link.size)


def _add_support(d: _Diagonal, i: int, key: str, member, translation: bool) -> None:
    """Coordinate ``i`` of a central member (sun, ring, carrier; ``key`` its scenario key): its linear
    bearing (a translation) or its torsional support (the rotation of the fixed member)."""
    if translation:
        add(d.K[i], f"{key}.bearing_stiffness_N_per_m", member.bearing_stiffness_N_per_m)
        add(d.C[i], f"{key}.bearing_damping_Ns_per_m", member.bearing_damping_Ns_per_m)
    else:
        add(d.K[i], f"{key}.torsion_stiffness_Nm_per_rad", member.torsion_stiffness_Nm_per_rad or 0.0)
        add(d.C[i], f"{key}.torsion_damping_Nms_per_rad", member.torsion_damping_Nms_per_rad)


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


def _add_part_diagonal(part, d: _Diagonal, step: float = 1e-7) -> None:
    """K_ii and C_ii of a stage part's drive terms by central differences at rest, and its bodies'
    masses (diagonal entries of the mass matrix)."""
    where = stage_key(part.stage)
    c = part.first
    for body in part.bodies():
        values = {"rotation": [body.inertia_kg_m2], "translation": [body.mass_kg]}.get(
            body.kind, [body.mass_kg, body.mass_kg, body.inertia_kg_m2]
        )
        for value in values:
            d.mass[c], d.keys[c] = value, where + "(its bodies)"
            c += 1
    for term in part.drive_terms():
        forces = term.factory()
        zero = np.zeros(term.size)
        for j in range(term.size):
            e = np.zeros(term.size)
            e[j] = step
            dk = -(forces(e, zero)[j] - forces(-e, zero)[j]) / (2 * step)
            dc = -(forces(zero, e)[j] - forces(zero, -e)[j]) / (2 * step)
            add(d.K[term.first + j], where + "(its force terms)", dk)
            add(d.C[term.first + j], where + "(its force terms)", dc)
