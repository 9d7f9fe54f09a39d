"""Modal results and Campbell lines, engine-free: natural frequencies, mode shapes and their labels
(:class:`ModeSet`, computed by :func:`gearbody.engine.scene_modes`), and the pinion speeds at which
the k-th mesh harmonic ``k z1 w / 2 pi`` meets a natural frequency (``w = 2 pi f_n / (k z1)``).

``gearbody modes`` prints these speeds; :func:`gearbody.plotting.campbell.plot_campbell` draws them.
The paper's claim (section 2, Figs. 5-8): the one-stage system is unstable (K_d > 2) when the mesh
frequency equals its natural frequency.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["ModeSet", "campbell_lines", "resonance_speeds_rad_s"]


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


def campbell_lines(
    natural_frequencies_hz: Sequence[float], pinion_teeth: int, harmonics: int = 3
) -> dict[str, np.ndarray]:
    """Pinion speeds [rad/s] at which mesh harmonic k meets each natural frequency.

    Returns ``{"harmonic": [1..harmonics], "speed_rad_s": array (harmonics, n_frequencies)}`` with
    ``speed_rad_s[k - 1, j] = 2 pi f_j / (k z1)``.
    """
    f = np.asarray(natural_frequencies_hz, float)
    k = np.arange(1, harmonics + 1)[:, None]
    return {"harmonic": k.ravel(), "speed_rad_s": 2 * math.pi * f[None, :] / (k * pinion_teeth)}


def resonance_speeds_rad_s(modes: ModeSet, pinion_teeth: int, harmonics: int = 1) -> np.ndarray:
    """:func:`campbell_lines` of a mode set: shape (harmonics, n_modes), NaN for rigid-body modes."""
    rigid = np.array([modes.is_rigid_body(m) for m in range(len(modes.frequencies_hz))], bool)
    f = np.where(rigid, np.nan, modes.frequencies_hz)
    return campbell_lines(f, pinion_teeth, harmonics)["speed_rad_s"]
