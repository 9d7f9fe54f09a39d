"""The system of a drive with planetary stages (:func:`gearbody.assembly.compound.compound_layout`): the
motor and machine are rotation bodies and each stage lists its own (parallel gears rotation bodies, every
planetary member a planar body, coordinates displacements from the nominal assembly); then every stage's
supports (a planetary stage's central members' bearings and the fixed member's torsional support);
shafts are springs, or constant matrices where a planetary member turns clockwise (``s = -1``); the
motor, the load, every stage's meshes and force terms (a planetary stage: the compiled
:func:`gearbody.physics.planetary_mesh.stage_forces`, then its bearing laws) are the drive's one force
item.
"""

from __future__ import annotations

import numpy as np

from .compound import (
    ChainShaft,
    CompoundLayout,
)
from .system import Body, DriveItem, MatrixItem, Spring, SystemLayout

__all__ = ["compound_system"]


def compound_system(
    layout: CompoundLayout, *, modal: bool = False, bearing_states: dict[int, np.ndarray] | None = None
) -> SystemLayout:
    """The system of a compound layout. ``modal``: the linearised system for natural frequencies, motor
    and load left out, every stage's modal items (parallel meshes constant springs at their mean
    stiffness; the layout's planetary meshes already are, ``compound_layout(..., modal=True)``), bearing
    laws linearised at ``bearing_states[stage]`` (the stage's displacements; default nominal)."""
    bodies = [Body("rotation", inertia_kg_m2=layout.motor_inertia_kg_m2)]
    for part in layout.parts:
        bodies += part.bodies()
    bodies.append(Body("rotation", inertia_kg_m2=layout.machine_inertia_kg_m2))
    system = SystemLayout(tuple(layout.dof_names), tuple(bodies))
    items: list = [item for part in layout.parts for item in part.supports()]
    for sh in layout.shafts:
        if sh.sign_i == sh.sign_j == 1:
            items.append(Spring(sh.i, sh.j, sh.stiffness_Nm_per_rad, sh.damping_Nms_per_rad))
        else:
            items.append(_signed_shaft(system, sh))
    if modal:
        for part in layout.parts:
            items += part.modal_items(system, bearing_states or {})
    else:
        meshes = tuple(m for part in layout.parts for m in part.drive_meshes())
        terms = tuple(term for part in layout.parts for term in part.drive_terms())
        items.append(DriveItem(layout.motor_at, layout.load_at, layout.drive, meshes, terms))
    return SystemLayout(system.dof_names, system.bodies, tuple(items), modal)


def _signed_shaft(system: SystemLayout, sh: ChainShaft) -> MatrixItem:
    """A shaft ``k (s_i q_i - s_j q_j)`` as constant stiffness and damping matrices on the two bodies."""
    (bi, li), (bj, lj) = system.body_of(sh.i), system.body_of(sh.j)
    pair = tuple(dict.fromkeys((bi, bj)))
    sizes = [system.bodies[b].size for b in pair]
    g = np.zeros(sum(sizes))
    g[li] = sh.sign_i
    g[sizes[0] + lj] = -sh.sign_j
    return MatrixItem(pair, sh.stiffness_Nm_per_rad * np.outer(g, g), sh.damping_Nms_per_rad * np.outer(g, g))
