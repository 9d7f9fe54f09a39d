"""The system of a drive with planetary stages (:func:`gearbody.assembly.compound.compound_layout`): the
motor, parallel gears and machine are rotation bodies, every planetary member a planar body (coordinates
displacements from the nominal assembly); the central members' supports are springs to the ground, the
fixed member's torsional support one more; shafts are springs, or constant matrices where a planetary
member turns clockwise (``s = -1``); the motor, the load, every parallel mesh and every planetary stage
(the compiled :func:`gearbody.physics.planetary_mesh.stage_forces`: each planet's meshes and bearing, then
the stage's bearing laws) are the drive's one force item.
"""

from __future__ import annotations

import numpy as np

from ..physics.compiled import compiled
from ..physics.mesh import I_R1, I_R2, mean_stiffness_N_per_m
from ..physics.planetary_mesh import stage_forces
from .compound import (
    ChainShaft,
    CompoundLayout,
    PlanetaryLink,
    bearing_law_forces,
    has_bearing_laws,
    stage_stiffness_matrix,
)
from .system import Body, DriveItem, MatrixItem, PairMesh, SliceTerm, Spring, SystemLayout

__all__ = ["compound_system"]


def compound_system(
    layout: CompoundLayout, *, modal: bool = False, bearing_states: dict[int, np.ndarray] | None = None
) -> SystemLayout:
    """The system of a compound layout. ``modal``: the linearised system for natural frequencies, motor
    and load left out, parallel meshes constant springs at their mean stiffness (the layout's planetary
    meshes already are, ``compound_layout(..., modal=True)``); bearing laws linearised at
    ``bearing_states[stage]`` (the stage's displacements; default nominal)."""
    bodies, planar = [], {}
    for link in layout.planetary:
        members = (*link.layout.members, *([link.layout.planet] * (len(link.names) - 3)))
        for m, member in enumerate(members):
            planar[link.first + 3 * m] = member
    rotation = dict(zip(layout.rotation_bodies, layout.inertias, strict=True))
    body_at: dict[int, int] = {}  # first coordinate -> body index
    i = 0
    while i < len(layout.dof_names):
        body_at[i] = len(bodies)
        if i in planar:
            bodies.append(Body("planar", inertia_kg_m2=planar[i].inertia_kg_m2, mass_kg=planar[i].mass_kg))
            i += 3
        else:
            bodies.append(Body("rotation", inertia_kg_m2=rotation[i]))
            i += 1
    system = SystemLayout(tuple(layout.dof_names), tuple(bodies))
    items: list = []
    for link in layout.planetary:
        for m, member in enumerate(link.layout.members):
            o = link.first + 3 * m
            for d in (0, 1) if member.bearing_law is None else ():  # a law: in the drive's force item
                items.append(
                    Spring(None, o + d, member.bearing_stiffness_N_per_m, member.bearing_damping_Ns_per_m)
                )
            if member.torsion_stiffness_Nm_per_rad is not None:
                items.append(
                    Spring(
                        None, o + 2, member.torsion_stiffness_Nm_per_rad, member.torsion_damping_Nms_per_rad
                    )
                )
    for sh in layout.shafts:
        if sh.sign_i == sh.sign_j == 1:
            items.append(Spring(sh.i, sh.j, sh.stiffness_Nm_per_rad, sh.damping_Nms_per_rad))
        else:
            items.append(_signed_shaft(system, sh))
    if modal:
        for m in layout.meshes:
            g = np.array([m.parameters[I_R1], -m.parameters[I_R2]])
            pair = (system.body_of(m.pinion)[0], system.body_of(m.wheel)[0])
            items.append(MatrixItem(pair, mean_stiffness_N_per_m(m.parameters) * np.outer(g, g)))
        for link in layout.planetary:
            stage_bodies = tuple(
                dict.fromkeys(system.body_of(c)[0] for c in range(link.first, link.first + link.size))
            )
            K = stage_stiffness_matrix(link, bearing_state=(bearing_states or {}).get(link.stage))
            items.append(MatrixItem(stage_bodies, K))
    else:
        meshes = tuple(PairMesh(m.pinion, m.wheel, m.parameters) for m in layout.meshes)
        terms = [SliceTerm(link.first, link.size, _stage_forces(link)) for link in layout.planetary]
        terms += [
            SliceTerm(link.first, link.size, _law_forces(link))
            for link in layout.planetary
            if has_bearing_laws(link)
        ]
        items.append(DriveItem(layout.motor_at, layout.load_at, layout.drive, meshes, tuple(terms)))
    return SystemLayout(system.dof_names, system.bodies, tuple(items), modal)


def _stage_forces(link: PlanetaryLink):
    """factory() -> the stage's meshes and planet bearings on its coordinates (displacements)."""

    def factory():
        ref, G = link.reference(), link.geometry_rows()
        Ps, Pr = link.layout.mesh_arrays()  # shared laws, or one row per planet (faulted planet teeth)
        forces = compiled(stage_forces, ref, ref, G, Ps, Pr)  # for this stage's array shapes

        def stage(q, q_t):
            return forces(q + ref, q_t, G, Ps, Pr)

        return stage

    return factory


def _law_forces(link: PlanetaryLink):
    """factory() -> the stage's Python bearing laws (docs/planetary.md, "Bearing laws")."""

    def factory():
        def laws(q, q_t):
            return bearing_law_forces(link, q, q_t)

        return laws

    return factory


def _signed_shaft(system: SystemLayout, sh: ChainShaft) -> MatrixItem:
    """A shaft ``k (s_i q_i - s_j q_j)`` as constant stiffness and damping matrices on the two bodies."""
    (bi, li), (bj, lj) = system.body_of(sh.i), system.body_of(sh.j)
    pair = tuple(dict.fromkeys((bi, bj)))
    sizes = [system.bodies[b].size for b in pair]
    g = np.zeros(sum(sizes))
    g[li] = sh.sign_i
    g[sizes[0] + lj] = -sh.sign_j
    return MatrixItem(pair, sh.stiffness_Nm_per_rad * np.outer(g, g), sh.damping_Nms_per_rad * np.outer(g, g))
