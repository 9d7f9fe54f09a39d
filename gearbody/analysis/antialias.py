"""Band-limited sampling of signals with jumps: what a transducer behind an anti-aliasing filter records.

The mesh force jumps whenever the number of tooth pairs in contact changes, so its harmonics decay only
as 1/k. Sampled point by point at ``fs`` they fold back into the band of interest: at 20 kHz the 40th
and 41st harmonics of a 494 Hz mesh land at 246 +- 1.3 Hz with ~10 N. Oversampling alone does not cure
that (the 1/k tail folds from any rate). Here a signal given on a uniform fine grid is split into a
staircase of known jumps plus a continuous rest; the rest is low-pass filtered on the fine grid (its
harmonics decay fast, so it barely aliases) and the steps are filtered analytically with the filter's
step response. The result is the continuous-time signal passed through one linear-phase low-pass
(Kaiser-windowed sinc, zero delay) and sampled at ``fs``.

Filter: cut-off ``0.45 fs``, transition 0.4 fs - 0.5 fs, ``stopband_db`` attenuation above 0.5 fs;
the pass band (below 0.4 fs) is flat to better than 1e-4. Like every linear-phase low-pass it rings
around a jump (Gibbs, ~9 % of the jump at +-1/fs), so time-domain extremes of a band-limited signal
are not those of the instantaneous one.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from ..errors import InputError

__all__ = ["KERNEL_HALF_WIDTH_SAMPLES", "band_limited_samples", "level_crossings"]

KERNEL_HALF_WIDTH_SAMPLES = 32
"""Half length of the filter kernel in output samples (also the length of the edge region)."""

_CUTOFF_FRACTION = 0.45


def _kaiser_beta(stopband_db: float) -> float:
    a = stopband_db
    return 0.1102 * (a - 8.7) if a > 50 else 0.5842 * (a - 21) ** 0.4 + 0.07886 * (a - 21)


def _kernel(tau_s: np.ndarray, rate_hz: float, half_width_s: float, beta: float) -> np.ndarray:
    """Continuous low-pass kernel h(tau) [1/s]: 2 fc sinc(2 fc tau) times a Kaiser window."""
    fc = _CUTOFF_FRACTION * rate_hz
    x = np.clip(tau_s / half_width_s, -1.0, 1.0)
    window = np.i0(beta * np.sqrt(1.0 - x * x)) / np.i0(beta)
    return np.where(np.abs(tau_s) <= half_width_s, 2 * fc * np.sinc(2 * fc * tau_s) * window, 0.0)


@lru_cache(maxsize=16)
def _filter_tables(rate_hz: float, oversampling: int, stopband_db: float):
    """Fine-grid taps (sum 1) and the tabulated step response (tau, S) of the low-pass; cached."""
    half_w = KERNEL_HALF_WIDTH_SAMPLES / rate_hz
    beta = _kaiser_beta(stopband_db)
    L = KERNEL_HALF_WIDTH_SAMPLES * oversampling
    dt = 1.0 / (oversampling * rate_hz)
    taps = _kernel(np.arange(-L, L + 1) * dt, rate_hz, half_w, beta)
    taps /= taps.sum()
    s_tau = np.linspace(-half_w, half_w, 16 * 2 * KERNEL_HALF_WIDTH_SAMPLES * 64 + 1)
    h = _kernel(s_tau, rate_hz, half_w, beta)
    s_cum = np.concatenate([[0.0], np.cumsum(0.5 * (h[1:] + h[:-1]) * np.diff(s_tau))])
    s_cum /= s_cum[-1]
    for array in (taps, s_tau, s_cum):
        array.flags.writeable = False
    return taps, s_tau, s_cum


def level_crossings(t_s: np.ndarray, g: np.ndarray, level: float = 0.0) -> np.ndarray:
    """Times where the sampled smooth function ``g`` crosses ``level`` (linear interpolation), s."""
    s = np.sign(np.asarray(g, float) - level)
    j = np.flatnonzero(s[:-1] * s[1:] < 0)
    g0, g1 = g[j] - level, g[j + 1] - level
    return t_s[j] + (t_s[j + 1] - t_s[j]) * g0 / (g0 - g1)


def _side_limit(x: np.ndarray, busy: np.ndarray, j: np.ndarray, s: np.ndarray, side: int) -> np.ndarray:
    """Limit of x at t_j + s dt (0 <= s < 1) from the left (side -1: samples j, j-1, j-2) or the right
    (side +1: j+1, j+2, j+3): quadratic, or linear / constant where a neighbouring interval jumps too."""
    n = x.size
    i0 = j if side < 0 else j + 1
    u = (i0 - j - s) * side  # distance from node i0 to the target, in steps away from the other nodes
    i1, i2 = i0 + side, i0 + 2 * side
    # interval between i0 and i1 is min(i0, i1); it must hold no jump, likewise for i1 and i2
    ok1 = (i1 >= 0) & (i1 < n) & ~busy[np.clip(np.minimum(i0, i1), 0, n - 1)]
    ok2 = ok1 & (i2 >= 0) & (i2 < n) & ~busy[np.clip(np.minimum(i1, i2), 0, n - 1)]
    x0, x1, x2 = x[i0], x[np.clip(i1, 0, n - 1)], x[np.clip(i2, 0, n - 1)]
    # nodes at 0, -1, -2 (steps away from the target side), target at +u
    linear = x0 + (x0 - x1) * u
    quadratic = x0 * (u + 1) * (u + 2) / 2 - x1 * u * (u + 2) + x2 * u * (u + 1) / 2
    return np.where(ok2, quadratic, np.where(ok1, linear, x0))


def band_limited_samples(
    t_fine_s: np.ndarray,
    x_fine: np.ndarray,
    oversampling: int,
    jump_times_s: np.ndarray,
    *,
    stopband_db: float = 100.0,
) -> np.ndarray:
    """Samples at ``t_fine_s[::oversampling]`` of ``x`` passed through the anti-aliasing low-pass.

    Args:
        t_fine_s: uniform fine time grid, s; the output rate is ``1 / (oversampling * dt)``.
        x_fine: the signal at ``t_fine_s``; continuous except at ``jump_times_s``.
        oversampling: fine points per output sample (>= 2); 4-8 resolves the continuous rest.
        jump_times_s: times of the signal's jumps (any order; a jump need not change every signal).
            Jump sizes are measured from the samples by linear extrapolation from each side.
        stopband_db: attenuation above the output Nyquist frequency.
    """
    t = np.asarray(t_fine_s, float)
    x = np.asarray(x_fine, float)
    M = int(oversampling)
    if M < 2:
        raise InputError(f"oversampling must be >= 2, got {oversampling}")
    if t.ndim != 1 or x.shape != t.shape or t.size < 4:
        raise InputError("t_fine_s and x_fine must be 1-D arrays of equal length >= 4")
    dt = (t[-1] - t[0]) / (t.size - 1)
    rate = 1.0 / (M * dt)
    half_w = KERNEL_HALF_WIDTH_SAMPLES / rate

    # 1. Jumps: one per fine interval, size = right limit - left limit, each limit extrapolated from
    #    its own side by a quadratic (error ~ dt^3 x'''), or linearly / constant next to other jumps.
    tj = np.sort(np.asarray(jump_times_s, float))
    tj = tj[(tj > t[0]) & (tj < t[-1])]
    j = np.clip(np.searchsorted(t, tj, side="right") - 1, 0, t.size - 2)  # t[j] <= tj < t[j + 1]
    j, first = np.unique(j, return_index=True)
    tj = tj[first]
    busy = np.zeros(t.size, bool)
    busy[j] = True  # intervals holding a jump: no extrapolation across them
    dx = _side_limit(x, busy, j, (tj - t[j]) / dt, +1) - _side_limit(x, busy, j, (tj - t[j]) / dt, -1)

    # 2. Continuous rest on the fine grid: subtract the staircase.
    stairs = np.zeros(t.size + 1)
    np.add.at(stairs, j + 1, dx)
    rest = x - np.cumsum(stairs)[:-1]

    # 3. Filter the rest with the sampled kernel (odd-reflection padding keeps value and slope at the ends).
    L = KERNEL_HALF_WIDTH_SAMPLES * M
    taps, s_tau, s_cum = _filter_tables(rate, M, stopband_db)
    padded = np.pad(rest, L, mode="reflect", reflect_type="odd")
    # only every M-th output is kept: a strided dot product computes just those (as fast as an FFT
    # convolution of the whole fine grid, exact to round-off, and no scipy.signal import, ~0.6 s)
    y = sliding_window_view(padded, taps.size)[::M] @ taps[::-1]

    # 4. Add the filtered steps: dx * S(t_k - t_jump), S the kernel's step response.
    t_out = t[::M]
    k0 = np.ceil((tj - half_w - t_out[0]) * rate - 1e-9).astype(int)
    span = 2 * KERNEL_HALF_WIDTH_SAMPLES + 2
    kk = k0[:, None] + np.arange(span)[None, :]
    valid = (kk >= 0) & (kk < t_out.size)
    tau = t_out[np.clip(kk, 0, t_out.size - 1)] - tj[:, None]
    step = np.interp(tau, s_tau, s_cum, left=0.0, right=1.0)
    inside = valid & (tau <= half_w)
    np.add.at(y, kk[inside], (dx[:, None] * step)[inside])
    after = np.zeros(t_out.size + 1)  # outputs past the kernel's reach get the whole step
    k_full = np.clip(k0 + span, 0, t_out.size)
    np.add.at(after, k_full, dx)
    y += np.cumsum(after)[:-1]
    # outputs within the span but beyond half_w also need the whole step
    beyond = valid & (tau > half_w)
    np.add.at(y, kk[beyond], np.broadcast_to(dx[:, None], kk.shape)[beyond])
    return y
