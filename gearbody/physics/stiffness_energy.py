r"""Spur-gear mesh stiffness by the potential-energy method, healthy and with tooth damage. Engine-free.

Tabulated once per scenario (numpy/scipy only). All lengths in m, forces in N, stiffnesses in N/m,
compliances in m/N, angles in rad unless a name says ``_deg``.

Pair geometry (standard involute spur gears, optional profile shifts ``x``; ISO 21771 / textbooks)
--------------------------------------------------------------------------------------------------
``r_p = m z / 2``, ``r_b = r_p cos(alpha)``, tip ``r_a = r_p + (h_a* + x) m``, root
``r_f = r_p - (h_f* - x) m`` (``h_a* = 1``, ``h_f* = 1.25`` by default);
working pressure angle ``inv(alpha_w) = inv(alpha) + 2 tan(alpha) (x1 + x2) / (z1 + z2)``,
``inv(t) = tan(t) - t``, centre distance ``a = (r_p1 + r_p2) cos(alpha) / cos(alpha_w)`` (zero backlash)
unless given; base pitch ``p_b = pi m cos(alpha)``; length of contact
``g = sqrt(r_a1^2 - r_b1^2) + sqrt(r_a2^2 - r_b2^2) - a sin(alpha_w)``; transverse contact ratio
``eps = g / p_b``. Roll position ``s`` of a contact point: its distance along the line of action from
the pinion's base-circle tangent point ``T1``; contact runs from ``s_start = a sin(alpha_w) -
sqrt(r_a2^2 - r_b2^2)`` (pinion root, wheel tip) to ``s_end = sqrt(r_a1^2 - r_b1^2)`` (pinion tip).
The wheel's roll length is ``a sin(alpha_w) - s``.

Mesh-phase convention (gearbody, ``mesh.stiffness_at_phase``, docs/scenario.md): ``p`` in [0, 1), one
period = one base pitch of roll (pinion drives, ``s`` grows with ``p``). The pair assigned to a period
is at ``s(p) = s_mid + (p - 0.5) p_b``, ``s_mid = (s_start + s_end) / 2``: it is alone in contact at
p = 0.5 (middle of the single-contact zone) and in contact for ``|p - 0.5| <= eps / 2``. The pair of
period ``n + j`` is at its own phase ``p - j`` (``j = -1`` outgoing, ``+1`` incoming). Total mesh
stiffness ``k(p) = sum_j k_pair(s(p - j))`` over the pairs in contact. (The pitch point is at
``p = 0.5`` only for equal gears; gearbody's ``pitch_point_phase`` is a separate friction parameter.)

Single-tooth compliances (Yang & Lin 1987; Tian 2004; Chen & Shao 2011)
------------------------------------------------------------------------
Tooth = non-uniform cantilever along its centre line ``x`` (from the gear centre). Involute point of
roll angle ``t`` written with ``beta = t - alpha_2``:
``x(beta) = r_b [cos(beta) + (beta + alpha_2) sin(beta)]``,
``h(beta) = r_b [(beta + alpha_2) cos(beta) - sin(beta)]`` (half thickness),
``dx = r_b (beta + alpha_2) cos(beta) dbeta``, with ``alpha_2 = (pi/2 + 2 x tan(alpha)) / z + inv(alpha)``
the half tooth angle on the base circle. Contact at roll ``t_c = tan(alpha_r)`` gives the load angle
``alpha_1 = t_c - alpha_2`` (angle between the normal force and the normal to the centre line).
Per unit normal force the moment at section ``x`` is ``r_b - x cos(alpha_1)`` (exact:
``(x_c - x) cos(alpha_1) - h_c sin(alpha_1)`` with the contact point ``(x_c, h_c)``), so, with
``I_x = 2/3 b h_x^3``, ``A_x = 2 b h_x``, ``G = E / (2 (1 + nu))``:

``1/k_b = int (r_b - x cos(alpha_1))^2 / (E I_x) dx``,
``1/k_s = int 1.2 cos^2(alpha_1) / (G A_x) dx``,
``1/k_a = int sin^2(alpha_1) / (E A_x) dx``,

from the clamped section to the contact point. On the involute part these are the classical forms
(Tian 2004, with Tian's integration angle ``alpha = -beta``):
``1/k_b = int_{beta_0}^{alpha_1} 3 [1 - cos(alpha_1)(cos(beta) + (beta + alpha_2) sin(beta))]^2
(beta + alpha_2) cos(beta) / (2 E b [(beta + alpha_2) cos(beta) - sin(beta)]^3) dbeta``,
``1/k_s = int 1.2 (1 + nu) (beta + alpha_2) cos(beta) cos^2(alpha_1) / (E b [(beta + alpha_2) cos(beta)
- sin(beta)]) dbeta``,
``1/k_a = int (beta + alpha_2) cos(beta) sin^2(alpha_1) / (2 E b [(beta + alpha_2) cos(beta) - sin(beta)])
dbeta``.
Evaluated by fixed Gauss-Legendre quadrature (``_GAUSS_NODES`` per sub-interval; intervals split at
the crack limit).

Clamped section (``tooth_root``):

* ``"improved"`` (default; Ma, Pang, Song & Yang 2014; Wan et al. 2014): the cantilever starts at the
  root circle. Root circle *below* the base circle (``r_f < r_b``, z <~ 41 for standard 20 deg gears):
  the flank between root and base circle is taken as straight, of constant half thickness
  ``h_b = r_b sin(alpha_2)``, from ``x_r = sqrt(r_f^2 - h_b^2)`` to ``x_b = r_b cos(alpha_2)``, then
  the involute from ``beta_0 = -alpha_2``. Root circle *above* the base circle: the involute from
  the root circle, ``beta_0 = sqrt((r_f / r_b)^2 - 1) - alpha_2``.
* ``"base"`` (Yang & Lin 1987; Tian 2004): the cantilever starts at the base circle,
  ``beta_0 = -alpha_2``, whatever the root radius.

Fillet-foundation compliance (Sainsot, Velex & Duverger 2004)
--------------------------------------------------------------
``1/k_f = cos^2(alpha_m) / (E b) [L* (u_f/S_f)^2 + M* (u_f/S_f) + P* (1 + Q* tan^2(alpha_m))]``,
``alpha_m = alpha_1``; ``u_f = r_b / cos(alpha_1) - r_f`` is the distance from the root circle to the
point where the line of action crosses the tooth centre line; ``S_f = 2 r_f theta_f`` the tooth
thickness at the root circle; ``theta_f`` the half tooth angle at the root circle, where the root
fillet generated by a basic rack of dedendum ``h_f*`` and tip radius ``rho* m`` meets the root circle:
``theta_f = [pi/2 + 2 h_f* tan(alpha) + 2 rho* (1 - sin(alpha)) / cos(alpha)] / z`` (the rack's tip
flat of width ``pi m / 2 - 2 h_f* m tan(alpha) - 2 rho* m (1 - sin alpha)/cos(alpha)`` rolls off the
tooth space's root arc; independent of the profile shift); ``rho* = (h_f* - h_a*) / (1 - sin(alpha))``
(full-round rack tip, 0.38 for ISO 53 profile A) unless given.
``X* = A_i / theta_f^2 + B_i h_fi^2 + C_i h_fi / theta_f + D_i / theta_f + E_i h_fi + F_i``,
``h_fi = r_f / r_int`` (``r_int`` = bore radius), coefficients ``SAINSOT_COEFFICIENTS`` (Sainsot et al.
2004, Table as reproduced by Chen & Shao 2011 and Ma et al. 2015 review; same values in ROSS
``gear_mesh_TVMS.py``). The fit covers about ``1.4 <= h_fi <= 7``; outside it the polynomial is
extrapolated with a warning.

Hertz contact (Yang & Lin 1987): ``1/k_h = 4 (1 - nu^2) / (pi E b)``, load- and position-independent;
for two materials ``1/k_h = 2 [(1 - nu1^2)/E1 + (1 - nu2^2)/E2] / (pi b)``. ``b`` = the common contact
width ``min(b1, b2)``, used for every term.

Pair stiffness: ``k_pair = 1 / (1/k_h + sum_{pinion, wheel} (1/k_b + 1/k_s + 1/k_a + 1/k_f))``.

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

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.optimize import brentq

__all__ = [
    "SAINSOT_COEFFICIENTS",
    "RootCrack",
    "Spall",
    "SpurGear",
    "SpurPair",
    "ToothBreakage",
    "ToothCompliance",
    "damaged_mesh_stiffness_window",
    "damaged_pair_stiffness_N_per_m",
    "hertz_stiffness_N_per_m",
    "mesh_stiffness_cycle",
    "mesh_stiffness_summary",
    "pair_stiffness_N_per_m",
    "tooth_compliance_m_per_N",
]

# Sainsot, Velex & Duverger (2004): X* = A/theta_f^2 + B h_fi^2 + C h_fi/theta_f + D/theta_f + E h_fi + F
SAINSOT_COEFFICIENTS: dict[str, tuple[float, float, float, float, float, float]] = {
    #      A_i          B_i          C_i          D_i         E_i      F_i
    "L": (-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045),
    "M": (60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086),
    "P": (-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236),
    "Q": (-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904),
}
SAINSOT_H_FI_RANGE = (1.4, 7.0)

_GAUSS_NODES = 48
_GX, _GW = np.polynomial.legendre.leggauss(_GAUSS_NODES)

ToothRoot = Literal["improved", "base"]
GearName = Literal["pinion", "wheel"]
_GEARS: tuple[GearName, GearName] = ("pinion", "wheel")


def _inv(a: float) -> float:
    return math.tan(a) - a


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

    @property
    def pressure_angle_rad(self) -> float:
        return math.radians(self.pressure_angle_deg)

    @property
    def pitch_radius_m(self) -> float:
        return 0.5 * self.module_m * self.teeth

    @property
    def base_radius_m(self) -> float:
        return self.pitch_radius_m * math.cos(self.pressure_angle_rad)

    @property
    def tip_radius_m(self) -> float:
        return self.pitch_radius_m + (self.addendum_coefficient + self.profile_shift) * self.module_m

    @property
    def root_radius_m(self) -> float:
        return self.pitch_radius_m - (self.dedendum_coefficient - self.profile_shift) * self.module_m

    @property
    def half_base_tooth_angle_rad(self) -> float:
        """alpha_2 = (pi/2 + 2 x tan(alpha)) / z + inv(alpha)."""
        a = self.pressure_angle_rad
        return (0.5 * math.pi + 2.0 * self.profile_shift * math.tan(a)) / self.teeth + _inv(a)

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
    """A pinion-wheel pair; ``center_distance_m`` None = zero-backlash distance from the profile shifts."""

    pinion: SpurGear
    wheel: SpurGear
    center_distance_m: float | None = None

    def __post_init__(self) -> None:
        p, w = self.pinion, self.wheel
        if not math.isclose(p.module_m, w.module_m) or not math.isclose(
            p.pressure_angle_deg, w.pressure_angle_deg
        ):
            raise ValueError("pinion and wheel need the same module and pressure angle")

    @property
    def working_pressure_angle_rad(self) -> float:
        p, w = self.pinion, self.wheel
        a0 = p.pitch_radius_m + w.pitch_radius_m
        alpha = p.pressure_angle_rad
        if self.center_distance_m is not None:
            return math.acos(a0 * math.cos(alpha) / self.center_distance_m)
        x_sum, z_sum = p.profile_shift + w.profile_shift, p.teeth + w.teeth
        target = _inv(alpha) + 2.0 * math.tan(alpha) * x_sum / z_sum
        if abs(target - _inv(alpha)) < 1e-15:
            return alpha
        return brentq(lambda t: _inv(t) - target, 1e-6, 1.5, xtol=1e-15)

    @property
    def operating_center_distance_m(self) -> float:
        if self.center_distance_m is not None:
            return self.center_distance_m
        a0 = self.pinion.pitch_radius_m + self.wheel.pitch_radius_m
        return a0 * math.cos(self.pinion.pressure_angle_rad) / math.cos(self.working_pressure_angle_rad)

    @property
    def line_of_centres_m(self) -> float:
        """T1 T2 = a sin(alpha_w): distance between the two base-circle tangent points."""
        return self.operating_center_distance_m * math.sin(self.working_pressure_angle_rad)

    @property
    def base_pitch_m(self) -> float:
        return 2.0 * math.pi * self.pinion.base_radius_m / self.pinion.teeth

    @property
    def contact_start_m(self) -> float:
        w = self.wheel
        return self.line_of_centres_m - math.sqrt(w.tip_radius_m**2 - w.base_radius_m**2)

    @property
    def contact_end_m(self) -> float:
        p = self.pinion
        return math.sqrt(p.tip_radius_m**2 - p.base_radius_m**2)

    @property
    def contact_length_m(self) -> float:
        return self.contact_end_m - self.contact_start_m

    @property
    def contact_ratio(self) -> float:
        return self.contact_length_m / self.base_pitch_m

    @property
    def contact_width_m(self) -> float:
        return min(self.pinion.face_width_m, self.wheel.face_width_m)

    def roll_position_m(self, pair_phase: float | np.ndarray) -> float | np.ndarray:
        """s of the pair at its own mesh phase (0.5 = middle of its contact)."""
        mid = 0.5 * (self.contact_start_m + self.contact_end_m)
        return mid + (np.asarray(pair_phase) - 0.5) * self.base_pitch_m

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


# --------------------------------------------------------------------------------------------- damage


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


# ------------------------------------------------------------------------------------ tooth compliances


@dataclass(frozen=True)
class ToothCompliance:
    """Compliances (m/N) of one tooth for a unit normal load: bending, shear, axial, fillet foundation."""

    bending: float
    shear: float
    axial: float
    fillet: float

    @property
    def total(self) -> float:
        return self.bending + self.shear + self.axial + self.fillet


def _half_thickness(beta: np.ndarray | float, r_b: float, a2: float) -> np.ndarray | float:
    return r_b * ((beta + a2) * np.cos(beta) - np.sin(beta))


def _clamp(gear: SpurGear, tooth_root: ToothRoot) -> tuple[float, float | None, float]:
    """(beta_0, x_r of the straight root segment or None, half thickness h_0 at the clamped section)."""
    r_b, r_f, a2 = gear.base_radius_m, gear.root_radius_m, gear.half_base_tooth_angle_rad
    if tooth_root == "base":
        return -a2, None, r_b * math.sin(a2)
    if tooth_root != "improved":
        raise ValueError(f"tooth_root must be 'improved' or 'base', not {tooth_root!r}")
    if r_f < r_b:
        h_b = r_b * math.sin(a2)
        return -a2, math.sqrt(max(r_f**2 - h_b**2, 0.0)), h_b
    beta_0 = math.sqrt((r_f / r_b) ** 2 - 1.0) - a2
    return beta_0, None, float(_half_thickness(beta_0, r_b, a2))


def _crack_limit(gear: SpurGear, beta_0: float, h_q: float) -> float:
    """beta_c where the flank's half thickness falls to h_q (on its decreasing branch, beta >= 0)."""
    r_b, a2 = gear.base_radius_m, gear.half_base_tooth_angle_rad
    beta_tip = gear.load_angle_rad(math.sqrt(gear.tip_radius_m**2 - r_b**2))
    lo = max(beta_0, 0.0)
    f = lambda b: float(_half_thickness(b, r_b, a2)) - h_q  # noqa: E731
    if f(lo) <= 0.0:
        return lo
    if f(beta_tip) >= 0.0:
        return math.inf
    return brentq(f, lo, beta_tip, xtol=1e-14)


def _gauss(a: float, b: float) -> tuple[np.ndarray, np.ndarray]:
    half = 0.5 * (b - a)
    return 0.5 * (a + b) + half * _GX, half * _GW


def sainsot_coefficients(gear: SpurGear) -> dict[str, float]:
    """L*, M*, P*, Q* of Sainsot et al. (2004) for the gear's h_fi = r_f / r_int and theta_f."""
    h = gear.root_radius_m / gear.bore_radius_m
    th = gear.root_half_angle_rad
    if not SAINSOT_H_FI_RANGE[0] <= h <= SAINSOT_H_FI_RANGE[1]:
        warnings.warn(
            f"h_fi = r_f / r_int = {h:.3g} outside the Sainsot fit range {SAINSOT_H_FI_RANGE}",
            stacklevel=3,
        )
    return {
        k: a / th**2 + b * h**2 + c * h / th + d / th + e * h + f
        for k, (a, b, c, d, e, f) in SAINSOT_COEFFICIENTS.items()
    }


def tooth_compliance_m_per_N(
    gear: SpurGear,
    roll_length_m: float,
    *,
    width_m: float | None = None,
    crack: RootCrack | None = None,
    tooth_root: ToothRoot = "improved",
) -> ToothCompliance:
    """Bending, shear, axial and fillet-foundation compliances of one tooth, contact at roll length
    ``r_b tan(alpha_r)`` (see the module docstring for the integrals)."""
    b = gear.face_width_m if width_m is None else width_m
    E, G = gear.youngs_modulus_Pa, gear.shear_modulus_Pa
    r_b, a2, r_f = gear.base_radius_m, gear.half_base_tooth_angle_rad, gear.root_radius_m
    a1 = gear.load_angle_rad(roll_length_m)
    beta_0, x_r, h_0 = _clamp(gear, tooth_root)
    if a1 < beta_0 - 1e-12:
        raise ValueError("contact point below the clamped section of the tooth")
    ca, sa = math.cos(a1), math.sin(a1)

    h_q = None
    if crack is not None and crack.depth_m > 0.0:
        h_q = h_0 - crack.depth_m * math.sin(math.radians(crack.angle_deg))
        if h_q < 0.0:
            raise ValueError("crack crosses the tooth centre line (only case 1, h_q >= 0, is modelled)")

    # sections: (x nodes, dx weights, effective I, effective A)
    parts: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
    if x_r is not None:  # straight flank between root and base circle
        x, w = _gauss(x_r, r_b * math.cos(a2))
        h = np.full_like(x, r_b * math.sin(a2))
        eff = 2.0 * h if h_q is None else h + h_q
        parts.append((x, w, b * eff**3 / 12.0, b * eff))
    cuts = [beta_0, a1]
    beta_c = -math.inf
    if h_q is not None:
        beta_c = _crack_limit(gear, beta_0, h_q)
        if beta_0 < beta_c < a1:
            cuts = [beta_0, beta_c, a1]
    for lo, hi in zip(cuts[:-1], cuts[1:], strict=True):
        if hi <= lo:
            continue
        beta, w = _gauss(lo, hi)
        x = r_b * (np.cos(beta) + (beta + a2) * np.sin(beta))
        w = w * r_b * (beta + a2) * np.cos(beta)
        h = _half_thickness(beta, r_b, a2)
        cracked = h_q is not None and hi <= beta_c + 1e-15
        eff = h + h_q if cracked else 2.0 * h
        parts.append((x, w, b * eff**3 / 12.0, b * eff))

    bend = shear = axial = 0.0
    for x, w, inertia, area in parts:
        bend += float(np.sum(w * (r_b - x * ca) ** 2 / (E * inertia)))
        shear += float(np.sum(w * 1.2 * ca**2 / (G * area)))
        axial += float(np.sum(w * sa**2 / (E * area)))

    c = sainsot_coefficients(gear)
    u_over_s = (r_b / ca - r_f) / (2.0 * r_f * gear.root_half_angle_rad)
    fillet = (
        ca**2
        / (E * b)
        * (c["L"] * u_over_s**2 + c["M"] * u_over_s + c["P"] * (1.0 + c["Q"] * math.tan(a1) ** 2))
    )
    return ToothCompliance(bend, shear, axial, fillet)


def hertz_stiffness_N_per_m(pair: SpurPair, width_m: float | None = None) -> float:
    """k_h = pi b / (2 [(1 - nu1^2)/E1 + (1 - nu2^2)/E2]) = pi E b / (4 (1 - nu^2)) for one material."""
    b = pair.contact_width_m if width_m is None else width_m
    p, w = pair.pinion, pair.wheel
    s = (1.0 - p.poisson_ratio**2) / p.youngs_modulus_Pa + (1.0 - w.poisson_ratio**2) / w.youngs_modulus_Pa
    return math.pi * b / (2.0 * s)


# ------------------------------------------------------------------------------------- pair stiffness


def _as_tuple(damage: Damage | Sequence[Damage] | None) -> tuple[Damage, ...]:
    if damage is None:
        return ()
    if isinstance(damage, RootCrack | ToothBreakage | Spall):
        return (damage,)
    return tuple(damage)


def damaged_pair_stiffness_N_per_m(
    pair: SpurPair,
    roll_position_m: float,
    damage: Damage | Sequence[Damage] | None,
    *,
    tooth_root: ToothRoot = "improved",
) -> float:
    """k_pair at roll position s (m from T1) of a pair with damaged teeth; 0 out of contact.

    ``damage``: one or several of :class:`RootCrack`, :class:`ToothBreakage`, :class:`Spall` (each on
    the pair's pinion or wheel tooth as named by its ``gear``)."""
    if not pair.in_contact(roll_position_m):
        return 0.0
    b = pair.contact_width_m
    width_factor, hertz_factor = 1.0, 1.0
    cracks: dict[str, RootCrack] = {}
    for d in _as_tuple(damage):
        gear = pair.gear(d.gear)
        r = gear.contact_radius_m(pair.roll_length_on_m(d.gear, roll_position_m))
        if isinstance(d, RootCrack):
            if d.gear in cracks:
                raise ValueError("one root crack per tooth")
            cracks[d.gear] = d
        elif isinstance(d, ToothBreakage):
            if d.missing_height_fraction > 0.0 and r > d.remaining_radius_m(gear):
                width_factor *= 1.0 - d.width_fraction
        elif d.start_radius_m <= r <= d.end_radius_m and d.width_loss_fraction > 0.0:
            if d.hertz_only:
                hertz_factor *= 1.0 - d.width_loss_fraction
            else:
                width_factor *= 1.0 - d.width_loss_fraction
    if width_factor * hertz_factor <= 0.0:
        return 0.0
    compliance = 1.0 / (hertz_factor * hertz_stiffness_N_per_m(pair, b))
    for name in _GEARS:
        compliance += tooth_compliance_m_per_N(
            pair.gear(name),
            pair.roll_length_on_m(name, roll_position_m),
            width_m=b,
            crack=cracks.get(name),
            tooth_root=tooth_root,
        ).total
    return width_factor / compliance


def pair_stiffness_N_per_m(
    pair: SpurPair, roll_position_m: float, *, tooth_root: ToothRoot = "improved"
) -> float:
    """Healthy k_pair = 1 / (1/k_h + sum over both teeth of 1/k_b + 1/k_s + 1/k_a + 1/k_f); 0 out of
    contact. ``roll_position_m``: distance of the contact point from the pinion's tangent point T1."""
    return damaged_pair_stiffness_N_per_m(pair, roll_position_m, None, tooth_root=tooth_root)


def _pairs_around(pair: SpurPair) -> int:
    return int(math.ceil(0.5 * pair.contact_ratio)) + 1


def mesh_stiffness_cycle(
    pair: SpurPair, n_phase: int = 400, *, tooth_root: ToothRoot = "improved"
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Healthy total mesh stiffness over one period.

    Returns ``(phase, k_total, k_pairs)``: ``phase = arange(n_phase) / n_phase`` in [0, 1);
    ``k_pairs[i]`` is the stiffness of the pair of period ``n + j``, ``j = i - J`` (own phase ``p - j``,
    0 out of contact), ``J = ceil(eps / 2) + 1``; ``k_total = k_pairs.sum(axis=0)``."""
    phase = np.arange(n_phase) / n_phase
    J = _pairs_around(pair)
    k_pairs = np.zeros((2 * J + 1, n_phase))
    for i, j in enumerate(range(-J, J + 1)):
        for n, p in enumerate(phase):
            s = float(pair.roll_position_m(p - j))
            if pair.in_contact(s):
                k_pairs[i, n] = pair_stiffness_N_per_m(pair, s, tooth_root=tooth_root)
    return phase, k_pairs.sum(axis=0), k_pairs


def damaged_mesh_stiffness_window(
    pair: SpurPair,
    damage: Damage | Sequence[Damage] | None,
    n_phase_per_period: int = 400,
    *,
    tooth_root: ToothRoot = "improved",
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Total mesh stiffness while the damaged pair (the pair of period 0) is in contact.

    Returns ``(phase, k_total, k_damaged_pair)`` with ``phase`` (in mesh periods, relative to the
    damaged pair's period) covering the whole periods ``floor(0.5 - eps/2) .. ceil(0.5 + eps/2) - 1``,
    i.e. [-1, 2) for 1 < eps < 2; the other pairs are healthy."""
    eps = pair.contact_ratio
    lo, hi = math.floor(0.5 - 0.5 * eps), math.ceil(0.5 + 0.5 * eps)
    phase = lo + np.arange((hi - lo) * n_phase_per_period) / n_phase_per_period
    J = _pairs_around(pair)
    k_total = np.zeros_like(phase)
    k_dam = np.zeros_like(phase)
    for n, p in enumerate(phase):
        for j in range(lo - J, hi + J + 1):
            s = float(pair.roll_position_m(p - j))
            if not pair.in_contact(s):
                continue
            k = damaged_pair_stiffness_N_per_m(pair, s, damage if j == 0 else None, tooth_root=tooth_root)
            if j == 0:
                k_dam[n] = k
            k_total[n] += k
    return phase, k_total, k_dam


def mesh_stiffness_summary(
    pair: SpurPair, n_phase: int = 400, *, tooth_root: ToothRoot = "improved"
) -> dict[str, float]:
    """Contact ratio, Hertz term, mean/min/max and single/double-contact mean of the healthy k(p)."""
    phase, k, k_pairs = mesh_stiffness_cycle(pair, n_phase, tooth_root=tooth_root)
    count = (k_pairs > 0.0).sum(axis=0)
    return {
        "contact_ratio": pair.contact_ratio,
        "hertz_N_per_m": hertz_stiffness_N_per_m(pair),
        "mean_N_per_m": float(k.mean()),
        "min_N_per_m": float(k.min()),
        "max_N_per_m": float(k.max()),
        "single_mean_N_per_m": float(k[count == 1].mean()) if np.any(count == 1) else math.nan,
        "double_mean_N_per_m": float(k[count == 2].mean()) if np.any(count == 2) else math.nan,
    }


def _scene_pairs() -> dict[str, SpurPair]:
    """Reference pair and the scenes' pairs (bores assumed, see the report in __main__)."""
    return {
        "62/62 m2 b20 (bore d 35 mm)": SpurPair(
            SpurGear(62, 0.002, 0.02, 0.0175), SpurGear(62, 0.002, 0.02, 0.0175)
        ),
        "one-stage 29/88 m5 b60 (bores r 30/45 mm)": SpurPair(
            SpurGear(29, 0.005, 0.06, 0.030), SpurGear(88, 0.005, 0.06, 0.045)
        ),
        "two-stage st.2 23/71 m8 b80 (bores r 45/60 mm)": SpurPair(
            SpurGear(23, 0.008, 0.08, 0.045), SpurGear(71, 0.008, 0.08, 0.060)
        ),
    }


if __name__ == "__main__":
    for name, pr in _scene_pairs().items():
        for root in ("improved", "base"):
            s = mesh_stiffness_summary(pr, 400, tooth_root=root)
            print(
                f"{name:48s} {root:8s} eps {s['contact_ratio']:.5f}  k_h {s['hertz_N_per_m']:.4e}  "
                f"mean {s['mean_N_per_m']:.4e}  min {s['min_N_per_m']:.4e}  max {s['max_N_per_m']:.4e}  "
                f"single {s['single_mean_N_per_m']:.4e}  double {s['double_mean_N_per_m']:.4e}"
            )
