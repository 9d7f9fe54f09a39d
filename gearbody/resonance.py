"""Resonance tools: K_d against speed from steady-state runs, and the Campbell diagram.

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
from pathlib import Path

import numpy as np

from .analysis.dynamic_factor import INSTABILITY_KD, separation_stats
from .analysis.modal import campbell_lines
from .model import Scenario, load_scenario, scenario_to_dict

__all__ = [
    "SpeedSweep",
    "campbell_lines",
    "kd_speed_sweep",
    "plot_campbell",
    "plot_kd_against_speed",
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


def plot_kd_against_speed(
    sweep: SpeedSweep, natural_frequencies_hz: Sequence[float], path: str | Path, title: str = ""
) -> Path:
    """K_d max / min against mesh frequency, with the natural frequencies as vertical lines."""
    from .plots import _figure, _save

    fig = _figure((900, 500), 100)
    ax = fig.add_subplot(1, 1, 1)
    ok = np.isfinite(sweep.kd_max)
    ax.plot(sweep.mesh_frequency_hz[ok], sweep.kd_max[ok], "o-", label="K_d max")
    ax.plot(sweep.mesh_frequency_hz[ok], sweep.kd_min[ok], "s--", label="K_d min")
    ax.axhline(INSTABILITY_KD, color="red", lw=0.8, ls=":", label=f"K_d = {INSTABILITY_KD:g}")
    lo, hi = ax.get_xlim()
    for f in natural_frequencies_hz:
        if f > 1.0 and lo <= f <= hi:
            ax.axvline(f, color="grey", lw=0.8, ls="--", label="natural frequency")
            ax.text(f, ax.get_ylim()[1], f" {f:.0f} Hz", rotation=90, va="top", fontsize=8, color="grey")
    handles, labels = ax.get_legend_handles_labels()
    seen = dict(zip(labels, handles, strict=True))
    ax.legend(seen.values(), seen.keys(), loc="best")
    ax.set_xlabel("mesh frequency f_z = z1 w / 2 pi [Hz]")
    ax.set_ylabel("K_d = F / F_rated [-]")
    ax.set_title(title or "K_d against speed (steady rated load)")
    ax.grid(alpha=0.3)
    return _save(fig, path, 100)


def plot_campbell(
    natural_frequencies_hz: Sequence[float],
    pinion_teeth: int,
    max_speed_rad_s: float,
    path: str | Path,
    harmonics: int = 3,
    title: str = "",
    operating_speed_rad_s: float | None = None,
) -> Path:
    """Campbell diagram: mesh harmonics k z1 w / 2 pi against pinion speed, natural frequencies as
    horizontal lines; crossings (resonance speeds) marked."""
    from .plots import _figure, _save

    fig = _figure((900, 600), 100)
    ax = fig.add_subplot(1, 1, 1)
    w = np.linspace(0, max_speed_rad_s, 200)
    f_top = harmonics * pinion_teeth * max_speed_rad_s / (2 * math.pi)
    for k in range(1, harmonics + 1):
        ax.plot(w, k * pinion_teeth * w / (2 * math.pi), label=f"{k} f_z")
    crossings = campbell_lines(natural_frequencies_hz, pinion_teeth, harmonics)["speed_rad_s"]
    for j, f in enumerate(natural_frequencies_hz):
        if f < 1.0 or f > f_top:
            continue
        ax.axhline(f, color="grey", lw=0.8, ls="--")
        ax.text(max_speed_rad_s, f, f" {f:.0f} Hz", va="center", fontsize=8, color="grey")
        for k in range(harmonics):
            ws = crossings[k, j]
            if ws <= max_speed_rad_s:
                ax.plot(ws, f, "ko", ms=4)
    if operating_speed_rad_s:
        ax.axvline(operating_speed_rad_s, color="green", lw=1, label="operating speed")
    ax.set_xlim(0, max_speed_rad_s)
    ax.set_ylim(0, f_top)
    ax.set_xlabel("pinion speed w [rad/s]")
    ax.set_ylabel("frequency [Hz]")
    ax.set_title(title or "Campbell diagram")
    ax.legend(loc="upper left")
    ax.grid(alpha=0.3)
    return _save(fig, path, 100)
