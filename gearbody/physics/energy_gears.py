r"""Gears and gear pairs of the potential-energy mesh stiffness (:mod:`.stiffness_energy`). Engine-free.

A :class:`SpurGear` adds to the basic-rack data what the tooth compliances need (bore, rack tip radius,
material); its radii come from :func:`.gear_geometry.gear_radii`. A :class:`SpurPair` takes its pair
geometry (working pressure angle, centre distance, base pitch, line of action, contact limits, contact
ratio, contact point over the mesh phase) from :func:`.gear_geometry.gear_pair_geometry`, the one gear
geometry of gearbody (ISO 21771; see there for the equations and the checks). All lengths in m.

Roll position ``s`` of a contact point: its distance along the line of action from the pinion's
base-circle tangent point ``T1``; contact runs from ``s_start = a sin(alpha_w) - sqrt(r_a2^2 - r_b2^2)``
(pinion root, wheel tip) to ``s_end = sqrt(r_a1^2 - r_b1^2)`` (pinion tip). The wheel's roll length is
``a sin(alpha_w) - s``.

Mesh-phase convention (gearbody, ``mesh.stiffness_at_phase``, docs/scenario.md): ``p`` in [0, 1), one
period = one base pitch of roll (pinion drives, ``s`` grows with ``p``). The pair assigned to a period
is at ``s(p) = s_mid + (p - 0.5) p_b``, ``s_mid = (s_start + s_end) / 2``: it is alone in contact at
p = 0.5 (middle of the single-contact zone) and in contact for ``|p - 0.5| <= eps / 2``. The pair of
period ``n + j`` is at its own phase ``p - j`` (``j = -1`` outgoing, ``+1`` incoming). Total mesh
stiffness ``k(p) = sum_j k_pair(s(p - j))`` over the pairs in contact. (The pitch point is at
``p = 0.5`` only for equal gears; gearbody's ``pitch_point_phase`` is a separate friction parameter.)
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .gear_geometry import GearPairGeometry, GearRadii, gear_pair_geometry, gear_radii, involute

GearName = Literal["pinion", "wheel"]
GEARS: tuple[GearName, GearName] = ("pinion", "wheel")


@dataclass(frozen=True)
class SpurGear:
    """One spur gear: basic-rack geometry, body bore and material (SI units)."""

    teeth: int
    module_m: float
    face_width_m: float
    bore_radius_m: float
    pressure_angle_deg: float = 20.0
    profile_shift: float = 0.0
    addendum_coefficient: float = 1.0
    dedendum_coefficient: float = 1.25
    rack_tip_radius_coefficient: float | None = None  # None: full round, (h_f* - h_a*) / (1 - sin alpha)
    youngs_modulus_Pa: float = 2.06e11
    poisson_ratio: float = 0.3

    @functools.cached_property
    def radii(self) -> GearRadii:
        """Pitch, base, tip and root radius (:func:`.gear_geometry.gear_radii`)."""
        return gear_radii(
            teeth=self.teeth,
            module_m=self.module_m,
            pressure_angle_deg=self.pressure_angle_deg,
            profile_shift=self.profile_shift,
            addendum_coefficient=self.addendum_coefficient,
            dedendum_coefficient=self.dedendum_coefficient,
        )

    @property
    def pressure_angle_rad(self) -> float:
        return math.radians(self.pressure_angle_deg)

    @property
    def pitch_radius_m(self) -> float:
        return self.radii.pitch_m

    @property
    def base_radius_m(self) -> float:
        return self.radii.base_m

    @property
    def tip_radius_m(self) -> float:
        return self.radii.tip_m

    @property
    def root_radius_m(self) -> float:
        return self.radii.root_m

    @property
    def half_base_tooth_angle_rad(self) -> float:
        """alpha_2 = (pi/2 + 2 x tan(alpha)) / z + inv(alpha)."""
        a = self.pressure_angle_rad
        return (0.5 * math.pi + 2.0 * self.profile_shift * math.tan(a)) / self.teeth + involute(a)

    @property
    def root_half_angle_rad(self) -> float:
        """theta_f: half tooth angle at the root circle (end of the rack-generated fillet)."""
        a = self.pressure_angle_rad
        rho = self.rack_tip_radius_coefficient
        if rho is None:
            rho = (self.dedendum_coefficient - self.addendum_coefficient) / (1.0 - math.sin(a))
        return (
            0.5 * math.pi
            + 2.0 * self.dedendum_coefficient * math.tan(a)
            + 2.0 * rho * (1.0 - math.sin(a)) / math.cos(a)
        ) / self.teeth

    @property
    def shear_modulus_Pa(self) -> float:
        return self.youngs_modulus_Pa / (2.0 * (1.0 + self.poisson_ratio))

    def load_angle_rad(self, roll_length_m: float) -> float:
        """alpha_1 = t - alpha_2 for a contact at roll length ``r_b tan(alpha_r)`` on this gear."""
        return roll_length_m / self.base_radius_m - self.half_base_tooth_angle_rad

    def contact_radius_m(self, roll_length_m: float) -> float:
        return math.hypot(self.base_radius_m, roll_length_m)


@dataclass(frozen=True)
class SpurPair:
    """A pinion-wheel pair; ``center_distance_m`` None = zero-backlash distance from the profile shifts.

    Both gears need the same basic rack (module, pressure angle, addendum and dedendum coefficients). The
    pair geometry is :attr:`geometry` (:func:`.gear_geometry.gear_pair_geometry`, which refuses unsound
    pairs with a :class:`~.exceptions.GearGeometryError`); a given centre distance is taken as it is (no
    tolerance against the shifts: it may include backlash). The properties below are that geometry's
    values under the names the energy method uses."""

    pinion: SpurGear
    wheel: SpurGear
    center_distance_m: float | None = None

    def __post_init__(self) -> None:
        p, w = self.pinion, self.wheel
        for name in ("module_m", "pressure_angle_deg", "addendum_coefficient", "dedendum_coefficient"):
            if not math.isclose(getattr(p, name), getattr(w, name)):
                raise ValueError(
                    "pinion and wheel need the same module, pressure angle and basic rack (addendum and "
                    f"dedendum coefficients); {name} is {getattr(p, name)!r} and {getattr(w, name)!r}"
                )
        self.geometry  # noqa: B018  (computed and checked now, not at the first stiffness)

    @functools.cached_property
    def geometry(self) -> GearPairGeometry:
        """The pair's geometry of record (the pinion's basic rack; face width = contact width)."""
        p, w = self.pinion, self.wheel
        return gear_pair_geometry(
            module_m=p.module_m,
            teeth_pinion=p.teeth,
            teeth_wheel=w.teeth,
            face_width_m=self.contact_width_m,
            pressure_angle_deg=p.pressure_angle_deg,
            profile_shift_pinion=p.profile_shift,
            profile_shift_wheel=w.profile_shift,
            addendum_coefficient=p.addendum_coefficient,
            dedendum_coefficient=p.dedendum_coefficient,
            centre_distance_m=self.center_distance_m,
            centre_distance_tolerance_m=None if self.center_distance_m is None else math.inf,
        )

    @property
    def working_pressure_angle_rad(self) -> float:
        return self.geometry.working_pressure_angle_rad

    @property
    def operating_center_distance_m(self) -> float:
        return self.geometry.centre_distance_m

    @property
    def line_of_centres_m(self) -> float:
        """T1 T2 = a sin(alpha_w): distance between the two base-circle tangent points."""
        return self.geometry.line_of_action_length_m

    @property
    def base_pitch_m(self) -> float:
        return self.geometry.transverse_base_pitch_m

    @property
    def contact_start_m(self) -> float:
        return self.geometry.contact_start_position_m

    @property
    def contact_end_m(self) -> float:
        return self.geometry.contact_end_position_m

    @property
    def contact_length_m(self) -> float:
        return self.geometry.path_of_contact_m

    @property
    def contact_ratio(self) -> float:
        return self.geometry.transverse_contact_ratio

    @property
    def contact_width_m(self) -> float:
        return min(self.pinion.face_width_m, self.wheel.face_width_m)

    def roll_position_m(self, pair_phase: float | np.ndarray) -> float | np.ndarray:
        """s of the pair at its own mesh phase (0.5 = middle of its contact)."""
        return self.geometry.position_on_line_of_action_m(np.asarray(pair_phase))

    def in_contact(self, roll_position_m: float) -> bool:
        tol = 1e-12 * self.base_pitch_m
        return self.contact_start_m - tol <= roll_position_m <= self.contact_end_m + tol

    def gear(self, name: GearName) -> SpurGear:
        if name not in ("pinion", "wheel"):
            raise ValueError(f"gear must be 'pinion' or 'wheel', not {name!r}")
        return self.pinion if name == "pinion" else self.wheel

    def roll_length_on_m(self, name: GearName, roll_position_m: float) -> float:
        """Roll length r_b tan(alpha_r) of the contact point on the named gear."""
        return roll_position_m if name == "pinion" else self.line_of_centres_m - roll_position_m
