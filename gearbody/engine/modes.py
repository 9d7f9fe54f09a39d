"""Natural frequencies of the linearised system, computed through Exudyn.

The mesh is linearised at its mean stiffness over a mesh period (no backlash, errors or friction);
motor and load contribute no stiffness, so a free drive train has one rigid-body mode at 0 Hz.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import exudyn as exu
import numpy as np
from exudyn.itemInterface import Node1D, ObjectGenericODE2, ObjectMass1D

from ..model import Scenario
from ..physics import mean_stiffness_N_per_m, mesh_parameters_from_scenario
from .build import build_torsional
from .layout import TorsionalLayout, reduced_mass_kg, torsional_layout


@dataclass(frozen=True)
class ModeSet:
    """Undamped natural frequencies (ascending) and mode shapes (columns, normalised to max |x| = 1)."""

    frequencies_hz: np.ndarray
    shapes: np.ndarray
    dof_names: list[str]
    mean_mesh_stiffness_N_per_m: tuple[float, ...] = ()  # per mesh, at which the modes were computed

    def dominant_dof(self, mode: int) -> str:
        return self.dof_names[int(np.argmax(np.abs(self.shapes[:, mode])))]


def _eigen(mbs: exu.MainSystem) -> tuple[np.ndarray, np.ndarray]:
    values, vectors = mbs.ComputeODE2Eigenvalues(
        useSparseSolver=False, convert2Frequencies=False, useAbsoluteValues=True
    )
    values = np.abs(np.asarray(values))
    order = np.argsort(values)
    freqs = np.sqrt(values[order]) / (2 * math.pi)
    shapes = np.asarray(vectors)[:, order]
    shapes = shapes / np.max(np.abs(shapes), axis=0, keepdims=True)
    return freqs, shapes


def natural_frequencies(
    layout: TorsionalLayout, mesh_stiffness_N_per_m: float | list[float] | None = None
) -> ModeSet:
    """Natural frequencies of a torsional layout (any branched chain of inertias, shafts, meshes).

    ``mesh_stiffness_N_per_m``: one line-of-action stiffness for all meshes or one per mesh; None
    takes each mesh's exact mean k_z over its mesh period.
    """
    if mesh_stiffness_N_per_m is None:
        mesh_stiffness_N_per_m = [mean_stiffness_N_per_m(m.parameters) for m in layout.meshes]
    k = tuple(np.broadcast_to(np.asarray(mesh_stiffness_N_per_m, float), (len(layout.meshes),)))
    built = build_torsional(layout, modal_mesh_stiffness_N_per_m=k, sensors=False)
    freqs, shapes = _eigen(built.mbs)
    return ModeSet(freqs, shapes, built.dof_names, k)


def scene_modes(scenario: Scenario) -> ModeSet:
    """Modes of a scene at its mean mesh stiffness (healthy teeth)."""
    if scenario.meta.scene == "muller":
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
    return natural_frequencies(torsional_layout(scenario))


def resonance_speeds_rad_s(modes: ModeSet, pinion_teeth: int, harmonics: int = 1) -> np.ndarray:
    """Pinion speeds at which the k-th mesh harmonic meets each non-zero natural frequency.

    Returns an array of shape (harmonics, n_modes): w = 2 pi f_n / (k z1); NaN for rigid-body modes.
    """
    f = np.where(modes.frequencies_hz > 1e-6, modes.frequencies_hz, np.nan)
    k = np.arange(1, harmonics + 1)[:, None]
    return 2 * math.pi * f[None, :] / (k * pinion_teeth)
