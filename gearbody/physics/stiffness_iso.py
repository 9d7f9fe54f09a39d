"""Tooth stiffness by ISO 6336-1 method B, and gearbody's two-level mesh stiffness from it.

Engine-free; math only. ISO quantities keep ISO units, N/(mm µm), and say so in their names
(``*_N_per_mm_um``); line-of-action stiffnesses are in N/m. Sources: ISO 6336-1:2006/2019, clause 9
(tooth stiffness parameters, method B); ISO/TR 6336-30:2017 Example 1 (check case, tests).

Equations (z_n, x of pinion 1 and wheel 2; b face width):

- virtual numbers of teeth ``z_n = z / (cos²(beta_b) cos(beta))`` (ISO 6336-1; z_n2 = inf for a rack);
- flexibility ``q' = C1 + C2/z_n1 + C3/z_n2 + C4 x1 + C5 x1/z_n1 + C6 x2 + C7 x2/z_n2 + C8 x1² + C9 x2²``
  [mm µm/N], C1..C9 = 0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529,
  0.00182 (x as given; ISO states the fit for x1 >= x2 and -0.5 <= x1 + x2 <= 2);
- theoretical single stiffness ``c'_th = 1/q'``;
- single stiffness ``c' = c'_th C_M C_R C_B cos(beta)`` [* (F_t K_A / b / 100 N/mm)^0.25 when that line
  load is below 100 N/mm], with ``C_M = 0.8``, blank factor ``C_R = 1 + ln(b_s/b) / (5 exp(s_R / (5 m_n)))``
  (1 for solid blanks; b_s/b limited to [0.2, 1.2], s_R/m_n to >= 1), basic-rack factor
  ``C_B = [1 + 0.5 (1.2 - h_fP/m_n)] [1 - 0.02 (20° - alpha_Pn)]``, the mean of pinion and wheel when
  their basic racks differ;
- mean mesh stiffness ``c_gamma_alpha = c' (0.75 eps_alpha + 0.25)`` (ISO: for eps_alpha >= 1.2; spur
  gears below that may be up to 10 % lower, not applied), ``c_gamma_beta = 0.85 c_gamma_alpha``;
- along the line of action per face width: 1 N/(mm µm) x 1 mm = 1 N/µm = 1e6 N/m, so
  ``k [N/m] = c [N/(mm µm)] * b [mm] * 1e6 = c * b [m] * 1e9``.

Two-level profile for gearbody's contact-ratio law (docs/scenario.md): ``k_single = c' b`` (one pair) and
``k_double`` chosen so that the mean over a mesh period, ``k_s (2 - eps) + k_d (eps - 1)`` for
1 <= eps_alpha < 2, equals ``c_gamma_alpha b``; with ISO's c_gamma_alpha this gives ``k_d = 1.75 k_s`` for
any eps_alpha. With eps_gamma = eps_alpha + eps_beta >= 2 (helical, or high contact ratio) the contact
length varies little and the profile is flat at ``c_gamma_alpha b``. Method B gives no time variation;
the load dependence of the stiffness beyond the line-load factor above is out of scope.
"""

from __future__ import annotations

import dataclasses
import math

from .exceptions import GearGeometryError
from .gear_geometry import GearPairGeometry

Q_COEFFICIENTS = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)
THEORETICAL_CORRECTION_C_M = 0.8
MESH_BETA_RATIO = 0.85  # c_gamma_beta / c_gamma_alpha
REFERENCE_LINE_LOAD_N_PER_MM = 100.0
DOUBLE_TO_SINGLE_RATIO = 1.75  # k_d / k_s that makes the two-level mean equal c_gamma_alpha b


def virtual_teeth(teeth: float, helix_angle_rad: float, base_helix_angle_rad: float) -> float:
    """z_n = z / (cos²(beta_b) cos(beta)) (ISO 6336-1)."""
    return teeth / (math.cos(base_helix_angle_rad) ** 2 * math.cos(helix_angle_rad))


def theoretical_single_stiffness_N_per_mm_um(
    *,
    virtual_teeth_pinion: float,
    virtual_teeth_wheel: float,
    profile_shift_pinion: float = 0.0,
    profile_shift_wheel: float = 0.0,
) -> float:
    """c'_th = 1/q' (ISO 6336-1 method B), N/(mm µm); ``virtual_teeth_wheel = math.inf`` for a rack."""
    c1, c2, c3, c4, c5, c6, c7, c8, c9 = Q_COEFFICIENTS
    zn1, zn2, x1, x2 = virtual_teeth_pinion, virtual_teeth_wheel, profile_shift_pinion, profile_shift_wheel
    q = c1 + c2 / zn1 + c3 / zn2 + c4 * x1 + c5 * x1 / zn1 + c6 * x2 + c7 * x2 / zn2 + c8 * x1**2 + c9 * x2**2
    if not q > 0.0:
        raise GearGeometryError(
            f"q' = {q:.6g} mm um/N: flexibility must be > 0 (profile shifts out of the fit)"
        )
    return 1.0 / q


def blank_factor(
    *,
    face_width_m: float,
    module_m: float,
    web_thickness_m: float | None = None,
    rim_thickness_m: float | None = None,
) -> float:
    """C_R = 1 + ln(b_s/b) / (5 exp(s_R / (5 m_n))); 1 for a solid blank (either thickness None).

    b_s/b is limited to [0.2, 1.2] and s_R/m_n to >= 1, as ISO 6336-1 prescribes.
    """
    if web_thickness_m is None or rim_thickness_m is None:
        return 1.0
    for name, value in (("web_thickness_m", web_thickness_m), ("rim_thickness_m", rim_thickness_m)):
        if not value > 0.0:
            raise GearGeometryError(f"{name} = {value:.6g}: must be > 0 m (or None for a solid blank)")
    ratio = min(max(web_thickness_m / face_width_m, 0.2), 1.2)
    rim_modules = max(rim_thickness_m / module_m, 1.0)
    return 1.0 + math.log(ratio) / (5.0 * math.exp(rim_modules / 5.0))


def basic_rack_factor(
    *,
    dedendum_coefficient_pinion: float,
    dedendum_coefficient_wheel: float | None = None,
    rack_pressure_angle_deg: float = 20.0,
) -> float:
    """C_B = [1 + 0.5 (1.2 - h_fP/m_n)] [1 - 0.02 (20° - alpha_Pn)], mean of pinion and wheel racks."""
    hf2 = dedendum_coefficient_pinion if dedendum_coefficient_wheel is None else dedendum_coefficient_wheel
    angle = 1.0 - 0.02 * (20.0 - rack_pressure_angle_deg)
    return 0.5 * sum((1.0 + 0.5 * (1.2 - hf)) * angle for hf in (dedendum_coefficient_pinion, hf2))


def line_load_factor(line_load_N_per_mm: float | None) -> float:
    """(F_t K_A / b / 100 N/mm)^0.25 below 100 N/mm, else 1 (ISO 6336-1 method B); None: >= 100 N/mm."""
    if line_load_N_per_mm is None or line_load_N_per_mm >= REFERENCE_LINE_LOAD_N_PER_MM:
        return 1.0
    if not line_load_N_per_mm > 0.0:
        raise GearGeometryError(f"line_load_N_per_mm = {line_load_N_per_mm:.6g}: must be > 0 N/mm")
    return (line_load_N_per_mm / REFERENCE_LINE_LOAD_N_PER_MM) ** 0.25


def stiffness_N_per_m(c_N_per_mm_um: float, face_width_m: float) -> float:
    """Line-of-action stiffness of face width b: k = c [N/(mm µm)] * b [mm] * 1e6 N/m."""
    return c_N_per_mm_um * (face_width_m * 1e3) * 1e6


@dataclasses.dataclass(frozen=True)
class IsoStiffness:
    """ISO 6336-1 method B stiffness parameters of one gear pair (per unit face width, N/(mm µm))."""

    virtual_teeth_pinion: float
    virtual_teeth_wheel: float
    flexibility_mm_um_per_N: float  # q'
    c_prime_th_N_per_mm_um: float
    C_M: float
    C_R: float
    C_B: float
    line_load_factor: float
    c_prime_N_per_mm_um: float
    c_gamma_alpha_N_per_mm_um: float
    c_gamma_beta_N_per_mm_um: float
    face_width_m: float

    @property
    def single_N_per_m(self) -> float:
        """c' b along the line of action, N/m."""
        return stiffness_N_per_m(self.c_prime_N_per_mm_um, self.face_width_m)

    @property
    def mesh_alpha_N_per_m(self) -> float:
        """c_gamma_alpha b, N/m (the mean mesh stiffness used for K_v, K_H_alpha)."""
        return stiffness_N_per_m(self.c_gamma_alpha_N_per_mm_um, self.face_width_m)

    @property
    def mesh_beta_N_per_m(self) -> float:
        """c_gamma_beta b, N/m (used for K_H_beta)."""
        return stiffness_N_per_m(self.c_gamma_beta_N_per_mm_um, self.face_width_m)


def iso_stiffness(
    geometry: GearPairGeometry,
    *,
    dedendum_coefficient_pinion: float | None = None,
    dedendum_coefficient_wheel: float | None = None,
    rack_pressure_angle_deg: float | None = None,
    web_thickness_m: float | None = None,
    rim_thickness_m: float | None = None,
    line_load_N_per_mm: float | None = None,
) -> IsoStiffness:
    """ISO 6336-1 method B for a gear pair; basic racks default to the geometry's dedendum and pressure
    angle; solid blanks unless web and rim thicknesses are given; ``line_load_N_per_mm`` = F_t K_A / b."""
    g = geometry
    zn1 = virtual_teeth(g.teeth_pinion, g.helix_angle_rad, g.base_helix_angle_rad)
    zn2 = virtual_teeth(g.teeth_wheel, g.helix_angle_rad, g.base_helix_angle_rad)
    c_th = theoretical_single_stiffness_N_per_mm_um(
        virtual_teeth_pinion=zn1,
        virtual_teeth_wheel=zn2,
        profile_shift_pinion=g.profile_shift_pinion,
        profile_shift_wheel=g.profile_shift_wheel,
    )
    hf1 = g.dedendum_coefficient if dedendum_coefficient_pinion is None else dedendum_coefficient_pinion
    hf2 = g.dedendum_coefficient if dedendum_coefficient_wheel is None else dedendum_coefficient_wheel
    alpha_pn = (
        math.degrees(g.pressure_angle_rad) if rack_pressure_angle_deg is None else rack_pressure_angle_deg
    )
    c_b = basic_rack_factor(
        dedendum_coefficient_pinion=hf1, dedendum_coefficient_wheel=hf2, rack_pressure_angle_deg=alpha_pn
    )
    c_r = blank_factor(
        face_width_m=g.face_width_m,
        module_m=g.module_m,
        web_thickness_m=web_thickness_m,
        rim_thickness_m=rim_thickness_m,
    )
    f_load = line_load_factor(line_load_N_per_mm)
    c_prime = c_th * THEORETICAL_CORRECTION_C_M * c_r * c_b * math.cos(g.helix_angle_rad) * f_load
    c_alpha = c_prime * (0.75 * g.transverse_contact_ratio + 0.25)
    return IsoStiffness(
        virtual_teeth_pinion=zn1,
        virtual_teeth_wheel=zn2,
        flexibility_mm_um_per_N=1.0 / c_th,
        c_prime_th_N_per_mm_um=c_th,
        C_M=THEORETICAL_CORRECTION_C_M,
        C_R=c_r,
        C_B=c_b,
        line_load_factor=f_load,
        c_prime_N_per_mm_um=c_prime,
        c_gamma_alpha_N_per_mm_um=c_alpha,
        c_gamma_beta_N_per_mm_um=MESH_BETA_RATIO * c_alpha,
        face_width_m=g.face_width_m,
    )


def iso_mesh_stiffness_profile(geometry: GearPairGeometry, **iso_options) -> tuple[float, float]:
    """(k_single, k_double) in N/m for gearbody's contact-ratio profile (module docstring).

    k_single = c' b, k_double = 1.75 c' b, whose mean over a period with eps_alpha equals c_gamma_alpha b;
    flat (both c_gamma_alpha b) when eps_gamma >= 2. ``iso_options`` go to :func:`iso_stiffness`.
    """
    iso = iso_stiffness(geometry, **iso_options)
    if geometry.total_contact_ratio >= 2.0:
        return iso.mesh_alpha_N_per_m, iso.mesh_alpha_N_per_m
    return iso.single_N_per_m, DOUBLE_TO_SINGLE_RATIO * iso.single_N_per_m


def planetary_mesh_stiffness_profile(
    *,
    teeth_1: int,
    teeth_2: int | None,
    face_width_m: float,
    pressure_angle_deg: float,
    dedendum_coefficient: float = 1.25,
    line_load_N_per_mm: float | None = None,
) -> tuple[float, float]:
    """(k_single, k_double) in N/m of a planetary stage's standard spur mesh by method B: the sun-planet
    mesh with ``teeth_1``, ``teeth_2`` (the smaller is ISO's pinion), the ring-planet mesh with the planet's
    ``teeth_1`` and ``teeth_2 = None`` (internal). ISO 6336-1's flexibility q' is a fit to external gears;
    for the internal mesh this takes the internal gear's term as a rack's (z_n2 = inf): an approximation
    (the internal tooth, thicker at its root, is somewhat stiffer than a rack tooth, so the ring mesh comes
    out a little soft). Solid blanks (C_R = 1), C_M = 0.8, the basic-rack factor of ``dedendum_coefficient``
    and the pressure angle, the line-load factor below 100 N/mm; k_double = 1.75 k_single as for parallel
    stages (module docstring)."""
    if teeth_2 is None:
        zn1, zn2 = float(teeth_1), math.inf
    else:
        zn1, zn2 = float(min(teeth_1, teeth_2)), float(max(teeth_1, teeth_2))
    c_th = theoretical_single_stiffness_N_per_mm_um(virtual_teeth_pinion=zn1, virtual_teeth_wheel=zn2)
    c_b = basic_rack_factor(
        dedendum_coefficient_pinion=dedendum_coefficient, rack_pressure_angle_deg=pressure_angle_deg
    )
    c_prime = c_th * THEORETICAL_CORRECTION_C_M * c_b * line_load_factor(line_load_N_per_mm)
    single = stiffness_N_per_m(c_prime, face_width_m)
    return single, DOUBLE_TO_SINGLE_RATIO * single
