"""Labelled spectrum peaks: :func:`label_peaks` finds the prominent local maxima of an amplitude spectrum
and names each one after the kinematic lines (:mod:`gearbody.analysis.kinematics`) within a tolerance.
Peaks that no line explains are kept with an empty label, so they stay visible. Engine-free.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from gearbody.analysis._validate import integer_at_least, is_real, positive_frequency
from gearbody.analysis.kinematics import KinematicLine
from gearbody.analysis.spectrum import Spectrum

from ..errors import InputError

__all__ = ["LABEL_SEPARATOR", "LabelledPeak", "label_peaks"]

LABEL_SEPARATOR = "; "
"""Joins several labels of one peak (not "/": "f_z1/2" already means half the mesh frequency)."""


@dataclass(frozen=True)
class LabelledPeak:
    """A prominent local maximum of an amplitude spectrum and the kinematic lines that explain it."""

    frequency_hz: float
    """Frequency of the maximum bin [Hz]."""
    amplitude: float
    """Its amplitude [signal units] (the bin value: off-bin lines read low by the window's scalloping)."""
    prominence_db: float
    """20 log10(amplitude / local median amplitude) [dB]."""
    labels: tuple[str, ...]
    """Labels of the kinematic lines within the tolerance, nearest first; () if none explains the peak."""
    offset_hz: float
    """frequency_hz minus the nearest explaining line's frequency [Hz]; nan if unexplained."""

    @property
    def label(self) -> str:
        """The labels joined by "; ", "" if unexplained."""
        return LABEL_SEPARATOR.join(self.labels)

    @property
    def explained(self) -> bool:
        """At least one kinematic line lies within the tolerance."""
        return bool(self.labels)


def label_peaks(
    spectrum: Spectrum,
    lines: Sequence[KinematicLine],
    tolerance_hz: float | None = None,
    min_prominence_db: float = 6.0,
    max_peaks: int | None = 50,
    floor_bins: int = 32,
    f_max_hz: float | None = None,
) -> list[LabelledPeak]:
    """Prominent local maxima of ``spectrum``, each labelled with the kinematic lines near it.

    A peak is a local maximum (scipy.signal.find_peaks's) whose amplitude is at least ``min_prominence_db``
    above the local floor, the median amplitude of the bins within +- ``floor_bins`` of it. Of those, the
    ``max_peaks`` most prominent are kept, returned in order of frequency. Bins 0 and 1 are not searched
    (DC and its leakage through the window). Each gets the labels of all
    ``lines`` within ``tolerance_hz`` (default 1.5 bins), nearest first; a peak no line explains gets no
    label (``labels == ()``, ``label == ""``) and stays in the list so it can be investigated.

    The threshold is relative to a noise floor: Rayleigh-distributed noise amplitudes exceed r times their
    median with probability 2^(-r^2), so at 6 dB (r = 2) about 6 % of noise bins qualify, at 10 dB 0.1 %,
    at 12 dB 0.002 %. On noisy spectra raise ``min_prominence_db`` or rely on ``max_peaks``.

    Args:
        spectrum: amplitude spectrum (:func:`gearbody.analysis.spectrum.amplitude_spectrum`).
        lines: kinematic lines (:func:`kinematic_lines`); may be empty.
        tolerance_hz: largest |peak - line| frequency distance for a label [Hz], default 1.5 resolution_hz.
        min_prominence_db: least amplitude over the local floor [dB], >= 0.
        max_peaks: most peaks returned (the most prominent), None for all.
        floor_bins: half-width of the band whose median amplitude is the local floor [bins], >= 1.
        f_max_hz: ignore peaks above this frequency [Hz]; None for all up to Nyquist.
    """
    if not isinstance(spectrum, Spectrum):
        raise InputError(f"spectrum must be a Spectrum, got {type(spectrum).__name__}")
    f = np.asarray(spectrum.frequency_hz, dtype=float)
    a = np.asarray(spectrum.amplitude, dtype=float)
    if a.ndim != 1 or a.size < 3 or f.shape != a.shape:
        raise InputError(f"spectrum must hold at least 3 bins, got amplitude shape {a.shape}")
    df = spectrum.resolution_hz
    if tolerance_hz is None:
        tolerance_hz = 1.5 * df
    else:
        tolerance_hz = positive_frequency("tolerance_hz", tolerance_hz)
    if not (is_real(min_prominence_db) and math.isfinite(min_prominence_db) and min_prominence_db >= 0):
        raise InputError(f"min_prominence_db must be a finite number >= 0 [dB], got {min_prominence_db!r}")
    if max_peaks is not None:
        max_peaks = integer_at_least("max_peaks", max_peaks, 1)
    floor_bins = integer_at_least("floor_bins", floor_bins, 1)
    if f_max_hz is not None:
        f_max_hz = positive_frequency("f_max_hz", f_max_hz)
    lines = list(lines)
    for i, line in enumerate(lines):
        if not isinstance(line, KinematicLine):
            raise InputError(f"lines[{i}] must be a KinematicLine, got {type(line).__name__}")

    index, prominence_db, keep = _prominent_peaks(f, a, min_prominence_db, max_peaks, floor_bins, f_max_hz)
    return _labelled(f, a, index, prominence_db, keep, lines, tolerance_hz)


def _prominent_peaks(
    f: np.ndarray,
    a: np.ndarray,
    min_prominence_db: float,
    max_peaks: int | None,
    floor_bins: int,
    f_max_hz: float | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(peak bins, their prominence over the local floor [dB], the positions kept)``: the local maxima
    ``min_prominence_db`` over the median of +- ``floor_bins``, from bin 2 up to ``f_max_hz``; the
    ``max_peaks`` most prominent kept, in order of frequency. Above ``f_max_hz`` only the bins that the
    floor and the local maxima up to it need are looked at (a long record's spectrum: most of its bins)."""
    if f_max_hz is not None:
        top = int(np.searchsorted(f, f_max_hz, side="right")) + floor_bins + 64  # the windows reach so far
        f, a = f[:top], a[:top]
    floor = running_median(a, 2 * floor_bins + 1)
    index = local_maxima(a)
    index = index[a[index] >= (floor * 10.0 ** (min_prominence_db / 20.0))[index]]
    index = index[index >= 2]  # bin 1 holds the window's leakage of the DC bin (the record's residual mean)
    if f_max_hz is not None:
        index = index[f[index] <= f_max_hz]
    with np.errstate(divide="ignore"):
        prominence_db = 20.0 * np.log10(a[index] / floor[index])
    keep = np.argsort(-prominence_db, kind="stable")[:max_peaks]
    keep = np.sort(keep)
    return index, prominence_db, keep


def _labelled(
    f: np.ndarray,
    a: np.ndarray,
    index: np.ndarray,
    prominence_db: np.ndarray,
    keep: np.ndarray,
    lines: list[KinematicLine],
    tolerance_hz: float,
) -> list[LabelledPeak]:
    """The kept peaks, each with the labels of the lines within ``tolerance_hz``, nearest first."""
    line_hz = np.array([line.frequency_hz for line in lines], dtype=float)
    within_hz = tolerance_hz * (1.0 + 1e-9)
    out = []
    for j in keep:
        peak_hz = float(f[index[j]])
        distance_hz = peak_hz - line_hz
        near = np.flatnonzero(np.abs(distance_hz) <= within_hz)
        near = near[np.argsort(np.abs(distance_hz[near]), kind="stable")]
        out.append(
            LabelledPeak(
                frequency_hz=peak_hz,
                amplitude=float(a[index[j]]),
                prominence_db=float(prominence_db[j]),
                labels=tuple(lines[i].label for i in near),
                offset_hz=float(distance_hz[near[0]]) if near.size else float("nan"),
            )
        )
    return out


def local_maxima(x: np.ndarray) -> np.ndarray:
    """Indices of the local maxima of ``x`` as ``scipy.signal.find_peaks(x)`` finds them (without its
    ~1 s import): a sample, or the middle of a run of equal samples (rounded down), higher than its
    neighbours on both sides; never the first or the last sample."""
    x = np.asarray(x, dtype=float)
    if x.size < 3:
        return np.zeros(0, dtype=np.intp)
    starts = np.concatenate(([0], np.flatnonzero(x[1:] != x[:-1]) + 1))  # runs of equal samples
    ends = np.concatenate((starts[1:] - 1, [x.size - 1]))
    v = x[starts]
    peak = np.zeros(starts.size, dtype=bool)
    peak[1:-1] = (v[:-2] < v[1:-1]) & (v[2:] < v[1:-1])
    return ((starts[peak] + ends[peak]) // 2).astype(np.intp)


def running_median(x: np.ndarray, size: int, chunk: int = 1 << 15) -> np.ndarray:
    """``scipy.ndimage.median_filter(x, size, mode="reflect")`` for an odd ``size`` (the same values: the
    median of an odd count is one of the samples), in chunks of ``chunk`` outputs (bounded memory)."""
    x = np.asarray(x, dtype=float)
    half = size // 2
    padded = np.pad(x, half, mode="symmetric")  # ndimage's "reflect": d c b a | a b c d | d c b a
    windows = np.lib.stride_tricks.sliding_window_view(padded, size)
    out = np.empty(x.size)
    for i in range(0, x.size, chunk):
        out[i : i + chunk] = np.median(windows[i : i + chunk], axis=-1)
    return out
