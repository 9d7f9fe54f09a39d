"""The ``[instruments]`` table of a scenario: virtual housing accelerometers (their path from the run's
force signals: housing modes or a measured FRF file; noise, sensitivity, where they sit), one data
acquisition rate, a tacho and a seed. What a run records with them is evaluated after the solve
(:mod:`gearbody.diagnosis.virtual`); the solve never reads this table.

Checked here, when the scenario is built: every key's type and range, names, one path per sensor, the
acquisition rate against the run's output rate, every mode below the run's Nyquist frequency. What needs
the drive's kinematics or a file (the force-signal names, the tacho's shaft, the FRF file's content) is
checked before a run starts, by :func:`gearbody.diagnosis.virtual.check_instruments`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from fractions import Fraction

from .params import Node, ScenarioError, param

__all__ = ["AccelerometerSpec", "Instruments", "SensorMode", "TachoSpec", "check_instruments_in_run"]

G = 9.80665
"""Standard gravity [m/s^2]: sensitivities in mV/g and noise in g convert with it."""

NAME = re.compile(r"[A-Za-z][A-Za-z0-9_.-]{0,63}")
"""An accelerometer's name: a channel name and a file-name tag (letters, digits, ``_ . -``; 64 at most)."""

MAX_DENOMINATOR = 1000
"""The acquisition rate is output_rate_hz * p / q with q at most this (a polyphase resampler's ratio)."""


@dataclass(frozen=True, kw_only=True)
class SensorMode(Node):
    """A housing mode between bearing forces and a sensor (gearbody.recording.instruments.HousingMode)."""

    frequency_hz: float = param(gt=0, doc="natural frequency f_n (< the run's Nyquist frequency)")
    damping_ratio: float = param(ge=1e-4, lt=1, doc="modal damping ratio zeta")
    participation: dict[str, float] = param(
        doc="force signal -> accelerance above the mode phi [(m/s^2)/N] (= 1 / effective mass)"
    )

    def __post_init__(self) -> None:
        if not self.participation:
            raise ScenarioError(
                "participation = {}: name at least one force signal, e.g. { pinion_bearing_force_y_N = 0.03 }"
            )


@dataclass(frozen=True, kw_only=True)
class AccelerometerSpec(Node):
    """A housing accelerometer: its path (``modes`` or ``frf_file``), noise, sensitivity and placement."""

    name: str = param(doc="channel name (letters, digits, _ . -)")
    location: str = param("", doc="where it sits (free text, e.g. 'pinion bearing housing, top')")
    direction: str = param("", doc="which way it measures (free text, e.g. '+y')")
    sensitivity_mV_per_g: float = param(100.0, gt=0, le=1e5, doc="voltage per acceleration [mV/g]")
    noise_rms_m_s2: float | None = param(None, ge=0, le=1e4, doc="white noise, RMS [m/s^2] (unset: 0)")
    noise_rms_g: float | None = param(None, ge=0, le=1e3, doc="the same in g (instead of noise_rms_m_s2)")
    modes: tuple[SensorMode, ...] = param((), doc="housing modes from the force signals to the sensor")
    frf_file: str | None = param(None, doc="a measured FRF (CSV) instead of modes; relative: to the scene")

    def __post_init__(self) -> None:
        if not NAME.fullmatch(self.name):
            raise ScenarioError(
                f"name = {self.name!r}: must start with a letter and hold letters, digits, _ . - "
                "(64 characters at most)"
            )
        if bool(self.modes) == (self.frf_file is not None):
            given = "both modes and frf_file" if self.modes else "neither modes nor frf_file"
            raise ScenarioError(f"modes: {given} given; the path to the sensor is one of the two")
        if self.frf_file is not None and not self.frf_file.strip():
            raise ScenarioError("frf_file = '': name a CSV file")
        if self.noise_rms_m_s2 is not None and self.noise_rms_g is not None:
            raise ScenarioError("noise_rms_g: give the noise once, noise_rms_m_s2 or noise_rms_g")

    @property
    def noise_m_s2(self) -> float:
        """The noise RMS [m/s^2]."""
        if self.noise_rms_g is not None:
            return self.noise_rms_g * G
        return self.noise_rms_m_s2 or 0.0

    @property
    def sensitivity_V_per_m_s2(self) -> float:
        """The sensitivity [V per m/s^2]."""
        return self.sensitivity_mV_per_g / 1000.0 / G


@dataclass(frozen=True, kw_only=True)
class TachoSpec(Node):
    """A once- (or N-) per-revolution tacho on a shaft of the drive."""

    shaft: str = param(
        "input", doc="input, output, or a rotating body (pinion, wheel, wheel_2, motor, sun, carrier, ...)"
    )
    pulses_per_rev: int = param(1, ge=1, le=100000, doc="pulses per revolution of the shaft")


@dataclass(frozen=True, kw_only=True)
class Instruments(Node):
    """What the virtual data acquisition records (``gearbody run`` writes it as instruments.mat)."""

    accelerometers: tuple[AccelerometerSpec, ...] = param(doc="the housing accelerometers (at least one)")
    tacho: TachoSpec = param(default_factory=TachoSpec, doc="the tacho")
    sample_rate_hz: float | None = param(
        None, gt=0, doc="acquisition rate of every channel (unset: solver.output_rate_hz)"
    )
    seed: int | None = param(None, ge=0, le=2**63 - 1, doc="seed of the sensors' noise (unset: meta.seed)")

    def __post_init__(self) -> None:
        if not self.accelerometers:
            raise ScenarioError("accelerometers = []: give at least one [[instruments.accelerometers]]")
        seen: set[str] = set()
        for k, acc in enumerate(self.accelerometers, 1):
            if acc.name in seen:
                raise ScenarioError(f"accelerometers.{k}.name = {acc.name!r}: another accelerometer has it")
            seen.add(acc.name)


def check_instruments_in_run(instruments: Instruments, output_rate_hz: float) -> None:
    """ScenarioError unless the acquisition rate is output_rate_hz * p / q (q <= MAX_DENOMINATOR) and at
    most output_rate_hz, and every mode lies below output_rate_hz / 2 (the run holds nothing above)."""
    rate = instruments.sample_rate_hz
    if rate is not None:
        if rate > output_rate_hz:
            raise ScenarioError(
                f"instruments.sample_rate_hz = {rate:g}: must be <= solver.output_rate_hz = "
                f"{output_rate_hz:g} (the run holds nothing above its Nyquist frequency; raise "
                "solver.output_rate_hz)"
            )
        ratio = Fraction(rate / output_rate_hz).limit_denominator(MAX_DENOMINATOR)
        if abs(float(ratio) * output_rate_hz - rate) > 1e-9 * rate:
            raise ScenarioError(
                f"instruments.sample_rate_hz = {rate:g}: must be solver.output_rate_hz = {output_rate_hz:g} "
                f"times p / q with q <= {MAX_DENOMINATOR} (e.g. {output_rate_hz / 2:g}, "
                f"{output_rate_hz * 64 / 125:g})"
            )
    nyquist = output_rate_hz / 2
    for k, acc in enumerate(instruments.accelerometers, 1):
        for m, mode in enumerate(acc.modes, 1):
            if mode.frequency_hz >= nyquist:
                raise ScenarioError(
                    f"instruments.accelerometers.{k}.modes.{m}.frequency_hz = {mode.frequency_hz:g}: must be "
                    f"< {nyquist:g} (solver.output_rate_hz / 2: the run's forces hold nothing above)"
                )
