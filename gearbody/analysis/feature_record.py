"""The record features are computed on (:mod:`gearbody.analysis.features`): signals on one uniform time
grid plus the drive facts features need, the analysed window, and the error every feature raises."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gearbody.errors import InputError

from ..signals import stage_signal

DEFAULT_FRACTION = 0.25


class FeatureError(InputError):
    """A feature spec that names no feature, takes an option it does not have, or cannot be computed
    from the record (a missing signal, an empty window, an unknown natural frequency, a stage of the
    wrong kind); a ValueError, and a gearbody input error (exit code 2)."""


def stage_name(name: str, stage: int) -> str:
    """Signal ``name`` of stage ``stage`` (1-based), as a Result names it."""
    if stage < 1:
        raise FeatureError(f"stage = {stage}: stages count from 1")
    return stage_signal(name, stage - 1)


def operating_periods_s(t0_s: float, t1_s: float, profile_times_s: Sequence[float]) -> tuple[float, ...]:
    """The operating periods of a run from ``t0_s`` to ``t1_s``: its start, every breakpoint of its speed
    and load profiles (``profile_times_s``) inside the run, its end [s]."""
    inner = {float(t) for t in profile_times_s if t0_s < float(t) < t1_s}
    return (float(t0_s), *sorted(inner), float(t1_s))


@dataclass(frozen=True)
class Record:
    """Signals on one uniform time grid and the facts of the drive that features need.

    ``signals`` by name as a Result names them: ``kd``, ``mesh_force_N`` (stage k > 1: ``stage_k_kd``, ...),
    a planetary stage's ``planet_<n>_sun_mesh_kd``, ``planet_<n>_ring_mesh_force_N``, ...,
    ``pinion_angle_rad`` (a tachometer's angle suffices for spectra and synchronous averages), any
    vibration signal. ``pinion_teeth``, ``wheel_teeth``: of a parallel first stage (None when the first
    stage is planetary: the spectral and synchronous-average features then do not apply).
    ``period_boundaries_s``: start of the first operating period, every boundary, end.
    """

    time_s: NDArray[np.float64]
    signals: Mapping[str, NDArray[np.float64]]
    pinion_teeth: int | None = None
    wheel_teeth: int | None = None
    period_boundaries_s: tuple[float, ...] = ()
    natural_frequencies_hz: tuple[float, ...] = ()
    meta: Mapping[str, Any] = field(default_factory=dict)
    """What the record came from (a run's ``scenario`` and ``vibration_signal``), for features that
    analyse it as its drive (:mod:`gearbody.diagnosis.features`)."""

    def __post_init__(self) -> None:
        t = np.asarray(self.time_s, dtype=float)
        if t.ndim != 1 or t.size < 2 or not np.all(np.diff(t) > 0):
            raise FeatureError("Record.time_s: need >= 2 strictly increasing sample times")
        for name, values in self.signals.items():
            if np.shape(values) != t.shape:
                raise FeatureError(
                    f"Record signal {name!r}: {np.shape(values)} samples, time_s has {t.shape}"
                )
        for name in ("pinion_teeth", "wheel_teeth"):
            if getattr(self, name) is not None and int(getattr(self, name)) < 1:
                raise FeatureError(f"Record.{name} = {getattr(self, name)}: must be >= 1")
        if (self.pinion_teeth is None) != (self.wheel_teeth is None):
            raise FeatureError(
                "Record: give both pinion_teeth and wheel_teeth, or neither (no parallel stage 1)"
            )

    @property
    def sample_rate_hz(self) -> float:
        return float((self.time_s.size - 1) / (self.time_s[-1] - self.time_s[0]))

    def signal(self, name: str) -> NDArray[np.float64]:
        if name not in self.signals:
            raise FeatureError(f"signal {name!r} not in the record (has: {', '.join(sorted(self.signals))})")
        return np.asarray(self.signals[name], dtype=float)

    def window(self, options: Mapping[str, float]) -> NDArray[np.bool_]:
        """Mask of the analysed samples: operating ``period``, or ``from_s``..``to_s``, or the final
        ``fraction`` (default 0.25)."""
        t = self.time_s
        if "period" in options:
            edges = self.period_boundaries_s
            n = int(options["period"])
            if not 1 <= n <= len(edges) - 1:
                raise FeatureError(f"period = {n}: the record has periods 1..{max(len(edges) - 1, 0)}")
            last = n == len(edges) - 1
            mask = (t >= edges[n - 1]) & ((t <= edges[n]) if last else (t < edges[n]))
        elif "from_s" in options or "to_s" in options:
            mask = (t >= options.get("from_s", -math.inf)) & (t <= options.get("to_s", math.inf))
        else:
            fraction = float(options.get("fraction", DEFAULT_FRACTION))
            if not 0 < fraction <= 1:
                raise FeatureError(f"fraction = {fraction}: must be > 0 and <= 1")
            mask = t >= t[-1] - fraction * (t[-1] - t[0])
        if np.count_nonzero(mask) < 2:
            raise FeatureError(f"window {dict(options)}: fewer than 2 samples")
        return mask

    def planets(self, stage: int = 1) -> tuple[int, ...]:
        """Planet numbers of stage ``stage`` (1-based) whose mesh K_d the record holds; () for a parallel
        stage."""
        prefix = stage_name("", stage)
        found = set()
        for name in self.signals:
            if name.startswith(prefix + "planet_") and name.endswith("_sun_mesh_kd"):
                number = name[len(prefix + "planet_") : -len("_sun_mesh_kd")]
                if number.isdigit():
                    found.add(int(number))
        return tuple(sorted(found))

    def pinion_hz(self, mask: NDArray[np.bool_], stage: int = 1) -> float:
        """Mean pinion rotation frequency [Hz] over the window, from the pinion angle."""
        angle = self.signal(stage_name("pinion_angle_rad", stage))[mask]
        t = self.time_s[mask]
        return float((angle[-1] - angle[0]) / (t[-1] - t[0]) / (2.0 * math.pi))
