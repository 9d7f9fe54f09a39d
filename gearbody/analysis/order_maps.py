"""Order spectra, rpm-order maps and order slices of an order-tracked signal (see
:mod:`gearbody.analysis.orders`).

Amplitudes are single-sided peak amplitudes [signal units]: a component A cos(o theta + phi) at order
o shows as A. Spectra use a periodic window w over each block and ``2 |rfft(x w)| / sum(w)`` (the
window's coherent gain corrected, as :func:`gearbody.analysis.spectrum.amplitude_spectrum`), so A is
exact when o falls on a bin (o x block revolutions an integer); off-bin the peak bin reads low by the
window's scalloping loss (Hann: up to 15 % at half a bin; "flattop": < 0.1 %).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ._validate import integer_at_least, is_real
from .orders import OrderTrackedSignal, order_track

__all__ = [
    "SLICE_KAISER_BETA",
    "OrderSlice",
    "OrderSpectrum",
    "RpmOrderMap",
    "order_slice",
    "order_spectrum",
    "rpm_order_map",
]

SLICE_KAISER_BETA: float = 10.0
"""Kaiser window of the order slice's low-pass: its main lobe reaches 3.34 / revolutions orders, and
components farther away are attenuated by > 70 dB."""

_BATCH_POINTS = 2**22
"""Block-spectrum points per FFT batch (memory bound of the block spectra)."""


def _tracked(tracked: object) -> OrderTrackedSignal:
    if not isinstance(tracked, OrderTrackedSignal):
        raise InputError(f"tracked must be an OrderTrackedSignal (from order_track), got {type(tracked)!r}")
    return tracked


def _overlap(overlap: float) -> float:
    if not (is_real(overlap) and 0.0 <= overlap < 1.0):
        raise InputError(f"overlap must be a fraction 0 <= overlap < 1, got {overlap!r}")
    return float(overlap)


def _block_points(tracked: OrderTrackedSignal, revolutions: int) -> int:
    revolutions = integer_at_least("revolutions", revolutions, 1)
    points = revolutions * tracked.samples_per_rev
    if points > tracked.values.size:
        raise InputError(
            f"revolutions must be <= the record's {tracked.revolutions:.6g} revolutions, got {revolutions}"
        )
    return points


def _block_amplitudes(
    values: NDArray[np.float64], points: int, hop: int, window: str | tuple, detrend: bool
) -> NDArray[np.float64]:
    """Single-sided peak amplitude of every block (rows) [signal units]."""
    blocks = sliding_window_view(values, points)[::hop]
    from scipy.signal import get_window

    w = get_window(window, points, fftbins=True)
    scale = 2.0 / np.sum(w)
    rows = []
    per_batch = max(1, _BATCH_POINTS // points)
    for i in range(0, blocks.shape[0], per_batch):
        chunk = blocks[i : i + per_batch]
        if detrend:
            chunk = chunk - chunk.mean(axis=1, keepdims=True)
        amplitude = np.abs(np.fft.rfft(chunk * w, axis=1)) * scale
        amplitude[:, 0] /= 2.0
        if points % 2 == 0:
            amplitude[:, -1] /= 2.0
        rows.append(amplitude)
    return np.concatenate(rows)


@dataclass(frozen=True)
class OrderSpectrum:
    """Single-sided order spectrum (peak amplitude per order bin, blocks RMS-averaged)."""

    order: NDArray[np.float64]
    """Bin orders 0 .. samples_per_rev / 2, spacing 1 / revolutions [cycles/rev]."""
    amplitude: NDArray[np.float64]
    """Peak amplitude per bin [signal units]."""
    revolutions: int
    """Revolutions per block (the order resolution is 1 / revolutions)."""
    n_blocks: int
    """Number of blocks averaged."""
    window: str
    """Window name (scipy.signal.get_window)."""


def order_spectrum(
    tracked: OrderTrackedSignal,
    *,
    window: str | tuple = "hann",
    revolutions: int | None = None,
    overlap: float = 0.5,
    detrend: bool = True,
) -> OrderSpectrum:
    """Order spectrum of an order-tracked signal: single-sided peak amplitude, coherent gain corrected.

    revolutions=None: one block over the largest whole number of revolutions from the record's start.
    Otherwise blocks of ``revolutions`` revolutions overlapping by ``overlap``, their amplitudes averaged
    as sqrt(mean |X|^2) (Welch in the angle domain): a steady order reads its amplitude A, an order whose
    amplitude varies reads its RMS over the blocks, random noise its RMS level per bin.

    Args:
        tracked: from :func:`gearbody.analysis.orders.order_track`.
        window: window for scipy.signal.get_window ("hann", "flattop", ("kaiser", 8), ...).
        revolutions: whole revolutions per block (>= 1), or None.
        overlap: fraction of a block shared with the next (0 <= overlap < 1).
        detrend: remove each block's mean first.
    """
    tracked = _tracked(tracked)
    overlap = _overlap(overlap)
    if revolutions is None:
        revolutions = int(tracked.values.size // tracked.samples_per_rev)
        if revolutions < 1:
            raise InputError(f"tracked must span a whole revolution, got {tracked.revolutions:.6g}")
    points = _block_points(tracked, revolutions)
    hop = max(1, int(round(points * (1.0 - overlap))))
    amplitude = _block_amplitudes(tracked.values, points, hop, window, detrend)
    return OrderSpectrum(
        order=np.arange(points // 2 + 1) / revolutions,
        amplitude=np.sqrt(np.mean(amplitude**2, axis=0)),
        revolutions=int(revolutions),
        n_blocks=int(amplitude.shape[0]),
        window=str(window),
    )


@dataclass(frozen=True)
class RpmOrderMap:
    """Amplitude over (block, order) of a run-up or coast-down: one order spectrum per block."""

    order: NDArray[np.float64]
    """Bin orders 0 .. max_order, spacing 1 / revolutions_per_block [cycles/rev]."""
    speed_hz: NDArray[np.float64]
    """Mean shaft speed of each block, its revolutions / its duration [Hz = rev/s]."""
    time_s: NDArray[np.float64]
    """Middle instant of each block, halfway between its first and last instant [s] (for a speed linear
    in time, the speed there is the block's mean speed)."""
    amplitude: NDArray[np.float64]
    """Peak amplitude, shape (n_blocks, n_orders) [signal units]."""
    revolutions_per_block: int
    """Revolutions per block."""

    @property
    def speed_rpm(self) -> NDArray[np.float64]:
        """Mean shaft speed of each block [rpm]."""
        return 60.0 * self.speed_hz


def rpm_order_map(
    signal: ArrayLike,
    sample_rate_hz: float,
    shaft_angle_rad: ArrayLike,
    *,
    revolutions_per_block: int,
    overlap: float = 0.5,
    max_order: float | None = None,
    samples_per_rev: int | None = None,
    window: str | tuple = "hann",
    upsample: int = 4,
    t0_s: float = 0.0,
) -> RpmOrderMap:
    """Rpm-order map: the signal order-tracked (:func:`gearbody.analysis.orders.order_track`, which takes
    max_order, samples_per_rev, upsample, t0_s), cut into blocks of ``revolutions_per_block`` whole
    revolutions overlapping by ``overlap``, and the order spectrum of each block (window ``window``,
    scaling of :func:`order_spectrum`, each block's mean removed). Orders up to the tracked signal's
    max_order are kept; each block's speed is its mean speed (revolutions / duration).
    """
    overlap = _overlap(overlap)
    tracked = order_track(
        signal,
        sample_rate_hz,
        shaft_angle_rad,
        samples_per_rev=samples_per_rev,
        max_order=max_order,
        upsample=upsample,
        t0_s=t0_s,
    )
    points = _block_points(tracked, revolutions_per_block)
    hop = max(1, int(round(points * (1.0 - overlap))))
    amplitude = _block_amplitudes(tracked.values, points, hop, window, True)
    starts = np.arange(amplitude.shape[0]) * hop
    t_start, t_end = tracked.time_s[starts], tracked.time_s[starts + points - 1]
    duration_s = (t_end - t_start) * points / (points - 1)  # points x grid step, i.e. whole revolutions
    order = np.arange(points // 2 + 1) / revolutions_per_block
    keep = order <= tracked.max_order
    return RpmOrderMap(
        order=order[keep],
        speed_hz=revolutions_per_block / duration_s,
        time_s=0.5 * (t_start + t_end),
        amplitude=amplitude[:, keep],
        revolutions_per_block=int(revolutions_per_block),
    )


@dataclass(frozen=True)
class OrderSlice:
    """Amplitude and phase of one order versus time and speed."""

    order: float
    """The tracked order [cycles/rev]."""
    time_s: NDArray[np.float64]
    """Instants of the estimates (the middle of each averaging window) [s]."""
    speed_hz: NDArray[np.float64]
    """Shaft speed at those instants [Hz = rev/s]."""
    amplitude: NDArray[np.float64]
    """Peak amplitude of the order [signal units]."""
    phase_rad: NDArray[np.float64]
    """Phase phi of A cos(order theta + phi), theta the shaft angle [rad], in (-pi, pi]."""
    revolutions: float
    """Length of the averaging window [rev]."""

    @property
    def speed_rpm(self) -> NDArray[np.float64]:
        """Shaft speed at the estimates [rpm]."""
        return 60.0 * self.speed_hz


def order_slice(
    tracked: OrderTrackedSignal,
    order: float,
    *,
    revolutions: float = 8.0,
    step_revolutions: float = 0.25,
) -> OrderSlice:
    """Amplitude of one order versus time and speed, by complex demodulation in the angle domain.

    The tracked signal is multiplied by exp(-i order theta) (the order moves to order 0, exactly, at any
    speed) and averaged over ``revolutions`` revolutions with a Kaiser window (beta SLICE_KAISER_BETA,
    unit sum): amplitude = 2 |average|. The window passes the order's slow amplitude changes and rejects
    every component more than 3.34 / revolutions orders away by > 70 dB (the default 8 revolutions:
    0.42 order), so neighbouring orders and the mean need that spacing. Estimates exist where the whole
    window lies in the record (half a window is lost at each end), every ``step_revolutions``.

    Args:
        tracked: from :func:`gearbody.analysis.orders.order_track`.
        order: the order to follow, 0 < order <= tracked.max_order [cycles/rev].
        revolutions: window length [rev] (> 0; at least 2 grid points).
        step_revolutions: spacing of the estimates [rev] (> 0).
    """
    tracked = _tracked(tracked)
    if not (is_real(order) and math.isfinite(order) and 0 < order <= tracked.max_order):
        raise InputError(f"order must be in (0, {tracked.max_order:.6g}] (tracked.max_order), got {order!r}")
    for name, value in (("revolutions", revolutions), ("step_revolutions", step_revolutions)):
        if not (is_real(value) and math.isfinite(value) and value > 0):
            raise InputError(f"{name} must be a positive number of revolutions, got {value!r}")
    spr = tracked.samples_per_rev
    points = int(round(revolutions * spr)) | 1  # odd: the estimate sits on a grid point
    if points > tracked.values.size:
        raise InputError(
            f"revolutions must be <= the record's {tracked.revolutions:.6g} revolutions, got {revolutions!r}"
        )
    from scipy.signal import fftconvolve, get_window

    w = get_window(("kaiser", SLICE_KAISER_BETA), points, fftbins=False)
    w /= w.sum()
    demodulated = tracked.values * np.exp(-1j * order * tracked.angle_rad)
    average = fftconvolve(demodulated, w, mode="valid")
    take = np.arange(0, average.size, max(1, int(round(step_revolutions * spr))))
    centre = take + points // 2
    return OrderSlice(
        order=float(order),
        time_s=tracked.time_s[centre],
        speed_hz=tracked.speed_hz[centre],
        amplitude=2.0 * np.abs(average[take]),
        phase_rad=np.angle(average[take]),
        revolutions=points / spr,
    )
