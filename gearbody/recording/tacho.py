"""A recording's tacho: where the shaft angle comes from.

Three forms, as data loggers give them: pulse times (a keyphasor or an N-per-revolution tacho already
triggered), a sampled pulse train (a channel of the recording, triggered on use), or an encoder angle (a
channel holding the unwrapped shaft angle in rad). The tacho names the ``shaft`` it measures; the other
shafts of a drive follow through the scenario's ratios.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError

__all__ = ["Tacho"]


@dataclass(frozen=True, eq=False)
class Tacho:
    """The shaft-angle reference of a recording: ``pulse_times_s`` (instants of the pulses,
    ``pulses_per_rev`` per revolution), or ``channel`` (the name of a pulse-train channel, or of an
    encoder channel with unit ``rad`` when ``pulses_per_rev`` is 0), on shaft ``shaft``."""

    shaft: str = "input"
    pulses_per_rev: int = 1
    pulse_times_s: np.ndarray | None = None
    channel: str = ""
    level: float | None = None
    """Trigger level of a pulse-train channel [its unit]; ``None``: midway between its low and high."""

    def __post_init__(self) -> None:
        if not isinstance(self.shaft, str) or not self.shaft:
            raise InputError(f"tacho shaft = {self.shaft!r}: must name a shaft")
        ppr = self.pulses_per_rev
        if isinstance(ppr, bool) or not isinstance(ppr, (int, np.integer)) or not 0 <= ppr <= 100_000:
            raise InputError(f"tacho pulses_per_rev = {ppr!r}: must be an integer in 0..100000 (0: encoder)")
        object.__setattr__(self, "pulses_per_rev", int(ppr))
        if (self.pulse_times_s is None) == (not self.channel):
            raise InputError("a tacho needs exactly one of pulse_times_s and channel")
        if self.pulse_times_s is not None:
            times = np.asarray(self.pulse_times_s, dtype=np.float64)
            if times.ndim != 1 or times.size < 3:
                raise InputError(
                    f"tacho pulse_times_s: needs at least 3 pulse times, got shape {times.shape}"
                )
            if not np.all(np.isfinite(times)) or np.any(np.diff(times) <= 0):
                raise InputError("tacho pulse_times_s: must be finite and strictly increasing")
            if ppr == 0:
                raise InputError("tacho pulses_per_rev = 0 (an encoder) needs a channel, not pulse times")
            object.__setattr__(self, "pulse_times_s", times)

    @property
    def is_encoder(self) -> bool:
        """True when the tacho is an encoder channel holding the shaft angle [rad]."""
        return self.pulses_per_rev == 0

    def describe(self) -> dict:
        """The tacho without its pulse times (what a file's header holds)."""
        out = {"shaft": self.shaft, "pulses_per_rev": self.pulses_per_rev}
        if self.channel:
            out["channel"] = self.channel
        if self.level is not None:
            out["level"] = float(self.level)
        return out
