"""Run a scenario on Exudyn and return a :class:`~gearbody.result.Result` on a fixed output grid.

The explicit adaptive solver records every step (sensors with write period 0). Coordinates are then
resampled onto ``t_k = k / output_rate_hz`` with cubic Hermite interpolation (positions from positions
and velocities, velocities from velocities and accelerations), and the mesh force is evaluated on the
resampled states by the same compiled law the solver used.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import exudyn as exu
import exudyn.solver
import numpy as np

from ..assembly import check_resolved_modes, mesh_frequency_hz
from ..assembly.layouts import drive_system
from ..errors import GearbodyError, SimulationError
from ..model import Scenario, load_scenario
from ..model.budget import memory_limit_bytes
from ..model.kinds import register_stage_kind, stage_kind
from ..model.solver import SOLVER_METHODS
from ..result import Result
from ..signals import stage_prefix
from .build import BuiltSystem, build
from .collect import collect
from .hints import divergence_hint, mesh_range_hint, stall_hint

SOLVER_TYPES = {name: getattr(exu.DynamicSolverType, name) for name in SOLVER_METHODS}
# Exudyn 1.13's explicit step control accepts a step at the minimum step size only once per run
# (CSolverExplicit.cpp: `if (hNew == hMin && !minStepSizeWarned)`), and rejects it forever after.
# Jumps of k_z and of the contact damping are therefore crossed by error control alone, with a
# minimum step far below any step it needs; the monitor below reports a stall instead of hanging.
MIN_STEP_S = 1e-14
FSAL_METHODS = ("DOPRI5", "ODE23")


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
    # DOPRI5 and ODE23 end a step with a stage at the step's end (first same as last): Exudyn's extra
    # end-of-step evaluation gives bitwise the same accelerations (checked on every topology), one force
    # call in eight saved. The other methods need it for the stored accelerations.
    ti.explicit.computeEndOfStepAccelerations = sv.method not in FSAL_METHODS
    s.solution.file.write = False
    s.solution.sensors.writePeriod = 0.0  # every step; resampled afterwards
    s.show.computationTime = False
    s.show.statistics = False
    return s


def build_scenario(scenario: Scenario) -> tuple[BuiltSystem, np.ndarray, np.ndarray]:
    """Exudyn system of a scenario at its initial state (an infeasible start raises InputError)."""
    layout, q0, v0 = drive_system(scenario)
    return build(layout, q0, v0, force_path=scenario.solver.force_path), q0, v0


def simulate(scenario: Scenario | str | Path, *, progress: bool = False) -> Result:
    """Simulate a scenario on Exudyn and return its :class:`~gearbody.result.Result`.

    ``scenario``: a :class:`~gearbody.model.Scenario`, or a scene name or TOML path
    (:func:`~gearbody.model.load_scenario`). ``progress`` shows a progress bar on stderr. Raises
    :class:`~gearbody.errors.InputError` for a scenario that cannot run (before anything is solved) and
    :class:`SimulationError` on numerical failure (the message names the simulated time and a hint).
    This is :func:`gearbody.simulate`.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    wall0 = time.perf_counter()
    check_resolved_modes(scenario)  # a mode far above what the run resolves: refused (exit 2)
    built, _, _ = build_scenario(scenario)
    build_s = time.perf_counter() - wall0
    mbs = built.mbs
    if scenario.meta.topology == "muller":  # anything near 1e3 m/s of deflection rate is divergence
        watched = (1e3, "deflection rate", "m/s")
    else:
        watched = (100.0 * scenario.design.motor.synchronous_speed_rad_s, "motor speed", "rad/s")
    sv = scenario.solver
    built.watchdog.watch(
        scenario.operation.t_end_s,
        watched[0],
        progress,
        *watched[1:],
        wall_time_limit_s=sv.wall_time_limit_s,
        memory_limit_bytes=memory_limit_bytes(scenario),
        memory_limit_default=sv.memory_limit_MiB is None,
        max_step_s=sv.max_step_s,
        resolved_period_s=1.0 / max(sv.output_rate_hz, 1.0 / sv.max_step_s),
        stall_hint=stall_hint(scenario),
        divergence_hint=divergence_hint(scenario),
    )
    settings = solver_settings(scenario)
    t_solve0 = time.perf_counter()
    exu.config.suppressWarnings = True  # min-step notices: gearbody checks the steps itself (_collect)
    # Exudyn prints its "DYNAMIC SOLVER FAILED" banner itself when a run stops; gearbody says what
    # happened in its own error instead (nothing else is printed by a run with verboseMode 0).
    print_to_console = exu.config.printToConsole
    exu.config.printToConsole = False
    # Python user functions allocate their return lists by design; Exudyn's allocation notice says so.
    exudyn.solver.solverCheckMemoryAllocationsThreshold = 2**62
    try:
        exu.SolveDynamic(mbs, settings, solverType=SOLVER_TYPES[sv.method], storeSolver=True, showHints=False)
        built.watchdog.finished = True
    except Exception as exc:  # a user function raised (stall watchdog) or Exudyn failed
        if built.watchdog.interrupted:  # Ctrl-C inside a user function, reported by Exudyn as its error
            raise KeyboardInterrupt from None
        if built.watchdog.failure:
            raise SimulationError(built.watchdog.failure) from None
        raise SimulationError(_failure_message(built.watchdog.t_max, exc)) from exc
    finally:
        exu.config.printToConsole = print_to_console
        exu.config.suppressWarnings = False
        built.watchdog.close()
    solve_s = time.perf_counter() - t_solve0
    result = collect(scenario, built)
    _check_mesh_range(scenario, result)
    it = mbs.sys["dynamicSolver"].it
    result.meta["solver_statistics"]["rejected_steps"] = int(it.rejectedAutomaticStepSizeSteps)
    result.meta["solver_statistics"].update(
        {
            "build_wall_s": build_s,
            "solve_wall_s": solve_s,
            "wall_time_s": time.perf_counter() - wall0,
            "force_path": built.force_path,
        }
    )
    return result


def _failure_message(t_s: float, exc: Exception) -> str:
    """What a failed solve tells the user: where it stopped and what to change, without Exudyn's
    internal text (its traceback and 'check your Python code') or Python reprs. A gearbody error
    raised inside a force law keeps its own message."""
    cause = exc.__cause__ or exc.__context__
    where = f"the solver stopped at t = {t_s:.6g} s" if t_s >= 0 else "the solver stopped at its start"
    if isinstance(cause, GearbodyError):
        return f"{where}: {cause}"
    if cause is not None:  # a force law raised (floating-point trouble in a compiled law, ...)
        return (
            f"{where}: a force law failed ({type(cause).__name__}). Hint: check for extreme stiffness, "
            "inertia or load values, or tighten solver.absolute_tolerance / lower solver.max_step_s"
        )
    return (
        f"{where}: Exudyn's explicit solver gave up ({type(exc).__name__}). Hint: tighten "
        "solver.absolute_tolerance or lower solver.max_step_s"
    )


MAX_DEFLECTION_BASE_PITCH = 0.1
"""Largest |mesh deflection| accepted, as a fraction of the base pitch: the lumped mesh (one pair of
teeth in mesh, phase from the pinion angle) means nothing once the gears have moved that far apart."""


def _check_mesh_range(scenario: Scenario, result: Result) -> None:
    """Every mesh of every stage within its range (each kind's ``check_result``)."""
    for k, st in enumerate(scenario.stages):
        hook = stage_kind(st).check_result
        if hook is not None:
            hook(scenario, k, result)


def _check_parallel_mesh_range(scenario: Scenario, k: int, result: Result) -> None:
    """The mesh deflection of parallel stage k within MAX_DEFLECTION_BASE_PITCH of the base pitch."""
    st = scenario.stages[k]
    prefix = stage_prefix(k)
    delta = np.abs(result[prefix + "mesh_deflection_m"])
    p_b = 2 * math.pi * st.pinion.base_radius_m / st.pinion.teeth
    if delta.max() > MAX_DEFLECTION_BASE_PITCH * p_b:
        m = int(np.argmax(delta > MAX_DEFLECTION_BASE_PITCH * p_b))
        hint = mesh_range_hint(scenario, k, MAX_DEFLECTION_BASE_PITCH * p_b)
        raise SimulationError(
            f"stage {k + 1}: the mesh deflection reached {delta[m] * 1e3:.3g} mm at t = "
            f"{result.time_s[m]:.6g} s, more than {MAX_DEFLECTION_BASE_PITCH:g} of the base pitch "
            f"({p_b * 1e3:.3g} mm): the lumped mesh model is outside its range (the gears ran "
            f"through each other). Hint: {hint}"
        )


def _check_planetary_mesh_range(scenario: Scenario, k: int, result: Result) -> None:
    """Every planet mesh of planetary stage k within MAX_DEFLECTION_BASE_PITCH of the base pitch."""
    st = scenario.stages[k]
    prefix = stage_prefix(k)
    p_b = math.pi * st.module_mm * 1e-3 * math.cos(math.radians(st.pressure_angle_deg))
    limit = MAX_DEFLECTION_BASE_PITCH * p_b
    for n in range(st.planets):
        for mesh in ("sun", "ring"):
            delta = np.abs(result[f"{prefix}planet_{n + 1}_{mesh}_mesh_deflection_m"])
            if delta.max() > limit:
                m = int(np.argmax(delta > limit))
                raise SimulationError(
                    f"stage {k + 1}, planet {n + 1}: the {mesh} mesh deflection reached "
                    f"{delta[m] * 1e3:.3g} mm at t = {result.time_s[m]:.6g} s, more than "
                    f"{MAX_DEFLECTION_BASE_PITCH:g} of the base pitch ({p_b * 1e3:.3g} mm): the lumped "
                    f"mesh is outside its range. Hint: check the load, the {mesh}_mesh stiffness and the "
                    "members' bearing stiffnesses"
                )


__all__ = ["SimulationError", "build", "simulate", "solver_settings", "mesh_frequency_hz"]


register_stage_kind("parallel", check_result=_check_parallel_mesh_range)
register_stage_kind("planetary", check_result=_check_planetary_mesh_range)
