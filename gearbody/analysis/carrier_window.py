"""The analysis window of a ring-fixed sensor: whole carrier revolutions relative to the ring, and the
spectrum over them in carrier orders (computed order tracking), read in hertz. Engine-free.

Every kinematic line of a planetary stage seen from the ring, k f_m + q f_c (f_m = Z_r f_c), is a
whole carrier order. Over n whole revolutions of the carrier relative to the ring, resampled onto a
uniform carrier-angle grid, each such line falls exactly on bin n (k Z_r + q) of the spectrum: no
scalloping, no leakage between the window's ends. With the Hann window a line on a bin fills that bin
and its two neighbours only, so

- n >= 3 makes every carrier order its own local maximum, whatever the amplitudes of its neighbours;
- n >= 4 (:data:`MIN_CARRIER_REVOLUTIONS`) also leaves one bin between neighbouring orders that holds
  nothing synchronous: f_m and f_m +- f_c are separate peaks with the floor (noise, lines that are not
  carrier orders) visible between them. The sidebands N f_c apart (equally spaced planets) are then
  4 N bins apart.

The spectrum's bins are carrier orders / n; :func:`carrier_order_spectrum` returns them in hertz (order
times the window's mean carrier speed relative to the ring), so a line that is no carrier order (a
natural mode, the sun's or a planet's own rotation) reads at its frequency as in any spectrum.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gearbody.analysis._validate import integer_at_least, is_real
from gearbody.analysis.spectrum import Spectrum, amplitude_spectrum

from ..errors import InputError

__all__ = ["MIN_CARRIER_REVOLUTIONS", "CarrierWindow", "carrier_order_spectrum", "carrier_window"]

MIN_CARRIER_REVOLUTIONS = 4
"""Least whole carrier revolutions (relative to the ring) for a spectrum that resolves the carrier
sidebands f_m +- f_c: see the module docstring."""

_TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class CarrierWindow:
    """Samples start .. stop - 1 of a run: whole carrier revolutions relative to the ring at the end of
    its steady part, or, when the steady part holds less than one revolution, all of it."""

    start: int
    """First sample of the window."""
    stop: int
    """One past the last sample (the run's last sample)."""
    revolutions: int
    """Whole carrier revolutions relative to the ring analysed; 0 when the steady part holds less than
    one (then the window is the steady part in time)."""
    available_revolutions: float
    """Carrier revolutions relative to the ring in the whole steady part."""
    carrier_hz: float
    """Mean carrier speed relative to the ring over the window, |f_c - f_r| [Hz]."""
    duration_s: float
    """Time the window spans [s]."""
    steady_from_s: float
    """Start of the steady part [s]."""
    min_revolutions: int
    """Revolutions needed to resolve the carrier sidebands."""
    settle_factor: float
    """The steady part is the last 1 / settle_factor of the time after the last change of speed or load:
    t_end must be at least t_change + settle_factor * min_revolutions / f_c."""
    change_s: float
    """The last change of speed or load [s] (0 for a steady run)."""

    @property
    def resolution_hz(self) -> float:
        """Bin spacing of the window's spectrum: f_c / revolutions, or 1 / duration [Hz]."""
        if self.revolutions:
            return self.carrier_hz / self.revolutions
        return 1.0 / self.duration_s if self.duration_s > 0 else math.inf

    @property
    def resolves_sidebands(self) -> bool:
        """The window holds at least min_revolutions whole revolutions (f_m +- f_c are separate)."""
        return self.revolutions >= self.min_revolutions

    @property
    def needed_t_end_s(self) -> float:
        """Simulated time whose steady part holds min_revolutions carrier revolutions [s], rounded up to
        the next 0.1 s."""
        if not self.carrier_hz > 0:
            return math.inf
        t = self.change_s + self.settle_factor * self.min_revolutions / self.carrier_hz
        return math.ceil(t * 10.0 - 1e-9) / 10.0

    def mask(self, n_samples: int) -> NDArray[np.bool_]:
        """Boolean mask of the window's samples in a run of n_samples."""
        m = np.zeros(int(n_samples), dtype=bool)
        m[self.start : self.stop] = True
        return m

    def describe(self) -> str:
        """One line: what the window is and its resolution, e.g. "6 carrier revolutions relative to the
        ring (1.11 s, f_c = 5.40 Hz): 0.90 Hz resolution"."""
        if self.revolutions:
            span = (
                f"{self.revolutions} carrier revolution{'s' if self.revolutions > 1 else ''} relative to "
                f"the ring ({self.duration_s:.3g} s, f_c = {self.carrier_hz:.3g} Hz)"
            )
        else:
            span = (
                f"the steady part, {self.duration_s:.3g} s = {self.available_revolutions:.2f} carrier "
                f"revolutions relative to the ring (f_c = {self.carrier_hz:.3g} Hz)"
            )
        return f"{span}: {self.resolution_hz:.3g} Hz resolution"

    def note(self) -> str:
        """ "" when the window resolves the carrier sidebands; otherwise one line saying the resolution
        and the simulated time (--t-end) that would resolve them."""
        if self.resolves_sidebands:
            return ""
        return (
            f"the ring-sensor spectrum does not resolve the carrier sidebands (f_m +- f_c, "
            f"{self.carrier_hz:.3g} Hz apart): it covers {self.describe()}; "
            f"{self.min_revolutions} whole revolutions in the steady part need --t-end "
            f"{self.needed_t_end_s:g} or longer"
        )


def _finite(name: str, value: float) -> float:
    if not (is_real(value) and math.isfinite(value)):
        raise InputError(f"{name} must be a finite number, got {value!r}")
    return float(value)


def carrier_window(
    time_s: ArrayLike,
    carrier_angle_rad: ArrayLike,
    change_s: float = 0.0,
    settle_factor: float = 2.0,
    min_revolutions: int = MIN_CARRIER_REVOLUTIONS,
) -> CarrierWindow:
    """The analysis window of a ring-fixed sensor: all whole carrier revolutions relative to the ring
    in the run's steady part, ending at its last sample.

    The steady part is the last 1 / ``settle_factor`` of the time after ``change_s``, the last change
    of speed or load (the first half, by default, is left to the transients of the change or of the
    start). When it holds less than one revolution, the window is the whole steady part (in time).

    Args:
        time_s: sample times, increasing [s].
        carrier_angle_rad: the carrier's angle relative to the ring (theta_c - theta_r), unwrapped, at
            the same instants [rad]; either sense of rotation.
        change_s: the last change of speed or load [s]; 0 for a run steady from its start.
        settle_factor: >= 1; see above.
        min_revolutions: revolutions that resolve the carrier sidebands (>= 1).
    """
    t = np.asarray(time_s, dtype=float)
    phi = np.asarray(carrier_angle_rad, dtype=float)
    if t.ndim != 1 or t.size < 2 or phi.shape != t.shape:
        raise InputError(
            f"time_s and carrier_angle_rad must be 1-D of one length >= 2, got shapes {t.shape} and "
            f"{phi.shape}"
        )
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(phi))):
        raise InputError("time_s and carrier_angle_rad must be finite")
    if not np.all(np.diff(t) > 0):
        raise InputError("time_s must be strictly increasing")
    change_s = _finite("change_s", change_s)
    settle_factor = _finite("settle_factor", settle_factor)
    if settle_factor < 1:
        raise InputError(f"settle_factor must be >= 1, got {settle_factor!r}")
    min_revolutions = integer_at_least("min_revolutions", min_revolutions, 1)
    change = min(max(change_s, float(t[0])), float(t[-1]))
    steady_from = float(t[-1]) - (float(t[-1]) - change) / settle_factor
    first = int(np.searchsorted(t, steady_from, side="left"))
    first = min(first, t.size - 2)
    turn = np.abs(phi - phi[-1])  # the carrier's turn back from the last sample, relative to the ring
    available = float(turn[first]) / _TWO_PI
    monotone = bool(np.all(np.diff(turn[first:]) < 0))
    whole = int(math.floor(available + 1e-9)) if monotone else 0
    if whole >= 1:
        # the last sample at or before the start of the whole revolutions: the spline has data there
        start = int(np.flatnonzero(turn[first:] >= whole * _TWO_PI * (1 - 1e-12))[-1]) + first
    else:
        start = first
    if whole >= 1:  # the instant the carrier is exactly `whole` revolutions before the end
        t_from = float(np.interp(whole * _TWO_PI, turn[start:][::-1], t[start:][::-1]))
        duration = float(t[-1]) - t_from
        carrier_hz = whole / duration
    else:
        duration = float(t[-1] - t[start])
        carrier_hz = float(turn[start] / duration / _TWO_PI) if duration > 0 else 0.0
    return CarrierWindow(
        start=start,
        stop=int(t.size),
        revolutions=whole,
        available_revolutions=available,
        carrier_hz=carrier_hz,
        duration_s=duration,
        steady_from_s=steady_from,
        min_revolutions=min_revolutions,
        settle_factor=settle_factor,
        change_s=change,
    )


def carrier_order_spectrum(
    signal: ArrayLike,
    carrier_angle_rad: ArrayLike,
    window: CarrierWindow,
    sample_rate_hz: float,
) -> Spectrum:
    """Hann amplitude spectrum of ``signal`` over ``window``, in hertz.

    With whole revolutions: the window's samples resampled (cubic spline over the carrier angle) onto a
    uniform grid of P points per revolution over exactly ``window.revolutions`` revolutions ending at the
    last sample, P the least integer >= the samples per revolution (the band stays that of the sampled
    signal); bin j is carrier order j / n, read at j f_c / n Hz (f_c the window's mean carrier speed).
    Without (the steady part holds less than a revolution): the plain time spectrum of the window.

    Args:
        signal: the sensor's samples at uniform time steps [any unit].
        carrier_angle_rad: the carrier's angle relative to the ring at the same instants [rad].
        window: from :func:`carrier_window` for the same run.
        sample_rate_hz: the signal's sample rate [Hz].
    """
    y = np.asarray(signal, dtype=float)
    phi = np.asarray(carrier_angle_rad, dtype=float)
    if not isinstance(window, CarrierWindow):
        raise InputError(f"window must be a CarrierWindow, got {type(window).__name__}")
    if y.shape != phi.shape or y.ndim != 1 or y.size < window.stop:
        raise InputError(
            f"signal and carrier_angle_rad must be 1-D of one length >= window.stop = {window.stop}, got "
            f"shapes {y.shape} and {phi.shape}"
        )
    if not (is_real(sample_rate_hz) and sample_rate_hz > 0 and math.isfinite(sample_rate_hz)):
        raise InputError(f"sample_rate_hz must be a positive number [Hz], got {sample_rate_hz!r}")
    y = y[window.start : window.stop]
    if not window.revolutions:
        return amplitude_spectrum(y, sample_rate_hz, window="hann")
    turn = np.abs(phi[window.start : window.stop] - phi[window.stop - 1])[::-1]  # increasing to 0 at end
    span = window.revolutions * _TWO_PI
    per_rev = int(math.ceil(sample_rate_hz / window.carrier_hz - 1e-9))
    grid = span - np.arange(window.revolutions * per_rev) * (span / (window.revolutions * per_rev))
    from scipy.interpolate import CubicSpline  # ~0.45 s to import: on use only

    values = CubicSpline(turn, y[::-1])(grid)  # the grid runs from the revolutions' start forwards
    return amplitude_spectrum(values, per_rev * window.carrier_hz, window="hann")
