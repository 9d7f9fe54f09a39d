"""Natural frequencies of the linearised system, computed through Exudyn.

The mesh is linearised at its mean stiffness over a mesh period (no backlash, errors or friction);
motor and load contribute no stiffness, so a free drive train has one rigid-body mode at 0 Hz.
Linear bearings enter with their stiffness; nonlinear bearing laws with their tangent stiffness at
the static displacement under the rated mesh forces. Each mode is labelled by its dominant motion,
from the share of each coordinate in the mode's kinetic energy (M_ii x_i^2). The engine-free result type
(:class:`~gearbody.analysis.modal.ModeSet`) and the resonance speeds (Campbell lines) live in
:mod:`gearbody.analysis.modal`.
"""

from __future__ import annotations

import math
from pathlib import Path

import exudyn as exu
import numpy as np

from ..analysis.modal import ModeSet
from ..assembly import TorsionalLayout, static_lateral_displacements_m, torsional_layout
from ..assembly.compound import compound_layout, has_bearing_laws, stage_static_displacements
from ..assembly.compound_system import compound_system
from ..assembly.topology import muller_system, torsional_coordinates, torsional_system
from ..model import Scenario, load_scenario
from ..physics import mean_stiffness_N_per_m
from .build import build

__all__ = ["ModeSet", "natural_frequencies", "scene_modes"]


def _eigen(mbs: exu.MainSystem, fixed: list[int] | None = None) -> tuple[np.ndarray, np.ndarray]:
    n_all = mbs.systemData.ODE2Size()
    fixed = sorted(fixed or [])
    values, vectors = mbs.ComputeODE2Eigenvalues(
        useSparseSolver=False,
        convert2Frequencies=False,
        useAbsoluteValues=True,
        constrainedCoordinates=fixed,
        numberOfEigenvalues=n_all - len(fixed) if fixed else 0,  # Exudyn needs the count with fixed ones
    )
    values = np.abs(np.asarray(values))
    order = np.argsort(values)
    freqs = np.sqrt(values[order]) / (2 * math.pi)
    shapes = np.asarray(vectors)[:, order]
    shapes = shapes / np.max(np.abs(shapes), axis=0, keepdims=True)
    return freqs, shapes


def natural_frequencies(
    layout: TorsionalLayout,
    mesh_stiffness_N_per_m: float | list[float] | None = None,
    *,
    lateral_u0: dict[str, np.ndarray] | None = None,
) -> ModeSet:
    """Natural frequencies of a layout (any branched chain of inertias, shafts, meshes; gears
    optionally on lateral bearings).

    ``mesh_stiffness_N_per_m``: one line-of-action stiffness for all meshes or one per mesh; None
    takes each mesh's exact mean k_z over its mesh period. ``lateral_u0``: static centre
    displacements at which nonlinear bearings are linearised.
    """
    if mesh_stiffness_N_per_m is None:
        mesh_stiffness_N_per_m = [mean_stiffness_N_per_m(m.parameters) for m in layout.meshes]
    k = tuple(np.broadcast_to(np.asarray(mesh_stiffness_N_per_m, float), (len(layout.meshes),)))
    system = torsional_system(layout, lateral_u0=lateral_u0, modal_mesh_stiffness_N_per_m=k)
    built = build(system, *torsional_coordinates(layout, None, None, lateral_u0), sensors=False)
    freqs, shapes = _eigen(built.mbs, built.fixed_coordinates)
    keep = [i for i in range(len(built.dof_names)) if i not in built.fixed_coordinates]
    masses = system.masses
    return ModeSet(
        freqs[: len(keep)],
        shapes[keep][:, : len(keep)],
        [built.dof_names[i] for i in keep],
        k,
        masses[keep],
    )


def scene_modes(scenario: Scenario | str | Path) -> ModeSet:
    """Natural frequencies and mode shapes of a drive, linearised at its mean mesh stiffness (healthy
    teeth, no backlash; nonlinear bearings at their tangent under the rated mesh forces): a
    :class:`~gearbody.analysis.modal.ModeSet`, each mode labelled by its dominant motion.

    ``scenario``: a :class:`~gearbody.model.Scenario`, or a scene name or TOML path. This is
    :func:`gearbody.modes`, and what ``gearbody modes SCENE`` prints.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    if scenario.meta.topology == "muller":
        system = muller_system(scenario, modal=True)
        freqs, shapes = _eigen(build(system, sensors=False).mbs)
        return ModeSet(freqs, shapes, ["deflection"], (float(system.items[0].stiffness[0, 0]),))
    if scenario.has_planetary:
        return compound_modes(scenario)
    return natural_frequencies(
        torsional_layout(scenario), lateral_u0=static_lateral_displacements_m(scenario, 1.0)
    )


def compound_modes(scenario: Scenario) -> ModeSet:
    """Modes of a drive with planetary stages at the nominal assembly, every mesh at its mean stiffness
    (exact geometry linearised by Exudyn: Lin & Parker's model for a planetary stage, no gyroscopic
    terms), motor and load free."""
    layout = compound_layout(scenario, modal=True)
    n = len(layout.dof_names)
    states = {}  # bearing laws: linearised where they carry the rated load (a clearance is closed there)
    for link in layout.planetary:
        if has_bearing_laws(link):
            st, F = scenario.stages[link.stage], scenario.stage_rated_force_N(link.stage)
            states[link.stage] = stage_static_displacements(
                link, link.input_sense * F * st.input_arm_m, -link.output_sense * F * st.output_arm_m
            )
    system = compound_system(layout, modal=True, bearing_states=states)
    built = build(system, np.zeros(n), np.zeros(n), sensors=False)
    freqs, shapes = _eigen(built.mbs)
    masses = system.masses
    k_mesh = [mean_stiffness_N_per_m(m.parameters) for m in layout.meshes]
    for link in layout.planetary:
        k_mesh += [
            mean_stiffness_N_per_m(link.layout.sun_mesh),
            mean_stiffness_N_per_m(link.layout.ring_mesh),
        ]
    # Exudyn orders the system's coordinates node by node, as the layout lists them
    return ModeSet(freqs, shapes, list(layout.dof_names), tuple(k_mesh), masses)
