"""How long a run will take, estimated from the scenario before anything runs (docs/scenario.md,
"Resource limits"): the solver's step attempts times the cost of one attempt on the machine the costs
were measured on.

Step attempts. Exudyn's explicit solvers control the step by the local error, and what sets the step
count of a gear drive is (a) every mesh's stiffness jumps, two per mesh period, each crossed by a
burst of short and rejected steps, and (b) the fastest coordinate (its natural frequency or damping
rate, :func:`~gearbody.assembly.stiff_modes.coordinate_frequencies`), which the error control must
follow between the jumps. So, per simulated second,

    attempts/s = max(1 / max_step_s, tol x (ATTEMPTS_PER_MESH_PERIOD x sum f_mesh
                                          + ATTEMPTS_PER_RATE_HZ x f_fastest))

with ``sum f_mesh`` over every mesh (a planetary stage: 2 per planet) at the time-averaged speed of
the speed profile, and ``tol = (atol / atol_default) ** -TOLERANCE_EXPONENT[method]`` (atol relative
to :func:`default_tolerance`: a planetary drive's scaled default counts as the default, Muller's
deflection tolerance is compared in metres at the pinion's base circle).
RK44 and RK67 take fixed steps of max_step_s. The two constants were fitted to the step counts of
every shipped scene in steady running at default accuracy; benchmarks/bench_wall_estimate.py checks
the estimate against measured steps and wall time on every scene and validation case
(benchmarks/RESULTS.md, "Wall-time estimate").

Cost of an attempt: EVALUATIONS_PER_ATTEMPT[method] right-hand sides, each of a cost that grows with
the coordinates, the gears on bearings and their bearing laws (:func:`us_per_attempt`; CPU time
measured on the 2-CPU x86_64 machine of benchmarks/RESULTS.md, Exudyn 1.13.6), plus OUTPUT_OVERHEAD for
building the model and sampling the output.

Accuracy: the right order of magnitude, not a timing. On every shipped scene and its validation cases
(141 runs) the attempts lie within 0.52-2.5x of the solver's and the time within 0.41-1.8x of the CPU
time (the wall time of an idle machine); a busy machine is slower, a faster one faster, and what the
model cannot foresee (tooth separation, impacts, a run that stalls) makes runs slower than estimated.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from ..model import Scenario
from ..model.budget import coordinates
from ..model.solver import default_solver
from .stiff_modes import coordinate_frequencies

__all__ = [
    "WallTimeEstimate",
    "duration_text",
    "estimate_wall_time",
    "makespan_s",
    "mean_speed_fraction",
]

ATTEMPTS_PER_MESH_PERIOD = 105.0
"""Step attempts per mesh period of each mesh (its two stiffness jumps), at the default tolerance."""
ATTEMPTS_PER_RATE_HZ = 45.0
"""Step attempts per simulated second per Hz of the fastest coordinate's rate, at the default
tolerance."""
TOLERANCE_EXPONENT = {"DOPRI5": 0.15, "ODE23": 0.28}
"""Attempts grow as (atol / default atol) ** -exponent (one-stage: x2 per 100x tighter with DOPRI5;
ODE23 x9 from 3e-5 to 1e-8)."""
REFERENCE_TOLERANCE = {"DOPRI5": 1.0, "ODE23": 3e3}
"""The atol, relative to the topology's default one, at which a method takes the attempts above scaled
by REFERENCE_ATTEMPTS."""
REFERENCE_ATTEMPTS = {"DOPRI5": 1.0, "ODE23": 0.53}
"""Attempts of a method at its reference tolerance relative to DOPRI5 at the default one (ODE23 at the
draft level: 0.36-0.87 on the scenes, 0.53 typical)."""
FIXED_STEP_METHODS = ("RK44", "RK67")
"""Methods that take fixed steps of max_step_s (no error control in Exudyn)."""
EVALUATIONS_PER_ATTEMPT = {"DOPRI5": 6, "ODE23": 3, "RK44": 5, "RK67": 10}
"""Right-hand sides per step attempt (DOPRI5, ODE23: first-same-as-last saved); for RK44 and RK67 the
cost of a step in evaluations' worth (their CPU time per step on one-stage and lateral-8dof is
1.0-1.8x this)."""
US_PER_EVALUATION_PER_COORDINATE = 0.5
MIN_US_PER_EVALUATION = 1.5
US_PER_EVALUATION_PER_LATERAL_GEAR = 1.2
US_PER_EVALUATION_PER_BEARING_LAW = 2.0
"""Cost of one right-hand side, us: max(MIN, PER_COORDINATE x coordinates), plus PER_LATERAL_GEAR for
each gear moving on its bearings (the lateral mesh law) and PER_BEARING_LAW for each of those whose
bearing is a Python law rather than Exudyn's linear spring-dampers (CPU time per evaluation of the
scenes as shipped: one-stage 2.4, two-stage 2.6, lateral-8dof 5.4, lateral-8dof-ball 7.3,
industrial-two-stage 9.5, planetary 11.5 us; benchmarks/RESULTS.md, "Wall-time estimate")."""
OUTPUT_OVERHEAD = 1.1
"""Wall time of a run over its solver time: building, output sampling and checks (1.01-1.16 measured
on the scenes; numba's first compilation, seconds once per machine, is not counted)."""


@dataclass(frozen=True)
class WallTimeEstimate:
    """A run's expected solver step attempts and wall time (see the module docstring for how)."""

    simulated_s: float
    attempts: float
    us_per_attempt: float
    wall_s: float

    @property
    def wall_per_simulated_s(self) -> float:
        """Wall seconds per simulated second."""
        return self.wall_s / self.simulated_s


def mean_speed_fraction(scenario: Scenario) -> float:
    """Time average of the speed profile's fraction over the run (the profile is piecewise linear and
    held outside its points, so the trapezoid rule on its points is exact)."""
    profile, t_end = scenario.operation.speed_profile, scenario.operation.t_end_s
    t = np.unique(np.clip([0.0, *profile.time_s, t_end], 0.0, t_end))
    f = np.interp(t, profile.time_s, profile.fraction)
    return float(np.sum((f[1:] + f[:-1]) * np.diff(t)) / 2 / t_end) if t_end > 0 else float(f[0])


def mesh_frequency_sum_hz(scenario: Scenario) -> float:
    """Sum of every mesh's frequency at the mean speed (a planetary stage: 2 meshes per planet)."""
    speed = scenario.design.motor.synchronous_speed_rad_s * mean_speed_fraction(scenario)
    total = 0.0
    for st in scenario.stages:
        total += st.mesh_count * st.mesh_frequency_hz(speed)
        speed /= st.ratio
    return total


def default_tolerance(scenario: Scenario) -> float:
    """The absolute tolerance at which the scenario's coordinates are held as closely as a torsional
    drive's at the default accuracy level: that level's own for trains and planetary drives; for
    Muller's model, which integrates the mesh deflection in metres, the rotations' default times the
    pinion's base radius (its own default, 3e-11 m, is ~30x tighter than that)."""
    method_atol = default_solver("default", "train", scenario.has_planetary)[1]
    if scenario.meta.topology == "muller":
        return method_atol * scenario.stages[0].pinion.base_radius_m
    return method_atol


def attempts_per_simulated_s(scenario: Scenario) -> float:
    """Expected solver step attempts per simulated second."""
    sv = scenario.solver
    floor = 1.0 / sv.max_step_s
    if sv.method in FIXED_STEP_METHODS:
        return floor
    fastest_hz = max(c.rate_hz for c in coordinate_frequencies(scenario))
    base = ATTEMPTS_PER_MESH_PERIOD * mesh_frequency_sum_hz(scenario) + ATTEMPTS_PER_RATE_HZ * fastest_hz
    relative = sv.absolute_tolerance / default_tolerance(scenario) / REFERENCE_TOLERANCE[sv.method]
    tolerance = REFERENCE_ATTEMPTS[sv.method] * relative ** -TOLERANCE_EXPONENT[sv.method]
    return max(floor, tolerance * base)


def us_per_attempt(scenario: Scenario) -> float:
    """Expected cost of one step attempt on the reference machine, us."""
    lateral = [g for st in scenario.parallel_stages for g in (st.pinion, st.wheel) if g.lateral != "none"]
    per_evaluation = (
        max(MIN_US_PER_EVALUATION, US_PER_EVALUATION_PER_COORDINATE * coordinates(scenario))
        + US_PER_EVALUATION_PER_LATERAL_GEAR * len(lateral)
        + US_PER_EVALUATION_PER_BEARING_LAW * sum(g.bearing.kind != "linear" for g in lateral)
    )
    return EVALUATIONS_PER_ATTEMPT[scenario.solver.method] * per_evaluation


def estimate_wall_time(scenario: Scenario) -> WallTimeEstimate:
    """Expected wall time of ``simulate(scenario)`` (engine-free; within a factor 3 on the scenes, see
    the module docstring)."""
    t_end = scenario.operation.t_end_s
    attempts = attempts_per_simulated_s(scenario) * t_end
    cost = us_per_attempt(scenario)
    return WallTimeEstimate(t_end, attempts, cost, OUTPUT_OVERHEAD * attempts * cost * 1e-6)


def makespan_s(durations_s: Iterable[float], workers: int) -> float:
    """Wall time of jobs of ``durations_s`` taken in order by ``workers`` processes, each job by the
    first process free (a process pool's queue)."""
    free = [0.0] * max(1, workers)
    for d in durations_s:
        heapq.heappush(free, heapq.heappop(free) + d)
    return max(free)


def duration_text(seconds: float) -> str:
    """``~40 s``, ``~12 min``, ``~3.5 h``, ``~2.1 days``."""
    if seconds < 90:
        return f"~{seconds:.2g} s"
    if seconds < 90 * 60:
        return f"~{seconds / 60:.2g} min"
    if seconds < 48 * 3600:
        return f"~{seconds / 3600:.2g} h"
    return f"~{seconds / 86400:.2g} days"


def refusal(
    wall_s: float, limit_minutes: float | None, what: str, remedy: str, at_least: bool = False
) -> str | None:
    """The message refusing ``what`` (e.g. ``the run``) estimated to take (``at_least``) ``wall_s``,
    above ``limit_minutes`` (None: no limit), naming the option that lifts the limit and ``remedy``;
    None when within it."""
    if limit_minutes is None or wall_s <= limit_minutes * 60:
        return None
    need = math.ceil(wall_s / 60)
    takes = f"{'at least ' if at_least else ''}{duration_text(wall_s)}"
    return (
        f"{what} is estimated to take {takes} of wall time, above the limit of --max-wall-minutes "
        f"{limit_minutes:g}; give --max-wall-minutes {need} to run it anyway, or {remedy}"
    )
