"""A gear mesh: stiffness profile k_z(p) (hand-given or from the gear-pair geometry), damping, backlash,
friction geometry and the directions of the line of action (docs/scenario.md, "Mesh", "Gear geometry")."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .params import Node, ScenarioError, param

STIFFNESS_PROFILES = ("contact-ratio", "table", "iso-6336-b", "potential-energy")
FROM_GEOMETRY = ("iso-6336-b", "potential-energy")


@dataclass(frozen=True, kw_only=True)
class MeshGeometry(Node):
    """Gear-pair geometry of a mesh (docs/scenario.md, "Gear geometry"): base radii, contact ratio,
    pitch point, working pressure angle, face width, backlash and the stiffness follow from it."""

    module_mm: float = param(gt=0, le=100, doc="normal module m_n")
    pressure_angle_deg: float = param(20.0, ge=10, le=35, doc="basic-rack (normal) pressure angle alpha_n")
    helix_angle_deg: float = param(0.0, ge=0, le=45, doc="helix angle beta (iso-6336-b only)")
    face_width_mm: float = param(gt=0, le=2000, doc="common face width b")
    profile_shift_pinion: float = param(0.0, ge=-1.5, le=1.5, doc="profile shift coefficient x_1")
    profile_shift_wheel: float = param(0.0, ge=-1.5, le=1.5, doc="profile shift coefficient x_2")
    addendum_coefficient: float = param(1.0, gt=0, le=2, doc="h_a* of the basic rack")
    dedendum_coefficient: float = param(1.25, gt=0, le=2, doc="h_f* of the basic rack")
    rack_tip_radius_coefficient: float | None = param(
        None, ge=0, le=1, doc="rho_fP* of the basic rack (unset: full round, 0.38 for ISO 53 A)"
    )
    centre_distance_mm: float | None = param(
        None, gt=0, doc="working centre distance (unset: from the shifts)"
    )
    bore_diameter_pinion_mm: float | None = param(
        None, gt=0, doc="pinion bore (potential-energy: fillet-foundation term)"
    )
    bore_diameter_wheel_mm: float | None = param(
        None, gt=0, doc="wheel bore (potential-energy: fillet-foundation term)"
    )
    youngs_modulus_GPa: float = param(206.0, gt=0, le=1000, doc="Young's modulus of both gears")
    poisson_ratio: float = param(0.3, ge=0, lt=0.5, doc="Poisson's ratio of both gears")
    thickness_allowance_pinion_um: float | None = param(
        None, ge=-2000, le=0, doc="E_sn1, normal tooth-thickness allowance (sets backlash_um)"
    )
    thickness_allowance_wheel_um: float | None = param(
        None, ge=-2000, le=0, doc="E_sn2, normal tooth-thickness allowance (sets backlash_um)"
    )
    centre_distance_deviation_um: float = param(
        0.0, ge=-2000, le=2000, doc="actual minus nominal centre distance (with the allowances)"
    )
    table_points: int = param(
        81, ge=11, le=2001, doc="potential-energy: points of the pair stiffness table over its contact"
    )

    @property
    def sets_backlash(self) -> bool:
        """True when tooth-thickness allowances are given (the mesh's backlash_um follows from them)."""
        return self.thickness_allowance_pinion_um is not None or self.thickness_allowance_wheel_um is not None


MESH_DEFAULTS = {
    "stiffness_single_N_per_m": 1.2e9,
    "stiffness_double_N_per_m": 1.3e9,
    "contact_ratio": 1.6,
    "pressure_angle_deg": 20.0,
    "pitch_point_phase": 0.5,
}


@dataclass(frozen=True, kw_only=True)
class Mesh(Node):
    """Gear mesh: stiffness profile k_z(p), damping C_z, backlash l_u, friction geometry."""

    stiffness_profile: str = param(
        "contact-ratio", choices=STIFFNESS_PROFILES, doc="how k_z(p) is given (or computed from geometry)"
    )
    geometry: MeshGeometry | None = param(
        None, doc="gear-pair geometry; required by iso-6336-b and potential-energy"
    )
    stiffness_single_N_per_m: float | None = param(
        None, gt=0, doc="k_z with one tooth pair in contact (default 1.2e9; geometry: computed)"
    )
    stiffness_double_N_per_m: float | None = param(
        None, gt=0, doc="k_z with two tooth pairs in contact (default 1.3e9; geometry: computed)"
    )
    contact_ratio: float | None = param(
        None, ge=1, lt=2, doc="transverse contact ratio eps_alpha (default 1.6; geometry: computed)"
    )
    table_phase: tuple[float, ...] = param((), doc="mesh phases in [0, 1) of a k_z table")
    table_stiffness_N_per_m: tuple[float, ...] = param((), doc="k_z at table_phase")
    damping_Ns_per_m: float = param(0.0, ge=0, doc="mesh damping C_z")
    backlash_um: float | None = param(
        None, ge=0, doc="l_u: half-width of the dead zone of eq. (4) (default 0; geometry: from allowances)"
    )
    pressure_angle_deg: float | None = param(
        None, gt=0, lt=45, doc="operating pressure angle (default 20; geometry: working transverse angle)"
    )
    pitch_point_phase: float | None = param(
        None, ge=0, le=1, doc="mesh phase where friction reverses (default 0.5; geometry: computed)"
    )
    centre_line_deg: float = param(
        0.0, ge=-360, le=360, doc="direction from pinion to wheel centre (lateral models)"
    )
    line_of_action_deg: float = param(
        -90.0, ge=-360, le=360, doc="direction of the mesh force on the wheel (lateral models)"
    )
    transition_width: float = param(
        0.0,
        ge=0,
        le=0.1,
        doc="fraction of the mesh period over which each jump of the law (k_z switches, tooth change, "
        "friction at the tooth change, pit edges) is spread; 0 = sharp",
    )

    def __post_init__(self) -> None:
        if self.stiffness_profile in FROM_GEOMETRY and self.geometry is None:
            raise ScenarioError(
                f"stiffness_profile = {self.stiffness_profile!r} computes k_z from the gears: add a "
                "[geometry] table (module_mm, face_width_mm, ...)"
            )
        if self.geometry is None:  # hand-given mesh: fill the documented defaults
            for key, value in MESH_DEFAULTS.items():
                if getattr(self, key) is None:
                    object.__setattr__(self, key, value)
        if self.backlash_um is None and (self.geometry is None or not self.geometry.sets_backlash):
            object.__setattr__(self, "backlash_um", 0.0)
        if self.contact_ratio is None:  # geometry not yet resolved (Scenario resolves it)
            return
        w = self.transition_width
        if w > 0:
            h = 0.5 * (self.contact_ratio - 1.0)
            if self.stiffness_profile != "table" and h > 0 and w > min(2 * h, 1 - 2 * h):
                raise ScenarioError(
                    f"transition_width = {w:g} with contact_ratio = {self.contact_ratio:g}: the width must "
                    f"not exceed the double or the single contact zone, <= {min(2 * h, 1 - 2 * h):g}"
                )
            if 0 < self.pitch_point_phase < 1 and not w / 2 <= self.pitch_point_phase <= 1 - w / 2:
                raise ScenarioError(
                    f"transition_width = {w:g} with pitch_point_phase = {self.pitch_point_phase:g}: the "
                    f"pitch point must lie in [{w / 2:g}, {1 - w / 2:g}] (or be 0 or 1)"
                )
        if abs(self.line_of_action_normal_projection) < 0.5:
            raise ScenarioError(
                f"line_of_action_deg = {self.line_of_action_deg:g} with centre_line_deg = "
                f"{self.centre_line_deg:g}: the line of action must lie within 60 deg of the normal "
                "of the centre line (for pressure angle alpha: centre_line_deg -+ (90 - alpha))"
            )
        if self.stiffness_profile == "table":
            ph, k = self.table_phase, self.table_stiffness_N_per_m
            if len(ph) < 2 or len(ph) != len(k):
                raise ScenarioError(
                    f"table_phase ({len(ph)} values) and table_stiffness_N_per_m ({len(k)} values) "
                    "must have the same length >= 2"
                )
            if any(not 0 <= p < 1 for p in ph) or any(b <= a for a, b in zip(ph, ph[1:], strict=False)):
                raise ScenarioError(f"table_phase = {list(ph)}: must increase strictly within [0, 1)")
            if any(v < 0 for v in k):
                raise ScenarioError(f"table_stiffness_N_per_m = {list(k)}: values must be >= 0")

    @property
    def line_of_action_normal_projection(self) -> float:
        """n . e_perp: n the line of action, e_perp the normal of the centre line."""
        lam, gam = math.radians(self.line_of_action_deg), math.radians(self.centre_line_deg)
        return math.cos(lam) * -math.sin(gam) + math.sin(lam) * math.cos(gam)
