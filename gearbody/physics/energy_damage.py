r"""Tooth damage for the potential-energy mesh stiffness (:mod:`.stiffness_energy`). Engine-free.

Tooth damage (one tooth of a pair; the pair's profile over its contact span)
----------------------------------------------------------------------------
* :class:`RootCrack` (Tian 2004; Wu, Zuo & Parey 2008; Chen & Shao 2011; Mohammed, Rantatalo &
  Aidanpaa 2013 "straight-line limit"): a straight crack of depth ``q`` starts on the loaded flank at
  the clamped section (half thickness ``h_0``) and runs into the tooth at angle ``nu`` to the centre
  line; its tip is at ``h_q = h_0 - q sin(nu)`` from the centre line (case 1: ``h_q >= 0``, the crack
  does not cross the centre line; deeper cracks are rejected). The material between the crack and the
  loaded flank is ineffective from the clamped section up to where a line through the crack tip,
  parallel to the centre line, meets the flank (``h_x = h_q``). There
  ``I_x = b (h_q + h_x)^3 / 12``, ``A_x = b (h_q + h_x)``; above it the healthy sections. Moment arm,
  Hertz and fillet-foundation terms unchanged (as in Chen & Shao 2011). ``q = 0`` is the healthy tooth.
* :class:`ToothBreakage`: the part of the tooth above ``r_f + (1 - missing) (r_a - r_f)`` is missing
  over a fraction ``width_fraction`` of the face width. Where the contact point on the damaged tooth is
  above that radius the pair has only the intact width ``(1 - width_fraction) b`` (0 for a full-width
  break: no contact); below it the tooth is unchanged, because in the energy method only the beam
  between the clamped section and the load point deforms.
* :class:`Spall` (simplification after Chaari, Baccar, Abbes & Haddar 2008 and Ma et al. 2015): while
  the contact point on the damaged tooth lies between two radii, a fraction ``w`` of the contact width
  is lost; every term of the pair (Hertz, and bending, shear, axial, fillet of both teeth) uses the
  effective width ``(1 - w) b`` (all are proportional to ``1/b``, so ``k_pair`` scales by ``1 - w``).
  With ``hertz_only=True`` only the Hertz term does (the spall as a contact-only defect). The section
  loss of a deep spall (Ma et al. 2015) is not modelled.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from .energy_gears import GearName, SpurGear


@dataclass(frozen=True)
class RootCrack:
    """Straight root crack of depth ``depth_m`` at ``angle_deg`` to the tooth centre line (case 1)."""

    depth_m: float
    angle_deg: float = 45.0
    gear: GearName = "pinion"

    def __post_init__(self) -> None:
        if self.depth_m < 0.0 or not 0.0 < self.angle_deg <= 90.0:
            raise ValueError("crack depth must be >= 0 and its angle in (0, 90] deg")


@dataclass(frozen=True)
class ToothBreakage:
    """Tip part of the tooth missing: ``missing_height_fraction`` of the height r_a - r_f, from the tip."""

    missing_height_fraction: float
    gear: GearName = "pinion"
    width_fraction: float = 1.0  # fraction of the face width over which it is missing

    def __post_init__(self) -> None:
        if not (0.0 <= self.missing_height_fraction <= 1.0 and 0.0 <= self.width_fraction <= 1.0):
            raise ValueError("breakage fractions must lie in [0, 1]")

    def remaining_radius_m(self, gear: SpurGear) -> float:
        r_a, r_f = gear.tip_radius_m, gear.root_radius_m
        return r_a - self.missing_height_fraction * (r_a - r_f)


@dataclass(frozen=True)
class Spall:
    """Flank spall between two radii of the damaged tooth, losing ``width_loss_fraction`` of the width."""

    start_radius_m: float
    end_radius_m: float
    width_loss_fraction: float
    gear: GearName = "pinion"
    hertz_only: bool = False

    def __post_init__(self) -> None:
        if self.end_radius_m < self.start_radius_m or not 0.0 <= self.width_loss_fraction <= 1.0:
            raise ValueError("spall needs start_radius_m <= end_radius_m and a width loss in [0, 1]")


Damage = RootCrack | ToothBreakage | Spall


def as_damage_tuple(damage: Damage | Sequence[Damage] | None) -> tuple[Damage, ...]:
    """One damage, several, or None as a tuple."""
    if damage is None:
        return ()
    if isinstance(damage, RootCrack | ToothBreakage | Spall):
        return (damage,)
    return tuple(damage)
