"""One measured or simulated channel: samples in physical units with what they are and where they come from.

A channel's samples are always held in physical SI-based units (``m/s^2``, ``m/s``, ``m``, ``N``, ``rad``,
...): a reader that finds volts or counts multiplies by the calibration on the way in, and keeps the
sensitivity it used so a writer can give the raw file back. :data:`UNIT_SCALE` lists the units a channel
may be given in (``g``, ``mm/s``, ``um``, ...) and their SI value; :func:`to_si_unit` converts.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError

__all__ = ["QUANTITIES", "UNIT_SCALE", "Channel", "quantity_of_unit", "to_si_unit"]

STANDARD_GRAVITY_M_S2 = 9.80665

UNIT_SCALE: dict[str, tuple[str, float]] = {
    # unit: (SI unit, factor to SI)
    "m/s^2": ("m/s^2", 1.0),
    "m/s2": ("m/s^2", 1.0),
    "g": ("m/s^2", STANDARD_GRAVITY_M_S2),
    "mm/s^2": ("m/s^2", 1e-3),
    "m/s": ("m/s", 1.0),
    "mm/s": ("m/s", 1e-3),
    "um/s": ("m/s", 1e-6),
    "in/s": ("m/s", 0.0254),
    "m": ("m", 1.0),
    "mm": ("m", 1e-3),
    "um": ("m", 1e-6),
    "mil": ("m", 25.4e-6),
    "N": ("N", 1.0),
    "kN": ("N", 1e3),
    "N m": ("N m", 1.0),
    "Nm": ("N m", 1.0),
    "rad": ("rad", 1.0),
    "deg": ("rad", np.pi / 180.0),
    "rev": ("rad", 2.0 * np.pi),
    "rad/s": ("rad/s", 1.0),
    "rpm": ("rad/s", 2.0 * np.pi / 60.0),
    "Hz": ("Hz", 1.0),
    "rad/s^2": ("rad/s^2", 1.0),
    "Pa": ("Pa", 1.0),
    "V": ("V", 1.0),
    "A": ("A", 1.0),
    "": ("", 1.0),
}
"""Units a channel may be given in: ``unit -> (SI unit, factor)``, value_SI = factor * value."""

QUANTITIES = {
    "m/s^2": "acceleration",
    "m/s": "velocity",
    "m": "displacement",
    "N": "force",
    "N m": "torque",
    "rad": "angle",
    "rad/s": "angular velocity",
    "rad/s^2": "angular acceleration",
    "Hz": "frequency",
    "Pa": "pressure",
    "V": "voltage",
    "A": "current",
    "": "dimensionless",
}
"""The quantity each SI unit measures."""


def to_si_unit(values: np.ndarray, unit: str) -> tuple[np.ndarray, str]:
    """``(values in SI, SI unit)`` for samples in ``unit`` (one of :data:`UNIT_SCALE`)."""
    if unit not in UNIT_SCALE:
        known = ", ".join(repr(u) for u in UNIT_SCALE)
        raise InputError(f"unit = {unit!r}: not a known unit; known: {known}")
    si, factor = UNIT_SCALE[unit]
    return (values if factor == 1.0 else values * factor), si


def quantity_of_unit(unit: str) -> str:
    """The quantity an SI unit measures (``m/s^2`` -> ``acceleration``), ``""`` if not one of
    :data:`QUANTITIES`."""
    return QUANTITIES.get(unit, "")


@dataclass(frozen=True, eq=False)
class Channel:
    """A named channel: ``data`` in SI ``unit`` on its recording's time grid, with the sensor's
    ``sensitivity`` (raw units per SI unit, e.g. V per m/s^2; 1 when the file held physical values),
    where it sits (``location``, e.g. ``"input bearing housing"``) and which way it looks (``direction``,
    e.g. ``"y"``, ``"radial"``). ``shaft`` names the shaft an angle (encoder) channel measures."""

    name: str
    data: np.ndarray
    unit: str = ""
    sensitivity: float = 1.0
    location: str = ""
    direction: str = ""
    shaft: str = ""
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise InputError(f"channel name = {self.name!r}: must be a non-empty string")
        data = np.asarray(self.data)
        if data.ndim != 1:
            raise InputError(f"channel {self.name!r}: data must be one-dimensional, got shape {data.shape}")
        if not np.issubdtype(data.dtype, np.floating):
            data = data.astype(np.float64)
        object.__setattr__(self, "data", data)
        if self.unit not in QUANTITIES:
            values, si = to_si_unit(data, self.unit)  # a non-SI unit converts on the way in
            object.__setattr__(self, "data", values)
            object.__setattr__(self, "sensitivity", float(self.sensitivity) / UNIT_SCALE[self.unit][1])
            object.__setattr__(self, "unit", si)
        s = float(self.sensitivity)
        if not (np.isfinite(s) and s > 0):
            raise InputError(
                f"channel {self.name!r}: sensitivity = {self.sensitivity!r}, must be finite and > 0"
            )
        object.__setattr__(self, "sensitivity", s)

    @property
    def quantity(self) -> str:
        """What the channel measures (``acceleration``, ``velocity``, ``displacement``, ``angle``, ...)."""
        return quantity_of_unit(self.unit)

    def __len__(self) -> int:
        return int(self.data.size)

    def describe(self) -> dict[str, Any]:
        """The channel's description without its samples (what a file's header or attributes hold)."""
        out = {"name": self.name, "unit": self.unit, "sensitivity": self.sensitivity}
        for key in ("location", "direction", "shaft"):
            if getattr(self, key):
                out[key] = getattr(self, key)
        if self.meta:
            out["meta"] = dict(self.meta)
        return out

    def with_data(self, data: np.ndarray, unit: str | None = None) -> Channel:
        """The same channel with other samples (and unit)."""
        return Channel(
            self.name,
            data,
            self.unit if unit is None else unit,
            self.sensitivity,
            self.location,
            self.direction,
            self.shaft,
            dict(self.meta),
        )
