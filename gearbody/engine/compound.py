"""Exudyn system of a drive with planetary stages (:mod:`gearbody.assembly.compound`): the motor,
parallel gears and machine are rotational masses (``Node1D``), every planetary member a planar rigid
body (``NodeRigidBody2D`` + ``ObjectRigidBody2D``, coordinates displacements from the nominal assembly);
the central members' supports are coordinate spring-dampers to the ground, the fixed member's torsional
support one more; shafts are coordinate spring-dampers, or a constant-matrix ``ObjectGenericODE2`` where a
planetary member turns clockwise (``s = -1``); the motor, the load, every parallel mesh and every
planetary stage (the compiled :func:`gearbody.physics.planetary_mesh.stage_forces`: each planet's meshes
and bearing) are one ``ObjectGenericODE2`` on all nodes, one Python call per right-hand side.
"""

from __future__ import annotations

import exudyn as exu
import numpy as np
from exudyn.itemInterface import (
    MarkerNodeCoordinate,
    Node1D,
    NodePointGround,
    NodeRigidBody2D,
    ObjectConnectorCoordinateSpringDamper,
    ObjectGenericODE2,
    ObjectRigidBody2D,
    ObjectRotationalMass1D,
)

from ..assembly.compound import CompoundLayout, bearing_law_forces, has_bearing_laws, stage_stiffness_matrix
from ..physics import load_torque_at, motor_torque_at
from ..physics.mesh import I_R1, I_R2, mean_stiffness_N_per_m, torsional_mesh_forces
from ..physics.planetary_mesh import stage_forces
from .build import HIDDEN, BuiltSystem, _add_sensors
from .user_functions import compiled

__all__ = ["build_compound", "drive_user_function"]


def drive_user_function(layout: CompoundLayout, watchdog):
    """The force function of the whole drive on all its coordinates: motor torque (and the run's
    watchdog), load torque, every parallel mesh and every planetary stage (the compiled laws), in one
    Python call per right-hand side (Exudyn's per-item call overhead dominates: 84 us per step with one
    item each for the motor, the load and the stage of the planetary scene)."""
    D = layout.drive
    n = len(layout.dof_names)
    im, il = layout.motor_at, layout.load_at
    motor = compiled(motor_torque_at, 0.0, 0.0, D)
    load = compiled(load_torque_at, 0.0, D)
    meshes = [(m.pinion, m.wheel, m.parameters) for m in layout.meshes]
    mesh_forces = compiled(torsional_mesh_forces, 0.0, 0.0, 0.0, 0.0, meshes[0][2]) if meshes else None
    stages, laws = [], []
    for link in layout.planetary:
        ref, G = link.reference(), link.geometry_rows()
        Ps, Pr = link.layout.mesh_arrays()  # shared laws, or one row per planet (faulted planet teeth)
        forces = compiled(stage_forces, ref, ref, G, Ps, Pr)  # for this stage's array shapes
        stages.append((link.first, link.first + link.size, ref, G, Ps, Pr, forces))
        if has_bearing_laws(link):  # Python laws (docs/planetary.md, "Bearing laws")
            laws.append((link.first, link.first + link.size, link))
    tick, check = watchdog.ticker()

    def drive_items(mbs, t, itemNumber, q, q_t):
        if tick():
            check(t, q_t[im])
        q, q_t = np.asarray(q), np.asarray(q_t)
        f = np.zeros(n)
        f[im] = motor(t, q_t[im], D)
        f[il] -= load(t, D)
        for ip, iw, P in meshes:
            a, b = mesh_forces(q[ip], q[iw], q_t[ip], q_t[iw], P)
            f[ip] += a
            f[iw] += b
        for a, b, ref, G, Ps, Pr, forces in stages:
            f[a:b] += forces(q[a:b] + ref, q_t[a:b], G, Ps, Pr)
        for a, b, link in laws:
            f[a:b] += bearing_law_forces(link, q[a:b], q_t[a:b])
        return f

    return drive_items


def build_compound(
    layout: CompoundLayout,
    q0: np.ndarray,
    v0: np.ndarray,
    *,
    sensors: bool = True,
    modal: bool = False,
    bearing_states: dict[int, np.ndarray] | None = None,
) -> BuiltSystem:
    """Exudyn system of a compound layout at initial coordinates ``q0`` and velocities ``v0`` (one per
    coordinate of ``layout.dof_names``). ``modal``: the linearised system for natural frequencies, motor
    and load left out, parallel meshes constant springs at their mean stiffness (the layout's planetary
    meshes already are, ``compound_layout(..., modal=True)``), linearised by Exudyn at ``q0``; bearing
    laws at ``bearing_states[stage]`` (the stage's displacements; default nominal)."""
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    names = list(layout.dof_names)
    node_of: dict[int, tuple[int, int]] = {}  # coordinate index -> (node, coordinate in node)
    nodes: list[int] = []
    planar_first = {link.first + 3 * m for link in layout.planetary for m in range(len(link.names))}
    masses = {}
    for link in layout.planetary:
        members = (*link.layout.members, *([link.layout.planet] * (len(link.names) - 3)))
        for m, member in enumerate(members):
            masses[link.first + 3 * m] = member
    rotation = dict(zip(layout.rotation_bodies, layout.inertias, strict=True))
    i = 0
    while i < len(names):
        if i in planar_first:
            nd = mbs.AddNode(
                NodeRigidBody2D(
                    referenceCoordinates=[0.0, 0.0, 0.0],
                    initialCoordinates=[float(x) for x in q0[i : i + 3]],
                    initialVelocities=[float(x) for x in v0[i : i + 3]],
                )
            )
            member = masses[i]
            mbs.AddObject(ObjectRigidBody2D(nodeNumber=nd, mass=member.mass_kg, inertia=member.inertia_kg_m2))
            for d in range(3):
                node_of[i + d] = (nd, d)
            i += 3
        else:
            nd = mbs.AddNode(
                Node1D(
                    referenceCoordinates=[0.0],
                    initialCoordinates=[float(q0[i])],
                    initialVelocities=[float(v0[i])],
                )
            )
            mbs.AddObject(ObjectRotationalMass1D(nodeNumber=nd, inertia=rotation[i]))
            node_of[i] = (nd, 0)
            i += 1
        nodes.append(nd)
    built = BuiltSystem(SC, mbs, names, nodes)
    marker = {}

    def coordinate_marker(index: int) -> int:
        if index not in marker:
            nd, d = node_of[index]
            marker[index] = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nd, coordinate=d))
        return marker[index]

    ground = mbs.AddNode(NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0]))
    ground_marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))

    def spring(a: int, b: int | None, k: float, c: float) -> None:
        """k, c between coordinate a and b (None: the ground)."""
        pair = [ground_marker if b is None else coordinate_marker(b), coordinate_marker(a)]
        mbs.AddObject(ObjectConnectorCoordinateSpringDamper(markerNumbers=pair, stiffness=k, damping=c))

    for link in layout.planetary:
        for m, member in enumerate(link.layout.members):
            o = link.first + 3 * m
            for d in (0, 1) if member.bearing_law is None else ():  # a law: in the drive's force item
                spring(o + d, None, member.bearing_stiffness_N_per_m, member.bearing_damping_Ns_per_m)
            if member.torsion_stiffness_Nm_per_rad is not None:
                spring(o + 2, None, member.torsion_stiffness_Nm_per_rad, member.torsion_damping_Nms_per_rad)
    for sh in layout.shafts:
        if sh.sign_i == sh.sign_j == 1:
            spring(sh.j, sh.i, sh.stiffness_Nm_per_rad, sh.damping_Nms_per_rad)
            continue
        _signed_shaft(built, node_of, sh)
    if modal:
        items = []
        for m in layout.meshes:
            r1, r2 = m.parameters[I_R1], m.parameters[I_R2]
            g = np.array([r1, -r2])
            mbs.AddObject(
                ObjectGenericODE2(
                    nodeNumbers=[node_of[m.pinion][0], node_of[m.wheel][0]],
                    massMatrix=np.zeros((2, 2)),
                    stiffnessMatrix=mean_stiffness_N_per_m(m.parameters) * np.outer(g, g),
                    visualization=HIDDEN,
                )
            )
    else:  # one item on every node: one Python call per right-hand side
        items = [(list(range(len(names))), drive_user_function(layout, built.watchdog))]
    for link in layout.planetary:
        coordinates = list(range(link.first, link.first + link.size))
        if modal:
            mbs.AddObject(
                ObjectGenericODE2(
                    nodeNumbers=list(dict.fromkeys(node_of[c][0] for c in coordinates)),
                    massMatrix=np.zeros((link.size, link.size)),
                    stiffnessMatrix=stage_stiffness_matrix(
                        link, bearing_state=(bearing_states or {}).get(link.stage)
                    ),
                    visualization=HIDDEN,
                )
            )

    for coordinates, function in items:
        item_nodes = list(dict.fromkeys(node_of[c][0] for c in coordinates))
        size = len(coordinates)
        built.user_functions.append(function)
        mbs.AddObject(
            ObjectGenericODE2(
                nodeNumbers=item_nodes,
                massMatrix=np.zeros((size, size)),
                forceUserFunction=function,
                visualization=HIDDEN,
            )
        )
    if sensors:
        _add_sensors(built)
    mbs.Assemble()
    return built


def _signed_shaft(built: BuiltSystem, node_of, sh) -> None:
    """A shaft ``k (s_i q_i - s_j q_j)`` as constant stiffness and damping matrices on the two nodes."""
    pair = []
    for index in (sh.i, sh.j):
        nd, _ = node_of[index]
        if nd not in pair:
            pair.append(nd)
    sizes = [len(built.mbs.GetNode(nd)["referenceCoordinates"]) for nd in pair]
    size = sum(sizes)
    g = np.zeros(size)
    g[node_of[sh.i][1]] = sh.sign_i
    g[sizes[0] + node_of[sh.j][1]] = -sh.sign_j
    built.mbs.AddObject(
        ObjectGenericODE2(
            nodeNumbers=pair,
            massMatrix=np.zeros((size, size)),
            stiffnessMatrix=sh.stiffness_Nm_per_rad * np.outer(g, g),
            dampingMatrix=sh.damping_Nms_per_rad * np.outer(g, g),
            visualization=HIDDEN,
        )
    )
