"""Real cepstrum, cepstrum pre-whitening and cepstral editing (liftering) of line families.

Engine-free: a uniformly sampled 1-D signal in, arrays or frozen dataclasses out.

The real cepstrum c(q) = IFFT(ln |X(f)|) of an N-sample record (FFT over exactly N samples, so an unedited
cepstrum rebuilds the record) turns a family of lines spaced by Delta f in the spectrum (harmonics, or
sidebands of a carrier) into peaks, "rahmonics", at quefrencies q = k / Delta f [s] (Randall, "Vibration-
based condition monitoring", Wiley 2011, ch. 3). ln |X| is floored at 1e-12 max |X| (silent bins).

- :func:`cepstrum_prewhiten` (CPW, Borghesani, Pennacchi, Randall, Sawalhi & Ricci 2013, MSSP 36):
  x_pw = IFFT(exp(i angle X)), i.e. ln |X| = 0, the whole real cepstrum zeroed: every line and
  resonance flattened to one level, which leaves impacts (bearing faults) standing out.
- :func:`lifter_family` (Sawalhi & Randall 2011, "Signal pre-whitening using cepstrum editing
  (liftering) to enhance fault detection in rolling element bearings", CM/MFPT): a comb lifter zeroes
  (or keeps only) the cepstrum within width_s of the rahmonics k / spacing_hz; the edited ln |X| is
  recombined with the original phase. Limits of the method, both measured in tests/test_cepstrum.py:
  the k = 0 member of a sideband family - the carrier - belongs to the family and goes with it; and any
  other line loses about width_s spacing_hz of its height in ln |X| over the floor (the lifter's share
  of quefrencies) and every bin moves at random by that share of the noise's log-spectrum scatter, so
  notches must stay narrow, which removes only families spanning a wide band (a family of few lines has
  broad rahmonics and needs wide notches).
- :func:`cepstral_peak`: the rahmonic of a family at q = 1 / spacing_hz, e.g. a mesh tone modulated at
  the shaft rate shows a peak at quefrency 1 / f_shaft (cepstrum of a segment-averaged spectrum).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.fft as sfft
from numpy.lib.stride_tricks import sliding_window_view
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ._validate import integer_at_least, is_real, positive_frequency
from .envelope import _signal
from .spectrum import periodic_window

__all__ = [
    "CepstralPeak",
    "Cepstrum",
    "cepstral_peak",
    "cepstrum_prewhiten",
    "lifter_family",
    "real_cepstrum",
]

LOG_FLOOR = 1e-12
"""|X| is floored at this fraction of max |X| before the logarithm."""


@dataclass(frozen=True)
class Cepstrum:
    """Real cepstrum over quefrencies 0 .. N / 2 / fs (it is even: c(N - n) = c(n))."""

    quefrency_s: NDArray[np.float64]
    """Quefrency of each sample, n / fs [s]."""
    cepstrum: NDArray[np.float64]
    """c(q) of ln |X| (natural log of the signal's units)."""
    sample_rate_hz: float
    """Sample rate of the analysed signal [Hz]."""


@dataclass(frozen=True)
class CepstralPeak:
    """Largest |c| near the first rahmonic q = 1 / spacing_hz, and the cepstrum's level around it."""

    quefrency_s: float
    """Quefrency of the largest |c| in the search window [s]."""
    amplitude: float
    """|c| there."""
    floor: float
    """Median |c| over quefrencies 0.5 q .. 1.5 q."""
    nperseg: int
    """Segment length of the averaged spectrum [samples]."""

    @property
    def prominence(self) -> float:
        """amplitude / floor (inf on a zero floor)."""
        return self.amplitude / self.floor if self.floor > 0 else float("inf")


def _log_spectrum(x: NDArray[np.float64]) -> tuple[NDArray[np.complex128], NDArray[np.float64]]:
    spectrum = sfft.rfft(x)
    magnitude = np.abs(spectrum)
    top = float(np.max(magnitude))
    if top == 0.0:
        raise InputError("signal is all zeros: its cepstrum is undefined")
    return spectrum, np.log(np.maximum(magnitude, LOG_FLOOR * top))


def real_cepstrum(signal: ArrayLike, sample_rate_hz: float) -> Cepstrum:
    """Real cepstrum c = IFFT(ln |FFT(x)|) (quefrencies 0 .. N / 2 / fs)."""
    x = _signal(signal)
    fs = positive_frequency("sample_rate_hz", sample_rate_hz)
    _, log_magnitude = _log_spectrum(x)
    c = sfft.irfft(log_magnitude, x.size)[: x.size // 2 + 1]
    return Cepstrum(np.arange(c.size) / fs, c, fs)


def cepstrum_prewhiten(signal: ArrayLike) -> NDArray[np.float64]:
    """Cepstrum pre-whitening x_pw = IFFT(exp(i angle FFT(x))): every bin's magnitude set to one, the
    phase kept (same length; unit-magnitude spectrum, so RMS ~ 1 / sqrt(N), not the input's)."""
    x = _signal(signal)
    spectrum = sfft.rfft(x)
    magnitude = np.abs(spectrum)
    unit = np.divide(spectrum, magnitude, out=np.ones_like(spectrum), where=magnitude > 0)
    return sfft.irfft(unit, x.size)


def _comb_mask(n: int, fs: float, spacing_hz: float, rahmonics: int | None, width_s: float) -> NDArray:
    """Quefrency samples 0 .. N-1 (both halves of the even cepstrum) within width_s / 2 of k / spacing_hz,
    and the sample nearest each k / spacing_hz."""
    index = np.arange(n)
    quefrency = np.minimum(index, n - index) / fs
    last = int(np.floor(n / 2 / fs * spacing_hz))
    count = last if rahmonics is None else min(rahmonics, last)
    if count < 1:
        raise InputError(
            f"spacing_hz must be >= 2 fs / N = {2 * fs / n:.4g} Hz for a rahmonic inside the record, "
            f"got {spacing_hz!r}"
        )
    nearest = np.clip(np.rint(quefrency * spacing_hz), 1, count)
    mask = np.abs(quefrency - nearest / spacing_hz) <= width_s / 2 + 1e-12 / fs
    centres = np.rint(np.arange(1, count + 1) * fs / spacing_hz).astype(int)  # always the nearest sample
    mask[centres] = True
    mask[n - centres] = True
    return mask


def lifter_family(
    signal: ArrayLike,
    sample_rate_hz: float,
    spacing_hz: float,
    *,
    rahmonics: int | None = None,
    width_s: float | None = None,
    keep: bool = False,
) -> NDArray[np.float64]:
    """The signal with the line family spaced by ``spacing_hz`` removed (or, ``keep=True``, kept alone)
    by editing its real cepstrum with a comb lifter and rebuilding with the original phase.

    Args:
        signal: samples in any unit.
        sample_rate_hz: sample rate [Hz].
        spacing_hz: spacing of the family's lines [Hz] (shaft rate for sidebands or shaft harmonics).
        rahmonics: notches at k / spacing_hz for k = 1 .. rahmonics (None: all up to N / 2 / fs).
        width_s: total notch width [s] around each rahmonic, at least its nearest sample (None: 3 / fs).
        keep: False zeroes the notches; True zeroes everything else but c(0) (the overall level): the
            family's lines stand alone on a flat floor at their positions and in their order of
            height, but with heights scaled in ln |X| (amplitudes are not kept).
    """
    x = _signal(signal)
    fs = positive_frequency("sample_rate_hz", sample_rate_hz)
    spacing = positive_frequency("spacing_hz", spacing_hz)
    if rahmonics is not None:
        rahmonics = integer_at_least("rahmonics", rahmonics, 1)
    width = 3.0 / fs if width_s is None else width_s
    if not (is_real(width) and 0.0 <= width < 1.0 / spacing):
        raise InputError(f"width_s must be in [0, 1 / spacing_hz = {1.0 / spacing:.4g}) s, got {width_s!r}")
    spectrum, log_magnitude = _log_spectrum(x)
    c = sfft.irfft(log_magnitude, x.size)
    mask = _comb_mask(x.size, fs, spacing, rahmonics, float(width))
    if keep:
        mask[0] = True
        c[~mask] = 0.0
    else:
        c[mask] = 0.0
    edited = np.exp(sfft.rfft(c).real)
    return sfft.irfft(edited * np.exp(1j * np.angle(spectrum)), x.size)


def _averaged_log_magnitude(x: NDArray[np.float64], nperseg: int) -> NDArray[np.float64]:
    """ln of the RMS-averaged magnitude of Hann-windowed segments (hop nperseg // 2), floored."""
    frames = sliding_window_view(x - np.mean(x), nperseg)[:: nperseg // 2]
    window = periodic_window("hann", nperseg)
    power = np.zeros(nperseg // 2 + 1)
    step = max(1, (1 << 22) // nperseg)
    for start in range(0, frames.shape[0], step):
        spectrum = sfft.rfft(frames[start : start + step] * window, axis=1)
        power += (spectrum.real**2 + spectrum.imag**2).sum(axis=0)
    top = float(np.max(power))
    if top == 0.0:
        raise InputError("signal is constant: its cepstrum is undefined")
    return 0.5 * np.log(np.maximum(power, (LOG_FLOOR**2) * top))


def cepstral_peak(
    signal: ArrayLike,
    sample_rate_hz: float,
    spacing_hz: float,
    *,
    nperseg: int | None = None,
    search_s: float | None = None,
) -> CepstralPeak:
    """The first rahmonic (q = 1 / spacing_hz) of a family of lines spaced by ``spacing_hz``: largest
    |c(q)| within ``search_s`` [s] of q (None: +- max(2 / fs, 0.02 q)), with the median |c| around it.

    The cepstrum is taken of the segment-averaged spectrum (Hann segments of ``nperseg`` samples, half
    overlapping; None: the power of two >= 8 fs / spacing_hz, at most N), so that the log spectrum's
    scatter over a long noisy record, which buries a family of few lines, averages down.
    """
    x = _signal(signal)
    fs = positive_frequency("sample_rate_hz", sample_rate_hz)
    spacing = positive_frequency("spacing_hz", spacing_hz)
    q = 1.0 / spacing
    if nperseg is None:
        nperseg = min(x.size, 1 << int(np.ceil(np.log2(8.0 * fs / spacing))))
    nperseg = integer_at_least("nperseg", nperseg, 8)
    if nperseg > x.size or q > nperseg / 2 / fs:
        raise InputError(
            f"nperseg must be <= N = {x.size} and hold the rahmonic 1 / spacing_hz = {q:.4g} s in its half "
            f"(nperseg >= {2 * q * fs:.0f}; spacing_hz >= {2 * fs / x.size:.4g} Hz), got {nperseg}"
        )
    half = max(2.0 / fs, 0.02 * q) if search_s is None else search_s
    if not (is_real(half) and 0.0 <= half < q / 2):
        raise InputError(
            f"search_s must be in [0, {q / 2:.4g}) s (half a rahmonic spacing), got {search_s!r}"
        )
    magnitude = np.abs(sfft.irfft(_averaged_log_magnitude(x, nperseg), nperseg)[: nperseg // 2 + 1])
    quefrency = np.arange(magnitude.size) / fs
    near = np.flatnonzero(np.abs(quefrency - q) <= half + 0.5 / fs)
    best = near[np.argmax(magnitude[near])]
    around = (quefrency >= 0.5 * q) & (quefrency <= 1.5 * q)
    return CepstralPeak(
        float(quefrency[best]), float(magnitude[best]), float(np.median(magnitude[around])), nperseg
    )
