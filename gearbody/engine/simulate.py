"""Run a scenario on Exudyn and return a :class:`~gearbody.result.Result` on a fixed output grid.

The explicit adaptive solver records every step (sensors with write period 0). Coordinates are then
resampled onto ``t_k = k / output_rate_hz`` with cubic Hermite interpolation (positions from positions
and velocities, velocities from velocities and accelerations), and the mesh force is evaluated on the
resampled states by the same compiled law the solver used.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import exudyn as exu
import exudyn.solver
import numpy as np

from ..assembly import (
    initial_state,
    mesh_frequency_hz,
    static_lateral_displacements_m,
    torsional_layout,
)
from ..errors import SimulationError
from ..model import Scenario
from ..result import Result
from .build import BuiltSystem, build_muller, build_torsional
from .collect import collect

SOLVER_TYPES = {
    name: getattr(exu.DynamicSolverType, name) for name in ("DOPRI5", "ODE23", "RK44", "RK67", "DVERK6")
}
# Exudyn 1.13's explicit step control accepts a step at the minimum step size only once per run
# (CSolverExplicit.cpp: `if (hNew == hMin && !minStepSizeWarned)`), and rejects it forever after.
# Jumps of k_z and of the contact damping are therefore crossed by error control alone, with a
# minimum step far below any step it needs; the monitor below reports a stall instead of hanging.
MIN_STEP_S = 1e-14
STALL_CHECKS = 50  # x Monitor.every step attempts
STALL_PROGRESS_S = 1e-9


@dataclass
class _Monitor:
    """Pre-step hook: progress display after a few seconds of wall time, and divergence detection."""

    mbs: exu.MainSystem
    watch_node: int
    t_end: float
    speed_limit: float
    progress: bool
    every: int = 200
    count: int = 0
    bar: object = None
    failure: str = ""
    last_draw: float = 0.0
    history: list = field(default_factory=list)

    def __post_init__(self):
        self.t_wall0 = time.monotonic()

    def __call__(self, mbs, t):
        self.count += 1
        if self.count % self.every:
            return True
        self.history.append(t)
        if len(self.history) > STALL_CHECKS:
            t_before = self.history.pop(0)
            if t - t_before < STALL_PROGRESS_S:
                self.failure = (
                    f"the solver stalled at t = {t:.9g} s: {STALL_CHECKS * self.every} step attempts "
                    f"advanced less than {STALL_PROGRESS_S:g} s (step size collapse). Hint: loosen "
                    "solver.relative_tolerance / absolute_tolerance, or check for extreme parameter values"
                )
                return False
        w = float(np.ravel(mbs.GetNodeOutput(self.watch_node, exu.OutputVariableType.Coordinates_t))[0])
        if not math.isfinite(w) or abs(w) > self.speed_limit:
            self.failure = (
                f"state diverged at t = {t:.6g} s (speed of {self.watch_node=} is {w:.3g} rad/s). "
                "Hint: check stiffness, inertia and load values, or tighten solver tolerances / "
                "lower solver.max_step_s"
            )
            return False
        if self.progress:
            if self.bar is None and time.monotonic() - self.t_wall0 > 2.0:
                from tqdm import tqdm

                self.bar = tqdm(
                    total=round(self.t_end, 6),
                    unit="s sim",
                    desc="simulating",
                    bar_format="{l_bar}{bar}| {n:.3f}/{total:.3f} s sim [{elapsed}<{remaining}]",
                )
            now = time.monotonic()
            if self.bar is not None and now - self.last_draw > 0.5:
                self.last_draw = now
                self.bar.n = round(t, 6)
                self.bar.refresh()
        return True

    def close(self):
        if self.bar is not None:
            self.bar.n = self.bar.total
            self.bar.close()


def solver_settings(scenario: Scenario) -> exu.SimulationSettings:
    s = exu.SimulationSettings()
    sv, t_end = scenario.solver, scenario.operation.t_end_s
    ti = s.timeIntegration
    ti.endTime = t_end
    ti.numberOfSteps = max(1, math.ceil(t_end / sv.max_step_s))  # max step = endTime / numberOfSteps
    ti.automaticStepSize = True
    ti.relativeTolerance = sv.relative_tolerance
    ti.absoluteTolerance = sv.absolute_tolerance
    ti.minimumStepSize = MIN_STEP_S
    ti.initialStepSize = min(sv.max_step_s, 1e-6)
    ti.verboseMode = 0
    ti.explicit.computeEndOfStepAccelerations = True
    s.solution.file.write = False
    s.solution.sensors.writePeriod = 0.0  # every step; resampled afterwards
    s.show.computationTime = False
    s.show.statistics = False
    return s


def build(scenario: Scenario) -> tuple[BuiltSystem, np.ndarray, np.ndarray]:
    """Exudyn system of a scenario at its initial state (an infeasible start raises InputError)."""
    q0, v0 = initial_state(scenario)
    if scenario.meta.topology == "muller":
        return build_muller(scenario, q0, v0), q0, v0
    lateral_u0 = static_lateral_displacements_m(scenario)
    return build_torsional(torsional_layout(scenario), q0, v0, lateral_u0=lateral_u0), q0, v0


def simulate(scenario: Scenario, *, progress: bool = False) -> Result:
    """Simulate a scenario; raise :class:`SimulationError` on numerical failure."""
    wall0 = time.perf_counter()
    built, _, _ = build(scenario)
    build_s = time.perf_counter() - wall0
    mbs = built.mbs
    watch = built.nodes[0]
    limit = 100.0 * scenario.design.motor.synchronous_speed_rad_s
    if scenario.meta.topology == "muller":
        limit = 1e3  # m/s of deflection rate: anything near this is divergence
    monitor = _Monitor(mbs, watch, scenario.operation.t_end_s, limit, progress)
    mbs.SetPreStepUserFunction(monitor)
    settings = solver_settings(scenario)
    t_solve0 = time.perf_counter()
    exu.config.suppressWarnings = True  # min-step notices: gearbody checks the steps itself (_collect)
    # Python user functions allocate their return lists by design; Exudyn's allocation notice says so.
    exudyn.solver.solverCheckMemoryAllocationsThreshold = 2**62
    try:
        exu.SolveDynamic(
            mbs, settings, solverType=SOLVER_TYPES[scenario.solver.method], storeSolver=True, showHints=False
        )
    except Exception as exc:  # a user function raised (stall watchdog) or Exudyn failed
        if built.watchdog.failure:
            raise SimulationError(built.watchdog.failure) from None
        message = str(exc)
        last = message.strip().splitlines()[-1] if message.strip() else repr(exc)
        raise SimulationError(f"Exudyn stopped: {last}") from exc
    finally:
        exu.config.suppressWarnings = False
        monitor.close()
    solve_s = time.perf_counter() - t_solve0
    if monitor.failure:
        raise SimulationError(monitor.failure)
    result = collect(scenario, built)
    _check_mesh_range(scenario, result)
    it = mbs.sys["dynamicSolver"].it
    result.meta["solver_statistics"]["rejected_steps"] = int(it.rejectedAutomaticStepSizeSteps)
    result.meta["solver_statistics"].update(
        {"build_wall_s": build_s, "solve_wall_s": solve_s, "wall_time_s": time.perf_counter() - wall0}
    )
    return result


MAX_DEFLECTION_BASE_PITCH = 0.1
"""Largest |mesh deflection| accepted, as a fraction of the base pitch: the lumped mesh (one pair of
teeth in mesh, phase from the pinion angle) means nothing once the gears have moved that far apart."""


def _check_mesh_range(scenario: Scenario, result: Result) -> None:
    for k, st in enumerate(scenario.stages):
        prefix = "" if k == 0 else f"stage_{k + 1}_"
        delta = np.abs(result[prefix + "mesh_deflection_m"])
        p_b = 2 * math.pi * st.pinion.base_radius_m / st.pinion.teeth
        if delta.max() > MAX_DEFLECTION_BASE_PITCH * p_b:
            m = int(np.argmax(delta > MAX_DEFLECTION_BASE_PITCH * p_b))
            raise SimulationError(
                f"stage {k + 1}: the mesh deflection reached {delta[m] * 1e3:.3g} mm at t = "
                f"{result.time_s[m]:.6g} s, more than {MAX_DEFLECTION_BASE_PITCH:g} of the base pitch "
                f"({p_b * 1e3:.3g} mm): the lumped mesh model is outside its range (the gears ran "
                "through each other). Hint: a tooth stiffness factor of 0 leaves no load path for a "
                "whole mesh period in the lumped model; use a factor > 0 (e.g. 0.2), or check loads "
                "and stiffnesses"
            )


__all__ = ["SimulationError", "build", "simulate", "solver_settings", "mesh_frequency_hz"]
