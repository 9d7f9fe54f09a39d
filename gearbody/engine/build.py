"""The Exudyn system of a :class:`~gearbody.assembly.system.SystemLayout`, every drive's one builder: each
body is an Exudyn node and object (a rotation or translation body ``Node1D`` with ``ObjectRotationalMass1D``
or ``ObjectMass1D``; a planar body ``NodeRigidBody2D`` + ``ObjectRigidBody2D``, coordinates x, y,
rotation), then each item in the layout's order: springs ``ObjectConnectorCoordinateSpringDamper``,
constraints ``CoordinateConstraint`` to the ground (Exudyn's explicit solvers eliminate them; a modal
layout lists them as fixed coordinates instead), constant matrices, and at the first force item the
layout's force items as user-function ``ObjectGenericODE2`` items, the laws of the drive in one
(:mod:`gearbody.engine.force_items`; compiled or Python, :mod:`gearbody.engine.compiled_path`).
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

from ..assembly.system import Constraint, MatrixItem, Spring, SystemLayout
from .compiled_path import CompiledItem, resolve_force_path
from .force_items import force_functions
from .user_functions import StallWatchdog

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

    forces_added = False
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
        elif not forces_added:  # the first force item: every force item, as few Exudyn items as can be
            forces_added = True
            for bodies, function in force_functions(layout, built.watchdog, compiled):
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


def _add_sensors(built: BuiltSystem) -> None:
    kinds = {"q": OVT.Coordinates, "v": OVT.Coordinates_t, "a": OVT.Coordinates_tt}
    for key, ovt in kinds.items():
        built.sensors[key] = [
            built.mbs.AddSensor(
                SensorNode(nodeNumber=n, outputVariableType=ovt, storeInternal=True, writeToFile=False)
            )
            for n in built.nodes
        ]
