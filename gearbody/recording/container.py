"""A recording: channels sampled at one rate, a tacho and operating metadata (measured or simulated alike).

A data logger's file and a simulated run become the same object here, so the analysis of
``gearbody analyze`` and ``gearbody compare`` treats them alike. Samples are held in SI units
(:mod:`gearbody.recording.channel`); the time grid is ``t0_s + k / sample_rate_hz``.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError, SignalError
from .channel import Channel
from .tacho import Tacho

__all__ = ["MAX_SAMPLE_RATE_HZ", "Recording"]

MAX_SAMPLE_RATE_HZ = 10e6
"""Highest sample rate accepted [Hz] (a logger's rate; above it a header is more likely wrong)."""


@dataclass(eq=False)
class Recording:
    """Channels on one uniform time grid (``sample_rate_hz``, first sample at ``t0_s``), an optional
    :class:`Tacho`, and ``meta`` (operating metadata: scene, speed, load, the file it came from, ...).
    ``recording["name"]`` gives a channel's samples [its SI unit], ``recording.channel("name")`` the
    :class:`Channel` with its unit, sensitivity, location and direction."""

    sample_rate_hz: float
    channels: dict[str, Channel]
    t0_s: float = 0.0
    tacho: Tacho | None = None
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        fs = self.sample_rate_hz
        if isinstance(fs, bool) or not isinstance(fs, (int, float, np.integer, np.floating)):
            raise InputError(f"sample_rate_hz = {fs!r}: must be a number in (0, {MAX_SAMPLE_RATE_HZ:g}] Hz")
        if not (np.isfinite(fs) and 0 < fs <= MAX_SAMPLE_RATE_HZ):
            raise InputError(f"sample_rate_hz = {fs!r}: must be in (0, {MAX_SAMPLE_RATE_HZ:g}] Hz")
        self.sample_rate_hz = float(fs)
        if not np.isfinite(self.t0_s):
            raise InputError(f"t0_s = {self.t0_s!r}: must be finite")
        self.t0_s = float(self.t0_s)
        if isinstance(self.channels, Mapping):
            channels = list(self.channels.values())
        else:
            channels = list(self.channels)
        if not channels:
            raise InputError("a recording needs at least one channel")
        self.channels = {}
        for ch in channels:
            if not isinstance(ch, Channel):
                raise InputError(f"channels must be Channel objects, got {type(ch).__name__}")
            if ch.name in self.channels:
                raise InputError(f"channel name {ch.name!r} appears twice")
            self.channels[ch.name] = ch
        sizes = {name: len(ch) for name, ch in self.channels.items()}
        if len(set(sizes.values())) > 1:
            raise InputError(f"every channel must have the same number of samples, got {sizes}")
        if self.n_samples < 2:
            raise InputError(f"a recording needs at least 2 samples, got {self.n_samples}")
        if self.tacho is not None and self.tacho.channel and self.tacho.channel not in self.channels:
            raise InputError(
                f"tacho channel {self.tacho.channel!r} is not a channel; channels: {', '.join(self.channels)}"
            )

    # -- what it holds -----------------------------------------------------------------------------
    @property
    def n_samples(self) -> int:
        return len(next(iter(self.channels.values())))

    @property
    def duration_s(self) -> float:
        """Time from the first sample to one sample period past the last [s]."""
        return self.n_samples / self.sample_rate_hz

    @property
    def time_s(self) -> np.ndarray:
        """The sample instants [s]."""
        return self.t0_s + np.arange(self.n_samples) / self.sample_rate_hz

    @property
    def names(self) -> list[str]:
        return list(self.channels)

    def __getitem__(self, name: str) -> np.ndarray:
        if name == "time_s":
            return self.time_s
        return self.channel(name).data

    def __contains__(self, name: str) -> bool:
        return name in self.channels

    def channel(self, name: str) -> Channel:
        """The channel called ``name`` (a SignalError naming the channels there are)."""
        try:
            return self.channels[name]
        except KeyError:
            raise SignalError(f"no channel {name!r}; channels: {', '.join(self.channels)}") from None

    def channels_of(self, quantity: str) -> list[str]:
        """Names of the channels measuring ``quantity`` (``acceleration``, ``velocity``, ``angle``, ...)."""
        return [name for name, ch in self.channels.items() if ch.quantity == quantity]

    @property
    def vibration_channels(self) -> list[str]:
        """The channels a diagnostician analyses as vibration: accelerations, else velocities, else
        displacements, else forces (a simulated run's mesh or bearing forces); ``meta["vibration_channel"]``
        first when it names a channel (a simulated run's vibration signal)."""
        first = self.meta.get("vibration_channel")
        if first in self.channels:
            return [first, *(n for n in self._vibration_channels() if n != first)]
        return self._vibration_channels()

    def _vibration_channels(self) -> list[str]:
        tacho = self.tacho.channel if self.tacho is not None else ""
        for quantity in ("acceleration", "velocity", "displacement", "force"):
            found = [n for n in self.channels_of(quantity) if n != tacho]
            if found:
                return found
        tacho = self.tacho.channel if self.tacho is not None else ""
        return [
            n
            for n, ch in self.channels.items()
            if ch.quantity not in ("angle", "angular velocity") and n != tacho
        ]

    def describe(self) -> dict[str, Any]:
        """Everything but the samples: rate, start, length, channels, tacho, metadata."""
        return {
            "sample_rate_hz": self.sample_rate_hz,
            "t0_s": self.t0_s,
            "n_samples": self.n_samples,
            "channels": [ch.describe() for ch in self.channels.values()],
            "tacho": None if self.tacho is None else self.tacho.describe(),
            "meta": self.meta,
        }

    # -- new recordings from this one --------------------------------------------------------------
    def select(self, names: Iterable[str]) -> Recording:
        """A recording of the named channels only (the tacho's channel is kept when it has one)."""
        names = list(dict.fromkeys(names))
        if self.tacho is not None and self.tacho.channel and self.tacho.channel not in names:
            names.append(self.tacho.channel)
        return Recording(
            self.sample_rate_hz, [self.channel(n) for n in names], self.t0_s, self.tacho, dict(self.meta)
        )

    def window(self, start_s: float | None = None, end_s: float | None = None) -> Recording:
        """The samples with ``start_s <= t < end_s`` (a tacho's pulse times are kept as they are)."""
        t = self.time_s
        lo = 0 if start_s is None else int(np.searchsorted(t, start_s - 0.5 / self.sample_rate_hz))
        hi = self.n_samples if end_s is None else int(np.searchsorted(t, end_s - 0.5 / self.sample_rate_hz))
        if hi - lo < 2:
            raise InputError(
                f"window {start_s!r}..{end_s!r} s holds {max(hi - lo, 0)} samples of the recording "
                f"({t[0]:.6g}..{t[-1]:.6g} s); needs at least 2"
            )
        chans = [ch.with_data(ch.data[lo:hi]) for ch in self.channels.values()]
        return Recording(self.sample_rate_hz, chans, float(t[lo]), self.tacho, dict(self.meta))

    def as_quantity(self, name: str, quantity: str, f_low_hz: float | None = None) -> Channel:
        """Channel ``name`` (acceleration, velocity or displacement) as ``quantity`` (integrated or
        differentiated in the frequency domain; ``f_low_hz``: the high-pass an integration needs), named
        ``<name>_<quantity>``."""
        from ..analysis.integration import change_quantity

        ch = self.channel(name)
        units = {"displacement": "m", "velocity": "m/s", "acceleration": "m/s^2"}
        if ch.quantity not in units:
            raise InputError(
                f"channel {name!r} holds {ch.quantity or 'a dimensionless quantity'} ({ch.unit!r}); only "
                "acceleration, velocity and displacement convert"
            )
        data = change_quantity(ch.data, self.sample_rate_hz, ch.quantity, quantity, f_low_hz)
        return Channel(f"{name}_{quantity}", data, units[quantity], 1.0, ch.location, ch.direction, ch.shaft)

    def with_channels(self, *channels: Channel) -> Recording:
        """This recording with ``channels`` added (or replacing those of the same name)."""
        merged = dict(self.channels)
        merged.update({ch.name: ch for ch in channels})
        return Recording(self.sample_rate_hz, merged, self.t0_s, self.tacho, dict(self.meta))
