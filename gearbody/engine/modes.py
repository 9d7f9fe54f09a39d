"""Natural frequencies of the linearised system, computed through Exudyn.

The mesh is linearised at its mean stiffness over a mesh period (no backlash, errors or friction);
motor and load contribute no stiffness, so a free drive train has one rigid-body mode at 0 Hz.
Linear bearings enter with their stiffness; nonlinear bearing laws with their tangent stiffness at
the static displacement under the rated mesh forces. Each mode is labelled by its dominant motion,
from the share of each coordinate in the mode's kinetic energy (M_ii x_i^2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import exudyn as exu
import numpy as np
from exudyn.itemInterface import Node1D, ObjectGenericODE2, ObjectMass1D

from ..assembly import (
    TorsionalLayout,
    mesh_parameters_from_scenario,
    reduced_mass_kg,
    static_lateral_displacements_m,
    torsional_layout,
)
from ..model import Scenario
from ..physics import mean_stiffness_N_per_m
from .build import build_torsional


@dataclass(frozen=True)
class ModeSet:
    """Undamped natural frequencies (ascending) and mode shapes (columns, normalised to max |x| = 1).

    Coordinates are named as in the simulation: rotations by their body ("pinion"), lateral
    translations with an axis suffix ("pinion_x", "pinion_y"). ``masses`` are the diagonal mass
    matrix entries (kg m^2 for rotations, kg for translations).
    """

    frequencies_hz: np.ndarray
    shapes: np.ndarray
    dof_names: list[str]
    mean_mesh_stiffness_N_per_m: tuple[float, ...] = ()  # per mesh, at which the modes were computed
    masses: np.ndarray | None = None

    def is_rigid_body(self, mode: int) -> bool:
        """A zero-frequency mode (to round-off: below 1e-5 of the highest frequency)."""
        return bool(self.frequencies_hz[mode] < 1e-5 * self.frequencies_hz.max())

    def energy_shares(self, mode: int) -> np.ndarray:
        """Share of each coordinate in the kinetic energy of a mode (sums to 1)."""
        m = np.ones(len(self.dof_names)) if self.masses is None else self.masses
        e = m * self.shapes[:, mode] ** 2
        return e / e.sum()

    def dominant_dof(self, mode: int) -> str:
        return self.dof_names[int(np.argmax(self.energy_shares(mode)))]

    def label(self, mode: int) -> str:
        """Dominant motion: 'rigid-body rotation', 'torsional: wheel (71 %)', 'lateral y: pinion (64 %)'.

        Torsional when rotations carry at least half of the kinetic energy; the body or axis named is
        the coordinate with the largest share within that kind.
        """
        if self.is_rigid_body(mode):
            return "rigid-body rotation"
        share = self.energy_shares(mode)
        lateral = np.array([n.endswith(("_x", "_y")) and n[:-2] in self.dof_names for n in self.dof_names])
        kind_mask = lateral if share[lateral].sum() > 0.5 else ~lateral
        i = int(np.argmax(np.where(kind_mask, share, -1.0)))
        name = self.dof_names[i]
        if lateral[i]:
            return f"lateral {name[-1]}: {name[:-2]} ({100 * share[i]:.0f} %)"
        return f"torsional: {name} ({100 * share[i]:.0f} %)"


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
    built = build_torsional(layout, modal_mesh_stiffness_N_per_m=k, lateral_u0=lateral_u0, sensors=False)
    freqs, shapes = _eigen(built.mbs, built.fixed_coordinates)
    keep = [i for i in range(len(built.dof_names)) if i not in built.fixed_coordinates]
    masses = []
    for b in layout.inertias:
        masses += [b.inertia_kg_m2] if b.lateral is None else [b.lateral.mass_kg] * 2 + [b.inertia_kg_m2]
    return ModeSet(
        freqs[: len(keep)],
        shapes[keep][:, : len(keep)],
        [built.dof_names[i] for i in keep],
        k,
        np.array(masses)[keep],
    )


def scene_modes(scenario: Scenario) -> ModeSet:
    """Modes of a scene at its mean mesh stiffness (healthy teeth)."""
    if scenario.meta.topology == "muller":
        k_mean = mean_stiffness_N_per_m(mesh_parameters_from_scenario(scenario))
        SC = exu.SystemContainer()
        mbs = SC.AddSystem()
        n = mbs.AddNode(Node1D(referenceCoordinates=[0.0]))
        mbs.AddObject(ObjectMass1D(nodeNumber=n, mass=reduced_mass_kg(scenario)))
        mbs.AddObject(
            ObjectGenericODE2(
                nodeNumbers=[n], massMatrix=np.zeros((1, 1)), stiffnessMatrix=np.array([[k_mean]])
            )
        )
        mbs.Assemble()
        freqs, shapes = _eigen(mbs)
        return ModeSet(freqs, shapes, ["deflection"], (k_mean,))
    return natural_frequencies(
        torsional_layout(scenario), lateral_u0=static_lateral_displacements_m(scenario, 1.0)
    )


def resonance_speeds_rad_s(modes: ModeSet, pinion_teeth: int, harmonics: int = 1) -> np.ndarray:
    """Pinion speeds at which the k-th mesh harmonic meets each non-zero natural frequency.

    Returns an array of shape (harmonics, n_modes): w = 2 pi f_n / (k z1); NaN for rigid-body modes.
    """
    rigid = np.array([modes.is_rigid_body(m) for m in range(len(modes.frequencies_hz))], bool)
    f = np.where(rigid, np.nan, modes.frequencies_hz)
    k = np.arange(1, harmonics + 1)[:, None]
    return 2 * math.pi * f[None, :] / (k * pinion_teeth)
