"""Resources a run needs, estimated from the scenario before anything runs (docs/scenario.md, "Resource
limits"): the output grid (samples x signals, and the fine grid of the band-limited signals, whose
oversampling grows as a mesh's transition width shrinks) and the solver's stored steps (every step is
recorded; at least t_end / max_step_s of them). A scenario whose estimate exceeds its memory budget
(``solver.memory_limit_MiB``) is refused with the key, the value and the limit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from .params import ScenarioError, stage_key

if TYPE_CHECKING:
    from .scenario import Scenario

DEFAULT_MEMORY_LIMIT_MIB = 2048.0
"""Memory budget of one run (output arrays and stored solver steps) when solver.memory_limit_MiB is
unset."""

OVERSAMPLING = 4
"""Fine points per output sample on which band-limited signals are evaluated before filtering."""

TRANSITION_POINTS = 3.0
"""Fine points across each smoothed transition of a mesh law (transition_width > 0)."""

SPEED_MARGIN = 1.05
"""The fastest pinion speed of a run, estimated before it as this times the highest speed fraction of
the synchronous speed (the run itself measures it: engine.collect checks again)."""

BYTES_PER_VALUE = 8
WORK_ARRAYS_PER_DOF = 2
"""Fine-grid values per coordinate besides the signals (states and interpolation temporaries): with
them the estimate lies above the measured peak of the output sampling (0.6-0.85 of it on one-stage and
lateral-8dof at 79 fine points per sample)."""
STORED_VALUES_PER_STEP_DOF = 14
STORED_VALUES_PER_STEP = 18
"""Stored values per solver step: q, v, a sensors (time included) read back and copied, and the
coefficients of the two cubic Hermite interpolants: ~14 per coordinate + 18."""


def memory_limit_bytes(scenario: Scenario) -> float:
    """The run's memory budget, bytes."""
    limit = scenario.solver.memory_limit_MiB
    return (DEFAULT_MEMORY_LIMIT_MIB if limit is None else limit) * 2**20


def oversampling(f_mesh_hz: float, transition_width: float, output_rate_hz: float) -> int:
    """Fine points per output sample: OVERSAMPLING, or more so that a smoothed transition of
    ``transition_width`` of a mesh period spans TRANSITION_POINTS fine points at ``f_mesh_hz``."""
    if transition_width <= 0:
        return OVERSAMPLING
    return max(OVERSAMPLING, math.ceil(TRANSITION_POINTS * f_mesh_hz / (transition_width * output_rate_hz)))


def coordinates(scenario: Scenario) -> int:
    """Coordinates of the simulated model (rotations and free gear-centre translations)."""
    if scenario.meta.topology == "muller":
        return 1
    parallel = scenario.parallel_stages
    rotations = 2 if scenario.meta.topology == "two-wheel" else 2 + 2 * len(parallel)
    planetary = sum(st.coordinate_count for st in scenario.stages if st not in parallel)
    return (
        rotations + planetary + sum(len(g.free_directions) for st in parallel for g in (st.pinion, st.wheel))
    )


def signal_count(scenario: Scenario) -> int:
    """Signals of the result: 3 per rotation, 10 per mesh, 2 drive torques, 3 per free direction and 4
    bearing and housing signals per lateral gear (13 for Muller's model)."""
    if scenario.meta.topology == "muller":
        return 13
    gears = [g for st in scenario.parallel_stages for g in (st.pinion, st.wheel)]
    rotations = coordinates(scenario) - sum(len(g.free_directions) for g in gears)
    lateral = sum(3 * len(g.free_directions) + 4 for g in gears if g.lateral != "none")
    meshes = sum(st.mesh_count for st in scenario.stages)
    return 3 * rotations + 10 * meshes + 2 + lateral


def is_band_limited(scenario: Scenario) -> bool:
    """True when force and acceleration signals are band-limited on a fine grid."""
    return scenario.solver.anti_aliasing and scenario.meta.topology != "muller"


@dataclass(frozen=True)
class Estimate:
    """Memory a run needs before it starts: output grid and stored steps."""

    samples: int
    signals: int
    oversampling: int
    oversampling_stage: int | None  # the stage whose transition width sets the oversampling
    output_bytes: float
    min_steps: float
    steps_bytes: float

    @property
    def total_bytes(self) -> float:
        return self.output_bytes + self.steps_bytes


def _pinion_speeds_rad_s(scenario: Scenario) -> list[float]:
    """Highest expected pinion speed of each stage (synchronous speed x highest speed fraction)."""
    fraction = max(1.0, *scenario.operation.speed_profile.fraction)
    speed = scenario.design.motor.synchronous_speed_rad_s * fraction * SPEED_MARGIN
    speeds = []
    for st in scenario.stages:
        speeds.append(speed)
        speed /= st.ratio
    return speeds


MOST_SAMPLES = 2**62
"""Output samples counted at most: t_end rate beyond it (up to an infinite product of two finite
numbers, 1.8e308 s at 20 kHz) is beyond every memory budget all the same."""


def _samples(t_end_s: float, rate_hz: float) -> int:
    points = t_end_s * rate_hz
    return math.floor(points + 1e-9) + 1 if points < MOST_SAMPLES else MOST_SAMPLES


def output_samples(scenario: Scenario) -> int:
    """Samples of the run's output grid, t_k = k / solver.output_rate_hz for k = 0 .. floor(t_end rate)."""
    return _samples(scenario.operation.t_end_s, scenario.solver.output_rate_hz)


def output_memory_bytes(scenario: Scenario, oversampling_points: int) -> float:
    """Peak memory of the output sampling with ``oversampling_points`` fine points per sample, bytes."""
    samples = output_samples(scenario)
    per_point = signal_count(scenario) + WORK_ARRAYS_PER_DOF * coordinates(scenario)
    fine = (samples - 1) * oversampling_points + 1 if is_band_limited(scenario) else samples
    return float(fine) * per_point * BYTES_PER_VALUE


def estimate(scenario: Scenario) -> Estimate:
    """Memory estimate of a run of ``scenario`` (lower bounds: the run may need more steps)."""
    sv, t_end = scenario.solver, scenario.operation.t_end_s
    samples = _samples(t_end, sv.output_rate_hz)
    M, stage = OVERSAMPLING, None
    if is_band_limited(scenario):
        for k, (st, w_p) in enumerate(zip(scenario.stages, _pinion_speeds_rad_s(scenario), strict=True)):
            m = oversampling(st.mesh_frequency_hz(w_p), st.transition_width, sv.output_rate_hz)
            if m > M:
                M, stage = m, k
    min_steps = t_end / sv.max_step_s
    n = coordinates(scenario)
    steps_bytes = min_steps * (STORED_VALUES_PER_STEP_DOF * n + STORED_VALUES_PER_STEP) * BYTES_PER_VALUE
    return Estimate(
        samples, signal_count(scenario), M, stage, output_memory_bytes(scenario, M), min_steps, steps_bytes
    )


def _mib(x: float) -> str:
    return f"{x / 2**20:.3g} MiB" if x < 2**30 else f"{x / 2**30:.3g} GiB"


def check_resources(scenario: Scenario) -> None:
    """Refuse a scenario whose estimated memory exceeds its budget, naming the responsible key."""
    est = estimate(scenario)
    limit = memory_limit_bytes(scenario)
    if est.total_bytes <= limit:
        return
    sv, t_end = scenario.solver, scenario.operation.t_end_s
    budget = f"the memory budget solver.memory_limit_MiB = {limit / 2**20:g}" + (
        " (default)" if sv.memory_limit_MiB is None else ""
    )
    if est.steps_bytes >= est.output_bytes:
        raise ScenarioError(
            f"solver.max_step_s = {sv.max_step_s:g} with operation.t_end_s = {t_end:g}: at least "
            f"{est.min_steps:.3g} solver steps, all stored (~{_mib(est.steps_bytes)}), exceed {budget}; "
            "raise solver.max_step_s or shorten operation.t_end_s"
        )
    if est.oversampling_stage is not None:
        k = est.oversampling_stage
        w = scenario.stages[k].transition_width
        raise ScenarioError(
            f"{stage_key(k, 'mesh')}.transition_width = {w:g}: resolving a transition of {w:g} mesh "
            f"periods needs {float(est.oversampling):.3g} fine points per output sample, {est.samples} "
            f"samples x {est.signals} signals on that grid (~{_mib(est.output_bytes)}) exceed {budget}; "
            "widen the transition (the fine grid shrinks as 1 / width), use 0 (sharp: jumps are treated "
            "exactly), or shorten operation.t_end_s"
        )
    raise ScenarioError(
        f"solver.output_rate_hz = {sv.output_rate_hz:g} with operation.t_end_s = {t_end:g}: "
        f"{est.samples:.3g} output samples x {est.signals} signals (~{_mib(est.output_bytes)}) exceed "
        f"{budget}; lower solver.output_rate_hz or shorten operation.t_end_s"
    )
