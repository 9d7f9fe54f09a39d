"""Resonance tools: K_d against speed from steady-state runs (its plots: gearbody.plotting.kd_speed and
gearbody.plotting.campbell; the Campbell lines: gearbody.analysis.modal).

``kd_speed_sweep`` runs the scenario at rated load from its steady state at each speed (a fraction of
the motor's synchronous speed), discards a settling time and records K_d statistics; the natural
frequencies of ``gearbody modes`` mark where the k-th mesh harmonic meets a mode
(``k z1 w / 2 pi = f_n``). The paper's claim (section 2, Figs. 5-8): the one-stage system is unstable
(K_d > 2) when the mesh frequency equals its natural frequency.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from .analysis.dynamic_factor import separation_stats
from .model import Scenario, load_scenario, scenario_to_dict

__all__ = [
    "SpeedSweep",
    "kd_speed_sweep",
    "steady_overrides",
]


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
        keys = ("speed_fraction", "pinion_speed_rad_s", "mesh_frequency_hz", "kd_max", "kd_min",
                "kd_rms_dynamic", "separation_fraction")
        return [
            {**{k: float(getattr(self, k)[i]) for k in keys}, "error": self.errors[i]}
            for i in range(self.speed_fraction.size)
        ]


def _one_speed(args) -> tuple:
    data, fraction, settle_s, record_s = args
    from .engine import simulate

    scenario = load_scenario(data, steady_overrides(fraction, settle_s + record_s))
    try:
        res = simulate(scenario)
    except Exception as exc:  # a failed speed is reported, the sweep goes on
        return (fraction, math.nan, math.nan, math.nan, math.nan, math.nan, math.nan, str(exc))
    window = res.time_s >= settle_s
    kd = res.kd[window]
    w = float(np.mean(res["pinion_speed_rad_s"][window]))
    f_z = float(np.mean(res["mesh_frequency_hz"][window]))
    sep = separation_stats(res.mesh_force[window], res.time_s[window], kd=kd)
    return (fraction, w, f_z, float(kd.max()), float(kd.min()), float(np.std(kd)),
            float(sep.separated_fraction), "")


def kd_speed_sweep(
    scenario: Scenario,
    speed_fractions: Sequence[float],
    *,
    settle_s: float = 0.1,
    record_s: float = 0.1,
    workers: int = 1,
) -> SpeedSweep:
    """K_d at rated load against speed: one steady run per speed fraction.

    Args:
        scenario: the system (its operation section is replaced by steady running).
        speed_fractions: motor speeds as fractions of the synchronous speed (> 0).
        settle_s: simulated time discarded at the start of each run [s].
        record_s: simulated time analysed after it [s].
        workers: processes to run speeds in parallel (each rebuilds the model).
    """
    fractions = [float(f) for f in speed_fractions]
    if not fractions or min(fractions) <= 0:
        raise ValueError(f"speed_fractions must be non-empty and > 0, got {fractions}")
    if settle_s < 0 or record_s <= 0:
        raise ValueError(f"settle_s must be >= 0 and record_s > 0, got {settle_s}, {record_s}")
    data = scenario_to_dict(scenario)
    jobs = [(data, f, settle_s, record_s) for f in fractions]
    if workers > 1:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            out = list(pool.map(_one_speed, jobs))
    else:
        out = [_one_speed(j) for j in jobs]
    cols = list(zip(*out, strict=True))
    return SpeedSweep(
        *(np.array(c, float) for c in cols[:7]),
        pinion_teeth=scenario.stages[0].pinion.teeth,
        errors=list(cols[7]),
    )
