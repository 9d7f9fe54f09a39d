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
- transverse base pitch ``p_bt = pi m_t cos(alpha_t) = 2 pi r_b1 / z1``; line of action
  ``T1T2 = a_w sin(alpha_wt)``; points measured from T1 (tangent point on the pinion base circle):
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
- backlash: :mod:`.gear_backlash`.

Arithmetic (kept to the last bit, the potential-energy pair table depends on it): spur gears take
``m_t = m_n`` and ``alpha_t = alpha_n`` as they are; shifts summing to zero give ``alpha_wt = alpha_t``
exactly, other shifts the root of the involute equation (no ``acos`` round trip); ``p_bt = 2 pi r_b1 / z1``.

Checks (:class:`~gearbody.physics.exceptions.GearGeometryError`, a ``ValueError`` that the model turns
into a ``ScenarioError``, naming parameter, value and allowed range): positive inputs, undercut, centre
distance vs shifts, tip thickness ``s_an >= 0.2 m_n``, tip-root clearance ``>= 0``, interference (contact
start before T1 or end beyond T2, or into the non-involute root below rho_F), ``eps_alpha >= 1``.

Module map: :mod:`.involute` (involute function, radii and tip thickness of one gear),
:mod:`.gear_pair` (the result, :class:`GearPairGeometry`, and the mesh-phase convention),
:mod:`.gear_backlash` (backlash); this module builds the pair and checks it, and re-exports the others'
public names.
"""

from __future__ import annotations

import math

from .exceptions import GearGeometryError, geometry_error
from .gear_backlash import backlash_half_width_m, backlash_range_m, normal_backlash_m
from .gear_pair import GearPairGeometry
from .involute import (
    GearRadii,
    gear_radii,
    inverse_involute,
    involute,
    normal_tip_thickness_m,
    pitch_base_root_radii_m,
    tip_radius_m,
    transverse_module_and_pressure_angle,
)

MIN_TIP_THICKNESS_MODULES = 0.2  # s_an >= 0.2 m_n (common design limit; 0.2-0.4 m_n)
CENTRE_DISTANCE_TOLERANCE_MODULES = 0.005  # |a_w - a_w(x1 + x2)| <= 0.005 m_n unless told otherwise

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
    # size: the ISO 21771 formula chain and its checks in order, read top to bottom (shared intermediates)
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
    r1, rb1, rf1 = pitch_base_root_radii_m(z1, x1, mn, mt, alpha_t, hf)
    r2, rb2, rf2 = pitch_base_root_radii_m(z2, x2, mn, mt, alpha_t, hf)

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
        ra1, ra2 = tip_radius_m(r1, x1, mn, ha, shortening), tip_radius_m(r2, x2, mn, ha, shortening)

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
    san1 = normal_tip_thickness_m(z1, x1, r1, rb1, ra1, alpha_n, alpha_t, beta)
    san2 = normal_tip_thickness_m(z2, x2, r2, rb2, ra2, alpha_n, alpha_t, beta)
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
