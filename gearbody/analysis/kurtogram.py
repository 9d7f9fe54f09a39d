"""Spectral kurtosis and the fast kurtogram: which frequency band holds the impulsive (bearing-fault) part.

Engine-free: a uniformly sampled 1-D signal in, frozen dataclasses out.

- :func:`spectral_kurtosis`: STFT estimate SK(f) = <|X(t, f)|^4> / <|X(t, f)|^2>^2 - 2 over the frames
  (Antoni 2006, "The spectral kurtosis: a useful tool for characterising non-stationary signals", MSSP 20).
  Stationary Gaussian noise gives 0 (the DC and Nyquist bins, where X is real, give 1); a transient
  repeating in the band gives a large positive value; a pure tone gives -1. The frame must be shorter
  than the spacing of the transients (frames each holding one impact), or SK falls towards -1.
- :func:`fast_kurtogram`: Antoni 2007 ("Fast computation of the kurtogram for the detection of transient
  faults", MSSP 21). The band [0, fs/2] is split along the 1/3-binary tree: level k (k = 0 .. K) holds 2^k
  bands of width fs / 2^(k+1); level k + log2(3) - 1 (k = 1 .. K-1; shown 1.6, 2.6, ...) holds 3 2^(k-1)
  bands of width fs / (3 2^k). For each band, the kurtosis of its complex envelope z (the band's analytic,
  decimated signal) K = <|z|^4> / <|z|^2>^2 - 2 (0 for Gaussian noise) is computed; the band of largest K
  is the one to demodulate (:meth:`Kurtogram.bandpass`, then :func:`envelope_spectrum`).

  The quasi-analytic filters of the tree are applied in the frequency domain: one FFT of the record, then
  for each band its one-sided bins (raised-cosine edges a quarter of a bandwidth either side of the band
  edge, adjacent bands summing to one; flat at 0 and fs/2) inverse-transformed at twice the bandwidth,
  i.e. a decimated complex envelope as in Antoni's filter bank, without the recursion's accumulated
  filter leakage. As Antoni drops each filter's transient, ``EDGE_SAMPLES`` samples at either end of
  every band signal are dropped (a strong tone's truncation at the record's ends would otherwise show as
  a transient in every band). Every level costs one inverse FFT of the record's length in total.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.fft as sfft
from numpy.lib.stride_tricks import sliding_window_view
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ._validate import integer_at_least, positive_frequency
from .envelope import _signal, band_signal
from .spectrum import periodic_window

__all__ = ["Kurtogram", "SpectralKurtosis", "fast_kurtogram", "spectral_kurtosis"]

MAX_DEFAULT_LEVEL = 7
"""Default deepest binary level (capped by log2(N) - 7, as Antoni recommends)."""

EDGE_SAMPLES = 16
"""Samples of each band's decimated envelope dropped at either end of the record (the band filter's
response to the record's ends, about 4 samples long, and to the circular wrap)."""

_SK_CHUNK = 1 << 22
"""STFT values computed at a time in :func:`spectral_kurtosis` (bounds memory on long records)."""


@dataclass(frozen=True)
class SpectralKurtosis:
    """STFT-based spectral kurtosis."""

    frequency_hz: NDArray[np.float64]
    """Bin frequencies 0 .. fs / 2 [Hz]."""
    kurtosis: NDArray[np.float64]
    """SK per bin (0 for Gaussian noise; 0 where the signal has no energy)."""
    nperseg: int
    """Frame length [samples] (Hann window, hop nperseg / 4)."""
    n_frames: int
    """Frames averaged."""


def spectral_kurtosis(signal: ArrayLike, sample_rate_hz: float, nperseg: int) -> SpectralKurtosis:
    """SK(f) = <|X|^4> / <|X|^2>^2 - 2 over Hann-windowed frames of ``nperseg`` samples, hop nperseg // 4
    (the mean of the signal removed first). Its estimate scatters by about 2 / sqrt(n_frames / 4)."""
    x = _signal(signal)
    fs = positive_frequency("sample_rate_hz", sample_rate_hz)
    nperseg = integer_at_least("nperseg", nperseg, 8)
    if nperseg > x.size:
        raise InputError(f"nperseg must be <= the signal's {x.size} samples, got {nperseg}")
    x = x - np.mean(x)
    hop = nperseg // 4
    frames = sliding_window_view(x, nperseg)[::hop]
    w = periodic_window("hann", nperseg)
    s2 = np.zeros(nperseg // 2 + 1)
    s4 = np.zeros_like(s2)
    step = max(1, _SK_CHUNK // nperseg)
    for start in range(0, frames.shape[0], step):
        spectrum = sfft.rfft(frames[start : start + step] * w, axis=1)
        power = spectrum.real**2 + spectrum.imag**2
        s2 += power.sum(axis=0)
        s4 += (power * power).sum(axis=0)
    m = frames.shape[0]
    with np.errstate(invalid="ignore", divide="ignore"):
        sk = np.where(s2 > 0, m * s4 / np.where(s2 > 0, s2, 1.0) ** 2 - 2.0, 0.0)
    return SpectralKurtosis(sfft.rfftfreq(nperseg, 1.0 / fs), sk, nperseg, m)


@dataclass(frozen=True)
class Kurtogram:
    """Fast kurtogram: envelope kurtosis per level and band, and the band where it is largest."""

    levels: NDArray[np.float64]
    """Level of each row: 0, 1, 1.585, 2, 2.585, ..., max_level (bandwidth fs / 2^(level + 1))."""
    n_bands: tuple[int, ...]
    """Bands of each row (equal widths over [0, fs / 2])."""
    kurtosis: NDArray[np.float64]
    """(rows, 3 2^max_level): row i holds its n_bands[i] values, each repeated to fill the columns."""
    sample_rate_hz: float
    """Sample rate of the analysed signal [Hz]."""
    level: float
    """Level of the best band."""
    centre_hz: float
    """Centre of the best band [Hz]."""
    bandwidth_hz: float
    """Width of the best band [Hz]."""
    max_kurtosis: float
    """Envelope kurtosis in the best band."""

    @property
    def band_hz(self) -> tuple[float, float]:
        """The best band (f_lo, f_hi) [Hz], as envelope_spectrum's band_hz."""
        return self.centre_hz - self.bandwidth_hz / 2, self.centre_hz + self.bandwidth_hz / 2

    def band_values(self, row: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Centre frequencies [Hz] and kurtosis of the bands of ``row``."""
        nb = self.n_bands[row]
        width = self.sample_rate_hz / 2 / nb
        return (np.arange(nb) + 0.5) * width, self.kurtosis[row, :: self.kurtosis.shape[1] // nb].copy()

    def bandpass(self, signal: ArrayLike) -> NDArray[np.float64]:
        """``signal`` band-passed to the best band (brick-wall FFT band, same length)."""
        return band_signal(signal, self.sample_rate_hz, self.band_hz)


def _tree(max_level: int) -> list[tuple[float, int]]:
    """(level, n_bands) of the rows, in Antoni's order 0, 1, 1.6, 2, 2.6, ..., max_level."""
    rows = [(0.0, 1)]
    for k in range(1, max_level + 1):
        rows.append((float(k), 2**k))
        if k < max_level:
            rows.append((k + math.log2(3.0) - 1.0, 3 * 2 ** (k - 1)))
    return rows


def _band_kurtosis(analytic: NDArray[np.complex128], n_bands: int, keep: float) -> NDArray[np.float64]:
    """Envelope kurtosis of each of ``n_bands`` equal bands of the one-sided spectrum ``analytic``
    (length divisible by n_bands); ``keep`` is the fraction of each band signal covering the record."""
    width = analytic.size // n_bands
    edge = width // 4
    taper = np.ones(width + 2 * edge)
    if edge:
        ramp = 0.5 - 0.5 * np.cos(np.pi * (np.arange(2 * edge) + 0.5) / (2 * edge))
        taper[: 2 * edge], taper[-2 * edge :] = ramp, ramp[::-1]
    padded = np.concatenate([np.zeros(edge, complex), analytic, np.zeros(edge, complex)])
    bands = np.zeros((n_bands, 2 * width), dtype=complex)
    bands[:, : width + 2 * edge] = sliding_window_view(padded, width + 2 * edge)[::width] * taper
    if edge:  # no neighbour beyond 0 and fs / 2: keep those edges flat
        bands[0, : 2 * edge] = padded[: 2 * edge]
        bands[-1, width : width + 2 * edge] = padded[-width - 2 * edge :][width:]
    stop = int(math.ceil(keep * 2 * width))
    z = sfft.ifft(bands, axis=1, overwrite_x=True)[:, EDGE_SAMPLES : stop - EDGE_SAMPLES]
    power = z.real**2 + z.imag**2
    m2 = power.mean(axis=1)
    m4 = (power * power).mean(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(m2 > 0, m4 / np.where(m2 > 0, m2, 1.0) ** 2 - 2.0, 0.0)


def fast_kurtogram(signal: ArrayLike, sample_rate_hz: float, max_level: int | None = None) -> Kurtogram:
    """Antoni's fast kurtogram of ``signal`` down to binary level ``max_level`` (default
    min(7, floor(log2 N) - 7); at most floor(log2 N) - 7, so the narrowest band keeps >= 128 samples)."""
    x = _signal(signal)
    fs = positive_frequency("sample_rate_hz", sample_rate_hz)
    deepest = int(math.floor(math.log2(x.size))) - 7
    if deepest < 1:
        raise InputError(f"signal must have at least 256 samples for a kurtogram, got {x.size}")
    if max_level is None:
        max_level = min(MAX_DEFAULT_LEVEL, deepest)
    max_level = integer_at_least("max_level", max_level, 1)
    if max_level > deepest:
        raise InputError(
            f"max_level must be in [1, {deepest}] (floor(log2 N) - 7, N = {x.size}), got {max_level}"
        )
    block = 3 * 2 ** (max_level + 1)  # n_fft / 2 divisible by every row's band count
    n_fft = block * sfft.next_fast_len(-(-x.size // block), real=True)
    spectrum = sfft.rfft(x - np.mean(x), n_fft)
    analytic = 2.0 * spectrum[: n_fft // 2]
    analytic[0] = 0.0
    del spectrum
    rows = _tree(max_level)
    columns = 3 * 2**max_level
    matrix = np.empty((len(rows), columns))
    for i, (_, nb) in enumerate(rows):
        matrix[i] = np.repeat(_band_kurtosis(analytic, nb, x.size / n_fft), columns // nb)
    row, column = np.unravel_index(int(np.argmax(matrix)), matrix.shape)
    nb = rows[row][1]
    width = fs / 2 / nb
    return Kurtogram(
        levels=np.array([level for level, _ in rows]),
        n_bands=tuple(n for _, n in rows),
        kurtosis=matrix,
        sample_rate_hz=fs,
        level=rows[row][0],
        centre_hz=(column // (columns // nb) + 0.5) * width,
        bandwidth_hz=width,
        max_kurtosis=float(matrix[row, column]),
    )
