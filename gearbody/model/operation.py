"""Operation: the speed and load profiles of a run and where it starts (the paper's operating periods)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .params import Node, ScenarioError, param


@dataclass(frozen=True, kw_only=True)
class Profile(Node):
    """Piecewise-linear fraction over time, held constant outside the given points."""

    time_s: tuple[float, ...] = param(doc="times, increasing")
    fraction: tuple[float, ...] = param(doc="fraction at those times, >= 0")

    def __post_init__(self) -> None:
        t, f = self.time_s, self.fraction
        if len(t) < 1 or len(t) != len(f):
            raise ScenarioError(
                f"time_s ({len(t)} values) and fraction ({len(f)} values) must have the same length >= 1"
            )
        if any(x < 0 for x in t) or any(b <= a for a, b in zip(t, t[1:], strict=False)):
            raise ScenarioError(f"time_s = {list(t)}: must be >= 0 and strictly increasing")
        if any(not (x >= 0 and math.isfinite(x)) for x in f):
            raise ScenarioError(f"fraction = {list(f)}: values must be finite and >= 0")


@dataclass(frozen=True, kw_only=True)
class Operation(Node):
    """How a run is driven: its simulated time, the speed and load profiles (fractions of the synchronous
    speed and the rated torque over time) and whether it starts from rest or steady running."""

    t_end_s: float = param(gt=0, doc="simulated time")
    initial_state: str = param("rest", choices=("rest", "steady"), doc="start from rest or steady running")
    speed_profile: Profile = param(
        default_factory=lambda: Profile(time_s=(0.0,), fraction=(1.0,)),
        doc="fraction of the synchronous speed over time",
    )
    load_profile: Profile = param(
        default_factory=lambda: Profile(time_s=(0.0,), fraction=(1.0,)),
        doc="fraction of the rated load torque over time",
    )


def steady(t_end_s: float, *, speed_fraction: float = 1.0, load_fraction: float = 1.0) -> Operation:
    """Steady running from t = 0: constant fraction of the synchronous speed and of the rated load,
    started at the steady operating point (no run-up transient)."""
    return Operation(
        t_end_s=t_end_s,
        initial_state="steady",
        speed_profile=Profile(time_s=(0.0,), fraction=(speed_fraction,)),
        load_profile=Profile(time_s=(0.0,), fraction=(load_fraction,)),
    )


def four_periods(
    t_end_s: float = 2.0,
    *,
    run_up_s: float = 0.5,
    load_start_s: float = 0.8,
    load_rated_s: float = 1.2,
    load_fraction: float = 1.0,
) -> Operation:
    """The paper's four operating periods (Fig. 12): (1) run-up from rest to the synchronous speed
    without load over ``run_up_s``, (2) running without load until ``load_start_s``, (3) a load ramp to
    ``load_fraction`` of rated until ``load_rated_s``, (4) rated load to ``t_end_s``."""
    if not 0 < run_up_s <= load_start_s < load_rated_s < t_end_s:
        raise ScenarioError(
            f"four_periods: need 0 < run_up_s ({run_up_s:g}) <= load_start_s ({load_start_s:g}) < "
            f"load_rated_s ({load_rated_s:g}) < t_end_s ({t_end_s:g})"
        )
    return Operation(
        t_end_s=t_end_s,
        initial_state="rest",
        speed_profile=Profile(time_s=(0.0, run_up_s), fraction=(0.0, 1.0)),
        load_profile=Profile(time_s=(0.0, load_start_s, load_rated_s), fraction=(0.0, 0.0, load_fraction)),
    )
