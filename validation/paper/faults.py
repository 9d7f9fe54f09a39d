"""Runs shared by the fault scripts (Figs. 10-11 and 13-16): one-stage, one pinion tooth weakened."""

from __future__ import annotations

from gearbody.engine import simulate
from gearbody.model import load_scenario
from gearbody.resonance import steady_overrides

SETTLE_S = 0.1
BROKEN_TOOTH = 5  # pinion tooth; not tooth 0, which carries the steady start
ERROR = "production.error_mode={a=0.5,e_um=10.0,r=0.0}"  # r = 0: a healthy pair excites k f_z only


def tooth_run(stiffness_factor: float | None, record_s: float):
    """Steady rated one-stage run with pinion tooth BROKEN_TOOTH at this stiffness factor (None: healthy)."""
    overrides = [*steady_overrides(1.0, SETTLE_S + record_s), ERROR]
    if stiffness_factor is not None:
        overrides.append(
            f'condition.damaged_teeth=[{{gear="pinion",tooth={BROKEN_TOOTH},stiffness_factor={stiffness_factor}}}]'
        )
    res = simulate(load_scenario("one-stage", overrides))
    return res, res.time_s >= SETTLE_S
