"""What a stage kind's render parts are given to place their bodies: the drive's frame (stage planes,
axes, walls, turning senses, rated torques, couplings) and the bearings that the shafts size (no
Exudyn). :func:`gearbody.render.layout.build_layout` fills it in; each kind's ``render_parts(scenario,
k).bodies(drive)`` reads it (:mod:`gearbody.render.parallel`, :mod:`gearbody.render.planetary`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from .shapes import BEARING, COUPLING, MARKER, Box, Cylinder

#: allowable torsional shear stress for the drawn shaft diameters, d = (16 T / (pi tau))^(1/3)
SHAFT_SHEAR_STRESS_PA = 30e6


def shaft_radius_m(torque_Nm: float) -> float:
    """Solid shaft sized for the torque: d = (16 T / (pi tau))^(1/3), tau = 30 MPa."""
    return 0.5 * (16 * abs(torque_Nm) / (math.pi * SHAFT_SHEAR_STRESS_PA)) ** (1 / 3)


def hub(z0: float, z1: float, r: float) -> tuple:
    """Coupling half with a marker stripe that shows its rotation."""
    return (
        Cylinder(z0, z1, 1.9 * r, COUPLING),
        Box((1.75 * r, 0.0, 0.5 * (z0 + z1)), (0.4 * r, 0.5 * r, 1.02 * abs(z1 - z0)), MARKER),
    )


@dataclass
class Bearings:
    """The bearings in both housing walls, once per axis (coaxial axes share them), sized by the shafts
    on the axis: the widest of them, or, on an axis through a coaxial stage, the first shaft at the
    front wall and the latest at the back."""

    axis_key: list[int]  # axis index -> the axis whose bearings it shares
    widest: dict[int, float] = field(default_factory=dict)
    walls: dict[int, list[float]] = field(default_factory=dict)  # an axis through a coaxial stage

    def shaft(self, j: int, r: float) -> None:
        """A shaft of radius r on axis j (on an axis through a coaxial stage: the back wall's)."""
        key = self.axis_key[j]
        if key in self.walls:
            self.walls[key][1] = r
        self.widest[key] = max(self.widest.get(key, 0.0), r)

    def coaxial(self, k: int, r_in: float, r_out: float) -> None:
        """Stage k's output shaft (radius r_out) continues its input's axis (input shaft r_in)."""
        self.axis_key[k + 1] = self.axis_key[k]
        key = self.axis_key[k]  # the front wall holds the axis's first shaft, the back wall this output's
        front = self.walls[key][0] if key in self.walls else self.widest.get(key, r_in)
        self.walls[key] = [front, r_out]
        self.widest[key] = max(self.widest.get(key, 0.0), r_in, r_out)

    def parts(self, axes, z_walls: tuple[float, float], wall: float) -> list[Cylinder]:
        """The bearing rings in the walls at ``z_walls`` (front, back), ``wall`` thick."""
        rings = []
        for j, shaft_r in self.widest.items():
            for w, zw in enumerate(z_walls):
                if j in self.walls:
                    shaft_r = self.walls[j][w]
                rings.append(
                    Cylinder(
                        zw - wall / 2,
                        zw + wall / 2,
                        1.8 * shaft_r,
                        BEARING,
                        inner_radius_m=1.05 * shaft_r,
                        x_m=axes[j][0],
                        y_m=axes[j][1],
                    )
                )
        return rings


@dataclass
class Drive:
    """The drive's frame, as a stage's render parts see it. Stage k lies in the plane z = ``z_stage[k]``
    between its input axis ``axes[k]`` and output axis ``axes[k + 1]``, which turn in the drawn senses
    ``senses[k]``, ``senses[k + 1]`` (``mirrors[k]``: -1 for a stage drawn mirrored) and carry the rated
    torques ``torques[k]``, ``torques[k + 1]``; ``ends[k]`` are its input and output bodies with their
    model angle per unit chain angle. The housing walls stand at ``z_front`` and ``z_back``."""

    stages: tuple
    z_stage: list[float]
    z_front: float
    z_back: float
    wall: float
    gap: float
    axes: list[tuple[float, float]]
    senses: list[int]
    mirrors: list[int]
    torques: list[float]
    ends: list[tuple]
    r_in: float  # the motor's shaft stub (and the input coupling)
    z_cpl_in: float  # the input coupling's joint
    hub_len: float
    bearings: Bearings

    @property
    def last(self) -> int:
        return len(self.stages) - 1

    def input_hub(self) -> tuple:
        """The input coupling's half on the first stage's input shaft."""
        return hub(self.z_cpl_in + 0.002, self.z_cpl_in + self.hub_len, self.r_in)

    def output_coupling_z_m(self, r: float) -> float:
        """Where the output coupling joins, for an output shaft of radius r."""
        return self.z_back + self.wall / 2 + 0.5 * self.gap + 1.6 * r

    def output_hub(self, r: float) -> tuple:
        """The output coupling's half on the last stage's output shaft (radius r)."""
        z = self.output_coupling_z_m(r)
        return hub(z - 1.6 * r, z - 0.002, r)

    def between_m(self, k: int) -> float:
        """The plane half-way between stage k and stage k + 1 (where their shared shaft is split)."""
        return 0.5 * (self.z_stage[k] + self.z_stage[k + 1])
