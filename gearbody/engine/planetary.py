"""Exudyn system of a planetary stage (issue 19, first step: the stage alone, with constant external
torques): sun, ring, carrier and every planet are planar rigid bodies (``NodeRigidBody2D`` +
``ObjectRigidBody2D``: x, y, theta in the fixed frame, the planets' centres moving on the carrier's circle);
the central members' supports are coordinate spring-dampers to the ground; every planet's two meshes and
its bearing on the carrier are one ``ObjectGenericODE2`` on all the stage's nodes calling the compiled
:func:`gearbody.physics.planetary_mesh.stage_forces` (one Python call per right-hand side). Exudyn's
planar rigid-body equations carry the planets' centripetal and Coriolis effects; nothing is linearised.

Node coordinates are displacements from the nominal assembly (reference coordinates: the planets'
centres on the carrier circle); the user functions add the reference to get absolute coordinates.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import exudyn as exu
import numpy as np
from exudyn.itemInterface import (
    LoadCoordinate,
    MarkerNodeCoordinate,
    NodePointGround,
    NodeRigidBody2D,
    ObjectConnectorCoordinateSpringDamper,
    ObjectGenericODE2,
    ObjectRigidBody2D,
    SensorNode,
    VObjectGenericODE2,
)

from ..assembly.planetary_layout import CENTRAL, PlanetaryLayout, rigid_speeds_rad_s
from ..physics.planetary_mesh import planet_forces, stage_forces
from .user_functions import compiled

__all__ = ["PlanetarySystem", "build_planetary", "planetary_mesh_forces", "solve_planetary"]

OVT = exu.OutputVariableType
HIDDEN = VObjectGenericODE2(show=False)


@dataclass
class PlanetarySystem:
    """An assembled planetary stage: Exudyn objects, node numbers by member, reference coordinates."""

    system_container: exu.SystemContainer
    mbs: exu.MainSystem
    layout: PlanetaryLayout
    nodes: dict[str, int]  # "sun", "ring", "carrier", "planet_1", ...
    reference: dict[str, np.ndarray]  # nominal [x, y, theta] of each member
    sensors: dict[str, dict[str, int]] = field(default_factory=dict)  # member -> {"q", "v"}
    user_functions: list = field(default_factory=list)


def _planet_names(layout: PlanetaryLayout) -> list[str]:
    return [f"planet_{n + 1}" for n in range(len(layout.planet_angles_rad))]


def build_planetary(
    layout: PlanetaryLayout,
    *,
    torques_Nm: dict[str, float] | None = None,
    sun_speed_rad_s: float = 0.0,
    carrier_speed_rad_s: float = 0.0,
) -> PlanetarySystem:
    """The stage at its nominal assembly, moving rigidly at the sun's and the carrier's speed (the ring
    and planets by rigid rolling), with constant ``torques_Nm`` on sun, ring or carrier."""
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    speeds = rigid_speeds_rad_s(layout, sun_speed_rad_s, carrier_speed_rad_s)
    ground = mbs.AddNode(NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0]))
    ground_marker = [mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=d)) for d in (0, 1)]
    nodes, reference = {}, {}

    def add_member(name: str, member, centre, spin_rad_s: float, centre_velocity) -> int:
        ref = np.array([centre[0], centre[1], 0.0])
        node = mbs.AddNode(
            NodeRigidBody2D(
                referenceCoordinates=ref.tolist(),
                initialCoordinates=[0.0, 0.0, 0.0],
                initialVelocities=[float(centre_velocity[0]), float(centre_velocity[1]), float(spin_rad_s)],
            )
        )
        mbs.AddObject(ObjectRigidBody2D(nodeNumber=node, mass=member.mass_kg, inertia=member.inertia_kg_m2))
        nodes[name], reference[name] = node, ref
        return node

    for name, member in zip(CENTRAL, layout.members, strict=True):
        node = add_member(name, member, (0.0, 0.0), speeds[name], (0.0, 0.0))
        markers = [mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=d)) for d in (0, 1, 2)]
        for d in (0, 1):
            mbs.AddObject(
                ObjectConnectorCoordinateSpringDamper(
                    markerNumbers=[ground_marker[d], markers[d]],
                    stiffness=member.bearing_stiffness_N_per_m,
                    damping=member.bearing_damping_Ns_per_m,
                )
            )
        if member.torsion_stiffness_Nm_per_rad is not None:
            mbs.AddObject(
                ObjectConnectorCoordinateSpringDamper(
                    markerNumbers=[ground_marker[0], markers[2]],  # ground coordinate 0 is fixed at 0
                    stiffness=member.torsion_stiffness_Nm_per_rad,
                    damping=member.torsion_damping_Nms_per_rad,
                )
            )
        torque = (torques_Nm or {}).get(name, 0.0)
        if torque:
            mbs.AddLoad(LoadCoordinate(markerNumber=markers[2], load=float(torque)))
    unknown = set(torques_Nm or {}) - set(CENTRAL)
    if unknown:
        raise ValueError(f"torques_Nm: {sorted(unknown)} are not sun, ring or carrier")
    wc = speeds["carrier"]
    for n, name in enumerate(_planet_names(layout)):
        x, y = layout.planet_centre_m(n)
        add_member(name, layout.planet, (x, y), speeds["planet"], (-wc * y, wc * x))
    names = [*CENTRAL, *_planet_names(layout)]
    ref = np.concatenate([reference[k] for k in names])
    G = np.array([layout.geometry(n) for n in range(len(layout.planet_angles_rad))])
    P_s, P_r = layout.sun_mesh, layout.ring_mesh
    forces = compiled(stage_forces, ref, ref, G, P_s, P_r)

    def stage_items(mbs, t, itemNumber, q, q_t):
        return forces(np.asarray(q) + ref, np.asarray(q_t), G, P_s, P_r)

    size = 3 * len(names)
    mbs.AddObject(
        ObjectGenericODE2(
            nodeNumbers=[nodes[k] for k in names],
            massMatrix=np.zeros((size, size)),
            forceUserFunction=stage_items,
            visualization=HIDDEN,
        )
    )
    system = PlanetarySystem(SC, mbs, layout, nodes, reference)
    system.user_functions = [stage_items]
    for name, node in nodes.items():
        system.sensors[name] = {
            kind: mbs.AddSensor(SensorNode(nodeNumber=node, outputVariableType=ovt, storeInternal=True))
            for kind, ovt in (("q", OVT.Coordinates), ("v", OVT.Coordinates_t))
        }
    mbs.Assemble()
    return system


def solve_planetary(
    system: PlanetarySystem, t_end_s: float, *, absolute_tolerance: float = 1e-10, max_step_s: float = 1e-4
) -> dict[str, np.ndarray]:
    """Integrate with Exudyn's DOPRI5; returns ``time_s`` and, per member, absolute ``<member>_q`` and
    ``<member>_v`` (n x 3: x, y, theta) at every accepted step."""
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.endTime = t_end_s
    ti.numberOfSteps = max(1, int(np.ceil(t_end_s / max_step_s)))
    ti.automaticStepSize = True
    ti.absoluteTolerance = absolute_tolerance
    ti.relativeTolerance = 1e-12
    ti.minimumStepSize = 1e-14
    ti.initialStepSize = 1e-7
    ti.verboseMode = 0
    s.solution.file.write = False
    s.solution.sensors.writePeriod = 0.0
    exu.SolveDynamic(system.mbs, s, solverType=exu.DynamicSolverType.DOPRI5)
    out: dict[str, np.ndarray] = {}
    for name, sensors in system.sensors.items():
        q = system.mbs.GetSensorStoredData(sensors["q"])
        v = system.mbs.GetSensorStoredData(sensors["v"])
        out["time_s"] = q[:, 0]
        out[f"{name}_q"] = q[:, 1:] + system.reference[name]
        out[f"{name}_v"] = v[:, 1:]
    return out


def planetary_mesh_forces(system: PlanetarySystem, states: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Sun- and ring-mesh normal forces of every planet (N) on recorded states, by the law integrated."""
    layout = system.layout
    out = {}
    central_q = [states[f"{k}_q"] for k in CENTRAL]
    central_v = [states[f"{k}_v"] for k in CENTRAL]
    for n, name in enumerate(_planet_names(layout)):
        G = layout.geometry(n)
        q = np.hstack([*central_q, states[f"{name}_q"]])
        v = np.hstack([*central_v, states[f"{name}_v"]])
        f_s, f_r = np.empty(len(q)), np.empty(len(q))
        for i in range(len(q)):
            _, f_s[i], f_r[i] = planet_forces(q[i], v[i], G, layout.sun_mesh, layout.ring_mesh)
        out[f"{name}_sun_mesh_force_N"], out[f"{name}_ring_mesh_force_N"] = f_s, f_r
    return out
