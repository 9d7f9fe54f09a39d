"""The geometry of record of an external involute gear pair, :class:`GearPairGeometry`, with gearbody's
mesh-phase convention. Built by :func:`.gear_geometry.gear_pair_geometry` (equations and checks there).
Engine-free; numpy/math only.

Mesh-phase convention of gearbody (docs/scenario.md; :func:`gearbody.physics.mesh.stiffness_at_phase`):
one mesh period is one transverse base pitch of travel along the line of action; the pair assigned to a
period passes the middle of the single-contact zone, ``(B + D)/2 = (A + E)/2``, at p = 0.5, so its contact
runs over ``-h <= p < 1 + h`` with ``h = (eps_alpha - 1)/2``; contact point
``s(p) = (A + E)/2 + (p - 0.5) p_bt``.
Friction arms are the radii of curvature of the flanks at the contact point (the distance to each
gear's base tangent point, not to the pitch point): ``rho_1 = s``, ``rho_2 = T1T2 - s``; at the pitch point
``rho_1 = r_b1 tan(alpha_wt)``, as in mesh.py.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np


@dataclasses.dataclass(frozen=True)
class GearPairGeometry:
    """Geometry of an external involute gear pair (pinion = gear 1); build it with
    :func:`.gear_geometry.gear_pair_geometry`.

    Positions on the line of action (``*_position_m``) are distances from T1, the tangent point on the
    pinion base circle, towards T2.
    """

    module_m: float  # normal module m_n
    teeth_pinion: int
    teeth_wheel: int
    face_width_m: float
    pressure_angle_rad: float  # normal pressure angle alpha_n
    helix_angle_rad: float  # |beta| at the reference cylinder
    profile_shift_pinion: float
    profile_shift_wheel: float
    addendum_coefficient: float
    dedendum_coefficient: float
    transverse_module_m: float
    transverse_pressure_angle_rad: float  # alpha_t
    base_helix_angle_rad: float  # beta_b
    working_pressure_angle_rad: float  # alpha_wt, transverse
    reference_centre_distance_m: float  # a = r1 + r2
    centre_distance_m: float  # working a_w
    tip_alteration_coefficient: float  # k = (a_w - a)/m_n - (x1 + x2)
    pitch_radius_pinion_m: float
    pitch_radius_wheel_m: float
    base_radius_pinion_m: float
    base_radius_wheel_m: float
    tip_radius_pinion_m: float
    tip_radius_wheel_m: float
    root_radius_pinion_m: float
    root_radius_wheel_m: float
    tip_thickness_pinion_m: float  # normal, s_an
    tip_thickness_wheel_m: float
    transverse_base_pitch_m: float  # p_bt
    line_of_action_length_m: float  # T1T2
    contact_start_position_m: float  # A
    single_start_position_m: float  # B
    pitch_point_position_m: float  # C
    single_end_position_m: float  # D
    contact_end_position_m: float  # E
    transverse_contact_ratio: float  # eps_alpha
    overlap_ratio: float  # eps_beta

    @property
    def total_contact_ratio(self) -> float:
        """eps_gamma = eps_alpha + eps_beta."""
        return self.transverse_contact_ratio + self.overlap_ratio

    @property
    def working_pitch_radius_pinion_m(self) -> float:
        """r_w1 = r_b1 / cos(alpha_wt)."""
        return self.base_radius_pinion_m / math.cos(self.working_pressure_angle_rad)

    @property
    def working_pitch_radius_wheel_m(self) -> float:
        """r_w2 = r_b2 / cos(alpha_wt)."""
        return self.base_radius_wheel_m / math.cos(self.working_pressure_angle_rad)

    @property
    def path_of_contact_m(self) -> float:
        """g_alpha = E - A."""
        return self.contact_end_position_m - self.contact_start_position_m

    @property
    def half_double_contact(self) -> float:
        """h = (eps_alpha - 1)/2: double contact for p < h or p >= 1 - h (when eps_alpha < 2)."""
        return 0.5 * (self.transverse_contact_ratio - 1.0)

    @property
    def pitch_point_phase(self) -> float:
        """Mesh phase at which the period's pair passes the pitch point C (0.5 + (C - (A+E)/2)/p_bt).

        May lie outside [0, 1) for strongly unequal addendum paths; gearbody's scenario needs [0, 1].
        """
        return self.phase_at_position(self.pitch_point_position_m)

    def position_on_line_of_action_m(self, phase: float | np.ndarray) -> float | np.ndarray:
        """Contact point of the period's pair at mesh phase p, distance from T1: (A+E)/2 + (p - 0.5) p_bt."""
        mid = 0.5 * (self.contact_start_position_m + self.contact_end_position_m)
        return mid + (phase - 0.5) * self.transverse_base_pitch_m

    def phase_at_position(self, position_m: float | np.ndarray) -> float | np.ndarray:
        """Inverse of :meth:`position_on_line_of_action_m`."""
        mid = 0.5 * (self.contact_start_position_m + self.contact_end_position_m)
        return 0.5 + (position_m - mid) / self.transverse_base_pitch_m

    def pairs_in_contact(self, phase: float) -> tuple[tuple[int, float], ...]:
        """Tooth pairs in contact at mesh phase p in [0, 1): ``(offset, position_m)`` per pair, by offset.

        Offset 0 is the period's pair, -1 the previous (outgoing, at its own phase p + 1), +1 the next
        (incoming, at p - 1), and so on. A pair is in contact over ``-h <= own phase < 1 + h``; the bounds
        are written as in ``stiffness_at_phase`` (previous pair: ``p < h``; next pair: ``p >= 1 - h``).
        """
        h = self.half_double_contact
        reach = math.ceil(h) + 1
        pairs = []
        for k in range(-reach, reach + 1):
            if k - h <= phase < (k + 1) + h:
                pairs.append((k, float(self.position_on_line_of_action_m(phase - k))))
        return tuple(pairs)

    def friction_arms_m(
        self, position_m: float | np.ndarray
    ) -> tuple[float | np.ndarray, float | np.ndarray]:
        """Friction arms (rho_1, rho_2) at a contact position s from T1: (s, T1T2 - s), m."""
        return position_m, self.line_of_action_length_m - position_m
