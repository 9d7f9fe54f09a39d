"""Involute functions and the involute quantities of one gear: transverse module and pressure angle,
radii, tip thickness (ISO 21771; equations in :mod:`.gear_geometry`). Engine-free; math/scipy only.

:func:`.gear_geometry.gear_pair_geometry` and the potential-energy gears
(:class:`.energy_gears.SpurGear`) compute with these, so both have the same radii to the last bit.
"""

from __future__ import annotations

import dataclasses
import math

_INVERSE_INVOLUTE_BRACKET_RAD = (1e-6, 1.5)


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
    from scipy.optimize import brentq  # ~0.4 s to import: only for drives given by their drawing

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


def pitch_base_root_radii_m(z, x, mn, mt, alpha_t, hf) -> tuple[float, float, float]:
    """(r, r_b, r_f) = (z m_t / 2, r cos(alpha_t), r - m_n (h_f* - x))."""
    r = 0.5 * z * mt
    return r, r * math.cos(alpha_t), r - mn * (hf - x)


def tip_radius_m(r, x, mn, ha, k=0.0) -> float:
    """r_a = r + m_n (h_a* + x + k), k = tip alteration."""
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
    """Radii of one gear (r, r_b, r_a without tip alteration, r_f); no checks. The same
    arithmetic as :func:`gear_pair_geometry`, which also checks the pair."""
    alpha_n, beta = math.radians(pressure_angle_deg), abs(math.radians(helix_angle_deg))
    mt, alpha_t = transverse_module_and_pressure_angle(module_m, alpha_n, beta)
    x = profile_shift
    r, rb, rf = pitch_base_root_radii_m(teeth, x, module_m, mt, alpha_t, dedendum_coefficient)
    return GearRadii(r, rb, tip_radius_m(r, x, module_m, addendum_coefficient), rf)


def normal_tip_thickness_m(z, x, r, rb, ra, alpha_n, alpha_t, beta) -> float:
    """Normal tip thickness s_an = s_at cos(beta_a), m (equation in :mod:`.gear_geometry`)."""
    alpha_at = math.acos(rb / ra)
    s_at = (
        2.0
        * ra
        * ((math.pi + 4.0 * x * math.tan(alpha_n)) / (2.0 * z) + involute(alpha_t) - involute(alpha_at))
    )
    beta_a = math.atan(math.tan(beta) * ra / r)
    return s_at * math.cos(beta_a)
