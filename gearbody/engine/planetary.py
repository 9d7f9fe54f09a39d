"""Exudyn system of a planetary stage (issue 19, first step: the stage alone, with constant external
torques): sun, ring, carrier and every planet are planar rigid bodies (``NodeRigidBody2D`` +
``ObjectRigidBody2D``: x, y, theta in the fixed frame, the planets' centres moving on the carrier's circle);
the central members' supports are coordinate spring-dampers to the ground; every planet's two meshes and
its bearing on the carrier are one ``ObjectGenericODE2`` on all the stage's nodes calling the compiled
:func:`gearbody.physics.planetary_mesh.stage_forces` (one Python call per right-hand side). Exudyn's
planar rigid-body equations carry the planets' centripetal and Coriolis effects; nothing is linearised.
Built, as every drive, by :func:`gearbody.engine.build.build` from a system layout.

Node coordinates are displacements from the nominal assembly (the planets' centres on the carrier circle,
:attr:`PlanetarySystem.reference`); the user functions add the reference to get absolute coordinates.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import exudyn as exu
import numpy as np

from ..assembly.planetary_layout import CENTRAL, PlanetaryLayout, rigid_speeds_rad_s
from ..assembly.system import Body, ForceItem, Spring, SystemLayout
from ..physics.compiled import compiled
from ..physics.planetary_mesh import planet_forces, stage_forces
from .build import build

__all__ = ["PlanetarySystem", "build_planetary", "planetary_mesh_forces", "solve_planetary"]


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
    and planets by rigid rolling), with constant ``torques_Nm`` on sun, ring or carrier; built by the one
    builder (:func:`gearbody.engine.build.build`) from its :class:`~gearbody.assembly.system.SystemLayout`."""
    unknown = set(torques_Nm or {}) - set(CENTRAL)
    if unknown:
        raise ValueError(f"torques_Nm: {sorted(unknown)} are not sun, ring or carrier")
    speeds = rigid_speeds_rad_s(layout, sun_speed_rad_s, carrier_speed_rad_s)
    names = [*CENTRAL, *_planet_names(layout)]
    members = [*layout.members, *([layout.planet] * len(layout.planet_angles_rad))]
    bodies = tuple(Body("planar", inertia_kg_m2=m.inertia_kg_m2, mass_kg=m.mass_kg) for m in members)
    reference = {name: np.zeros(3) for name in CENTRAL}
    v0 = np.zeros(3 * len(names))
    for m, name in enumerate(CENTRAL):
        v0[3 * m + 2] = speeds[name]
    wc = speeds["carrier"]
    for n, name in enumerate(_planet_names(layout)):
        x, y = layout.planet_centre_m(n)
        reference[name] = np.array([x, y, 0.0])
        v0[9 + 3 * n : 12 + 3 * n] = (-wc * y, wc * x, speeds["planet"])
    items: list = []
    for m, (name, member) in enumerate(zip(CENTRAL, layout.members, strict=True)):
        o = 3 * m
        items += [
            Spring(None, o + d, member.bearing_stiffness_N_per_m, member.bearing_damping_Ns_per_m)
            for d in (0, 1)
        ]
        if member.torsion_stiffness_Nm_per_rad is not None:
            items.append(
                Spring(None, o + 2, member.torsion_stiffness_Nm_per_rad, member.torsion_damping_Nms_per_rad)
            )
        torque = float((torques_Nm or {}).get(name, 0.0))
        if torque:
            items.append(ForceItem((m,), _constant_torque(torque)))
    ref = np.concatenate([reference[k] for k in names])
    items.append(ForceItem(tuple(range(len(names))), _stage_items(layout, ref)))
    coordinates = tuple(c for name in names for c in (f"{name}_x", f"{name}_y", name))
    built = build(SystemLayout(coordinates, bodies, tuple(items)), np.zeros(len(coordinates)), v0)
    system = PlanetarySystem(
        built.system_container, built.mbs, layout, dict(zip(names, built.nodes, strict=True)), reference
    )
    system.user_functions = built.user_functions
    for i, name in enumerate(names):
        system.sensors[name] = {kind: built.sensors[kind][i] for kind in ("q", "v")}
    return system


def _constant_torque(torque_Nm: float):
    """factory(watchdog) -> a constant torque on a planar body's rotation."""

    def factory(watchdog):
        def constant(mbs, t, itemNumber, q, q_t):
            return [0.0, 0.0, torque_Nm]

        return constant

    return factory


def _stage_items(layout: PlanetaryLayout, ref: np.ndarray):
    """factory(watchdog) -> every planet's meshes and bearing on the stage's coordinates."""

    def factory(watchdog):
        G = np.array([layout.geometry(n) for n in range(len(layout.planet_angles_rad))])
        P_s, P_r = layout.sun_mesh, layout.ring_mesh
        forces = compiled(stage_forces, ref, ref, G, P_s, P_r)

        def stage_items(mbs, t, itemNumber, q, q_t):
            return forces(np.asarray(q) + ref, np.asarray(q_t), G, P_s, P_r)

        return stage_items

    return factory


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
