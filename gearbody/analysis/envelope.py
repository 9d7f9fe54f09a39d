"""Envelope spectra (bearing-fault and modulation analysis) from an FFT analytic signal.

Engine-free: a uniformly sampled 1-D signal in, a frozen :class:`EnvelopeSpectrum` out.

Method: the signal's one-sided spectrum restricted to a band [f_lo, f_hi] (the whole band by default)
gives the analytic signal a(t) of the band-passed signal; its envelope |a(t)| or squared envelope
|a(t)|^2 is then analysed by a single-sided amplitude spectrum whose DC bin is the envelope's mean and
whose other bins are peak amplitudes (a component A cos(2 pi f t) of the envelope reads A at f, on a bin).
Example: x = (1 + m cos 2 pi f_m t) cos 2 pi f_c t has |a| = 1 + m cos 2 pi f_m t (DC 1, m at f_m) and
|a|^2 = 1 + m^2/2 + 2 m cos 2 pi f_m t + m^2/2 cos 4 pi f_m t (for m = 0.5: 1.125, 1.0 at f_m, 0.125 at
2 f_m). The squared envelope is the usual choice for bearing faults (Randall & Antoni 2011, "Rolling
element bearing diagnostics - a tutorial", MSSP 25): it has no square-root distortion.

Both FFTs run over n_fft = scipy.fft.next_fast_len(N) samples: the record is zero-padded when N is not
5-smooth (the analytic signal then treats it as not periodic; bin spacing fs / n_fft). With a 5-smooth N
no padding happens and a record holding whole periods is analysed exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
import scipy.fft as sfft
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ._validate import is_real, positive_frequency
from .spectrum import periodic_window

__all__ = ["EnvelopeSpectrum", "analytic_band", "band_signal", "envelope_spectrum"]

Convention = Literal["squared", "envelope"]


@dataclass(frozen=True)
class EnvelopeSpectrum:
    """Single-sided amplitude spectrum of a signal's (squared) envelope."""

    frequency_hz: NDArray[np.float64]
    """Bin frequencies 0 .. max_frequency_hz (or fs / 2) [Hz]."""
    amplitude: NDArray[np.float64]
    """DC bin: the envelope's mean; other bins: peak amplitude [signal units, squared for "squared"]."""
    convention: str
    """"squared" (|a|^2) or "envelope" (|a|)."""
    band_hz: tuple[float, float]
    """Band [Hz] the signal was restricted to before demodulation."""
    sample_rate_hz: float
    """Sample rate of the analysed signal [Hz]."""
    window: str
    """Window applied to the envelope (after removing its mean)."""
    n_fft: int
    """FFT length (the record, zero-padded to a fast length)."""

    @property
    def resolution_hz(self) -> float:
        """Bin spacing sample_rate_hz / n_fft [Hz]."""
        return self.sample_rate_hz / self.n_fft


def _signal(signal: ArrayLike) -> NDArray[np.float64]:
    x = np.asarray(signal, dtype=float)
    if x.ndim != 1 or x.size < 4:
        raise InputError(f"signal must be 1-D with at least 4 samples, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        first = int(np.flatnonzero(~np.isfinite(x))[0])
        raise InputError(f"signal must be finite, sample {first} is {x[first]!r}")
    return x


def _band(band_hz: tuple[float, float] | None, fs: float) -> tuple[float, float]:
    nyquist = fs / 2.0
    if band_hz is None:
        return 0.0, nyquist
    try:
        lo, hi = band_hz
    except (TypeError, ValueError):
        raise InputError(f"band_hz must be a pair (f_lo, f_hi) [Hz] or None, got {band_hz!r}") from None
    if not (is_real(lo) and is_real(hi) and 0.0 <= lo < hi <= nyquist * (1 + 1e-12)):
        raise InputError(f"band_hz must satisfy 0 <= f_lo < f_hi <= {nyquist:g} Hz (fs / 2), got {band_hz!r}")
    return float(lo), float(min(hi, nyquist))


def analytic_band(
    signal: ArrayLike, sample_rate_hz: float, band_hz: tuple[float, float] | None = None
) -> NDArray[np.complex128]:
    """Analytic signal (length N) of ``signal`` restricted to ``band_hz`` [Hz] (brick-wall FFT band;
    None: the whole band, as scipy.signal.hilbert). Its real part is the band-passed signal."""
    x = _signal(signal)
    fs = positive_frequency("sample_rate_hz", sample_rate_hz)
    lo, hi = _band(band_hz, fs)
    n = x.size
    n_fft = sfft.next_fast_len(n, real=True)
    spectrum = sfft.rfft(x, n_fft)
    f = np.arange(spectrum.size) * (fs / n_fft)
    weight = np.where((f >= lo) & (f <= hi), 2.0, 0.0)
    weight[0] /= 2.0
    if n_fft % 2 == 0:
        weight[-1] /= 2.0
    if not np.any(weight):
        raise InputError(f"band_hz {band_hz!r} holds no FFT bin (bin spacing {fs / n_fft:.4g} Hz)")
    full = np.zeros(n_fft, dtype=complex)
    full[: spectrum.size] = spectrum * weight
    return sfft.ifft(full, overwrite_x=True)[:n]


def band_signal(
    signal: ArrayLike, sample_rate_hz: float, band_hz: tuple[float, float] | None = None
) -> NDArray[np.float64]:
    """The real band-passed signal Re(analytic_band(...)) (length N)."""
    return analytic_band(signal, sample_rate_hz, band_hz).real


def envelope_spectrum(
    signal: ArrayLike,
    sample_rate_hz: float,
    *,
    band_hz: tuple[float, float] | None = None,
    convention: Convention = "squared",
    window: str | tuple = "hann",
    max_frequency_hz: float | None = None,
) -> EnvelopeSpectrum:
    """Amplitude spectrum of the (squared) envelope of ``signal`` band-passed to ``band_hz``.

    Args:
        signal: samples in any unit.
        sample_rate_hz: sample rate [Hz].
        band_hz: (f_lo, f_hi) [Hz] demodulated, 0 <= f_lo < f_hi <= fs / 2; None: the whole band.
        convention: "squared" analyses |a(t)|^2, "envelope" |a(t)|.
        window: window of the envelope's spectrum (scipy.signal.get_window names), applied after removing
            the envelope's mean; amplitudes are corrected for its coherent gain (2 |E| / sum(w)).
        max_frequency_hz: keep bins up to this frequency [Hz] (None: up to fs / 2).
    """
    if convention not in ("squared", "envelope"):
        raise InputError(f"convention must be 'squared' or 'envelope', got {convention!r}")
    fs = positive_frequency("sample_rate_hz", sample_rate_hz)
    if max_frequency_hz is not None:
        positive_frequency("max_frequency_hz", max_frequency_hz)
    a = analytic_band(signal, fs, band_hz)
    e = a.real * a.real + a.imag * a.imag
    del a
    if convention == "envelope":
        np.sqrt(e, out=e)
    mean = float(np.mean(e))
    n = e.size
    try:
        w = periodic_window(window, n)
    except ValueError as error:
        raise InputError(f"window {window!r} is not a scipy.signal.get_window window: {error}") from None
    e -= mean
    e *= w
    n_fft = sfft.next_fast_len(n, real=True)
    amplitude = np.abs(sfft.rfft(e, n_fft)) * (2.0 / float(np.sum(w)))
    amplitude[0] = mean
    if n_fft % 2 == 0:
        amplitude[-1] /= 2.0
    frequency = np.arange(amplitude.size) * (fs / n_fft)
    if max_frequency_hz is not None:
        keep = int(math.floor(max_frequency_hz / (fs / n_fft) * (1 + 1e-12))) + 1
        frequency, amplitude = frequency[:keep], amplitude[:keep]
    return EnvelopeSpectrum(
        frequency_hz=frequency,
        amplitude=amplitude,
        convention=convention,
        band_hz=_band(band_hz, fs),
        sample_rate_hz=fs,
        window=str(window),
        n_fft=int(n_fft),
    )
