"""Runs shared by the fault scripts (Figs. 10-11 and 13-16): one-stage, one pinion tooth weakened."""

from __future__ import annotations

from gearbody.engine import simulate
from gearbody.model import load_scenario
from gearbody.studies import steady_overrides

SETTLE_S = 0.1
BROKEN_TOOTH = 5  # pinion tooth; not tooth 0, which carries the steady start
ERROR = "production.error_mode={a=0.5,e_um=10.0,r=0.0}"  # r = 0: a healthy pair excites k f_z only


# Figs. 13-16 stated by geometry (one-stage-geometry, potential-energy stiffness): the damage whose pair
# stiffness over its contact comes closest to the paper's bare factors. A case-1 root crack of the
# module-5 pinion loses at most ~23 % (6 mm at 45 deg: mean pair ratio 0.77); the heavier cases are
# tooth breakage over part of the face width (ratio 1 - width) and the whole tooth broken off.
GEOMETRIC_DAMAGE = {
    "root crack 6 mm (~0.8)": "crack_depth_mm=6.0,crack_angle_deg=45.0",
    "40 % of the width broken off (0.6)": "broken_height_fraction=1.0,broken_width_fraction=0.4",
    "80 % of the width broken off (0.2)": "broken_height_fraction=1.0,broken_width_fraction=0.8",
    "tooth broken off (0.0)": "broken_height_fraction=1.0,broken_width_fraction=1.0",
}


def damaged_tooth_run(damage: str | None, record_s: float):
    """As :func:`tooth_run` on one-stage-geometry, pinion tooth BROKEN_TOOTH with these damage keys."""
    overrides = [*steady_overrides(1.0, SETTLE_S + record_s), ERROR]
    if damage is not None:
        overrides.append(f'condition.damaged_teeth=[{{gear="pinion",tooth={BROKEN_TOOTH},{damage}}}]')
    res = simulate(load_scenario("one-stage-geometry", overrides))
    return res, res.time_s >= SETTLE_S


def tooth_run(stiffness_factor: float | None, record_s: float, scene: str = "one-stage"):
    """Steady rated run of a one-stage scene with pinion tooth BROKEN_TOOTH at this stiffness factor (None:
    healthy)."""
    overrides = [*steady_overrides(1.0, SETTLE_S + record_s), ERROR]
    if stiffness_factor is not None:
        overrides.append(
            f'condition.damaged_teeth=[{{gear="pinion",tooth={BROKEN_TOOTH},stiffness_factor={stiffness_factor}}}]'
        )
    res = simulate(load_scenario(scene, overrides))
    return res, res.time_s >= SETTLE_S
