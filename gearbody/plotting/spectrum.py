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

__all__ = ["LINE_COLOURS", "mark_lines", "plot_labelled_spectrum", "spectrum_panels", "zoom_limit"]

LINE_COLOURS = {"BPFO": "tab:purple", "BPFI": "tab:brown", "BSF": "tab:olive", "FTF": "tab:cyan"}
"""Colour of a marked line by the symbol its label names (bearing lines); others are grey."""


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


def zoom_limit(lines: Sequence, x_max: float) -> float | None:
    """The upper end of a panel that shows ``lines`` apart (1.15 x the highest one), when every line in
    (0, ``x_max``] lies below a quarter of ``x_max`` (bearing lines on a spectrum of mesh harmonics);
    None otherwise."""
    inside = [float(line.frequency_hz) for line in lines if 0 < float(line.frequency_hz) <= x_max]
    if not inside or max(inside) >= x_max / 4:
        return None
    return min(x_max, 1.15 * max(inside))


def spectrum_panels(spectrum: Spectrum, peaks, lines: Sequence, x_max: float, unit: str, size_px=(1100, 500)):
    """(figure, main axes, zoom panel or None): one axes, or, when ``lines`` crowd the foot of the axis
    (:func:`zoom_limit`), a second panel below it showing the spectrum from 0 to the lines' zoom limit
    with its peaks and the lines labelled (mark the main axes' lines without labels; its zoomed span is
    shaded). The caller draws the main axes; this draws the panel."""
    from .figure import new_figure

    low_max = zoom_limit(lines, x_max)
    if low_max is None:
        fig = new_figure(size_px, 100)
        return fig, fig.add_subplot(1, 1, 1), None
    fig = new_figure((size_px[0], size_px[1] + 330), 100)
    grid = fig.add_gridspec(2, 1, height_ratios=(2.0, 1.2))  # the panel holds its peaks' labels
    ax, low = fig.add_subplot(grid[0]), fig.add_subplot(grid[1])
    kept = [p for p in peaks if p.frequency_hz <= low_max]
    plot_labelled_spectrum(spectrum, kept, ax=low, unit=unit, f_max_hz=low_max)
    set_title(low, f"0-{low_max:.4g}: the bearing lines apart", fontsize=9, pad=3)
    mark_lines(low, lines, low_max)
    ax.axvspan(0.0, low_max, color="tab:purple", alpha=0.08, linewidth=0)
    return fig, ax, low


def mark_lines(ax: Axes, lines: Sequence, x_max: float | None = None, labels: bool = True) -> list:
    """Mark ``lines`` (each with ``frequency_hz`` and ``label``: a
    :class:`~gearbody.analysis.KinematicLine`, in Hz or in orders as the axes are) on ``ax`` where they
    fall inside (0, ``x_max``] (default: the axes' right edge): a dotted vertical line in the colour of
    its symbol (:data:`LINE_COLOURS`) and its label, rotated, at the foot of the axes (a label that would
    overlap another is left out; every line keeps its mark; ``labels=False``: marks only). Returns the
    labels drawn."""
    from matplotlib.transforms import blended_transform_factory

    top = ax.get_xlim()[1] if x_max is None else float(x_max)
    transform = blended_transform_factory(ax.transData, ax.transAxes)
    drawn = []
    for line in sorted(lines, key=lambda line: line.frequency_hz):
        f = float(line.frequency_hz)
        if not 0 < f <= top:
            continue
        colour = next((c for symbol, c in LINE_COLOURS.items() if symbol in line.label.split()), "0.4")
        ax.axvline(f, color=colour, linestyle=":", linewidth=0.9, alpha=0.9, zorder=0.5)
        if not labels:
            continue
        text = ax.text(
            f,
            0.015,
            line.label,
            transform=transform,
            rotation=90,
            fontsize=6,
            ha="right",
            va="bottom",
            color=colour,
            bbox={"facecolor": "white", "edgecolor": "none", "alpha": 0.7, "pad": 0.3},
            in_layout=False,
        )
        drawn.append(text)
    return drop_overlapping(drawn, within=ax)
