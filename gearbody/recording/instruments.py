"""Virtual instruments: the path from a run's bearing forces to housing accelerometers, and a tacho.

Evaluated after the solve (it costs the integrator nothing). The housing is a set of modes; mode m with
natural frequency f_m, damping ratio zeta_m and participation phi_(m,b) [m/s^2 per N] of force b (a
bearing force signal, e.g. ``pinion_bearing_force_y_N``) adds to the accelerometer

    A_m(s) = sum_b phi_(m,b) F_b(s) s^2 / (s^2 + 2 zeta_m w_m s + w_m^2),   w_m = 2 pi f_m,

the accelerance of a mode of unit modal mass scaled by the mode shape at the bearing and at the sensor
(phi = psi_bearing psi_sensor / m_modal). Above its frequency a mode passes phi F (a rigid mass
1/phi); at it, phi F / (2 zeta); far below, nothing. The response is computed in the frequency domain,
for band-limited forces (the run's force signals are band-limited samples, docs/scenario.md "Output
sampling and aliasing"): the exact accelerance on an FFT grid, its impulse response (a few samples of
pre-ring, windowed where it has decayed) convolved with the force, from static equilibrium under the
first sample's force (a run starts loaded: no step from rest rings the modes). A time-domain solution
(``scipy.signal.lsim``) instead takes the force linear between samples; below a mode that costs
accuracy, as the mode's response s^2 / (...) is the small difference of the force and the spring's
share: for a 3 kHz mode at 20 kHz it read 7.5 % low at 500 Hz. A measured FRF
(:class:`gearbody.recording.frf.MeasuredFRF`) may stand for the modes: its impulse response convolved
with the forces in the same way (:mod:`gearbody.recording.frf`). The sensor
then adds seeded Gaussian noise and is sampled at its own rate behind an anti-alias filter (the polyphase
Kaiser FIR of ``scipy.signal.resample_poly``: what would alias is attenuated by more than 60 dB).
A tacho gives N pulses per revolution of a shaft, where its simulated angle crosses 2 pi k / N.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

from ..errors import InputError
from .channel import Channel
from .container import Recording
from .frf import MeasuredFRF, convolve, modal_kernels, uniform_rate
from .from_run import hermite_crossings
from .tacho import Tacho

__all__ = ["MIN_PULSES", "Accelerometer", "HousingMode", "housing_acceleration", "virtual_instruments"]

MIN_PULSES = 3
"""Fewest pulses a tacho holds (:class:`~gearbody.recording.tacho.Tacho`); fewer: no tacho."""


@dataclass(frozen=True)
class HousingMode:
    """One mode of the housing: ``frequency_hz``, ``damping_ratio`` and ``participation`` (force signal ->
    m/s^2 per N at the sensor)."""

    frequency_hz: float
    damping_ratio: float
    participation: Mapping[str, float]

    def __post_init__(self) -> None:
        if not (math.isfinite(self.frequency_hz) and self.frequency_hz > 0):
            raise InputError(f"HousingMode frequency_hz = {self.frequency_hz!r}: must be > 0 Hz")
        if not (math.isfinite(self.damping_ratio) and 0 < self.damping_ratio < 1):
            raise InputError(f"HousingMode damping_ratio = {self.damping_ratio!r}: must be in (0, 1)")
        if not self.participation:
            raise InputError("HousingMode participation: name at least one force signal")
        for name, value in self.participation.items():
            if not math.isfinite(value):
                raise InputError(f"HousingMode participation[{name!r}] = {value!r}: must be finite")


@dataclass(frozen=True)
class Accelerometer:
    """A housing accelerometer: its path from the forces, ``modes`` or a measured ``frf`` (one of the two),
    Gaussian ``noise_rms_m_s2`` (seeded), its ``sample_rate_hz`` (None: the run's), where it sits and
    which way it looks."""

    name: str
    modes: Sequence[HousingMode]
    noise_rms_m_s2: float = 0.0
    sample_rate_hz: float | None = None
    location: str = ""
    direction: str = ""
    sensitivity_v_per_m_s2: float = 0.0102  # 100 mV/g
    extra: Mapping[str, str] = field(default_factory=dict)
    frf: MeasuredFRF | None = None

    def __post_init__(self) -> None:
        if bool(self.modes) == (self.frf is not None):
            raise InputError(
                f"accelerometer {self.name!r}: give at least one HousingMode or a MeasuredFRF (not both)"
            )
        if not (math.isfinite(self.noise_rms_m_s2) and self.noise_rms_m_s2 >= 0):
            raise InputError(
                f"accelerometer {self.name!r}: noise_rms_m_s2 = {self.noise_rms_m_s2!r}, must be >= 0"
            )
        if self.sample_rate_hz is not None and not (
            math.isfinite(self.sample_rate_hz) and self.sample_rate_hz > 0
        ):
            raise InputError(
                f"accelerometer {self.name!r}: sample_rate_hz = {self.sample_rate_hz!r}, must be > 0"
            )


def housing_acceleration(time_s: np.ndarray, forces: Mapping[str, np.ndarray], modes: Sequence[HousingMode]):
    """The housing acceleration [m/s^2] at the run's samples (uniform): the sum over ``modes`` of each
    mode's response to its participating forces (the module's formula), from static equilibrium under
    the first sample's forces (a mode passes no static force)."""
    fs = uniform_rate(time_s)
    kernels, pre = modal_kernels(modes, fs)
    return convolve(kernels, pre, len(time_s), forces, "HousingMode participation")


def _resampled(x: np.ndarray, fs_in: float, fs_out: float) -> np.ndarray:
    from scipy.signal import resample_poly

    ratio = Fraction(fs_out / fs_in).limit_denominator(1000)
    if abs(float(ratio) - fs_out / fs_in) > 1e-9 * fs_out / fs_in:
        raise InputError(
            f"sample_rate_hz = {fs_out:g}: must be a ratio p/q (q <= 1000) of the run's {fs_in:g} Hz"
        )
    if ratio == 1:
        return x
    return resample_poly(x, ratio.numerator, ratio.denominator)


def virtual_instruments(
    result,
    accelerometers: Sequence[Accelerometer],
    *,
    tacho_shaft: str = "pinion",
    pulses_per_rev: int = 1,
    seed: int = 0,
) -> Recording:
    """The run ``result`` seen by ``accelerometers`` and a tacho of ``pulses_per_rev`` pulses per
    revolution of ``tacho_shaft``, as a :class:`Recording` (every accelerometer at the rate of the first;
    the same ``seed`` gives bit-identical noise; without a tacho, and ``meta["tacho_note"]`` saying why,
    when the run gives fewer than MIN_PULSES pulses)."""
    if not accelerometers:
        raise InputError("virtual_instruments: give at least one Accelerometer")
    t = np.asarray(result.time_s, dtype=float)
    fs_run = float(result.meta.get("output_rate_hz") or (t.size - 1) / (t[-1] - t[0]))
    fs = float(accelerometers[0].sample_rate_hz or fs_run)
    forces = {k: v for k, v in result.signals.items() if k.endswith("_N")}
    rng = np.random.default_rng(seed)
    channels = []
    for acc in accelerometers:
        if (acc.sample_rate_hz or fs_run) != fs:
            raise InputError(
                f"accelerometer {acc.name!r}: every accelerometer samples at {fs:g} Hz (the first's)"
            )
        path = (
            acc.frf.response(t, forces) if acc.frf is not None else housing_acceleration(t, forces, acc.modes)
        )
        x = _resampled(path, fs_run, fs)
        x = x + rng.normal(0.0, acc.noise_rms_m_s2, x.size) if acc.noise_rms_m_s2 > 0 else x
        channels.append(
            Channel(acc.name, x, "m/s^2", acc.sensitivity_v_per_m_s2, acc.location, acc.direction)
        )
    angle_name = f"{tacho_shaft}_angle_rad"
    if angle_name not in result.signals:
        raise InputError(f"tacho_shaft = {tacho_shaft!r}: the run has no {angle_name}")
    speed = result.signals.get(f"{tacho_shaft}_speed_rad_s")
    angle = np.asarray(result.signals[angle_name], dtype=float)
    speed = np.gradient(angle, t) if speed is None else np.asarray(speed)
    pulses = hermite_crossings(t, angle, speed, 2 * math.pi / pulses_per_rev)
    meta = {"source": "virtual instruments", "scene": result.meta.get("scene"), "seed": seed,
            "scenario": result.meta.get("scenario")}  # fmt: skip
    tacho = None
    if pulses.size >= MIN_PULSES:
        tacho = Tacho(tacho_shaft, pulses_per_rev, pulse_times_s=pulses)
    else:  # a run too short for a tacho: the recording is tacholess, and says so
        meta["tacho_note"] = (
            f"the tacho on {tacho_shaft} gave {pulses.size} pulses in the run (a tacho needs "
            f"{MIN_PULSES}): the recording has no tacho; run longer or give more pulses_per_rev"
        )
    return Recording(fs, channels, float(t[0]), tacho, meta)
