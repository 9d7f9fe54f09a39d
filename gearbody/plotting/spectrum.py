"""The labelled spectrum: an amplitude spectrum with its peaks marked, explained peaks by their kinematic
labels, unexplained ones by their frequency (gearbody.analysis finds and labels them)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from gearbody.analysis._validate import positive_frequency
from gearbody.analysis.peak_report import checked_peaks
from gearbody.analysis.peaks import LabelledPeak
from gearbody.analysis.planetary_lines import is_cancelled_label
from gearbody.analysis.spectrum import Spectrum

from .figure import drop_overlapping, new_figure, set_title

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["plot_labelled_spectrum"]


def _cancelled(peak: LabelledPeak) -> bool:
    """Every label of the peak is a planetary line its phasing rule cancels."""
    return bool(peak.labels) and all(is_cancelled_label(label) for label in peak.labels)


def plot_labelled_spectrum(
    spectrum: Spectrum,
    peaks: Sequence[LabelledPeak],
    ax: Axes | None = None,
    title: str = "",
    unit: str = "",
    f_max_hz: float | None = None,
    log: bool = True,
) -> Axes:
    """Amplitude spectrum with its peaks marked: explained peaks with their labels (rotated, small, red),
    unexplained ones in grey with their frequency; a peak all of whose labels are planetary lines marked
    "(cancelled)" (:func:`gearbody.analysis.planetary_lines.mark_cancelled`) in grey with an open
    marker. Where labels would overlap, the explained and then
    the stronger peak keeps its label; every peak keeps its marker.

    Draws into ``ax``, or into a new Agg figure (no pyplot, global backend untouched) when None; returns
    the axes (``save_figure(ax.figure, path)`` writes it).
    """
    if not isinstance(spectrum, Spectrum):
        raise ValueError(f"spectrum must be a Spectrum, got {type(spectrum).__name__}")
    peaks = checked_peaks(peaks)
    if f_max_hz is not None:
        f_max_hz = positive_frequency("f_max_hz", f_max_hz)
    if ax is None:
        ax = new_figure((1000, 600)).add_subplot()
    f = np.asarray(spectrum.frequency_hz, dtype=float)
    a = np.asarray(spectrum.amplitude, dtype=float)
    keep = f <= (f_max_hz if f_max_hz is not None else f[-1])
    if log:
        a = np.where(a > 0, a, np.nan)
    ax.plot(f[keep], a[keep], linewidth=0.6, color="tab:blue")
    shown = [p for p in peaks if f_max_hz is None or p.frequency_hz <= f_max_hz]
    labels = []
    for p in sorted(shown, key=lambda p: (not p.explained, _cancelled(p), -p.amplitude)):
        colour = ("0.45" if _cancelled(p) else "tab:red") if p.explained else "0.5"
        text = p.label if p.explained else f"{p.frequency_hz:.1f} Hz"
        face = "none" if _cancelled(p) else colour
        ax.plot(
            [p.frequency_hz],
            [p.amplitude],
            marker="v",
            markersize=3,
            linestyle="none",
            color=colour,
            markerfacecolor=face,
        )
        label = ax.annotate(
            text,
            (p.frequency_hz, p.amplitude),
            xytext=(0, 5),
            textcoords="offset points",
            rotation=90,
            fontsize=6,
            ha="center",
            va="bottom",
            color=colour,
        )
        label.set_in_layout(False)  # the y headroom below holds them; the layout stays put when some hide
        labels.append(label)
    if log:
        ax.set_yscale("log")
    top = np.nanmax(a[keep]) if np.any(np.isfinite(a[keep])) else None
    if top is not None and top > 0:
        # room for the rotated labels: ~1/4 of the axes height above the highest line
        decades = np.log10(top / np.nanmin(a[keep])) if log else 0.0
        ax.set_ylim(top=top * (10.0 ** max(2.5, decades / 3.0) if log else 1.4))
    ax.set_xlim(0.0, f_max_hz if f_max_hz is not None else f[-1])
    ax.set_xlabel("Frequency f [Hz]")
    ax.set_ylabel(f"Amplitude [{unit}]" if unit else "Amplitude")
    if title:
        set_title(ax, title)
    drop_overlapping(labels, within=ax)
    return ax
