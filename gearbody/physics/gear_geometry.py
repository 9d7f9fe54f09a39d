"""Involute gear-pair geometry (external spur and helical gears) in gearbody's mesh-phase convention.

Engine-free; numpy/math only. Lengths in metres, angles in radians inside (``*_rad``), degrees only as
inputs (``*_deg``). Transverse-plane quantities unless the name says normal. Sources: ISO 21771:2007
(geometry), ISO 53 (basic rack), ISO/TR 10064-2 and Niemann & Winter, Maschinenelemente II (backlash),
ISO/TR 6336-30:2017 Example 1 (helical check case).

Equations (gear k = 1 pinion, 2 wheel; h_a*, h_f* addendum/dedendum coefficients of the basic rack):

- ``m_t = m_n / cos(beta)``, ``tan(alpha_t) = tan(alpha_n) / cos(beta)``,
  ``tan(beta_b) = tan(beta) cos(alpha_t)``;
- ``r_k = z_k m_t / 2``, ``r_bk = r_k cos(alpha_t)``, ``r_ak = r_k + m_n (h_a* + x_k + k)``,
  ``r_fk = r_k - m_n (h_f* - x_k)``; ``k`` = tip alteration, applied only with ``tip_shortening``;
- ``inv(a) = tan(a) - a``; working pressure angle from the shifts (no backlash)
  ``inv(alpha_wt) = inv(alpha_t) + 2 tan(alpha_n) (x1 + x2) / (z1 + z2)``,
  ``a_w = (r1 + r2) cos(alpha_t) / cos(alpha_wt)``; if ``a_w`` is given,
  ``cos(alpha_wt) = a cos(alpha_t) / a_w``
  and it must agree with the shifts within ``centre_distance_tolerance_m`` (default 0.005 m_n); the
  difference is the design's centre-distance backlash, ``k = (a_w - a)/m_n - (x1 + x2)``;
- transverse base pitch ``p_bt = pi m_t cos(alpha_t)``; line of action ``T1T2 = a_w sin(alpha_wt)``;
  points measured from T1 (tangent point on the pinion base circle):
  ``E = sqrt(r_a1² - r_b1²)`` (pinion tip, end of contact), ``A = T1T2 - sqrt(r_a2² - r_b2²)``
  (wheel tip, start of contact), ``C = r_b1 tan(alpha_wt)``, ``B = E - p_bt``, ``D = A + p_bt``;
- ``eps_alpha = (E - A) / p_bt`` (= g_alpha / p_bt), ``eps_beta = b sin(beta) / (pi m_n)``,
  ``eps_gamma = eps_alpha + eps_beta``;
- undercut: ``z_min = 2 (h_a* - x) cos(beta) / sin²(alpha_t)`` (rack whose straight flank reaches
  h_a* m_n, ISO 53: h_FfP = h_fP - c_P = h_aP); the generated involute starts at roll length
  ``rho_F = r sin(alpha_t) - (h_a* - x) m_n / sin(alpha_t)`` from the base tangent point;
- normal tip thickness ``s_an = s_at cos(beta_a)``,
  ``s_at = d_a [(pi + 4 x tan(alpha_n)) / (2 z) + inv(alpha_t) - inv(alpha_at)]``,
  ``cos(alpha_at) = r_b / r_a``, ``tan(beta_a) = tan(beta) r_a / r``;
- backlash (Niemann & Winter; ISO/TR 10064-2): base normal backlash
  ``j_bn = -(E_sn1 + E_sn2) cos(alpha_n) + 2 Delta_a sin(alpha_wt) cos(beta_b)``
  (E_sn: normal tooth-thickness allowance, negative = thinner; Delta_a: centre-distance deviation;
  uses cos(alpha_t) cos(beta_b) / cos(beta) = cos(alpha_n)); along the transverse line of action
  ``j_bt = j_bn / cos(beta_b)``; gearbody's eq. (4) half-width ``l_u = j_bt / 2`` (= j_bn / 2 for spur).

Checks (:class:`~gearbody.physics.exceptions.GearGeometryError`, a ``ValueError`` that the model turns
into a ``ScenarioError``, naming parameter, value and allowed range): positive inputs, undercut, centre
distance vs shifts, tip thickness ``s_an >= 0.2 m_n``, tip-root clearance ``>= 0``, interference (contact
start before T1 or end beyond T2, or into the non-involute root below rho_F), ``eps_alpha >= 1``.

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
from scipy.optimize import brentq

from .exceptions import GearGeometryError, geometry_error

MIN_TIP_THICKNESS_MODULES = 0.2  # s_an >= 0.2 m_n (common design limit; 0.2-0.4 m_n)
CENTRE_DISTANCE_TOLERANCE_MODULES = 0.005  # |a_w - a_w(x1 + x2)| <= 0.005 m_n unless told otherwise
_INVERSE_INVOLUTE_BRACKET_RAD = (1e-6, 1.5)


__all__ = [
    "GearGeometryError",
    "GearPairGeometry",
    "GearRadii",
    "backlash_half_width_m",
    "backlash_range_m",
    "gear_pair_geometry",
    "gear_radii",
    "inverse_involute",
    "involute",
    "normal_backlash_m",
    "transverse_module_and_pressure_angle",
]


def involute(angle_rad: float) -> float:
    """Involute function inv(a) = tan(a) - a."""
    return math.tan(angle_rad) - angle_rad


def inverse_involute(value: float) -> float:
    """Angle a in [1e-6, 1.5] rad with inv(a) = value (0 < value <= inv(1.5) = 12.6)."""
    lo, hi = _INVERSE_INVOLUTE_BRACKET_RAD
    if value <= 0.0:
        raise ValueError(f"inverse_involute: value = {value:g} must be > 0")
    if not involute(lo) <= value <= involute(hi):
        raise ValueError(f"inverse_involute: value = {value:g} outside [inv({lo:g}), inv({hi:g})]")
    return brentq(lambda a: involute(a) - value, lo, hi, xtol=1e-15)


def transverse_module_and_pressure_angle(
    module_m: float, pressure_angle_rad: float, helix_angle_rad: float
) -> tuple[float, float]:
    """(m_t, alpha_t): ``m_n / cos(beta)`` and ``atan(tan(alpha_n) / cos(beta))``; exactly (m_n, alpha_n)
    for spur gears."""
    if helix_angle_rad == 0.0:
        return module_m, pressure_angle_rad
    return (
        module_m / math.cos(helix_angle_rad),
        math.atan(math.tan(pressure_angle_rad) / math.cos(helix_angle_rad)),
    )


def _pitch_base_root_radii_m(z, x, mn, mt, alpha_t, hf) -> tuple[float, float, float]:
    r = 0.5 * z * mt
    return r, r * math.cos(alpha_t), r - mn * (hf - x)


def _tip_radius_m(r, x, mn, ha, k=0.0) -> float:
    return r + mn * (ha + x + k)


@dataclasses.dataclass(frozen=True)
class GearRadii:
    """Reference (pitch), base, tip and root radius of one gear, m."""

    pitch_m: float
    base_m: float
    tip_m: float
    root_m: float


def gear_radii(
    *,
    teeth: int,
    module_m: float,
    pressure_angle_deg: float = 20.0,
    helix_angle_deg: float = 0.0,
    profile_shift: float = 0.0,
    addendum_coefficient: float = 1.0,
    dedendum_coefficient: float = 1.25,
) -> GearRadii:
    """Radii of one gear (module docstring: r, r_b, r_a without tip alteration, r_f); no checks. The same
    arithmetic as :func:`gear_pair_geometry`, which also checks the pair."""
    alpha_n, beta = math.radians(pressure_angle_deg), abs(math.radians(helix_angle_deg))
    mt, alpha_t = transverse_module_and_pressure_angle(module_m, alpha_n, beta)
    x = profile_shift
    r, rb, rf = _pitch_base_root_radii_m(teeth, x, module_m, mt, alpha_t, dedendum_coefficient)
    return GearRadii(r, rb, _tip_radius_m(r, x, module_m, addendum_coefficient), rf)


@dataclasses.dataclass(frozen=True)
class GearPairGeometry:
    """Geometry of an external involute gear pair (pinion = gear 1); build it with :func:`gear_pair_geometry`.

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


def gear_pair_geometry(
    *,
    module_m: float,
    teeth_pinion: int,
    teeth_wheel: int,
    face_width_m: float,
    pressure_angle_deg: float = 20.0,
    helix_angle_deg: float = 0.0,
    profile_shift_pinion: float = 0.0,
    profile_shift_wheel: float = 0.0,
    addendum_coefficient: float = 1.0,
    dedendum_coefficient: float = 1.25,
    centre_distance_m: float | None = None,
    centre_distance_tolerance_m: float | None = None,
    tip_shortening: bool = False,
    tip_diameters_m: tuple[float, float] | None = None,
) -> GearPairGeometry:
    """Geometry of an external involute gear pair from its basic data (module = normal module m_n).

    ``centre_distance_m`` None: the no-backlash distance from the shifts. ``tip_shortening``: reduce both tip
    radii by |k| m_n when k < 0 (ISO 21771 tip alteration, keeps the bottom clearance). ``tip_diameters_m``:
    given (pinion, wheel) tip diameters override the computed ones (e.g. a drawing's rounded values).
    Raises :class:`GearGeometryError` for impossible or unsound pairs (module docstring, "Checks").
    """
    _check_inputs(
        module_m,
        teeth_pinion,
        teeth_wheel,
        face_width_m,
        pressure_angle_deg,
        helix_angle_deg,
        addendum_coefficient,
        dedendum_coefficient,
        (profile_shift_pinion, profile_shift_wheel),
        centre_distance_m,
    )
    mn, z1, z2 = module_m, int(teeth_pinion), int(teeth_wheel)
    x1, x2, ha, hf = profile_shift_pinion, profile_shift_wheel, addendum_coefficient, dedendum_coefficient
    alpha_n, beta = math.radians(pressure_angle_deg), abs(math.radians(helix_angle_deg))
    mt, alpha_t = transverse_module_and_pressure_angle(mn, alpha_n, beta)
    beta_b = math.atan(math.tan(beta) * math.cos(alpha_t))
    r1, rb1, rf1 = _pitch_base_root_radii_m(z1, x1, mn, mt, alpha_t, hf)
    r2, rb2, rf2 = _pitch_base_root_radii_m(z2, x2, mn, mt, alpha_t, hf)

    for name, z, x in (("teeth_pinion", z1, x1), ("teeth_wheel", z2, x2)):
        z_min = 2.0 * (ha - x) * math.cos(beta) / math.sin(alpha_t) ** 2
        if z < z_min:
            shift = "profile_shift_pinion" if name == "teeth_pinion" else "profile_shift_wheel"
            x_min = ha - z * math.sin(alpha_t) ** 2 / (2.0 * math.cos(beta))
            raise geometry_error(
                name, z, f"undercut with {shift} = {x:g}", f">= {z_min:.4g} teeth, or {shift} >= {x_min:.4g}"
            )

    a = r1 + r2
    inv_t = involute(alpha_t)
    inv_wt = inv_t + 2.0 * math.tan(alpha_n) * (x1 + x2) / (z1 + z2)
    if inv_wt <= 0.0:
        x_lim = -involute(alpha_t) * (z1 + z2) / (2.0 * math.tan(alpha_n))
        raise geometry_error(
            "profile_shift_pinion + profile_shift_wheel",
            x1 + x2,
            "no working pressure angle",
            f"> {x_lim:.4g}",
        )
    # shifts summing to (about) zero: alpha_wt = alpha_t exactly, not the solver's approximation
    alpha_wt_shifts = alpha_t if abs(inv_wt - inv_t) < 1e-15 else inverse_involute(inv_wt)
    a_w_shifts = a * math.cos(alpha_t) / math.cos(alpha_wt_shifts)
    if centre_distance_m is None:
        a_w, alpha_wt = a_w_shifts, alpha_wt_shifts
    else:
        tol = (
            CENTRE_DISTANCE_TOLERANCE_MODULES * mn
            if centre_distance_tolerance_m is None
            else centre_distance_tolerance_m
        )
        if abs(centre_distance_m - a_w_shifts) > tol:
            raise geometry_error(
                "centre_distance_m",
                float(centre_distance_m),
                f"does not match the profile shifts x1 + x2 = {x1 + x2:g} "
                f"(no-backlash distance {a_w_shifts:.6g} m)",
                f"[{a_w_shifts - tol:.6g}, {a_w_shifts + tol:.6g}] m",
            )
        if centre_distance_m <= a * math.cos(alpha_t):
            raise geometry_error(
                "centre_distance_m",
                float(centre_distance_m),
                "below the base-circle sum",
                f"> {a * math.cos(alpha_t):.6g} m",
            )
        a_w = float(centre_distance_m)
        alpha_wt = math.acos(a * math.cos(alpha_t) / a_w)
    k = (a_w - a) / mn - (x1 + x2)

    if tip_diameters_m is not None:
        ra1, ra2 = 0.5 * tip_diameters_m[0], 0.5 * tip_diameters_m[1]
        for name, ra, r in (("tip_diameters_m[0]", ra1, r1), ("tip_diameters_m[1]", ra2, r2)):
            if not ra > r:
                raise geometry_error(
                    name, 2.0 * ra, "tip diameter not above the reference diameter", f"> {2.0 * r:.6g} m"
                )
    else:
        shortening = k if (tip_shortening and k < 0.0) else 0.0
        ra1, ra2 = _tip_radius_m(r1, x1, mn, ha, shortening), _tip_radius_m(r2, x2, mn, ha, shortening)

    pbt = 2.0 * math.pi * rb1 / z1  # = pi m_t cos(alpha_t)
    t1t2 = a_w * math.sin(alpha_wt)
    s_e = math.sqrt(ra1**2 - rb1**2)
    s_a = t1t2 - math.sqrt(ra2**2 - rb2**2)
    s_c = rb1 * math.tan(alpha_wt)
    rho_f1 = r1 * math.sin(alpha_t) - (ha - x1) * mn / math.sin(alpha_t)
    rho_f2 = r2 * math.sin(alpha_t) - (ha - x2) * mn / math.sin(alpha_t)
    if s_a < 0.0:
        raise geometry_error(
            "tip_radius_wheel_m",
            ra2,
            "contact starts before T1 (interference below the pinion base circle)",
            f"<= {math.hypot(t1t2, rb2):.6g} m",
        )
    if s_e > t1t2:
        raise geometry_error(
            "tip_radius_pinion_m",
            ra1,
            "contact ends beyond T2 (interference below the wheel base circle)",
            f"<= {math.hypot(t1t2, rb1):.6g} m",
        )
    san1 = _normal_tip_thickness_m(z1, x1, r1, rb1, ra1, alpha_n, alpha_t, beta)
    san2 = _normal_tip_thickness_m(z2, x2, r2, rb2, ra2, alpha_n, alpha_t, beta)
    s_min = MIN_TIP_THICKNESS_MODULES * mn
    for i, (name, san, x) in enumerate(
        (("profile_shift_pinion", san1, x1), ("profile_shift_wheel", san2, x2))
    ):
        if san < s_min:
            if tip_diameters_m is not None:
                name, x = f"tip_diameters_m[{i}]", float(tip_diameters_m[i])
            raise geometry_error(
                name,
                x,
                f"tip too thin, normal tip thickness {san:.4g} m",
                f"a value giving s_an >= 0.2 m_n = {s_min:.4g} m",
            )
    for name, clearance in (("tip_radius_pinion", a_w - ra1 - rf2), ("tip_radius_wheel", a_w - ra2 - rf1)):
        if clearance < 0.0:
            raise geometry_error(
                "centre_distance_m",
                a_w,
                f"{name} reaches {-clearance:.4g} m into the mating root (try tip_shortening=True)",
                ">= 0 m tip-root clearance",
            )

    if s_a < rho_f1:
        limit = math.hypot(t1t2 - rho_f1, rb2)
        raise geometry_error(
            "tip_radius_wheel_m",
            ra2,
            "contact starts below the generated involute of the pinion (root interference)",
            f"<= {limit:.6g} m",
        )
    if t1t2 - s_e < rho_f2:
        limit = math.hypot(t1t2 - rho_f2, rb1)
        raise geometry_error(
            "tip_radius_pinion_m",
            ra1,
            "contact ends below the generated involute of the wheel (root interference)",
            f"<= {limit:.6g} m",
        )
    eps_alpha = (s_e - s_a) / pbt
    if eps_alpha < 1.0:
        raise geometry_error(
            "transverse_contact_ratio", eps_alpha, "less than one pair always in contact", ">= 1"
        )

    return GearPairGeometry(
        module_m=mn,
        teeth_pinion=z1,
        teeth_wheel=z2,
        face_width_m=face_width_m,
        pressure_angle_rad=alpha_n,
        helix_angle_rad=beta,
        profile_shift_pinion=x1,
        profile_shift_wheel=x2,
        addendum_coefficient=ha,
        dedendum_coefficient=hf,
        transverse_module_m=mt,
        transverse_pressure_angle_rad=alpha_t,
        base_helix_angle_rad=beta_b,
        working_pressure_angle_rad=alpha_wt,
        reference_centre_distance_m=a,
        centre_distance_m=a_w,
        tip_alteration_coefficient=k,
        pitch_radius_pinion_m=r1,
        pitch_radius_wheel_m=r2,
        base_radius_pinion_m=rb1,
        base_radius_wheel_m=rb2,
        tip_radius_pinion_m=ra1,
        tip_radius_wheel_m=ra2,
        root_radius_pinion_m=rf1,
        root_radius_wheel_m=rf2,
        tip_thickness_pinion_m=san1,
        tip_thickness_wheel_m=san2,
        transverse_base_pitch_m=pbt,
        line_of_action_length_m=t1t2,
        contact_start_position_m=s_a,
        single_start_position_m=s_e - pbt,
        pitch_point_position_m=s_c,
        single_end_position_m=s_a + pbt,
        contact_end_position_m=s_e,
        transverse_contact_ratio=eps_alpha,
        overlap_ratio=face_width_m * math.sin(beta) / (math.pi * mn),
    )


def _normal_tip_thickness_m(z, x, r, rb, ra, alpha_n, alpha_t, beta) -> float:
    alpha_at = math.acos(rb / ra)
    s_at = (
        2.0
        * ra
        * ((math.pi + 4.0 * x * math.tan(alpha_n)) / (2.0 * z) + involute(alpha_t) - involute(alpha_at))
    )
    beta_a = math.atan(math.tan(beta) * ra / r)
    return s_at * math.cos(beta_a)


def _check_inputs(mn, z1, z2, b, alpha_deg, beta_deg, ha, hf, shifts, a_w) -> None:
    if not (isinstance(mn, (int, float)) and mn > 0.0 and math.isfinite(mn)):
        raise geometry_error("module_m", mn, "module must be positive", "> 0 m")
    for name, z in (("teeth_pinion", z1), ("teeth_wheel", z2)):
        if isinstance(z, bool) or int(z) != z or z < 5:
            raise geometry_error(name, z, "tooth count must be a whole number of at least 5", "integer >= 5")
    if not b > 0.0:
        raise geometry_error("face_width_m", b, "face width must be positive", "> 0 m")
    if not 0.0 < alpha_deg < 45.0:
        raise geometry_error(
            "pressure_angle_deg", alpha_deg, "normal pressure angle out of range", "> 0 and < 45"
        )
    if not -45.0 < beta_deg < 45.0:
        raise geometry_error("helix_angle_deg", beta_deg, "helix angle out of range", "> -45 and < 45")
    if not ha > 0.0:
        raise geometry_error("addendum_coefficient", ha, "addendum must be positive", "> 0")
    if not hf >= ha:
        raise geometry_error(
            "dedendum_coefficient",
            hf,
            "dedendum below the addendum (negative bottom clearance)",
            f">= {ha:g}",
        )
    for name, x in zip(("profile_shift_pinion", "profile_shift_wheel"), shifts, strict=True):
        if not math.isfinite(x):
            raise geometry_error(name, x, "profile shift must be finite", "finite")
    if a_w is not None and not a_w > 0.0:
        raise geometry_error("centre_distance_m", a_w, "centre distance must be positive", "> 0 m")


def normal_backlash_m(
    geometry: GearPairGeometry,
    *,
    thickness_allowance_pinion_m: float,
    thickness_allowance_wheel_m: float,
    centre_distance_deviation_m: float = 0.0,
) -> float:
    """Base normal backlash j_bn = -(E_sn1 + E_sn2) cos(alpha_n) + 2 Delta_a sin(alpha_wt) cos(beta_b), m.

    E_sn: normal tooth-thickness allowances (negative = thinner teeth); Delta_a: deviation of the actual
    from the nominal centre distance. Niemann & Winter, ISO/TR 10064-2 (first order in the deviations).
    """
    return -(thickness_allowance_pinion_m + thickness_allowance_wheel_m) * math.cos(
        geometry.pressure_angle_rad
    ) + 2.0 * centre_distance_deviation_m * math.sin(geometry.working_pressure_angle_rad) * math.cos(
        geometry.base_helix_angle_rad
    )


def backlash_half_width_m(geometry: GearPairGeometry, normal_backlash: float) -> float:
    """gearbody's l_u (``backlash_um`` * 1e-6): half the backlash along the transverse line of action,
    j_bn / (2 cos(beta_b)) (= j_bn / 2 for spur gears)."""
    return 0.5 * normal_backlash / math.cos(geometry.base_helix_angle_rad)


def backlash_range_m(
    geometry: GearPairGeometry,
    *,
    thickness_allowances_pinion_m: tuple[float, float],
    thickness_allowances_wheel_m: tuple[float, float],
    centre_distance_allowances_m: tuple[float, float] = (0.0, 0.0),
) -> tuple[float, float]:
    """(j_bn_min, j_bn_max), m, from (upper, lower) allowances E_sns, E_sni of each gear and (upper, lower)
    centre-distance allowances. The least backlash (upper thickness allowances, lower centre distance)
    must be >= 0, else the teeth jam."""
    for name, (upper, lower) in (
        ("thickness_allowances_pinion_m", thickness_allowances_pinion_m),
        ("thickness_allowances_wheel_m", thickness_allowances_wheel_m),
        ("centre_distance_allowances_m", centre_distance_allowances_m),
    ):
        if upper < lower:
            raise geometry_error(
                name,
                (upper, lower),
                "upper allowance below the lower one",
                "(upper, lower) with upper >= lower",
            )
    j_min = normal_backlash_m(
        geometry,
        thickness_allowance_pinion_m=thickness_allowances_pinion_m[0],
        thickness_allowance_wheel_m=thickness_allowances_wheel_m[0],
        centre_distance_deviation_m=centre_distance_allowances_m[1],
    )
    j_max = normal_backlash_m(
        geometry,
        thickness_allowance_pinion_m=thickness_allowances_pinion_m[1],
        thickness_allowance_wheel_m=thickness_allowances_wheel_m[1],
        centre_distance_deviation_m=centre_distance_allowances_m[0],
    )
    if j_min < 0.0:
        raise geometry_error(
            "normal_backlash_min_m", j_min, "the teeth jam at the upper thickness allowances", ">= 0 m"
        )
    return j_min, j_max
