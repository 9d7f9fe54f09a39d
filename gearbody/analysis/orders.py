"""Computed order tracking (COT): a time signal resampled on a uniform shaft-angle grid, its order
spectrum, the rpm-order map of a run-up and the amplitude of one order versus speed.

Engine-free: plain numpy arrays in (a signal sampled uniformly in time and the unwrapped shaft angle at
the same instants, simulated, from a tacho via :mod:`gearbody.analysis.tacho` or tacholess), frozen
dataclasses out. Orders are cycles per shaft revolution; speeds are shaft rotation frequencies [Hz =
rev/s] (and rpm).

Resampling (:func:`order_track`): the signal is upsampled by ``upsample`` with a zero-phase
(linear-phase, delay-compensated) Kaiser FIR low-pass, and the upsampled series is interpolated with a
quintic B-spline at the instants where the shaft reaches each grid angle (those instants from the
angle by linear interpolation between samples). The same FIR is the anti-aliasing filter: it passes
``max_order`` at the highest speed of the record and stops everything above samples_per_rev / 2 orders
at the lowest speed (and the images of the upsampling), so nothing can alias into the angle grid.
Long signals are processed in overlapping chunks of 2**18 input samples (the filtering's working memory
is that of a chunk; the result holds 3 arrays of revolutions x samples_per_rev points). 3e6 samples at
50 kHz over a 10 -> 40 rev/s run-up: 1.3 s with the defaults (1.2e7 points), 0.4 s with max_order=100
(benchmarks/bench_order_track.py, two busy cores).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ._validate import finite_1d, integer_at_least, is_real, positive_frequency, strictly_increasing_angle

__all__ = [
    "MAX_DEFAULT_SAMPLES_PER_REV",
    "OrderTrackedSignal",
    "order_track",
]

MAX_DEFAULT_SAMPLES_PER_REV: int = 2**16
"""Cap of the default angle grid [samples per revolution]; a wider speed range needs ``max_order``
lowered (done for the default) or the record split."""

_TWO_PI = 2.0 * np.pi
_PASS_FRACTION = 0.8
"""Default max_order: the order at 80 % of the Nyquist frequency at the highest speed (the rest is the
filter's transition band)."""
_GRID_MARGIN = 1.25
"""Default grid: samples_per_rev / 2 >= 1.25 max_order f_max / f_min (the anti-aliasing filter's
transition band, 1 .. 1.25 max_order at the top speed)."""
_MAX_PASS_TO_STOP = 0.9
"""Narrowest accepted transition band: pass-band edge <= 0.9 x stop-band edge."""
_STOPBAND_DB = 80.0
"""Stop-band attenuation of the anti-aliasing FIR [dB]; its pass band is flat to 1e-4."""
_CHUNK_SAMPLES = 2**18
"""Input samples per chunk of the resampling."""
_SPLINE_MARGIN = 32
"""Upsampled samples beyond the filter margin for the B-spline prefilter to settle (its poles <= 0.43)."""


def _positive(name: str, value: float | None, unit: str) -> float | None:
    if value is None:
        return None
    if not (is_real(value) and math.isfinite(value) and value > 0):
        raise InputError(f"{name} must be a positive number [{unit}] or None, got {value!r}")
    return float(value)


@dataclass(frozen=True)
class OrderTrackedSignal:
    """A signal on a uniform shaft-angle grid: point j is at angle start_rad + j step_rad."""

    values: NDArray[np.float64]
    """Resampled signal [signal units]."""
    start_rad: float
    """Shaft angle of the first point, a multiple of step_rad (the first grid angle inside the data) [rad]."""
    samples_per_rev: int
    """Grid points per revolution (orders up to samples_per_rev / 2 are representable)."""
    time_s: NDArray[np.float64]
    """Instant at which the shaft reaches each grid angle [s]."""
    speed_hz: NDArray[np.float64]
    """Shaft speed at each grid angle [Hz = rev/s]."""
    max_order: float
    """Highest order passed flat (within 1e-4) at every speed of the record [cycles/rev]."""

    @property
    def step_rad(self) -> float:
        """Grid step 2 pi / samples_per_rev [rad]."""
        return _TWO_PI / self.samples_per_rev

    @property
    def angle_rad(self) -> NDArray[np.float64]:
        """Shaft angle of every point [rad]."""
        return self.start_rad + self.step_rad * np.arange(self.values.size)

    @property
    def revolutions(self) -> float:
        """Record length, number of points / samples_per_rev [rev]."""
        return self.values.size / self.samples_per_rev

    @property
    def speed_rpm(self) -> NDArray[np.float64]:
        """Shaft speed at each grid angle [rpm]."""
        return 60.0 * self.speed_hz


def _check_angle(angle: NDArray[np.float64], n: int) -> None:
    if angle.size != n:
        raise InputError(f"signal and shaft_angle_rad must have equal lengths, got {n} and {angle.size}")
    strictly_increasing_angle(angle)


def _grid_and_band(
    fs: float, f_min: float, f_max: float, samples_per_rev: int | None, max_order: float | None
) -> tuple[int, float, float]:
    """samples_per_rev, max_order (given, or the defaults, see order_track) and the stop-band edge [Hz]."""
    nyquist_order = 0.5 * fs / f_max
    if max_order is not None and max_order > _PASS_FRACTION * nyquist_order:
        raise InputError(
            f"max_order must be <= {_PASS_FRACTION} x the Nyquist order at the highest speed, "
            f"{_PASS_FRACTION * nyquist_order:.6g} (0.5 x {fs:.6g} Hz / {f_max:.6g} rev/s), got {max_order!r}"
        )
    if samples_per_rev is None:
        order = _PASS_FRACTION * nyquist_order if max_order is None else max_order
        need = 2.0 * _GRID_MARGIN * order * f_max / f_min
        samples_per_rev = 1 << max(3, math.ceil(math.log2(need)))
        if samples_per_rev > MAX_DEFAULT_SAMPLES_PER_REV:
            if max_order is not None:
                raise InputError(
                    f"max_order={max_order!r} over speeds {f_min:.6g} .. {f_max:.6g} rev/s needs "
                    f"samples_per_rev >= {need:.0f}, over the default cap {MAX_DEFAULT_SAMPLES_PER_REV}: "
                    "give samples_per_rev, lower max_order or split the record"
                )
            samples_per_rev = MAX_DEFAULT_SAMPLES_PER_REV
    samples_per_rev = integer_at_least("samples_per_rev", samples_per_rev, 8)
    stop_hz = min(0.5 * samples_per_rev * f_min, fs - _PASS_FRACTION * 0.5 * fs)
    if max_order is None:
        max_order = min(_PASS_FRACTION * nyquist_order, stop_hz / (_GRID_MARGIN * f_max))
    elif max_order * f_max > _MAX_PASS_TO_STOP * stop_hz:
        raise InputError(
            f"samples_per_rev={samples_per_rev} is too small for max_order={max_order!r} over speeds "
            f"{f_min:.6g} .. {f_max:.6g} rev/s: the anti-aliasing filter must pass "
            f"{max_order * f_max:.6g} Hz and stop {stop_hz:.6g} Hz; need samples_per_rev >= "
            f"{2 * max_order * f_max / (_MAX_PASS_TO_STOP * f_min):.0f}"
        )
    return samples_per_rev, float(max_order), stop_hz


def _antialias_taps(fs: float, upsample: int, pass_hz: float, stop_hz: float) -> NDArray[np.float64]:
    """Odd-length linear-phase Kaiser low-pass at upsample x fs, unit DC gain."""
    from scipy.signal import firwin, kaiserord

    rate = upsample * fs
    numtaps, beta = kaiserord(_STOPBAND_DB, (stop_hz - pass_hz) / (0.5 * rate))
    numtaps |= 1
    return firwin(numtaps, 0.5 * (pass_hz + stop_hz), window=("kaiser", beta), fs=rate)


def _odd_extension(x: NDArray[np.float64], margin: int) -> NDArray[np.float64]:
    """x extended by point reflection about its end samples (keeps value and slope continuous)."""
    m = min(margin, x.size - 1)
    head = 2.0 * x[0] - x[m:0:-1]
    tail = 2.0 * x[-1] - x[-2 : -m - 2 : -1]
    pad_head = np.full(margin - m, head[0]) if margin > m else head[:0]
    pad_tail = np.full(margin - m, tail[-1]) if margin > m else tail[:0]
    return np.concatenate([pad_head, head, x, tail, pad_tail])


def _upsampled(piece: NDArray[np.float64], taps: NDArray[np.float64], upsample: int) -> NDArray[np.float64]:
    """``scipy.signal.resample_poly(piece, upsample, 1, window=taps)`` (zero-phase: sample j at input
    position j / upsample), by FFT convolution: its cost does not grow with the number of taps."""
    from scipy.signal import oaconvolve

    stuffed = np.zeros(piece.size * upsample)
    stuffed[::upsample] = piece * upsample
    return oaconvolve(stuffed, taps, mode="same")


def _resample_chunks(
    x: NDArray[np.float64], fs: float, angle: NDArray[np.float64], step: float, taps: NDArray, upsample: int
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], int]:
    """At the grid angles k step inside the data: the values, the instants [s, from the first sample]
    and the speed [rev/s, linear between the mid-sample speeds]; and the first k."""
    from scipy import ndimage

    n = x.size
    margin = (taps.size // 2) // upsample + _SPLINE_MARGIN
    padded = _odd_extension(x, margin)
    speed = np.diff(angle) * (fs / _TWO_PI)  # between samples i and i + 1, at i + 1/2
    k_first, k_last = math.ceil(angle[0] / step), math.floor(angle[-1] / step)
    values = np.empty(max(k_last - k_first + 1, 0))
    time_s, speed_hz = np.empty_like(values), np.empty_like(values)
    for a in range(0, n - 1, _CHUNK_SAMPLES):
        b = min(a + _CHUNK_SAMPLES, n - 1)
        # grid angles in [angle[a], angle[b]) (the last chunk includes angle[n - 1])
        k0 = max(math.ceil(angle[a] / step), k_first)
        k1 = k_last + 1 if b == n - 1 else math.ceil(angle[b] / step)
        if k1 <= k0:
            continue
        out = slice(k0 - k_first, k1 - k_first)
        # position in the upsampled piece, which starts at input sample a - margin
        samples = np.arange(margin * upsample, (b - a + margin) * upsample + 1, upsample, dtype=float)
        where = np.interp(np.arange(k0, k1, dtype=float) * step, angle[a : b + 1], samples)
        up = _upsampled(padded[a : b + 1 + 2 * margin], taps, upsample)
        coefficients = ndimage.spline_filter1d(up, order=5, mode="mirror")
        values[out] = ndimage.map_coordinates(coefficients, [where], order=5, mode="mirror", prefilter=False)
        speed_hz[out] = np.interp(where, samples[:-1] + 0.5 * upsample, speed[a:b])
        time_s[out] = where * (1.0 / (upsample * fs)) + (a - margin) / fs
    return values, time_s, speed_hz, k_first


def order_track(
    signal: ArrayLike,
    sample_rate_hz: float,
    shaft_angle_rad: ArrayLike,
    *,
    samples_per_rev: int | None = None,
    max_order: float | None = None,
    upsample: int = 4,
    t0_s: float = 0.0,
) -> OrderTrackedSignal:
    """Resample a time signal onto a uniform shaft-angle grid (computed order tracking).

    The grid is the multiples of 2 pi / samples_per_rev inside the data. Anti-aliasing: a zero-phase FIR
    (Kaiser, 80 dB) passes up to max_order x the highest speed f_max and stops from samples_per_rev / 2 x
    the lowest speed f_min (or, if lower, from the first image of the upsampling): no order above
    samples_per_rev / 2 aliases, at any speed of the record, and every order <= max_order passes flat
    (1e-4) at every speed. The speeds come from the angle's increments between samples.

    Defaults: max_order = 0.8 x the Nyquist order at the highest speed, 0.4 fs / f_max; samples_per_rev =
    the power of two >= 2 x 1.25 max_order f_max / f_min (the speed ratio widens the grid so the filter
    can pass max_order at f_max and stop samples_per_rev / 2 at f_min), capped at
    MAX_DEFAULT_SAMPLES_PER_REV (then max_order is lowered to fit).

    Accuracy: the FIR's pass band ripple (1e-4), the quintic B-spline on the upsampled series (< 1e-5
    relative at 0.4 fs with upsample=4) and the linear interpolation of the grid instants between angle
    samples (time error ~ angle'' dt^2 / (8 angle')). The first and last ~ numtaps / (2 upsample) input
    samples lean on a point-reflected extension of the record (edge error).

    Args:
        signal: samples at uniform time steps [any unit].
        sample_rate_hz: sample rate [Hz].
        shaft_angle_rad: unwrapped, strictly increasing shaft angle at the same instants [rad].
        samples_per_rev: grid points per revolution (>= 8), or None for the default.
        max_order: highest order to pass flat [cycles/rev], or None for the default.
        upsample: upsampling factor before the interpolation (>= 2).
        t0_s: time of the first sample [s].
    """
    x = finite_1d("signal", signal, 4)
    fs = positive_frequency("sample_rate_hz", sample_rate_hz)
    angle = finite_1d("shaft_angle_rad", shaft_angle_rad, 4)
    _check_angle(angle, x.size)
    max_order = _positive("max_order", max_order, "cycles/rev")
    upsample = integer_at_least("upsample", upsample, 2)
    if not (is_real(t0_s) and math.isfinite(t0_s)):
        raise InputError(f"t0_s must be a finite time [s], got {t0_s!r}")
    increments = np.diff(angle) * (fs / _TWO_PI)  # speed between samples [rev/s]
    f_min, f_max = float(increments.min()), float(increments.max())
    samples_per_rev, max_order, stop_hz = _grid_and_band(fs, f_min, f_max, samples_per_rev, max_order)
    taps = _antialias_taps(fs, upsample, max_order * f_max, stop_hz)
    step = _TWO_PI / samples_per_rev
    values, time_s, speed_hz, k_first = _resample_chunks(x, fs, angle, step, taps, upsample)
    if values.size < 2:
        raise InputError(f"shaft_angle_rad spans < 2 grid points (samples_per_rev={samples_per_rev})")
    if t0_s != 0.0:
        time_s += t0_s
    return OrderTrackedSignal(
        values=values,
        start_rad=k_first * step,
        samples_per_rev=samples_per_rev,
        time_s=time_s,
        speed_hz=speed_hz,
        max_order=max_order,
    )
