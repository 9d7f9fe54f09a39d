"""Backlash of an involute gear pair (Niemann & Winter, Maschinenelemente II; ISO/TR 10064-2).
Engine-free; math only. Lengths in m.

Base normal backlash ``j_bn = -(E_sn1 + E_sn2) cos(alpha_n) + 2 Delta_a sin(alpha_wt) cos(beta_b)``
(E_sn: normal tooth-thickness allowance, negative = thinner; Delta_a: centre-distance deviation;
uses cos(alpha_t) cos(beta_b) / cos(beta) = cos(alpha_n)); along the transverse line of action
``j_bt = j_bn / cos(beta_b)``; gearbody's eq. (4) half-width ``l_u = j_bt / 2`` (= j_bn / 2 for spur).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from .exceptions import geometry_error

if TYPE_CHECKING:
    from .gear_pair import GearPairGeometry


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
