"""Presentation of labelled peaks (:mod:`gearbody.analysis.peaks`): a plain-text table, flat rows for
csv/json, and a labelled spectrum plot. Engine-free; matplotlib is imported only inside
:func:`plot_labelled_spectrum`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from gearbody.analysis._validate import integer_at_least, positive_frequency
from gearbody.analysis.peaks import LabelledPeak
from gearbody.analysis.spectrum import Spectrum

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["UNEXPLAINED", "peaks_table", "peaks_to_rows", "plot_labelled_spectrum"]


def _checked_peaks(peaks: Sequence[LabelledPeak]) -> list[LabelledPeak]:
    peaks = list(peaks)
    for i, peak in enumerate(peaks):
        if not isinstance(peak, LabelledPeak):
            raise ValueError(f"peaks[{i}] must be a LabelledPeak, got {type(peak).__name__}")
    return peaks


UNEXPLAINED = "(unexplained)"
"""What :func:`peaks_table` shows in the label column of a peak no kinematic line explains."""


def peaks_table(peaks: Sequence[LabelledPeak], unit: str = "", max_rows: int | None = None) -> str:
    """Plain-text table of labelled peaks, one row each, in the given order.

    Columns: f [Hz], amplitude [unit], prominence [dB], label, offset [Hz] (peak minus the nearest
    explaining line). Unexplained peaks read "(unexplained)" with no offset. With ``max_rows`` only the
    most prominent rows are shown (still in the given order) and a last line counts those left out.
    """
    peaks = _checked_peaks(peaks)
    if max_rows is not None:
        max_rows = integer_at_least("max_rows", max_rows, 0)
    shown = peaks
    if max_rows is not None and len(peaks) > max_rows:
        order = sorted(range(len(peaks)), key=lambda i: -peaks[i].prominence_db)[:max_rows]
        shown = [peaks[i] for i in sorted(order)]
    header = [
        "f [Hz]",
        f"amplitude [{unit}]" if unit else "amplitude",
        "prominence [dB]",
        "label",
        "offset [Hz]",
    ]
    rows = [
        [
            f"{p.frequency_hz:.3f}",
            f"{p.amplitude:.4g}",
            f"{p.prominence_db:.1f}",
            p.label or UNEXPLAINED,
            "" if math.isnan(p.offset_hz) else f"{p.offset_hz:+.3f}",
        ]
        for p in shown
    ]
    widths = [max(len(r[c]) for r in [header, *rows]) for c in range(len(header))]
    left = {3}  # labels left-aligned, numbers right-aligned

    def line(cells: list[str]) -> str:
        return "  ".join(
            cell.ljust(w) if c in left else cell.rjust(w)
            for c, (cell, w) in enumerate(zip(cells, widths, strict=True))
        ).rstrip()

    text = [line(header), line(["-" * w for w in widths]), *(line(r) for r in rows)]
    if len(shown) < len(peaks):
        text.append(f"({len(peaks) - len(shown)} less prominent peaks not shown)")
    return "\n".join(text)


def peaks_to_rows(peaks: Sequence[LabelledPeak]) -> list[dict[str, float | str | None]]:
    """One flat dict per peak for csv.DictWriter or json.dumps.

    Keys: frequency_hz, amplitude, prominence_db, label (labels joined by "; ", "" if unexplained),
    offset_hz. Non-finite numbers (no offset, infinite prominence over a zero floor) become None.
    """

    def finite(x: float) -> float | None:
        return float(x) if math.isfinite(x) else None

    return [
        {
            "frequency_hz": p.frequency_hz,
            "amplitude": p.amplitude,
            "prominence_db": finite(p.prominence_db),
            "label": p.label,
            "offset_hz": finite(p.offset_hz),
        }
        for p in _checked_peaks(peaks)
    ]


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
    unexplained ones in grey with their frequency.

    Draws into ``ax``, or into a new Agg figure (no pyplot, global backend untouched) when None; returns
    the axes (``ax.figure.savefig(...)`` writes it). matplotlib is imported here only.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    if not isinstance(spectrum, Spectrum):
        raise ValueError(f"spectrum must be a Spectrum, got {type(spectrum).__name__}")
    peaks = _checked_peaks(peaks)
    if f_max_hz is not None:
        f_max_hz = positive_frequency("f_max_hz", f_max_hz)
    if ax is None:
        fig = Figure(figsize=(10, 6), dpi=100, layout="constrained")
        FigureCanvasAgg(fig)
        ax = fig.add_subplot()
    f = np.asarray(spectrum.frequency_hz, dtype=float)
    a = np.asarray(spectrum.amplitude, dtype=float)
    keep = f <= (f_max_hz if f_max_hz is not None else f[-1])
    if log:
        a = np.where(a > 0, a, np.nan)
    ax.plot(f[keep], a[keep], linewidth=0.6, color="tab:blue")
    shown = [p for p in peaks if f_max_hz is None or p.frequency_hz <= f_max_hz]
    for p in shown:
        colour = "tab:red" if p.explained else "0.5"
        text = p.label if p.explained else f"{p.frequency_hz:.1f} Hz"
        ax.plot([p.frequency_hz], [p.amplitude], marker="v", markersize=3, linestyle="none", color=colour)
        ax.annotate(
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
    if log:
        ax.set_yscale("log")
    top = np.nanmax(a[keep]) if np.any(np.isfinite(a[keep])) else None
    if top is not None and top > 0:
        ax.set_ylim(top=top * (300.0 if log else 1.4))  # room for the rotated labels
    ax.set_xlim(0.0, f_max_hz if f_max_hz is not None else f[-1])
    ax.set_xlabel("Frequency f [Hz]")
    ax.set_ylabel(f"Amplitude [{unit}]" if unit else "Amplitude")
    if title:
        ax.set_title(title)
    return ax
