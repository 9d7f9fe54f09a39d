"""The ring sensor of a planetary stage in a run: the window of whole carrier revolutions it is analysed
over (after the run's last change of speed or load, :mod:`gearbody.analysis.carrier_window`), its
order-tracked spectrum and the stage's kinematic lines to label it with (:mod:`.planetary_lines`),
the lines McFadden and Smith's rule cancels marked when the planets are equally spaced.

Engine-free: each function reads a :class:`~gearbody.result.Result` (its signals by name and its
``meta["stages"]``), whose ring-sensor spectrum (``Result.spectrum``), plot and report are made from
these."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..signals import stage_prefix
from .carrier_window import CarrierWindow, carrier_order_spectrum, carrier_window
from .peaks import LabelledPeak, label_peaks
from .planetary_lines import PlanetaryLine, PlanetarySources, mark_cancelled, planetary_lines
from .spectrum import Spectrum

if TYPE_CHECKING:
    from gearbody.result import Result

__all__ = [
    "RingSensorSpectrum",
    "equally_spaced",
    "last_change_s",
    "planetary_sources",
    "ring_sensor_notes",
    "ring_sensor_spectrum",
    "ring_sensor_window",
]


def planetary_sources(result: Result, stage: int, mask: np.ndarray | None = None) -> PlanetarySources:
    """The stage's teeth, planets and mean member speeds (Hz, signed) over ``mask`` (default: the final
    window, :meth:`Result.final_window`)."""
    meta = result.meta["stages"][stage]
    prefix = stage_prefix(stage)
    win = result.final_window() if mask is None else mask
    hz = {
        m: float(np.mean(result[f"{prefix}{m}_speed_rad_s"][win])) / (2 * np.pi)
        for m in ("sun", "ring", "carrier")
    }
    planet = float(np.mean(result[f"{prefix}planet_1_speed_rad_s"][win])) / (2 * np.pi)
    return PlanetarySources(
        z_sun=meta["sun_teeth"],
        z_planet=meta["planet_teeth"],
        z_ring=meta["ring_teeth"],
        n_planets=meta["planets"],
        carrier_hz=hz["carrier"],
        sun_hz=hz["sun"],
        ring_hz=hz["ring"],
        planet_hz=planet,
        rtol=1e-3,  # mean speeds of a vibrating run
    )


def last_change_s(result: Result) -> float:
    """The last change of speed or load of the run's operation (the last point of its speed and load
    profiles), at least the run's start [s]."""
    op = (result.meta.get("scenario") or {}).get("operation") or {}
    times = [float(result.time_s[0])]
    for key in ("speed_profile", "load_profile"):
        times.extend(float(t) for t in (op.get(key) or {}).get("time_s") or ())
    return max(times)


def equally_spaced(result: Result, stage: int) -> bool:
    """The stage's planets sit at 360 n / N degrees (McFadden and Smith's rule applies)."""
    meta = result.meta["stages"][stage]
    n = int(meta["planets"])
    angles = meta.get("planet_angles_deg") or [360.0 * k / n for k in range(n)]
    return all(abs(a - 360.0 * k / n) < 1e-6 for k, a in enumerate(angles))


def ring_sensor_window(result: Result, stage: int) -> CarrierWindow:
    """The analysis window of the stage's ring sensor: the whole carrier revolutions (relative to the
    ring) of the second half of the time after the run's last change of speed or load
    (:func:`gearbody.analysis.carrier_window.carrier_window`)."""
    prefix = stage_prefix(stage)
    carrier = result[f"{prefix}carrier_angle_rad"] - result[f"{prefix}ring_angle_rad"]
    return carrier_window(result.time_s, carrier, change_s=last_change_s(result))


@dataclass(frozen=True)
class RingSensorSpectrum:
    """The ring sensor's spectrum over its window and the stage's lines to label it with."""

    signal: str
    """The sensor signal's name."""
    window: CarrierWindow
    spectrum: Spectrum
    sources: PlanetarySources
    """The stage's teeth and mean speeds over the window."""
    lines: list[PlanetaryLine]
    """The catalogue, cancelled lines marked (equally spaced planets)."""
    f_max_hz: float
    """Highest frequency shown: 3.5 f_m or Nyquist [Hz]."""

    def peaks(self, **kwargs) -> list[LabelledPeak]:
        """:func:`gearbody.analysis.label_peaks` of the spectrum with the lines, up to f_max_hz; the
        tolerance is 1.5 bins unless given."""
        kwargs.setdefault("tolerance_hz", 1.5 * self.spectrum.resolution_hz)
        return label_peaks(self.spectrum, self.lines, f_max_hz=self.f_max_hz, **kwargs)

    def title(self, head: str) -> str:
        """``head`` with the window and, when it does not resolve the carrier sidebands, why not."""
        text = f"{head}, over {self.window.describe()}"
        if not self.window.resolves_sidebands:
            text += f"; carrier sidebands unresolved: run with --t-end {self.window.needed_t_end_s:g}"
        return text


def ring_sensor_spectrum(result: Result, stage: int) -> RingSensorSpectrum:
    """The stage's ring sensor over :func:`ring_sensor_window`: its spectrum (order-tracked over whole
    carrier revolutions, read in Hz) and the stage's lines at the window's mean speeds, 3 mesh harmonics,
    cancelled lines marked when the planets are equally spaced."""
    prefix = stage_prefix(stage)
    name = f"{prefix}ring_sensor_N"
    window = ring_sensor_window(result, stage)
    carrier = result[f"{prefix}carrier_angle_rad"] - result[f"{prefix}ring_angle_rad"]
    spec = carrier_order_spectrum(result[name], carrier, window, result.sample_rate_hz)
    sources = planetary_sources(result, stage, window.mask(result.time_s.size))
    f_max = min(spec.frequency_hz[-1], 3.5 * sources.mesh_hz)
    lines = planetary_lines(sources, f_max, harmonics=3)
    if equally_spaced(result, stage):
        lines = mark_cancelled(lines)
    return RingSensorSpectrum(name, window, spec, sources, lines, f_max)


def ring_sensor_notes(result: Result) -> list[str]:
    """Per planetary stage whose ring-sensor window cannot resolve the carrier sidebands, one line saying
    its resolution and the --t-end that would (empty when all do)."""
    notes = []
    for k in result.planetary_stages:
        note = ring_sensor_window(result, k).note()
        if note:
            notes.append(f"stage {k + 1}: {note}" if len(result.meta["stages"]) > 1 else note)
    return notes
