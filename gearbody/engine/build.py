"""Exudyn system from a layout: inertias are Exudyn nodes and bodies, shafts are Exudyn spring-damper
connectors, and each gear mesh is a user-function connector (``ObjectGenericODE2`` on the two gear
nodes) calling the compiled mesh law of :mod:`gearbody.physics.mesh`.

A gear on lateral bearings is a planar rigid body (``NodeRigidBody2D`` + ``ObjectRigidBody2D``,
coordinates x, y, rotation; its rotation coordinate is the angle in its own driven direction, so no
sign changes are needed between torsional and lateral gears). A direction held fixed ("y" gears) is a
``CoordinateConstraint`` to ground, which Exudyn's explicit solvers eliminate. Linear bearings are
``ObjectConnectorCoordinateSpringDamper`` per free direction; any other bearing law is an
``ObjectGenericODE2`` on the gear node calling the law's ``force_N``.

The motor and the load are ``ObjectGenericODE2`` items on one node each, so their torques can depend
on speed and time. For modes, the mesh becomes a constant stiffness matrix at mean mesh stiffness
and the motor and load are left out (free ends).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import exudyn as exu
import numpy as np
from exudyn.itemInterface import (
    CoordinateConstraint,
    MarkerNodeCoordinate,
    Node1D,
    NodePointGround,
    NodeRigidBody2D,
    ObjectConnectorCoordinateSpringDamper,
    ObjectGenericODE2,
    ObjectMass1D,
    ObjectRigidBody2D,
    ObjectRotationalMass1D,
    SensorNode,
    VObjectGenericODE2,
)

from ..assembly import (
    Inertia,
    TorsionalLayout,
    mesh_parameters_from_scenario,
    pack_drive_parameters,
    reduced_mass_kg,
)
from ..model import Scenario
from ..physics import load_fraction_at, load_torque_at, motor_torque_at, synchronous_angle_at
from ..physics.bearings import LinearBearing
from ..physics.lateral import tangent_stiffness_N_per_m
from ..physics.mesh import contact_force, single_mesh_drive_forces, torsional_mesh_forces
from .user_functions import (
    StallWatchdog,
    bearing_user_function,
    compiled,
    lateral_mesh_user_function,
    load_user_function,
    mesh_user_function,
    motor_user_function,
)

OVT = exu.OutputVariableType
HIDDEN = VObjectGenericODE2(show=False)


@dataclass
class BuiltSystem:
    """An assembled Exudyn system and the indices gearbody needs to read it back."""

    system_container: exu.SystemContainer
    mbs: exu.MainSystem
    dof_names: list[str]  # one per ODE2 coordinate, in Exudyn's order ("pinion_x", "pinion_y", "pinion")
    nodes: list[int]
    sensors: dict[str, list[int]] = field(default_factory=dict)  # kind -> one sensor per node
    user_functions: list = field(default_factory=list)  # keep references alive
    fixed_coordinates: list[int] = field(default_factory=list)  # held at 0 (CoordinateConstraint)
    watchdog: StallWatchdog = field(default_factory=lambda: StallWatchdog())  # records a stall


def _add_nodes(mbs, masses: list[tuple[str, float]], q0, v0, *, rotational: bool) -> list[int]:
    nodes = []
    for k, (_, value) in enumerate(masses):
        n = mbs.AddNode(
            Node1D(
                referenceCoordinates=[0.0],
                initialCoordinates=[float(q0[k])],
                initialVelocities=[float(v0[k])],
            )
        )
        if rotational:
            mbs.AddObject(ObjectRotationalMass1D(nodeNumber=n, inertia=value))
        else:
            mbs.AddObject(ObjectMass1D(nodeNumber=n, mass=value))
        nodes.append(n)
    return nodes


def _add_sensors(built: BuiltSystem) -> None:
    kinds = {"q": OVT.Coordinates, "v": OVT.Coordinates_t, "a": OVT.Coordinates_tt}
    for key, ovt in kinds.items():
        built.sensors[key] = [
            built.mbs.AddSensor(
                SensorNode(nodeNumber=n, outputVariableType=ovt, storeInternal=True, writeToFile=False)
            )
            for n in built.nodes
        ]


def _node_coordinate_names(b: Inertia) -> list[str]:
    return [f"{b.name}_x", f"{b.name}_y", b.name] if b.lateral is not None else [b.name]


def build_torsional(
    layout: TorsionalLayout,
    q0=None,
    v0=None,
    *,
    lateral_u0: dict[str, np.ndarray] | None = None,
    modal_mesh_stiffness_N_per_m=None,
    sensors: bool = True,
) -> BuiltSystem:
    """Exudyn system of a layout (torsional, or with gears on lateral bearings).

    ``q0``/``v0`` are the rotations and speeds (one per inertia); ``lateral_u0`` the initial centre
    displacements of lateral gears (lateral velocities start at 0). With
    ``modal_mesh_stiffness_N_per_m`` (one value for all meshes, or one per mesh) the meshes are
    constant line-of-action springs of that stiffness (no backlash, errors or friction), nonlinear
    bearings are replaced by their tangent stiffness at ``lateral_u0``, directions held fixed are
    listed in ``fixed_coordinates`` instead of constrained, and the motor and load are left out: the
    linearised system for natural frequencies.
    """
    n = len(layout.inertias)
    q0 = np.zeros(n) if q0 is None else q0
    v0 = np.zeros(n) if v0 is None else v0
    lateral_u0 = lateral_u0 or {}
    modal = modal_mesh_stiffness_N_per_m is not None
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    nodes, names = [], []
    for k, b in enumerate(layout.inertias):
        if b.lateral is None:
            nd = mbs.AddNode(
                Node1D(
                    referenceCoordinates=[0.0],
                    initialCoordinates=[float(q0[k])],
                    initialVelocities=[float(v0[k])],
                )
            )
            mbs.AddObject(ObjectRotationalMass1D(nodeNumber=nd, inertia=b.inertia_kg_m2))
        else:
            u0 = lateral_u0.get(b.name, np.zeros(2))
            nd = mbs.AddNode(
                NodeRigidBody2D(
                    referenceCoordinates=[0.0, 0.0, 0.0],
                    initialCoordinates=[float(u0[0]), float(u0[1]), float(q0[k])],
                    initialVelocities=[0.0, 0.0, float(v0[k])],
                )
            )
            mbs.AddObject(ObjectRigidBody2D(nodeNumber=nd, mass=b.lateral.mass_kg, inertia=b.inertia_kg_m2))
        nodes.append(nd)
        names += _node_coordinate_names(b)
    built = BuiltSystem(SC, mbs, names, nodes)
    rot = [
        mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nd, coordinate=0 if b.lateral is None else 2))
        for nd, b in zip(nodes, layout.inertias, strict=True)
    ]
    for sh in layout.shafts:
        mbs.AddObject(
            ObjectConnectorCoordinateSpringDamper(
                markerNumbers=[rot[sh.i], rot[sh.j]],
                stiffness=sh.stiffness_Nm_per_rad,
                damping=sh.damping_Nms_per_rad,
            )
        )
    if layout.is_lateral:
        _add_bearings(built, layout, lateral_u0, modal)
    if modal:
        k_modal = np.broadcast_to(np.asarray(modal_mesh_stiffness_N_per_m, float), (len(layout.meshes),))
    if not modal and not layout.is_lateral and layout.motor_at is not None and layout.load_at is not None:
        _add_drive_and_meshes(built, layout)
        if sensors:
            _add_sensors(built)
        mbs.Assemble()
        return built
    for index, m in enumerate(layout.meshes):
        pair = [nodes[m.pinion], nodes[m.wheel]]
        bp, bw = layout.inertias[m.pinion], layout.inertias[m.wheel]
        size = len(_node_coordinate_names(bp)) + len(_node_coordinate_names(bw))
        idx = _mesh_coordinate_index(bp, bw)
        if modal:
            g = np.zeros(size)
            g[idx[0]], g[idx[3]] = m.r_pinion_m, -m.r_wheel_m
            if idx[1] >= 0:
                g[idx[1]], g[idx[2]] = m.line_of_action
            if idx[4] >= 0:
                g[idx[4]], g[idx[5]] = -m.line_of_action[0], -m.line_of_action[1]
            mbs.AddObject(
                ObjectGenericODE2(
                    nodeNumbers=pair,
                    massMatrix=np.zeros((size, size)),
                    stiffnessMatrix=k_modal[index] * np.outer(g, g),
                    visualization=HIDDEN,
                )
            )
            continue
        if size == 2:
            built.user_functions.append(mesh_user_function(m.parameters))
        else:
            built.user_functions.append(lateral_mesh_user_function(m, bp, bw, idx))
        mbs.AddObject(
            ObjectGenericODE2(
                nodeNumbers=pair,
                massMatrix=np.zeros((size, size)),
                forceUserFunction=built.user_functions[-1],
                visualization=HIDDEN,
            )
        )
    if not modal:
        D = layout.drive
        if layout.motor_at is not None:
            built.user_functions.append(motor_user_function(D, built.watchdog))
            mbs.AddObject(
                ObjectGenericODE2(
                    nodeNumbers=[nodes[layout.motor_at]],
                    massMatrix=np.zeros((1, 1)),
                    forceUserFunction=built.user_functions[-1],
                    visualization=HIDDEN,
                )
            )
        if layout.load_at is not None:
            built.user_functions.append(load_user_function(D))
            mbs.AddObject(
                ObjectGenericODE2(
                    nodeNumbers=[nodes[layout.load_at]],
                    massMatrix=np.zeros((1, 1)),
                    forceUserFunction=built.user_functions[-1],
                    visualization=HIDDEN,
                )
            )
    if sensors:
        _add_sensors(built)
    mbs.Assemble()
    return built


def _mesh_coordinate_index(bp: Inertia, bw: Inertia) -> np.ndarray:
    """Positions in the mesh connector's q of [pinion rot, x, y, wheel rot, x, y] (-1: none)."""
    idx = []
    offset = 0
    for b in (bp, bw):
        if b.lateral is None:
            idx += [offset, -1, -1]
            offset += 1
        else:
            idx += [offset + 2, offset, offset + 1]
            offset += 3
    return np.array(idx, dtype=np.int64)


def _add_bearings(built: BuiltSystem, layout: TorsionalLayout, lateral_u0, modal: bool) -> None:
    mbs = built.mbs
    ground = mbs.AddNode(NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0]))
    ground_markers = [mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=d)) for d in (0, 1)]
    offset = 0
    for nd, b in zip(built.nodes, layout.inertias, strict=True):
        size = 1 if b.lateral is None else 3
        if b.lateral is None:
            offset += size
            continue
        sup, law = b.lateral, b.lateral.bearing
        markers = [mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nd, coordinate=d)) for d in (0, 1)]
        for d in (0, 1):
            if d not in sup.free_directions:
                if modal:
                    built.fixed_coordinates.append(offset + d)
                else:
                    mbs.AddObject(CoordinateConstraint(markerNumbers=[ground_markers[d], markers[d]]))
        if isinstance(law, LinearBearing):
            k = (law.stiffness_x_N_per_m, law.stiffness_y_N_per_m)
            c = (law.damping_x_Ns_per_m, law.damping_y_Ns_per_m)
            for d in sup.free_directions:
                mbs.AddObject(
                    ObjectConnectorCoordinateSpringDamper(
                        markerNumbers=[ground_markers[d], markers[d]], stiffness=k[d], damping=c[d]
                    )
                )
        elif modal:
            K = np.zeros((3, 3))
            K[:2, :2] = tangent_stiffness_N_per_m(law, lateral_u0.get(b.name, np.zeros(2)))
            mbs.AddObject(
                ObjectGenericODE2(
                    nodeNumbers=[nd], massMatrix=np.zeros((3, 3)), stiffnessMatrix=K, visualization=HIDDEN
                )
            )
        else:
            built.user_functions.append(bearing_user_function(law, sup.free_directions))
            mbs.AddObject(
                ObjectGenericODE2(
                    nodeNumbers=[nd],
                    massMatrix=np.zeros((3, 3)),
                    forceUserFunction=built.user_functions[-1],
                    visualization=HIDDEN,
                )
            )
        offset += size


def build_muller(scenario: Scenario, q0, v0, *, sensors: bool = True) -> BuiltSystem:
    """Muller's one-mass model (Fig. 1): reduced mass on the line of action, kinematic pitch line."""
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    nodes = _add_nodes(mbs, [("deflection", reduced_mass_kg(scenario))], q0, v0, rotational=False)
    built = BuiltSystem(SC, mbs, ["deflection"], nodes)
    P = mesh_parameters_from_scenario(scenario, friction=False)
    D = pack_drive_parameters(scenario)
    F_rated = scenario.rated_mesh_force_N
    watchdog = built.watchdog
    contact = compiled(contact_force, 0.0, 0.0, 0.0, P)
    angle = compiled(synchronous_angle_at, 0.0, D)
    load = compiled(load_fraction_at, 0.0, D)

    tick, check = watchdog.ticker()

    def muller_force(mbs, t, itemNumber, q, q_t):
        if tick():
            check(t, q_t[0])
        F = contact(angle(t, D), q[0], q_t[0], P)[0]
        return [F_rated * load(t, D) - F]

    built.user_functions.append(muller_force)
    mbs.AddObject(
        ObjectGenericODE2(
            nodeNumbers=nodes,
            massMatrix=np.zeros((1, 1)),
            forceUserFunction=muller_force,
            visualization=HIDDEN,
        )
    )
    if sensors:
        _add_sensors(built)
    mbs.Assemble()
    return built


def _add_drive_and_meshes(built: BuiltSystem, layout: TorsionalLayout) -> None:
    """Motor, load and all meshes of a torsional layout as ONE user-function item: one Python call per
    right-hand-side evaluation instead of one per item (Exudyn's per-call overhead dominates the cost)."""
    D = layout.drive
    watchdog = built.watchdog
    if (
        len(layout.meshes) == 1
        and len({layout.motor_at, layout.meshes[0].pinion, layout.meshes[0].wheel, layout.load_at}) == 4
    ):
        m = layout.meshes[0]
        order = [layout.motor_at, m.pinion, m.wheel, layout.load_at]
        P = m.parameters
        forces = compiled(single_mesh_drive_forces, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, P, D)

        tick, check = watchdog.ticker()

        def drive_and_mesh(mbs, t, itemNumber, q, q_t):
            if tick():
                check(t, q_t[0])
            return forces(t, q_t[0], q[1], q[2], q_t[1], q_t[2], P, D)

        function = drive_and_mesh
    else:
        order = list(range(len(layout.inertias)))
        n, im, il = len(order), layout.motor_at, layout.load_at
        meshes = [(m.pinion, m.wheel, m.parameters) for m in layout.meshes]
        motor = compiled(motor_torque_at, 0.0, 0.0, D)
        load = compiled(load_torque_at, 0.0, D)
        mesh_forces = compiled(torsional_mesh_forces, 0.0, 0.0, 0.0, 0.0, meshes[0][2])

        tick, check = watchdog.ticker()

        def drive_and_meshes(mbs, t, itemNumber, q, q_t):
            if tick():
                check(t, q_t[im])
            f = [0.0] * n
            f[im] = motor(t, q_t[im], D)
            f[il] -= load(t, D)
            for ip, iw, P in meshes:
                a, b = mesh_forces(q[ip], q[iw], q_t[ip], q_t[iw], P)
                f[ip] += a
                f[iw] += b
            return f

        function = drive_and_meshes
    built.user_functions.append(function)
    built.mbs.AddObject(
        ObjectGenericODE2(
            nodeNumbers=[built.nodes[k] for k in order],
            massMatrix=np.zeros((len(order), len(order))),
            forceUserFunction=function,
            visualization=HIDDEN,
        )
    )
