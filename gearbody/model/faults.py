"""Tooth errors and faults of one gear stage: the error mode E(a, e, r) (production technology),
once-per-revolution run-out, damaged and pitted teeth (change of condition)."""

from __future__ import annotations

from dataclasses import dataclass

from .params import Node, ScenarioError, param


@dataclass(frozen=True, kw_only=True)
class ErrorMode(Node):
    """Tooth error mode E(a, e, r) of the paper (Fig. 4, eq. 6)."""

    a: float = param(0.5, ge=0, le=1, doc="position of the maximum error in the mesh period")
    e_um: float = param(0.0, doc="maximum error e (negative allowed)")
    r: float = param(0.0, ge=0, le=1, doc="scope of the random per-tooth variation")


@dataclass(frozen=True, kw_only=True)
class Eccentricity(Node):
    """Once-per-revolution error of one gear (eccentricity, run-out): A sin(phi + theta) along the line
    of action, phi the gear's angle."""

    gear: str = param(choices=("pinion", "wheel"))
    amplitude_um: float = param(ge=0, le=1000, doc="amplitude A along the line of action")
    phase_deg: float = param(0.0, ge=-360, le=360, doc="theta: phase at angle 0")


@dataclass(frozen=True, kw_only=True)
class DamagedTooth(Node):
    """A damaged tooth: a bare stiffness factor (the paper's Figs. 13-16) and/or, with the
    potential-energy stiffness, a root crack, a broken-off tip or a spall that give that tooth's pair its
    own stiffness profile over its contact (docs/scenario.md, "Tooth damage from geometry")."""

    gear: str = param(choices=("pinion", "wheel"))
    tooth: int = param(ge=0, doc="tooth index, 0-based")
    stiffness_factor: float = param(1.0, ge=0, le=1, doc="factor on k_z while this tooth meshes")
    crack_depth_mm: float = param(0.0, ge=0, le=100, doc="root crack depth q (potential-energy)")
    crack_angle_deg: float = param(45.0, gt=0, le=90, doc="crack angle to the tooth centre line")
    broken_height_fraction: float = param(
        0.0, ge=0, le=1, doc="part of the tooth height missing from the tip (potential-energy)"
    )
    broken_width_fraction: float = param(1.0, ge=0, le=1, doc="part of the face width it is missing over")
    spall_start_diameter_mm: float = param(0.0, ge=0, doc="spall from this diameter of the flank")
    spall_end_diameter_mm: float = param(0.0, ge=0, doc="spall up to this diameter")
    spall_width_fraction: float = param(0.0, ge=0, le=1, doc="part of the contact width lost in the spall")

    def __post_init__(self) -> None:
        if self.spall_width_fraction > 0 and not self.spall_end_diameter_mm > self.spall_start_diameter_mm:
            raise ScenarioError(
                f"spall_end_diameter_mm = {self.spall_end_diameter_mm:g}: must be > spall_start_diameter_mm "
                f"= {self.spall_start_diameter_mm:g} when spall_width_fraction > 0"
            )

    @property
    def has_geometric_damage(self) -> bool:
        """True when a crack, breakage or spall is given (needs the potential-energy stiffness)."""
        return self.crack_depth_mm > 0 or self.broken_height_fraction > 0 or self.spall_width_fraction > 0


@dataclass(frozen=True, kw_only=True)
class PittedTooth(Node):
    """A pit (spall) on one tooth's flank: the pair deflects depth_um less while that tooth is in mesh
    between two mesh phases (material missing)."""

    gear: str = param(choices=("pinion", "wheel"))
    tooth: int = param(ge=0, doc="tooth index, 0-based")
    depth_um: float = param(ge=0, le=1000, doc="depth of the missing material along the line of action")
    start_phase: float = param(ge=0, lt=1, doc="mesh phase where the pit starts")
    end_phase: float = param(gt=0, le=1, doc="mesh phase where the pit ends (> start_phase)")
