"""The standard PNG plots of a run with planetary stages (``gearbody run``): every planet's mesh K_d over
time, the load sharing, and the ring-sensor spectrum with the stage's kinematic lines labelled (carrier,
planet pass, mesh harmonics and their carrier sidebands, tooth fault frequencies).

The ring-sensor spectrum is taken over whole carrier revolutions relative to the ring at the end of the
run's steady part (:func:`ring_sensor_window`, :mod:`gearbody.analysis.carrier_window`); lines that
McFadden and Smith's rule cancels for equally spaced planets are marked "(cancelled)" and drawn grey."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from gearbody.analysis import label_peaks
from gearbody.analysis.carrier_window import CarrierWindow, carrier_order_spectrum, carrier_window
from gearbody.analysis.peaks import LabelledPeak
from gearbody.analysis.planetary_lines import (
    PlanetaryLine,
    PlanetarySources,
    mark_cancelled,
    planetary_lines,
)
from gearbody.analysis.spectrum import Spectrum

from ..signals import stage_file_tag, stage_prefix
from .figure import new_figure, save_figure, set_title
from .result import plot_signals
from .spectrum import plot_labelled_spectrum

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
    "write_planetary_plots",
]

CANCELLED_CAPTION = (
    'open grey markers, "(cancelled)": lines McFadden & Smith\'s rule cancels for equally spaced identical '
    "planets; grey frequencies: peaks no line explains"
)


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


def write_planetary_plots(result: Result, out_dir: str | Path) -> list[Path]:
    """Per planetary stage: planet mesh K_d over time, mean planet mesh forces (sharing), and the
    ring-sensor spectrum over its window of whole carrier revolutions with its labelled peaks."""
    out = Path(out_dir)
    title = result.meta.get("title", result.meta.get("scene", ""))
    paths = []
    win = result.final_window()
    for k, meta in enumerate(result.meta["stages"]):
        if meta.get("type") != "planetary":
            continue
        prefix = stage_prefix(k)
        tag = stage_file_tag(k)
        n = meta["planets"]
        kd = {
            f"planet {p} {mesh}": result[f"{prefix}planet_{p}_{mesh}_mesh_kd"]
            for p in range(1, n + 1)
            for mesh in ("sun", "ring")
        }
        paths.append(
            plot_signals(
                result.time_s,
                kd,
                out / f"planet_kd_time{tag}.png",
                title=f"{title}: planet mesh K_d = F(t)/F_rated, stage {k + 1}",
                ylabel="dynamic factor K_d [-]",
            )
        )
        fig = new_figure((800, 450))
        ax = fig.add_subplot()
        x = np.arange(1, n + 1)
        for offset, mesh in ((-0.2, "sun"), (0.2, "ring")):
            mean = [float(np.mean(result[f"{prefix}planet_{p}_{mesh}_mesh_kd"][win])) for p in x]
            ax.bar(x + offset, mean, width=0.4, label=f"{mesh} mesh")
        ax.axhline(1.0, color="0.4", linestyle=":", linewidth=1.0)
        ax.set_xticks(x)
        ax.set_xlabel("planet")
        ax.set_ylabel(f"mean K_d, last {result.FINAL_FRACTION:.0%} of run [-]")
        ax.legend(loc="lower right")
        set_title(ax, f"{title}: load sharing, stage {k + 1}")
        paths.append(save_figure(fig, out / f"load_sharing{tag}.png"))
        ring = ring_sensor_spectrum(result, k)
        ax = plot_labelled_spectrum(
            ring.spectrum,
            ring.peaks(max_peaks=30),
            title=ring.title(f"{title}: ring sensor, stage {k + 1}"),
            unit="N",
            f_max_hz=ring.f_max_hz,
        )
        if equally_spaced(result, k):
            ax.text(0.01, 0.98, CANCELLED_CAPTION, transform=ax.transAxes, fontsize=7, color="0.4", va="top")
        paths.append(save_figure(ax.figure, out / f"ring_sensor_spectrum{tag}.png"))
    return paths
