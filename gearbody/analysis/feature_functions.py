"""The feature functions on plain arrays (:mod:`gearbody.analysis.features`): a K_d statistic, the
frequency and amplitude of a spectral line, a natural frequency, the resonance speed of a speed sweep."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .feature_record import FeatureError
from .spectrum import amplitude_spectrum, peak_near

KD_STATISTICS = ("max", "mean", "min", "std", "p50", "p95", "p99")


def kd_statistic(kd: ArrayLike, statistic: str = "max") -> float:
    """``statistic`` of the K_d samples [-]: max, mean, min, std, p50, p95 or p99 (non-finite ignored)."""
    values = np.asarray(kd, dtype=float).ravel()
    values = values[np.isfinite(values)]
    if values.size == 0:
        raise FeatureError("kd: no finite samples in the window")
    if statistic not in KD_STATISTICS:
        raise FeatureError(f"kd statistic {statistic!r}: valid are {', '.join(KD_STATISTICS)}")
    if statistic.startswith("p"):
        return float(np.percentile(values, float(statistic[1:])))
    return float(getattr(np, statistic)(values))


def line_frequency_hz(
    pinion_hz: float,
    pinion_teeth: int,
    wheel_teeth: int,
    mesh: int = 1,
    order: int = 0,
    shaft: str = "pinion",
) -> float:
    """Frequency of the line ``mesh`` f_z + ``order`` f_shaft [Hz] of a gear pair whose pinion turns at
    ``pinion_hz``: a mesh harmonic (order 0), a sideband (both non-zero) or a shaft order (mesh 0)."""
    if shaft not in ("pinion", "wheel"):
        raise FeatureError(f"shaft = {shaft!r}: valid are 'pinion', 'wheel'")
    f_shaft = pinion_hz if shaft == "pinion" else pinion_hz * pinion_teeth / wheel_teeth
    return mesh * pinion_hz * pinion_teeth + order * f_shaft


def line_amplitude(
    signal: ArrayLike, sample_rate_hz: float, frequency_hz: float, tolerance_bins: float = 2.0
) -> float:
    """Amplitude [signal unit] of the line at ``frequency_hz``: the largest bin of the Hann-windowed
    amplitude spectrum (:func:`~gearbody.analysis.spectrum.amplitude_spectrum`) within
    ``tolerance_bins`` bins of it (a sine of amplitude A on a bin reads A)."""
    spec = amplitude_spectrum(signal, sample_rate_hz, window="hann")
    if not 0.0 < frequency_hz < sample_rate_hz / 2:
        raise FeatureError(
            f"line at {frequency_hz:.6g} Hz: outside the spectrum (0, {sample_rate_hz / 2:.6g}) Hz"
        )
    return peak_near(spec, frequency_hz, tolerance_bins * spec.resolution_hz).amplitude


def natural_frequency_hz(frequencies_hz: ArrayLike, mode: int = 1) -> float:
    """The ``mode``-th (1-based) elastic natural frequency [Hz]: rigid-body modes (below 1e-5 of the
    highest frequency) are skipped."""
    f = np.sort(np.asarray(frequencies_hz, dtype=float).ravel())
    if f.size == 0:
        raise FeatureError("natural_frequency_hz: the record has no natural frequencies (compute the modes)")
    elastic = f[f >= 1e-5 * f.max()]
    if not 1 <= mode <= elastic.size:
        raise FeatureError(f"natural_frequency_hz: mode = {mode}; the record has modes 1..{elastic.size}")
    return float(elastic[mode - 1])


def resonance_speed(speeds: ArrayLike, response: ArrayLike) -> tuple[float, bool]:
    """The speed at which a speed sweep's ``response`` (e.g. max K_d per speed) peaks, refined by the
    parabola through the largest sample and its two neighbours, in the unit of ``speeds``; and whether
    the peak is inside the sweep (False: the largest response is at an end, the resonance may lie beyond)."""
    s = np.asarray(speeds, dtype=float).ravel()
    r = np.asarray(response, dtype=float).ravel()
    if s.size != r.size or s.size < 3:
        raise FeatureError(f"resonance_speed: need >= 3 speeds and as many responses, got {s.size}, {r.size}")
    order = np.argsort(s)
    s, r = s[order], r[order]
    if np.any(np.diff(s) <= 0) or not np.all(np.isfinite(r)):
        raise FeatureError("resonance_speed: speeds must be distinct and responses finite")
    k = int(np.argmax(r))
    if k in (0, s.size - 1):
        return float(s[k]), False
    a, b, _ = np.polyfit(s[k - 1 : k + 2], r[k - 1 : k + 2], 2)
    vertex = -b / (2.0 * a) if a < 0 else s[k]
    return float(min(max(vertex, s[k - 1]), s[k + 1])), True
