"""Presentation of labelled peaks (:mod:`gearbody.analysis.peaks`): a plain-text table and flat rows for
csv/json (the plot is :func:`gearbody.plotting.spectrum.plot_labelled_spectrum`). Engine-free."""

from __future__ import annotations

import math
from collections.abc import Sequence

from gearbody.analysis._validate import integer_at_least
from gearbody.analysis.peaks import LabelledPeak

from ..errors import InputError

__all__ = ["UNEXPLAINED", "peaks_table", "peaks_to_rows"]


def checked_peaks(peaks: Sequence[LabelledPeak]) -> list[LabelledPeak]:
    """``peaks`` as a list, each checked to be a LabelledPeak (ValueError otherwise)."""
    peaks = list(peaks)
    for i, peak in enumerate(peaks):
        if not isinstance(peak, LabelledPeak):
            raise InputError(f"peaks[{i}] must be a LabelledPeak, got {type(peak).__name__}")
    return peaks


UNEXPLAINED = "(unexplained)"
"""What :func:`peaks_table` shows in the label column of a peak no kinematic line explains."""


def peaks_table(peaks: Sequence[LabelledPeak], unit: str = "", max_rows: int | None = None) -> str:
    """Plain-text table of labelled peaks, one row each, in the given order.

    Columns: f [Hz], amplitude [unit], prominence [dB], label, offset [Hz] (peak minus the nearest
    explaining line). Unexplained peaks read "(unexplained)" with no offset. With ``max_rows`` only the
    most prominent rows are shown (still in the given order) and a last line counts those left out.
    """
    peaks = checked_peaks(peaks)
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
        for p in checked_peaks(peaks)
    ]
