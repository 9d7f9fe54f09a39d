"""A study's wall time, told before it runs: every pending simulation's estimate
(:func:`gearbody.assembly.wall_time.estimate_wall_time`) taken in order by the local workers, as the
process pool takes its queue; printed on stderr above a minute, and refused (SweepSpecError, exit 2)
above ``max_wall_minutes``. On a Dask cluster, whose size is not known before it runs, the study takes
at least its longest simulation: that is what is judged, with the total given as CPU time."""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from typing import Any

from gearbody.assembly.wall_time import duration_text, estimate_wall_time, makespan_s, refusal

from .parse import SweepSpecError

__all__ = ["ANNOUNCE_ABOVE_S", "check_study_wall_time", "run_estimates_s"]

ANNOUNCE_ABOVE_S = 60.0
"""Estimates above this are printed before the work starts (progress on)."""


def run_estimates_s(scenarios: Sequence[Any]) -> list[float]:
    """Estimated wall time of a simulation of each scenario, s."""
    return [estimate_wall_time(sc).wall_s for sc in scenarios]


def check_study_wall_time(
    durations_s: Sequence[float],
    *,
    workers: int | None,
    scheduler: Any | None,
    max_wall_minutes: float | None,
    progress: bool,
    what: str,
    remedy: str,
    parallel: int | None = None,
    repeat: int = 1,
) -> float:
    """Estimate, announce and judge a study of simulations of ``durations_s`` (estimates, s, in the
    order they are queued), run ``repeat`` times in rounds of at most ``parallel`` at once (default:
    all). ``workers``, ``scheduler`` as for :func:`~gearbody.studies.executors.run_jobs`. Returns the
    estimated wall time, s; raises SweepSpecError above ``max_wall_minutes`` (None: no limit)."""
    durations = [float(d) for d in durations_s]
    if not durations:
        return 0.0
    runs = len(durations) * repeat
    longest, total = max(durations), sum(durations) * repeat
    each = (
        duration_text(longest)
        if duration_text(min(durations)) == duration_text(longest)
        else (f"{duration_text(min(durations))} to {duration_text(longest)}")
    )
    if scheduler is not None:
        wall = longest
        detail = (
            f"{runs} simulations of {each}, {duration_text(total)} of CPU time over the Dask cluster's "
            "workers; the longest simulation bounds the wall time from below"
        )
        shown = f"at least {duration_text(wall)}"
    else:
        n = min(workers or os.cpu_count() or 1, parallel or len(durations), len(durations))
        wall = makespan_s(durations, n) * repeat
        detail = f"{runs} simulations of {each} on {n} worker{'s' if n != 1 else ''}"
        shown = duration_text(wall)
    message = refusal(wall, max_wall_minutes, what, remedy, at_least=scheduler is not None)
    if message:
        raise SweepSpecError(f"{message} ({detail})")
    if progress and wall > ANNOUNCE_ABOVE_S:
        print(f"estimated wall time {shown} ({detail})", file=sys.stderr)
    return wall
