"""K_d against speed from steady-state runs (the paper's section 2, Figs. 5-8), as a study on the
common executors (:mod:`.executors`).

``kd_speed_sweep`` runs the scenario at rated load from its steady state at each speed (a fraction of
the motor's synchronous speed), discards a settling time and records K_d statistics; one case per
speed, each running :func:`gearbody.studies.tasks.speed_case`. The natural frequencies of
``gearbody modes`` mark where the k-th mesh harmonic meets a mode (:mod:`gearbody.analysis.modal`);
:func:`gearbody.plotting.kd_speed.plot_kd_against_speed` draws the result.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gearbody.model import Scenario, load_scenario, scenario_to_dict

from ..errors import InputError
from .executors import run_jobs
from .tasks import SPEED_VALUES, speed_case

__all__ = ["SpeedSweep", "kd_speed_sweep", "steady_overrides"]


def steady_overrides(speed_fraction: float, t_end_s: float, load_fraction: float = 1.0) -> list[str]:
    """Scenario overrides for steady running at a speed fraction and load fraction from t = 0."""
    return [
        'operation.initial_state="steady"',
        f"operation.speed_profile={{time_s=[0.0],fraction=[{speed_fraction}]}}",
        f"operation.load_profile={{time_s=[0.0],fraction=[{load_fraction}]}}",
        f"operation.t_end_s={t_end_s}",
    ]


@dataclass
class SpeedSweep:
    """K_d statistics per speed of a sweep (arrays of equal length, one entry per speed)."""

    speed_fraction: np.ndarray
    """Motor speed as a fraction of its synchronous speed [-]."""
    pinion_speed_rad_s: np.ndarray
    """Mean pinion speed over the record [rad/s]."""
    mesh_frequency_hz: np.ndarray
    """Mean first-stage mesh frequency over the record [Hz]."""
    kd_max: np.ndarray
    kd_min: np.ndarray
    kd_rms_dynamic: np.ndarray
    """RMS of K_d - mean(K_d) [-]."""
    separation_fraction: np.ndarray
    """Fraction of the record with F <= 0 [-]."""
    pinion_teeth: int
    errors: list[str] = field(default_factory=list)
    """Per speed: "" or the error message of a failed run."""

    def rows(self) -> list[dict]:
        keys = (
            "speed_fraction",
            "pinion_speed_rad_s",
            "mesh_frequency_hz",
            "kd_max",
            "kd_min",
            "kd_rms_dynamic",
            "separation_fraction",
        )
        return [
            {**{k: float(getattr(self, k)[i]) for k in keys}, "error": self.errors[i]}
            for i in range(self.speed_fraction.size)
        ]


def kd_speed_sweep(
    scenario: Scenario,
    speed_fractions: Sequence[float],
    *,
    settle_s: float = 0.1,
    record_s: float = 0.1,
    workers: int = 1,
    scheduler: str | Any | None = None,
) -> SpeedSweep:
    """K_d at rated load against speed: one steady run per speed fraction.

    Args:
        scenario: the system (its operation section is replaced by steady running).
        speed_fractions: motor speeds as fractions of the synchronous speed (> 0).
        settle_s: simulated time discarded at the start of each run [s].
        record_s: simulated time analysed after it [s].
        workers: processes to run speeds in parallel (each rebuilds the model); 1: in this process.
        scheduler: a Dask scheduler address or client: run the speeds on that cluster instead.
    Raises:
        ValueError: no speeds, a speed <= 0, or a bad settle/record time.
        ScenarioError: the scenario does not take the steady-running overrides (before anything runs).
    """
    fractions = [float(f) for f in speed_fractions]
    if not fractions or min(fractions) <= 0:
        raise InputError(f"speed_fractions must be non-empty and > 0, got {fractions}")
    if settle_s < 0 or record_s <= 0:
        raise InputError(f"settle_s must be >= 0 and record_s > 0, got {settle_s}, {record_s}")
    data = scenario_to_dict(scenario)
    overrides = [steady_overrides(f, settle_s + record_s) for f in fractions]
    for ov in overrides:  # every case valid before anything runs (a ScenarioError is raised, not recorded)
        load_scenario(data, ov)
    jobs = [(f"speed-{i:04d}", (data, ov, settle_s)) for i, ov in enumerate(overrides)]
    outcomes = dict(
        run_jobs(
            speed_case,
            jobs,
            workers=None if scheduler is not None else max(int(workers), 1),
            scheduler=scheduler,
            name="gearbody-speed",
        )
    )
    columns: dict[str, list[float]] = {k: [] for k in SPEED_VALUES}
    errors = []
    for jid, _ in jobs:
        outcome = outcomes[jid]
        for k in SPEED_VALUES:
            columns[k].append(outcome["values"][k] if outcome["ok"] else math.nan)
        errors.append("" if outcome["ok"] else outcome["message"])
    return SpeedSweep(
        np.array(fractions, float),
        *(np.array(columns[k], float) for k in SPEED_VALUES),
        pinion_teeth=scenario.stages[0].pinion.teeth,
        errors=errors,
    )
