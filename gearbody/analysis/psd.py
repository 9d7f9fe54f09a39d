"""Power spectral density by Welch's method (:func:`power_spectral_density`, :class:`Psd`).

Engine-free: works on any uniformly sampled 1-D signal, simulated or measured.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gearbody.analysis._validate import is_real, positive_frequency

from ..errors import InputError

__all__ = ["Psd", "power_spectral_density"]


@dataclass(frozen=True)
class Psd:
    """One-sided power spectral density (Welch average of windowed, overlapping segments)."""

    frequency_hz: NDArray[np.float64]
    """Bin frequencies 0 .. sample_rate_hz / 2 [Hz]."""
    psd: NDArray[np.float64]
    """Power spectral density [signal units^2 / Hz]."""
    sample_rate_hz: float
    """Sample rate of the analysed signal [Hz]."""
    window: str
    """Window name passed to scipy.signal.get_window."""
    segment_samples: int
    """Samples per segment (one FFT)."""
    overlap_samples: int
    """Samples shared by consecutive segments (half a segment)."""
    n_averages: int
    """Number of segments averaged."""

    @property
    def resolution_hz(self) -> float:
        """Bin spacing sample_rate_hz / segment_samples [Hz]."""
        return self.sample_rate_hz / self.segment_samples

    @property
    def segment_s(self) -> float:
        """Segment duration [s]."""
        return self.segment_samples / self.sample_rate_hz


def _checked_signal(signal: ArrayLike, sample_rate_hz: float) -> NDArray[np.float64]:
    x = np.asarray(signal, dtype=float)
    if x.ndim != 1 or x.size < 2:
        raise InputError(f"signal must be 1-D with at least 2 samples, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise InputError("signal contains non-finite samples")
    positive_frequency("sample_rate_hz", sample_rate_hz)
    return x


def power_spectral_density(
    signal: ArrayLike,
    sample_rate_hz: float,
    window: str | tuple = "hann",
    segment_s: float | None = None,
    detrend: bool | Literal["constant", "linear"] = "constant",
) -> Psd:
    """One-sided power spectral density by Welch's method (scipy.signal.welch, density scaling).

    The signal is cut into segments of ``segment_s`` overlapping by half a segment; each is detrended,
    multiplied by the window w[n] (periodic, M samples) and transformed, X = rfft(w x). The estimate is the
    mean over segments of ``2 |X|^2 / (sample_rate_hz * sum(w^2))`` [signal units^2 / Hz] (the DC bin and,
    for even M, the Nyquist bin are not doubled).

    Scaling: by Parseval, ``sum(psd) * resolution_hz`` equals the mean over segments of
    ``sum((w x)^2) / sum(w^2)``, the window-weighted mean square of the detrended signal; so the integral of
    the PSD over frequency is the variance. White noise of variance s^2 has PSD 2 s^2 / sample_rate_hz;
    a sine A sin(2 pi f t) integrated over its line (a few bins) gives A^2 / 2, its mean square, exactly
    when it completes an integer number (>= 2) of periods per Hann segment. The PSD does not depend on the
    segment length for noise; a line's peak PSD grows with it (its power sits in fewer, narrower bins).
    Use :func:`gearbody.analysis.spectrum.amplitude_spectrum` to read line amplitudes.

    Args:
        signal: samples in any unit (m/s^2, N, K_d, ...).
        sample_rate_hz: sample rate [Hz].
        window: window for scipy.signal.get_window ("hann", "boxcar", ("kaiser", 8), ...).
        segment_s: segment duration [s], between 2 samples and the whole signal; resolution 1 / segment_s.
            Default: a quarter of the signal, which gives 7 averages.
        detrend: True or "constant" removes each segment's mean, "linear" a least-squares line, False none.
    """
    x = _checked_signal(signal, sample_rate_hz)
    n = x.size
    if segment_s is None:
        nperseg = max(2, n // 4)
    else:
        if not (is_real(segment_s) and math.isfinite(segment_s) and segment_s > 0):
            raise InputError(f"segment_s must be a positive duration [s], got {segment_s!r}")
        nperseg = int(round(segment_s * sample_rate_hz))
        if not 2 <= nperseg <= n:
            raise InputError(
                f"segment_s must lie in [{2 / sample_rate_hz:.6g}, {n / sample_rate_hz:.6g}] s "
                f"(2 samples .. the whole signal), got {segment_s!r} s = {nperseg} samples"
            )
    if detrend is True:
        detrend = "constant"
    if not (detrend is False or detrend in ("constant", "linear")):
        raise InputError(f"detrend must be a bool, 'constant' or 'linear', got {detrend!r}")
    noverlap = nperseg // 2
    from scipy.signal import welch  # ~0.4 s to import: on use only

    frequency_hz, psd = welch(
        x,
        fs=sample_rate_hz,
        window=window,
        nperseg=nperseg,
        noverlap=noverlap,
        detrend=detrend,
        return_onesided=True,
        scaling="density",
        average="mean",
    )
    return Psd(
        frequency_hz=np.asarray(frequency_hz, dtype=float),
        psd=np.asarray(psd, dtype=float),
        sample_rate_hz=float(sample_rate_hz),
        window=str(window),
        segment_samples=int(nperseg),
        overlap_samples=int(noverlap),
        n_averages=int(1 + (n - nperseg) // (nperseg - noverlap)),
    )
