"""Fault bands: a band round every line the scenario implies (mesh harmonics, shaft orders, bearing and
planetary fault lines), and what a diagnostician reads in each: the peak amplitude, where the peak is, and
the band power. In the frequency domain (Hz) or the order domain (orders of the input shaft) alike."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..analysis import Spectrum
from ..errors import InputError

__all__ = ["BandMetric", "band_metrics"]

FAMILIES = ("mesh", "shaft", "bearing", "fault", "planet_pass")
"""Line families that get a fault band (sidebands and cross terms are read inside the mesh bands)."""


@dataclass(frozen=True)
class BandMetric:
    """One fault band: the line it surrounds and what the spectrum holds in it."""

    label: str
    family: str
    centre: float
    """The line's frequency [Hz] or order."""
    half_width: float
    peak_amplitude: float
    """Largest bin in the band [signal units]."""
    peak_at: float
    """Where it is [Hz] or [order]."""
    band_power: float
    """Sum over the band's bins of amplitude^2 / 2 (the mean square of the band's tones) [unit^2]."""

    def as_row(self) -> dict:
        return {
            "line": self.label,
            "family": self.family,
            "centre": self.centre,
            "half_width": self.half_width,
            "peak_amplitude": self.peak_amplitude,
            "peak_at": self.peak_at,
            "band_power": self.band_power,
        }


def band_metrics(
    spectrum: Spectrum,
    lines: Sequence,
    half_width: float | None = None,
    relative_width: float = 0.01,
    families: Sequence[str] = FAMILIES,
) -> list[BandMetric]:
    """The metrics of a band round each line of ``families`` in ``lines`` (``KinematicLine``s in the
    spectrum's unit: Hz, or orders for an order spectrum). Half-width: ``half_width``, default the larger
    of 2 bins and ``relative_width`` of the line's frequency (a speed that wanders spreads a line in
    proportion to its order)."""
    f = np.asarray(spectrum.frequency_hz, dtype=float)
    a = np.asarray(spectrum.amplitude, dtype=float)
    if f.size < 3:
        raise InputError(f"spectrum must hold at least 3 bins, got {f.size}")
    df = float(f[1] - f[0])
    if half_width is not None and not (np.isfinite(half_width) and half_width > 0):
        raise InputError(f"half_width = {half_width!r}: must be > 0 (in the spectrum's unit)")
    if not (0 <= relative_width < 0.5):
        raise InputError(f"relative_width = {relative_width!r}: must be in [0, 0.5)")
    out = []
    for line in lines:
        if line.family not in families or not (f[0] < line.frequency_hz <= f[-1]):
            continue
        hw = half_width if half_width is not None else max(2 * df, relative_width * line.frequency_hz)
        lo, hi = np.searchsorted(f, [line.frequency_hz - hw, line.frequency_hz + hw])
        lo, hi = max(int(lo), 1), max(int(hi), int(lo) + 1)
        band = a[lo:hi]
        if band.size == 0:
            continue
        k = int(np.argmax(band))
        out.append(
            BandMetric(
                line.label,
                line.family,
                float(line.frequency_hz),
                float(hw),
                float(band[k]),
                float(f[lo + k]),
                float(np.sum(band**2) / 2),
            )
        )
    return out
