"""Single-sided amplitude spectra and mesh-harmonic helpers (as the paper's Figs. 13-16 and 20).

Engine-free: works on any uniformly sampled 1-D signal, simulated or measured.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError

__all__ = [
    "Peak",
    "SidebandLine",
    "Spectrum",
    "amplitude_spectrum",
    "mesh_harmonics",
    "peak_at",
    "peak_near",
    "sideband_lines",
]


@dataclass(frozen=True)
class Spectrum:
    """Single-sided amplitude spectrum.

    ``amplitude`` is in the units of the analysed signal (peak amplitude, not RMS, not a density).
    """

    frequency_hz: NDArray[np.float64]
    """Bin frequencies 0 .. sample_rate_hz / 2 [Hz]."""
    amplitude: NDArray[np.float64]
    """Peak amplitude per bin [signal units]."""
    sample_rate_hz: float
    """Sample rate of the analysed signal [Hz]."""
    window: str
    """Window name passed to scipy.signal.get_window."""
    n_samples: int
    """Number of samples analysed."""

    @property
    def resolution_hz(self) -> float:
        """Bin spacing sample_rate_hz / n_samples [Hz]."""
        return self.sample_rate_hz / self.n_samples


def periodic_window(window: str | tuple, n: int) -> np.ndarray:
    """``scipy.signal.get_window(window, n, fftbins=True)``; "hann" and "boxcar" computed here with
    scipy's own operations (bitwise the same window), so that a spectrum needs no scipy.signal import."""
    if window == "boxcar":
        return np.ones(n)
    if window == "hann":
        if n <= 1:
            return np.ones(n)
        fac = np.linspace(-np.pi, np.pi, n + 1)  # scipy: general_cosine(n + 1, [0.5, 0.5]) truncated
        w = np.zeros(n + 1)
        for k, a in enumerate((0.5, 0.5)):
            w += a * np.cos(k * fac)
        return w[:-1]
    from scipy.signal import get_window

    return get_window(window, n, fftbins=True)


def amplitude_spectrum(
    signal: ArrayLike,
    sample_rate_hz: float,
    window: str | tuple = "hann",
    detrend: bool | Literal["constant", "linear"] = True,
) -> Spectrum:
    """Windowed single-sided amplitude spectrum of a uniformly sampled signal.

    Scaling: with window w[n] (periodic, from scipy.signal.get_window) and X = rfft(x * w),
    ``amplitude = 2 |X| / sum(w)`` (the DC bin and, for even N, the Nyquist bin are not doubled).
    Dividing by sum(w) = N * coherent gain corrects the window's coherent gain, so a sine
    A sin(2 pi f t) with f exactly on a bin shows amplitude A. Off-bin the peak bin reads lower by the
    window's scalloping loss (Hann: at most 1.42 dB, i.e. >= 0.849 A at half a bin), and the energy
    spreads over neighbouring bins. A constant C shows as C in the DC bin (with detrend=False).

    Args:
        signal: samples in any unit (m/s^2, N, K_d, ...).
        sample_rate_hz: sample rate [Hz].
        window: window for scipy.signal.get_window ("hann", "boxcar", ("kaiser", 8), ...).
        detrend: True or "constant" removes the mean, "linear" removes a least-squares line, False none.
    """
    x = np.asarray(signal, dtype=float)
    if x.ndim != 1 or x.size < 2:
        raise InputError(f"signal must be 1-D with at least 2 samples, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise InputError("signal contains non-finite samples")
    if not sample_rate_hz > 0:
        raise InputError(f"sample_rate_hz must be positive, got {sample_rate_hz!r}")
    if detrend is True:
        detrend = "constant"
    if detrend:
        if detrend not in ("constant", "linear"):
            raise InputError(f"detrend must be a bool, 'constant' or 'linear', got {detrend!r}")
        if detrend == "constant":  # what scipy.signal.detrend does, without its ~0.6 s import
            x = x - np.mean(x, axis=-1, keepdims=True)
        else:
            from scipy.signal import detrend as _detrend

            x = _detrend(x, type=detrend)
    n = x.size
    w = periodic_window(window, n)
    spectrum = np.abs(np.fft.rfft(x * w)) / np.sum(w)
    spectrum[1:] *= 2.0
    if n % 2 == 0:
        spectrum[-1] /= 2.0
    return Spectrum(
        frequency_hz=np.fft.rfftfreq(n, d=1.0 / sample_rate_hz),
        amplitude=spectrum,
        sample_rate_hz=float(sample_rate_hz),
        window=str(window),
        n_samples=int(n),
    )


def mesh_harmonics(mesh_frequency_hz: float, fmax_hz: float) -> NDArray[np.float64]:
    """Mesh frequency harmonics k * f_z [Hz] for k = 1, 2, ... with k * f_z <= fmax_hz."""
    if not mesh_frequency_hz > 0:
        raise InputError(f"mesh_frequency_hz must be positive, got {mesh_frequency_hz!r}")
    count = int(np.floor(fmax_hz / mesh_frequency_hz * (1.0 + 1e-12))) if fmax_hz > 0 else 0
    return mesh_frequency_hz * np.arange(1, count + 1, dtype=float)


@dataclass(frozen=True)
class Peak:
    """Largest spectrum bin near a frequency."""

    frequency_hz: float
    """Frequency of the largest bin [Hz]."""
    amplitude: float
    """Its amplitude [signal units]."""


def peak_near(spectrum: Spectrum, f_hz: float, tol_hz: float) -> Peak:
    """Largest bin with |frequency - f_hz| <= tol_hz; raises ValueError if no bin lies in that band."""
    inside = np.abs(spectrum.frequency_hz - f_hz) <= tol_hz
    if not np.any(inside):
        raise InputError(
            f"no spectrum bin within {tol_hz} Hz of {f_hz} Hz (resolution {spectrum.resolution_hz:.4g} Hz)"
        )
    candidates = np.flatnonzero(inside)
    best = candidates[np.argmax(spectrum.amplitude[candidates])]
    return Peak(frequency_hz=float(spectrum.frequency_hz[best]), amplitude=float(spectrum.amplitude[best]))


def peak_at(spectrum: Spectrum, f_hz: float, tol_hz: float) -> float:
    """Largest amplitude [signal units] among bins within tol_hz [Hz] of f_hz [Hz]."""
    return peak_near(spectrum, f_hz, tol_hz).amplitude


@dataclass(frozen=True)
class SidebandLine:
    """A line of the family k f_c + n f_m (carrier harmonic k, sideband order n) found in a spectrum."""

    label: str
    """E.g. "f_z1+2f_z2"."""
    expected_hz: float
    """Where kinematics puts it, k f_c + n f_m [Hz]."""
    found_hz: float
    """Frequency of the local maximum next to it [Hz]."""
    amplitude: float
    """Its amplitude [signal units]."""
    floor: float
    """Median amplitude of the band +- half a spacing around it [signal units]."""
    is_peak: bool
    """The found bin is a local maximum (higher than both neighbours)."""

    @property
    def prominence_db(self) -> float:
        """Amplitude over the local floor, dB."""
        return float(20.0 * np.log10(self.amplitude / self.floor)) if self.floor > 0 else float("inf")


def sideband_lines(
    spectrum: Spectrum,
    carrier_hz: float,
    modulation_hz: float,
    carrier_orders: tuple[int, ...] = (1, 2, 3),
    sideband_orders: tuple[int, ...] = (-2, -1, 1, 2),
    search_bins: int = 2,
    carrier_symbol: str = "f_z1",
    modulation_symbol: str = "f_z2",
) -> list[SidebandLine]:
    """Lines at k f_c + n f_m, e.g. the first stage's mesh harmonics modulated by the second stage's
    mesh frequency (the paper's Fig. 20).

    Each line is the largest bin within ``search_bins`` bins of k f_c + n f_m; its floor is the median
    amplitude over +- f_m / 2 around it, so a line is visible when ``prominence_db`` is well above 0.
    """
    if not (carrier_hz > 0 and modulation_hz > 0):
        raise InputError(f"carrier_hz and modulation_hz must be positive, got {carrier_hz}, {modulation_hz}")
    f, a = spectrum.frequency_hz, spectrum.amplitude
    df = spectrum.resolution_hz
    out = []
    for k in carrier_orders:
        for n in sideband_orders:
            target = k * carrier_hz + n * modulation_hz
            if not 0 < target < f[-1]:
                continue
            centre = int(round(target / df))
            lo, hi = max(centre - search_bins, 1), min(centre + search_bins, f.size - 2)
            best = lo + int(np.argmax(a[lo : hi + 1]))
            band = np.abs(f - target) <= 0.5 * modulation_hz
            carrier = f"{k if k > 1 else ''}{carrier_symbol}"
            order = f"{abs(n) if abs(n) > 1 else ''}{modulation_symbol}"
            side = "" if n == 0 else ("+" if n > 0 else "-") + order
            out.append(
                SidebandLine(
                    label=carrier + side,
                    expected_hz=float(target),
                    found_hz=float(f[best]),
                    amplitude=float(a[best]),
                    floor=float(np.median(a[band])),
                    is_peak=bool(a[best] > a[best - 1] and a[best] > a[best + 1]),
                )
            )
    return out
