"""Exudyn system from a layout: inertias are Exudyn nodes and bodies, shafts are Exudyn spring-damper
connectors, and each gear mesh is a user-function connector (``ObjectGenericODE2`` on the two gear
nodes) calling the compiled mesh law of :mod:`gearbody.physics.mesh`.

The motor and the load are ``ObjectGenericODE2`` items on one node each, so their torques can depend
on speed and time. For modes, the mesh becomes a constant stiffness matrix at mean mesh stiffness
and the motor and load are left out (free ends).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import exudyn as exu
import numpy as np
from exudyn.itemInterface import (
    MarkerNodeCoordinate,
    Node1D,
    ObjectConnectorCoordinateSpringDamper,
    ObjectGenericODE2,
    ObjectMass1D,
    ObjectRotationalMass1D,
    SensorNode,
    VObjectGenericODE2,
)

from ..model import Scenario
from ..physics import load_fraction_at, load_torque_at, motor_torque_at, synchronous_angle_at
from ..physics.mesh import mesh_contact, mesh_parameters_from_scenario, torsional_mesh_forces
from ..physics.motor import pack_drive_parameters
from .layout import TorsionalLayout, reduced_mass_kg

OVT = exu.OutputVariableType
HIDDEN = VObjectGenericODE2(show=False)


@dataclass
class BuiltSystem:
    """An assembled Exudyn system and the indices gearbody needs to read it back."""

    system_container: exu.SystemContainer
    mbs: exu.MainSystem
    dof_names: list[str]
    nodes: list[int]
    sensors: dict[str, list[int]] = field(default_factory=dict)  # kind -> one sensor per node
    user_functions: list = field(default_factory=list)  # keep references alive


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


def build_torsional(
    layout: TorsionalLayout, q0=None, v0=None, *, modal_mesh_stiffness_N_per_m=None, sensors: bool = True
) -> BuiltSystem:
    """Exudyn system of a torsional layout.

    With ``modal_mesh_stiffness_N_per_m`` (one value for all meshes, or one per mesh) the meshes are
    constant line-of-action springs of that
    stiffness (no backlash, errors or friction), and the motor and load are left out: the linearised
    system for natural frequencies.
    """
    n = len(layout.inertias)
    q0 = np.zeros(n) if q0 is None else q0
    v0 = np.zeros(n) if v0 is None else v0
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    nodes = _add_nodes(mbs, [(b.name, b.inertia_kg_m2) for b in layout.inertias], q0, v0, rotational=True)
    built = BuiltSystem(SC, mbs, layout.names, nodes)
    markers = [mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nd, coordinate=0)) for nd in nodes]
    for s in layout.shafts:
        mbs.AddObject(
            ObjectConnectorCoordinateSpringDamper(
                markerNumbers=[markers[s.i], markers[s.j]],
                stiffness=s.stiffness_Nm_per_rad,
                damping=s.damping_Nms_per_rad,
            )
        )
    modal = modal_mesh_stiffness_N_per_m is not None
    if modal:
        k_modal = np.broadcast_to(np.asarray(modal_mesh_stiffness_N_per_m, float), (len(layout.meshes),))
    for index, m in enumerate(layout.meshes):
        pair = [nodes[m.pinion], nodes[m.wheel]]
        if modal:
            r1, r2 = m.r_pinion_m, m.r_wheel_m
            K = k_modal[index] * np.array([[r1 * r1, -r1 * r2], [-r1 * r2, r2 * r2]])
            mbs.AddObject(
                ObjectGenericODE2(
                    nodeNumbers=pair, massMatrix=np.zeros((2, 2)), stiffnessMatrix=K, visualization=HIDDEN
                )
            )
            continue
        built.user_functions.append(_mesh_user_function(m.parameters))
        mbs.AddObject(
            ObjectGenericODE2(
                nodeNumbers=pair,
                massMatrix=np.zeros((2, 2)),
                forceUserFunction=built.user_functions[-1],
                visualization=HIDDEN,
            )
        )
    if not modal:
        D = layout.drive
        if layout.motor_at is not None:
            built.user_functions.append(_motor_user_function(D))
            mbs.AddObject(
                ObjectGenericODE2(
                    nodeNumbers=[nodes[layout.motor_at]],
                    massMatrix=np.zeros((1, 1)),
                    forceUserFunction=built.user_functions[-1],
                    visualization=HIDDEN,
                )
            )
        if layout.load_at is not None:
            built.user_functions.append(_load_user_function(D))
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


def build_muller(scenario: Scenario, q0, v0, *, sensors: bool = True) -> BuiltSystem:
    """Muller's one-mass model (Fig. 1): reduced mass on the line of action, kinematic pitch line."""
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    nodes = _add_nodes(mbs, [("deflection", reduced_mass_kg(scenario))], q0, v0, rotational=False)
    built = BuiltSystem(SC, mbs, ["deflection"], nodes)
    P = mesh_parameters_from_scenario(scenario, friction=False)
    D = pack_drive_parameters(scenario)
    F_rated = scenario.rated_mesh_force_N

    def muller_force(mbs, t, itemNumber, q, q_t):
        F = mesh_contact(synchronous_angle_at(t, D), q[0], q_t[0], P)[0]
        return [F_rated * load_fraction_at(t, D) - F]

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


def _mesh_user_function(P: np.ndarray):
    def mesh_force(mbs, t, itemNumber, q, q_t):
        return torsional_mesh_forces(q[0], q[1], q_t[0], q_t[1], P)

    return mesh_force


def _motor_user_function(D: np.ndarray):
    def motor_torque(mbs, t, itemNumber, q, q_t):
        return [motor_torque_at(t, q_t[0], D)]

    return motor_torque


def _load_user_function(D: np.ndarray):
    def load_torque(mbs, t, itemNumber, q, q_t):
        return [-load_torque_at(t, D)]

    return load_torque
