"""The angle of every shaft of a recorded drive from its one tacho (or, without one, from a tracked mesh
harmonic), through the scenario's speed ratios."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..recording import Recording
from .drive import DriveKinematics

__all__ = ["ShaftAngles", "shaft_angles"]


@dataclass(frozen=True)
class ShaftAngles:
    """The input shaft's unwrapped angle [rad] at the recording's samples, and how it was found
    (``source``: ``"encoder"``, ``"pulses"``, ``"pulse channel"``, ``"tacholess"``)."""

    time_s: np.ndarray
    input_angle_rad: np.ndarray
    drive: DriveKinematics
    source: str
    note: str = ""

    def of(self, body: str) -> np.ndarray:
        """The unwrapped angle of ``body`` [rad] in its driven direction (its speed ratio's magnitude)."""
        return self.input_angle_rad * abs(
            self.drive.ratio(self.drive.resolve_body(body), self.drive.input_body)
        )

    @property
    def input_hz(self) -> np.ndarray:
        """The input shaft's speed [rev/s] at each sample (from the angle's gradient)."""
        return np.gradient(self.input_angle_rad, self.time_s) / (2 * np.pi)

    def mean_input_hz(self) -> float:
        """Mean input shaft speed over the recording [rev/s]."""
        t, a = self.time_s, self.input_angle_rad
        return float((a[-1] - a[0]) / (t[-1] - t[0]) / (2 * np.pi))


def shaft_angles(recording: Recording, drive: DriveKinematics) -> ShaftAngles:
    """The input shaft's angle over the recording, from its tacho (through the ratio of the tacho's shaft
    to the input), or tacholess from the first stage's mesh harmonic near the scenario's nominal speed."""
    from ..analysis.tacho import pulse_times, shaft_angle_from_pulses

    t = recording.time_s
    tacho = recording.tacho
    if tacho is None:
        return _tacholess(recording, drive)
    ratio = abs(drive.ratio(drive.resolve_body(tacho.shaft), drive.input_body))
    if tacho.is_encoder:
        ch = recording.channel(tacho.channel)
        if ch.unit != "rad":
            raise InputError(
                f"tacho channel {tacho.channel!r} is an encoder (0 pulses per rev) but holds "
                f"{ch.unit!r}, not rad"
            )
        angle, source = np.unwrap(ch.data), "encoder"
        angle = angle if angle[-1] >= angle[0] else -angle
    else:
        if tacho.pulse_times_s is not None:
            pulses, source = tacho.pulse_times_s, "pulses"
        else:
            ch = recording.channel(tacho.channel)
            pulses = pulse_times(ch.data, recording.sample_rate_hz, level=tacho.level, t0_s=recording.t0_s)
            source = "pulse channel"
        _check_pulses(pulses, tacho.pulses_per_rev, ratio, drive, tacho.channel or "the tacho's pulse times")
        angle = shaft_angle_from_pulses(pulses, tacho.pulses_per_rev, t, method="pchip")
    return ShaftAngles(t, angle / ratio, drive, source)


IRREGULAR_FRACTION = 0.05
"""Share of consecutive pulse intervals differing by more than 2x above which a tacho is refused."""
MAX_OVER_NOMINAL = 10.0
"""Highest input-shaft speed a tacho may imply, over the scenario's nominal speed."""


def _check_pulses(pulses: np.ndarray, ppr: int, ratio: float, drive: DriveKinematics, where: str) -> None:
    """Refuse a tacho whose pulses cannot be a shaft's: irregular (noise triggered), or far faster than
    the drive turns (a wrong channel, pulses per revolution or shaft)."""
    hint = "check --tacho (the channel), its trigger level, --pulses-per-rev and --tacho-shaft"
    intervals = np.diff(pulses)
    jumps = intervals[1:] / intervals[:-1]
    irregular = float(np.mean((jumps > 2) | (jumps < 0.5))) if jumps.size else 0.0
    if irregular > IRREGULAR_FRACTION:
        raise InputError(
            f"tacho {where}: {irregular:.0%} of its consecutive pulse intervals differ by more than 2x "
            f"(allowed {IRREGULAR_FRACTION:.0%}): not a shaft's pulses; {hint}"
        )
    fastest_hz = 1.0 / (ppr * float(np.min(intervals))) / ratio
    nominal = drive.nominal_input_hz
    if nominal and fastest_hz > MAX_OVER_NOMINAL * nominal:
        raise InputError(
            f"tacho {where}: its pulses put the input shaft at up to {fastest_hz:.4g} rev/s, over "
            f"{MAX_OVER_NOMINAL:g} x the scene's nominal {nominal:.4g} rev/s; {hint}"
        )


def _tacholess(recording: Recording, drive: DriveKinematics) -> ShaftAngles:
    from ..analysis.tacholess import tacholess_angle

    gear = drive.gears[0]
    speed = recording.meta.get("input_speed_hz") or drive.nominal_input_hz
    if not speed:
        raise InputError(
            "the recording has no tacho: give one (--tacho CHANNEL or a tacho in the file), or its input "
            "shaft speed for the tacholess estimate (--input-speed HZ, or meta['input_speed_hz'])"
        )
    ratio = abs(drive.ratio(gear.body, drive.input_body))
    channel = recording.vibration_channels[0]
    found = tacholess_angle(
        recording[channel],
        recording.sample_rate_hz,
        gear.teeth,
        speed_guess_hz=float(speed) * ratio,
        t0_s=recording.t0_s,
    )
    guess = "given" if recording.meta.get("input_speed_hz") else "the scene's nominal"
    note = (
        f"tacholess: shaft angle from the {gear.teeth}x mesh harmonic of {gear.body} on {channel!r}, "
        f"searched near the {guess} input speed {float(speed):.4g} rev/s"
    )
    return ShaftAngles(recording.time_s, np.asarray(found.angle_rad) / ratio, drive, "tacholess", note)
