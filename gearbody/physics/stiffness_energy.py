r"""Spur-gear mesh stiffness by the potential-energy method, healthy and with tooth damage. Engine-free.

Tabulated once per scenario (numpy/scipy only). All lengths in m, forces in N, stiffnesses in N/m,
compliances in m/N, angles in rad unless a name says ``_deg``.

The method lives in four modules; this one computes the pair stiffness and the mesh stiffness over the
mesh cycle, and re-exports the public names of the others:

- :mod:`.energy_gears`: :class:`SpurGear`, :class:`SpurPair` (geometry from :mod:`.gear_geometry`,
  roll positions, mesh-phase convention);
- :mod:`.energy_tooth`: bending, shear, axial and fillet-foundation compliances of one tooth
  (Yang & Lin 1987; Tian 2004; Sainsot, Velex & Duverger 2004), Hertz contact;
- :mod:`.energy_damage`: :class:`RootCrack`, :class:`ToothBreakage`, :class:`Spall`.

Pair stiffness: ``k_pair = 1 / (1/k_h + sum_{pinion, wheel} (1/k_b + 1/k_s + 1/k_a + 1/k_f))``.
Damage acts on one tooth of a pair over the pair's contact span (:mod:`.energy_damage`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .energy_damage import Damage, RootCrack, Spall, ToothBreakage, as_damage_tuple
from .energy_gears import GEARS, GearName, SpurGear, SpurPair
from .energy_tooth import (
    SAINSOT_COEFFICIENTS,
    SAINSOT_H_FI_RANGE,
    ToothCompliance,
    ToothRoot,
    hertz_stiffness_N_per_m,
    sainsot_coefficients,
    tooth_compliance_m_per_N,
)

__all__ = [
    "SAINSOT_COEFFICIENTS",
    "SAINSOT_H_FI_RANGE",
    "Damage",
    "GearName",
    "RootCrack",
    "Spall",
    "SpurGear",
    "SpurPair",
    "ToothBreakage",
    "ToothCompliance",
    "ToothRoot",
    "damaged_mesh_stiffness_window",
    "damaged_pair_stiffness_N_per_m",
    "hertz_stiffness_N_per_m",
    "mesh_stiffness_cycle",
    "mesh_stiffness_summary",
    "pair_stiffness_N_per_m",
    "sainsot_coefficients",
    "tooth_compliance_m_per_N",
]

# ------------------------------------------------------------------------------------- pair stiffness


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
    for d in as_damage_tuple(damage):
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
    for name in GEARS:
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
