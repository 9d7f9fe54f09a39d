"""A simulated run as a recording: every signal a channel in its unit, the exact shaft angles as encoder
channels, and a virtual N-per-revolution tacho whose pulses fall where the simulated shaft angle crosses
each 2 pi k / N (located by cubic Hermite interpolation of the angle and speed samples, to ~1e-12 rad)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from ..errors import InputError, SignalError
from ..signals import signal_unit
from .channel import Channel
from .container import Recording
from .tacho import Tacho

__all__ = ["hermite_crossings", "recording_from_run"]

_META_KEYS = (
    "scene",
    "title",
    "seed",
    "scenario",
    "gearbody_version",
    "exudyn_version",
    "stages",
    "nominal_speeds_rad_s",
    "rated_mesh_force_N",
    "pinion_teeth",
    "wheel_teeth",
    "sources",
)


def hermite_crossings(
    time_s: np.ndarray, angle_rad: np.ndarray, speed_rad_s: np.ndarray, step_rad: float
) -> np.ndarray:
    """Instants [s] where the angle crosses each multiple of ``step_rad`` upwards, from the cubic Hermite
    interpolant of the samples (angle and its rate at each sample); the angle must not fall."""
    q = np.floor(angle_rad / step_rad)
    k = np.nonzero(np.diff(q) > 0)[0]  # sample intervals holding at least one crossing
    out = []
    for extra in range(int(np.max(np.diff(q)[k], initial=0))):
        kk = k[np.diff(q)[k] > extra]
        target = (q[kk] + 1 + extra) * step_rad
        h = time_s[kk + 1] - time_s[kk]
        p0, p1 = angle_rad[kk], angle_rad[kk + 1]
        m0, m1 = speed_rad_s[kk] * h, speed_rad_s[kk + 1] * h
        s = np.clip((target - p0) / np.where(p1 > p0, p1 - p0, 1.0), 0.0, 1.0)  # linear first guess
        for _ in range(8):  # Newton on the Hermite cubic in the unit interval
            s2, s3 = s * s, s * s * s
            value = (2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * m0
            value += (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * m1
            slope = (6 * s2 - 6 * s) * p0 + (3 * s2 - 4 * s + 1) * m0
            slope += (-6 * s2 + 6 * s) * p1 + (3 * s2 - 2 * s) * m1
            s = np.clip(s - (value - target) / np.where(np.abs(slope) > 0, slope, 1.0), 0.0, 1.0)
        out.append(time_s[kk] + s * h)
    return np.sort(np.concatenate(out)) if out else np.empty(0)


def _rate(time_s: np.ndarray, meta: Mapping[str, Any]) -> float:
    if time_s.size < 2:
        raise InputError(f"a run with {time_s.size} output sample(s) cannot be a recording (needs 2)")
    fs = meta.get("output_rate_hz") or 1.0 / float(np.mean(np.diff(time_s)))
    grid = time_s[0] + np.arange(time_s.size) / fs
    if np.max(np.abs(grid - time_s)) > 1e-6 / fs * max(1.0, time_s.size / 1e3):
        raise InputError("the run's output grid is not uniform; a recording needs one sample rate")
    return float(fs)


def _tacho(time_s, signals, shaft: str, pulses_per_rev: int) -> tuple[Tacho, str]:
    """The run's virtual tacho on ``shaft`` and a note when it had to be the exact angle instead."""
    angle_name = f"{shaft}_angle_rad"
    if pulses_per_rev == 0:
        return Tacho(shaft=shaft, pulses_per_rev=0, channel=angle_name), ""
    angle = np.asarray(signals[angle_name], dtype=np.float64)
    speed = signals.get(f"{shaft}_speed_rad_s")
    if speed is None:  # Muller's pinion has no speed signal: its rate from the samples
        speed = np.gradient(angle, np.asarray(time_s))
    pulses = hermite_crossings(np.asarray(time_s), angle, np.asarray(speed), 2 * np.pi / pulses_per_rev)
    if pulses.size >= 3:
        return Tacho(shaft=shaft, pulses_per_rev=pulses_per_rev, pulse_times_s=pulses), ""
    note = (  # too short a turn for pulses: the exact angle is the tacho, and it says so
        f"{shaft} turns through {pulses.size} pulse(s) at {pulses_per_rev} per revolution "
        "(a pulse tacho needs 3): the tacho is its exact angle (an encoder channel)"
    )
    return Tacho(shaft=shaft, pulses_per_rev=0, channel=angle_name), note


def recording_from_run(
    time_s: np.ndarray,
    signals: Mapping[str, np.ndarray],
    meta: Mapping[str, Any],
    *,
    channels: Iterable[str] | None = None,
    tacho_shaft: str = "pinion",
    pulses_per_rev: int = 1,
    vibration_signal: str = "",
) -> Recording:
    """The run (its ``time_s``, ``signals`` and ``meta``, as in :class:`gearbody.result.Result`) as a
    :class:`Recording`: ``channels`` (default every signal) in their units; every ``<shaft>_angle_rad``
    an encoder channel of that shaft; a virtual tacho of ``pulses_per_rev`` pulses per revolution of
    ``tacho_shaft`` (a rotation of the drive: ``pinion``, ``wheel``, ``motor``, ...; ``pulses_per_rev``
    0: the tacho is that shaft's encoder channel); ``vibration_signal``: the channel the analysis reads first
    (``meta["vibration_channel"]``)."""
    fs = _rate(np.asarray(time_s), meta)
    names = list(signals) if channels is None else list(dict.fromkeys(channels))
    missing = [n for n in names if n not in signals]
    if missing:
        raise SignalError(f"no signal {missing[0]!r} in the run; signals: {', '.join(sorted(signals))}")
    angle_name = f"{tacho_shaft}_angle_rad"
    if angle_name not in signals:
        shafts = sorted(n[: -len("_angle_rad")] for n in signals if n.endswith("_angle_rad"))
        raise InputError(
            f"tacho_shaft = {tacho_shaft!r}: the run has no angle of it; shafts: {', '.join(shafts)}"
        )
    chans = []
    for name in names:
        unit = signal_unit(name)
        shaft = name[: -len("_angle_rad")] if name.endswith("_angle_rad") else ""
        chans.append(Channel(name, np.asarray(signals[name], dtype=np.float64), unit, shaft=shaft))
    tacho, note = _tacho(time_s, signals, tacho_shaft, pulses_per_rev)
    if tacho.is_encoder and tacho.channel not in names:
        chans.append(
            Channel(angle_name, np.asarray(signals[angle_name], np.float64), "rad", shaft=tacho_shaft)
        )
    run_meta = {k: meta[k] for k in _META_KEYS if k in meta}
    run_meta["source"] = "simulation"
    if note:
        run_meta["tacho_note"] = note
    if vibration_signal in names:
        run_meta["vibration_channel"] = vibration_signal
    return Recording(fs, chans, float(np.asarray(time_s)[0]), tacho, run_meta)
