"""Tacholess shaft speed and angle from a tracked harmonic of the vibration (e.g. a gear mesh harmonic,
order = number of teeth).

Engine-free: a signal sampled uniformly in time in, a frozen dataclass out. Two steps:

1. Ridge: the harmonic's frequency is tracked in a short-time Fourier transform (Hann frames, 75 %
   overlap), as the largest bin of each frame inside a search band (a fixed ``band_hz``, or a band
   ``order x speed_guess_hz x (1 +- search_fraction)`` that follows the guess), refined by a parabola
   through the log magnitudes and median-filtered over 5 frames.
2. Phase demodulation: the signal is multiplied by exp(-i phi_ridge(t)) (phi_ridge the integral of the
   ridge), low-passed (zero-phase Butterworth, ``lowpass_hz``), and the residual phase is unwrapped. The
   harmonic's phase is phi_ridge + residual; divided by the order it is the shaft angle, its derivative
   the speed. The ridge need only be right to within the low-pass band: the demodulation corrects it.

Accuracy limits: the angle is relative (it starts at 0; the harmonic's own phase is unknown). Speed
fluctuations faster than ``lowpass_hz`` are not followed. Any other component inside +- lowpass_hz of
the harmonic (neighbouring orders of the same shaft sit one shaft frequency away, hence the default
lowpass of 0.4 x the lowest shaft speed) and noise there bias the phase: a component of relative
amplitude r shifts it by up to r rad, i.e. r / order rad of shaft angle. The first and last ~ 1 /
lowpass_hz seconds carry the filter's edge transients; the ridge search fails where another line in the
band is stronger than the harmonic.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ._validate import is_real, positive_frequency

__all__ = ["TacholessSpeed", "tacholess_angle"]

_TWO_PI = 2.0 * np.pi
_LOWPASS_FRACTION = 0.4
"""Default lowpass_hz: 0.4 x the lowest shaft speed of the search band."""
_FRAME_CYCLES = 4.0
"""Default STFT frame: 4 periods of the lowest shaft speed (bins <= 1/4 of the order spacing)."""
_BUTTER_ORDER = 8


def _positive(name: str, value: float, unit: str) -> float:
    if not (is_real(value) and math.isfinite(value) and value > 0):
        raise InputError(f"{name} must be a positive number [{unit}], got {value!r}")
    return float(value)


@dataclass(frozen=True)
class TacholessSpeed:
    """Shaft angle and speed estimated from one harmonic of the signal."""

    time_s: NDArray[np.float64]
    """Sample instants [s]."""
    angle_rad: NDArray[np.float64]
    """Unwrapped shaft angle, 0 at the first sample [rad]."""
    speed_hz: NDArray[np.float64]
    """Shaft speed [Hz = rev/s]."""
    harmonic_amplitude: NDArray[np.float64]
    """Peak amplitude of the tracked harmonic (after the low-pass) [signal units]: low values flag
    where the estimate is unreliable."""
    ridge_time_s: NDArray[np.float64]
    """Centres of the STFT frames [s]."""
    ridge_hz: NDArray[np.float64]
    """The harmonic's frequency found in each frame [Hz]."""
    order: float
    """Order of the tracked harmonic [cycles/rev]."""


def _search_band(
    n_frames_t: NDArray, order: float, speed_guess_hz, band_hz, search_fraction: float, n: int, fs: float
) -> tuple[NDArray, NDArray, float]:
    """Lower and upper frequency [Hz] of the ridge search per frame, and the lowest shaft speed [Hz]."""
    if (speed_guess_hz is None) == (band_hz is None):
        raise InputError("give exactly one of speed_guess_hz and band_hz, got both or neither")
    if band_hz is not None:
        band = np.asarray(band_hz, dtype=float).reshape(-1)
        lo, hi = (float(band[0]), float(band[1])) if band.size == 2 else (0.0, 0.0)
        if not (0 < lo < hi <= 0.5 * fs):
            raise InputError(
                f"band_hz must be (f_lo, f_hi) with 0 < f_lo < f_hi <= {0.5 * fs:g} Hz, got {band_hz!r}"
            )
        ones = np.ones_like(n_frames_t)
        return lo * ones, hi * ones, lo / order
    if not (is_real(search_fraction) and 0 < search_fraction < 1):
        raise InputError(f"search_fraction must be in (0, 1), got {search_fraction!r}")
    guess = np.asarray(speed_guess_hz, dtype=float)
    if guess.ndim == 0:
        guess = np.full(n, float(guess))
    if guess.shape != (n,) or not np.all(np.isfinite(guess)) or np.any(guess <= 0):
        raise InputError(
            f"speed_guess_hz must be a positive speed [Hz] or {n} of them (one per sample), got "
            f"shape {guess.shape}, range {np.min(guess):.6g} .. {np.max(guess):.6g}"
        )
    at_frames = np.interp(n_frames_t, np.arange(n) / fs, guess)
    lo = order * at_frames * (1.0 - search_fraction)
    hi = np.minimum(order * at_frames * (1.0 + search_fraction), 0.5 * fs)
    return lo, hi, float(np.min(guess)) * (1.0 - search_fraction)


def _ridge(magnitude: NDArray, f_hz: NDArray, lo: NDArray, hi: NDArray) -> NDArray[np.float64]:
    """Per frame: the largest bin inside [lo, hi], refined by a parabola through log magnitudes."""
    from scipy.ndimage import median_filter

    inside = (f_hz[:, None] >= lo[None, :]) & (f_hz[:, None] <= hi[None, :])
    if not np.all(inside.any(axis=0)):
        raise InputError(
            "the ridge search band holds no STFT bin in some frame: widen band_hz / search_fraction"
        )
    log_mag = np.log(magnitude + 1e-300)
    peak = np.argmax(np.where(inside, log_mag, -np.inf), axis=0)
    peak = np.clip(peak, 1, f_hz.size - 2)
    cols = np.arange(peak.size)
    left, mid, right = log_mag[peak - 1, cols], log_mag[peak, cols], log_mag[peak + 1, cols]
    curvature = left - 2.0 * mid + right
    offset = np.where(curvature < 0, 0.5 * (left - right) / np.where(curvature < 0, curvature, -1.0), 0.0)
    ridge = f_hz[peak] + np.clip(offset, -0.5, 0.5) * (f_hz[1] - f_hz[0])
    return median_filter(ridge, size=5, mode="nearest")


def tacholess_angle(
    signal: ArrayLike,
    sample_rate_hz: float,
    order: float,
    *,
    speed_guess_hz: float | ArrayLike | None = None,
    band_hz: tuple[float, float] | None = None,
    search_fraction: float = 0.2,
    lowpass_hz: float | None = None,
    frame_s: float | None = None,
    t0_s: float = 0.0,
) -> TacholessSpeed:
    """Shaft angle and speed from the harmonic of order ``order`` (see the module docstring).

    Args:
        signal: samples at uniform time steps [any unit].
        sample_rate_hz: sample rate [Hz].
        order: order of the tracked harmonic [cycles/rev], e.g. the number of teeth for the mesh.
        speed_guess_hz: rough shaft speed [Hz], one value or one per sample; the ridge is searched
            within order x guess x (1 +- search_fraction). Exclusive with band_hz.
        band_hz: fixed search band (f_lo, f_hi) of the harmonic's frequency [Hz].
        search_fraction: relative half-width of the band around the guess (0 < . < 1).
        lowpass_hz: low-pass of the demodulation [Hz]; None: 0.4 x the lowest shaft speed of the band.
        frame_s: STFT frame length [s]; None: 4 periods of the lowest shaft speed of the band.
        t0_s: time of the first sample [s].
    """
    x = np.asarray(signal, dtype=float)
    if x.ndim != 1 or x.size < 16 or not np.all(np.isfinite(x)):
        raise InputError(f"signal must be 1-D, finite, with at least 16 samples, got shape {x.shape}")
    fs = positive_frequency("sample_rate_hz", sample_rate_hz)
    order = _positive("order", order, "cycles/rev")
    if not (is_real(t0_s) and math.isfinite(t0_s)):
        raise InputError(f"t0_s must be a finite time [s], got {t0_s!r}")
    from scipy.signal import butter, sosfiltfilt, stft

    _, _, f_low = _search_band(np.zeros(1), order, speed_guess_hz, band_hz, search_fraction, x.size, fs)
    frame_s = _FRAME_CYCLES / f_low if frame_s is None else _positive("frame_s", frame_s, "s")
    nperseg = int(min(max(16, 2 ** round(math.log2(frame_s * fs))), x.size))
    f_hz, frame_t, spectrum = stft(x, fs, window="hann", nperseg=nperseg, noverlap=3 * nperseg // 4)
    lo, hi, _ = _search_band(frame_t, order, speed_guess_hz, band_hz, search_fraction, x.size, fs)
    ridge_hz = _ridge(np.abs(spectrum), f_hz, lo, hi)
    del spectrum
    lowpass_hz = (
        _LOWPASS_FRACTION * f_low if lowpass_hz is None else positive_frequency("lowpass_hz", lowpass_hz)
    )
    if lowpass_hz >= 0.5 * fs:
        raise InputError(
            f"lowpass_hz must be below the Nyquist frequency {0.5 * fs:g} Hz, got {lowpass_hz!r}"
        )
    time_s = np.arange(x.size) / fs
    ridge_at = np.interp(time_s, frame_t, ridge_hz)
    ridge_phase = _TWO_PI / fs * (np.cumsum(ridge_at) - 0.5 * (ridge_at + ridge_at[0]))  # trapezoid
    sos = butter(_BUTTER_ORDER, lowpass_hz, fs=fs, output="sos")
    base = sosfiltfilt(sos, x * np.exp(-1j * ridge_phase))
    residual = np.unwrap(np.angle(base))
    phase = ridge_phase + residual
    speed_hz = (ridge_at + np.gradient(residual) * (fs / _TWO_PI)) / order
    return TacholessSpeed(
        time_s=t0_s + time_s,
        angle_rad=(phase - phase[0]) / order,
        speed_hz=speed_hz,
        harmonic_amplitude=2.0 * np.abs(base),
        ridge_time_s=t0_s + frame_t,
        ridge_hz=ridge_hz,
        order=float(order),
    )
