"""Mesh stiffness of a scenario's gear pair from its geometry: the pair-stiffness table used by the mesh
law (``stiffness_profile = "potential-energy"``), per-tooth damage ratios, and the static transmission
error. Engine-free; tabulated once per stage and cached.

Table (docs/scenario.md, "Pair stiffness table"): the healthy stiffness of one tooth pair over its own
mesh phase ``q`` on the uniform grid ``q_m = -h + m (1 + 2h)/(N - 1)``, ``m = 0 .. N-1``,
``h = (eps_alpha - 1)/2`` (the pair of a period is in contact for ``-h <= q < 1 + h``); a damaged tooth
gets the ratio ``k_damaged(q) / k_healthy(q)`` of its pair (the mating tooth healthy) on the same grid.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

from .stiffness_energy import (
    RootCrack,
    Spall,
    SpurGear,
    SpurPair,
    ToothBreakage,
    damaged_pair_stiffness_N_per_m,
    pair_stiffness_N_per_m,
)


@dataclasses.dataclass(frozen=True, eq=False)
class PairStiffnessTable:
    """Healthy pair stiffness over the pair's contact, and per-tooth damage ratios, on one grid."""

    half_double: float  # h = (eps_alpha - 1)/2
    stiffness_N_per_m: np.ndarray  # healthy k_pair(q_m)
    ratios: dict[tuple[str, int], np.ndarray]  # (gear, tooth) -> k_damaged / k_healthy at q_m

    @property
    def own_phase(self) -> np.ndarray:
        """Grid q_m over [-h, 1 + h]."""
        h = self.half_double
        return np.linspace(-h, 1.0 + h, self.stiffness_N_per_m.size)

    def pair_stiffness(
        self, own_phase: np.ndarray, gear: str | None = None, tooth: int | None = None
    ) -> np.ndarray:
        """k of one pair at its own phase q (0 out of contact), healthy or with the named tooth damaged."""
        q = np.asarray(own_phase, float)
        k = np.interp(q, self.own_phase, self.stiffness_N_per_m)
        if gear is not None and (gear, tooth) in self.ratios:
            k = k * np.interp(q, self.own_phase, self.ratios[(gear, tooth)])
        h = self.half_double
        return np.where((q >= -h) & (q < 1.0 + h), k, 0.0)

    def mean_stiffness_N_per_m(self) -> float:
        """Mean of the healthy total (summed pairs) over one mesh period: the integral of one pair's
        (piecewise-linear) stiffness over its contact, per period."""
        k = self.stiffness_N_per_m
        return float(0.5 * np.sum(k[1:] + k[:-1]) * (1.0 + 2.0 * self.half_double) / (k.size - 1))

    def zone_means_N_per_m(self, n: int = 4000) -> tuple[float, float]:
        """Mean healthy total stiffness in the single- and in the double-contact zones."""
        p = (np.arange(n) + 0.5) / n
        k = sum(self.pair_stiffness(p - o) for o in (-1, 0, 1))
        h = self.half_double
        double = (p < h) | (p >= 1.0 - h)
        return float(k[~double].mean()), float(k[double].mean()) if double.any() else float(k.mean())


def spur_pair(geometry, teeth_pinion: int, teeth_wheel: int) -> SpurPair:
    """:class:`SpurPair` of a scenario's ``MeshGeometry`` (bores required: the fillet-foundation term)."""
    g = geometry
    for name in ("bore_diameter_pinion_mm", "bore_diameter_wheel_mm"):
        if getattr(g, name) is None:
            raise ValueError(
                f"geometry.{name} is required by stiffness_profile = 'potential-energy' (the "
                "fillet-foundation term of Sainsot et al. 2004 depends on the rim's inner radius)"
            )

    def gear(z: int, x: float, bore_mm: float) -> SpurGear:
        return SpurGear(
            teeth=z,
            module_m=g.module_mm * 1e-3,
            face_width_m=g.face_width_mm * 1e-3,
            bore_radius_m=0.5e-3 * bore_mm,
            pressure_angle_deg=g.pressure_angle_deg,
            profile_shift=x,
            addendum_coefficient=g.addendum_coefficient,
            dedendum_coefficient=g.dedendum_coefficient,
            rack_tip_radius_coefficient=g.rack_tip_radius_coefficient,
            youngs_modulus_Pa=g.youngs_modulus_GPa * 1e9,
            poisson_ratio=g.poisson_ratio,
        )

    a = None if g.centre_distance_mm is None else g.centre_distance_mm * 1e-3
    return SpurPair(
        gear(teeth_pinion, g.profile_shift_pinion, g.bore_diameter_pinion_mm),
        gear(teeth_wheel, g.profile_shift_wheel, g.bore_diameter_wheel_mm),
        a,
    )


def tooth_damage(tooth) -> tuple:
    """Damage objects of a scenario ``DamagedTooth`` (crack, breakage, spall on its gear)."""
    out = []
    if tooth.crack_depth_mm > 0:
        out.append(RootCrack(tooth.crack_depth_mm * 1e-3, tooth.crack_angle_deg, tooth.gear))
    if tooth.broken_height_fraction > 0:
        out.append(ToothBreakage(tooth.broken_height_fraction, tooth.gear, tooth.broken_width_fraction))
    if tooth.spall_width_fraction > 0:
        out.append(
            Spall(
                0.5e-3 * tooth.spall_start_diameter_mm,
                0.5e-3 * tooth.spall_end_diameter_mm,
                tooth.spall_width_fraction,
                tooth.gear,
            )
        )
    return tuple(out)


@functools.lru_cache(maxsize=64)
def pair_stiffness_table(
    geometry, teeth_pinion: int, teeth_wheel: int, damaged_teeth=()
) -> PairStiffnessTable:
    """The pair table of a scenario mesh geometry (cached; arguments are frozen scenario objects)."""
    pair = spur_pair(geometry, teeth_pinion, teeth_wheel)
    h = pair.geometry.half_double_contact
    q = np.linspace(-h, 1.0 + h, geometry.table_points)
    s = pair.roll_position_m(q)
    # the grid's ends lie on the contact limits; clamp round-off so that both count as in contact
    s = np.clip(s, pair.contact_start_m, pair.contact_end_m)
    k = np.array([pair_stiffness_N_per_m(pair, float(x)) for x in s])
    ratios: dict[tuple[str, int], np.ndarray] = {}
    for tooth in damaged_teeth:
        damage = tooth_damage(tooth)
        if not damage:
            continue
        kd = np.array([damaged_pair_stiffness_N_per_m(pair, float(x), damage) for x in s])
        key = (tooth.gear, tooth.tooth)
        ratios[key] = ratios.get(key, 1.0) * kd / k
    return PairStiffnessTable(half_double=h, stiffness_N_per_m=k, ratios=ratios)


def stage_pair_table(stage) -> PairStiffnessTable:
    """Pair table of a scenario :class:`~gearbody.model.Stage` with potential-energy stiffness."""
    damaged = tuple(t for t in stage.damaged_teeth if t.has_geometric_damage)
    return pair_stiffness_table(stage.mesh.geometry, stage.pinion.teeth, stage.wheel.teeth, damaged)


def static_transmission_error_m(
    stiffness_N_per_m: np.ndarray, force_N: float, error_m: np.ndarray | float = 0.0, backlash_m: float = 0.0
) -> np.ndarray:
    """Loaded static transmission error along the line of action, m: the deflection
    ``delta = r1 phi_p - r2 phi_w`` at which the mesh carries ``force_N`` (eq. 4 solved for delta):
    ``delta = F / k - E + l_u`` (infinite where k = 0: the force cannot be carried)."""
    k = np.asarray(stiffness_N_per_m, float)
    with np.errstate(divide="ignore"):
        return np.where(k > 0, force_N / np.where(k > 0, k, 1.0) - error_m + backlash_m, math.inf)
