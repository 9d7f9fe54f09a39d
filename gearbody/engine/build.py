"""The Exudyn system of a :class:`~gearbody.assembly.system.SystemLayout`, every drive's one builder: each
body is an Exudyn node and object (a rotation or translation body ``Node1D`` with ``ObjectRotationalMass1D``
or ``ObjectMass1D``; a planar body ``NodeRigidBody2D`` + ``ObjectRigidBody2D``, coordinates x, y,
rotation), then each item in the layout's order: springs ``ObjectConnectorCoordinateSpringDamper``,
constraints ``CoordinateConstraint`` to the ground (Exudyn's explicit solvers eliminate them; a modal
layout lists them as fixed coordinates instead), constant matrices and user-function force items
``ObjectGenericODE2`` (the force laws are the compiled ones of :mod:`gearbody.physics`; see
:mod:`gearbody.engine.user_functions`).
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

from ..assembly.system import (
    BearingItem,
    Constraint,
    DriveItem,
    ForceItem,
    MatrixItem,
    MeshItem,
    MullerItem,
    Spring,
    SystemLayout,
    TorqueItem,
)
from .compiled_path import CompiledItem, NotCompiled, compiled_item, resolve_force_path, say_once
from .user_functions import (
    StallWatchdog,
    bearing_user_function,
    drive_user_function,
    lateral_mesh_user_function,
    load_user_function,
    mesh_user_function,
    motor_user_function,
    muller_user_function,
)

__all__ = ["BuiltSystem", "build"]

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

    @property
    def force_path(self) -> str:
        """``"compiled"`` (every force item called from C++), ``"python"`` (none), or ``"mixed"``."""
        kinds = {isinstance(f, CompiledItem) for f in self.user_functions}
        return "mixed" if len(kinds) > 1 else ("compiled" if True in kinds else "python")


def build(
    layout: SystemLayout, q0=None, v0=None, *, sensors: bool = True, force_path: str = "auto"
) -> BuiltSystem:
    """The Exudyn system of ``layout`` at coordinates ``q0`` and velocities ``v0`` (one per coordinate of
    ``layout.dof_names``; default 0), assembled. ``sensors``: coordinates, velocities and accelerations of
    every node stored at every step (what :func:`gearbody.engine.collect.collect` reads).
    ``force_path``: how Exudyn calls the force items, ``"compiled"`` (C++ calls the laws' kernels;
    an item without kernels goes through Python, said once), ``"python"``, or ``"auto"`` (compiled
    where it works here; :mod:`gearbody.engine.compiled_path`)."""
    compiled = resolve_force_path(force_path) == "compiled"
    n = len(layout.dof_names)
    q0 = np.zeros(n) if q0 is None else np.asarray(q0, dtype=float)
    v0 = np.zeros(n) if v0 is None else np.asarray(v0, dtype=float)
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    nodes = [
        _add_body(mbs, body, q0[i : i + body.size], v0[i : i + body.size])
        for body, i in zip(layout.bodies, layout.first_coordinates, strict=True)
    ]
    built = BuiltSystem(SC, mbs, list(layout.dof_names), nodes)
    markers: dict[int | None, int] = {}

    def marker(coordinate: int | None) -> int:
        """The coordinate marker of a global coordinate (None: the ground), made on first use."""
        if coordinate not in markers:
            if coordinate is None:
                ground = mbs.AddNode(NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0]))
                markers[None] = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))
            else:
                body, local = layout.body_of(coordinate)
                markers[coordinate] = mbs.AddMarker(
                    MarkerNodeCoordinate(nodeNumber=nodes[body], coordinate=local)
                )
        return markers[coordinate]

    for item in layout.items:
        if isinstance(item, Spring):
            mbs.AddObject(
                ObjectConnectorCoordinateSpringDamper(
                    markerNumbers=[marker(item.i), marker(item.j)],
                    stiffness=item.stiffness,
                    damping=item.damping,
                )
            )
        elif isinstance(item, Constraint):
            if layout.modal:
                built.fixed_coordinates.append(item.j)
            else:
                mbs.AddObject(CoordinateConstraint(markerNumbers=[marker(None), marker(item.j)]))
        elif isinstance(item, MatrixItem):
            size = sum(layout.bodies[b].size for b in item.bodies)
            mbs.AddObject(
                ObjectGenericODE2(
                    nodeNumbers=[nodes[b] for b in item.bodies],
                    massMatrix=np.zeros((size, size)),
                    stiffnessMatrix=item.stiffness,
                    **({} if item.damping is None else {"dampingMatrix": item.damping}),
                    visualization=HIDDEN,
                )
            )
        else:
            bodies, function = _force_function(item, layout, built.watchdog, compiled)
            built.user_functions.append(function)
            size = sum(layout.bodies[b].size for b in bodies)
            mbs.AddObject(
                ObjectGenericODE2(
                    nodeNumbers=[nodes[b] for b in bodies],
                    massMatrix=np.zeros((size, size)),
                    forceUserFunction=function.entry if isinstance(function, CompiledItem) else function,
                    visualization=HIDDEN,
                )
            )
    if sensors:
        _add_sensors(built)
    mbs.Assemble()
    return built


def _add_body(mbs, body, q0: np.ndarray, v0: np.ndarray) -> int:
    if body.kind == "planar":
        nd = mbs.AddNode(
            NodeRigidBody2D(
                referenceCoordinates=[0.0, 0.0, 0.0],
                initialCoordinates=[float(x) for x in q0],
                initialVelocities=[float(x) for x in v0],
            )
        )
        mbs.AddObject(ObjectRigidBody2D(nodeNumber=nd, mass=body.mass_kg, inertia=body.inertia_kg_m2))
        return nd
    nd = mbs.AddNode(
        Node1D(
            referenceCoordinates=[0.0], initialCoordinates=[float(q0[0])], initialVelocities=[float(v0[0])]
        )
    )
    if body.kind == "rotation":
        mbs.AddObject(ObjectRotationalMass1D(nodeNumber=nd, inertia=body.inertia_kg_m2))
    else:
        mbs.AddObject(ObjectMass1D(nodeNumber=nd, mass=body.mass_kg))
    return nd


def _force_function(item, layout: SystemLayout, watchdog: StallWatchdog, compiled: bool = False):
    """(bodies, user function) of a force item: on the compiled path a C++ entry where every term of the
    item has a kernel (the Python function otherwise)."""
    if compiled and not isinstance(item, ForceItem):
        bodies = _item_bodies(item, layout)
        size = sum(layout.bodies[b].size for b in bodies)
        try:
            entry = compiled_item(item, layout, size, _watched(item, watchdog))
        except NotCompiled as why:
            say_once(f"a {type(item).__name__} runs through Python (slower): {why}")
        else:
            return bodies, entry
    if isinstance(item, DriveItem):
        return tuple(range(len(layout.bodies))), drive_user_function(item, len(layout.dof_names), watchdog)
    if isinstance(item, MeshItem):
        if item.geometry is None:
            return item.bodies, mesh_user_function(item.parameters)
        return item.bodies, lateral_mesh_user_function(item.parameters, item.geometry, item.index)
    if isinstance(item, BearingItem):
        return (item.body,), bearing_user_function(item.law, item.free_directions)
    if isinstance(item, TorqueItem):
        if item.role == "motor":
            return (item.body,), motor_user_function(item.drive, watchdog)
        return (item.body,), load_user_function(item.drive)
    if isinstance(item, MullerItem):
        return (item.body,), muller_user_function(item, watchdog)
    if isinstance(item, ForceItem):
        return item.bodies, item.factory(watchdog)
    raise TypeError(f"{type(item).__name__} is not an item of a SystemLayout")


def _item_bodies(item, layout: SystemLayout) -> tuple[int, ...]:
    if isinstance(item, DriveItem):
        return tuple(range(len(layout.bodies)))
    if isinstance(item, (BearingItem, TorqueItem, MullerItem)):
        return (item.body,)
    return item.bodies


def _watched(item, watchdog: StallWatchdog):
    """(check, speed index) of the run's watchdog on the item that carries it (as on the Python path)."""
    if isinstance(item, DriveItem):
        return watchdog.ticker()[1], item.motor_at
    if isinstance(item, MullerItem) or (isinstance(item, TorqueItem) and item.role == "motor"):
        return watchdog.ticker()[1], 0
    return None


def _add_sensors(built: BuiltSystem) -> None:
    kinds = {"q": OVT.Coordinates, "v": OVT.Coordinates_t, "a": OVT.Coordinates_tt}
    for key, ovt in kinds.items():
        built.sensors[key] = [
            built.mbs.AddSensor(
                SensorNode(nodeNumber=n, outputVariableType=ovt, storeInternal=True, writeToFile=False)
            )
            for n in built.nodes
        ]
