"""Dynamic factor K_d = F(t) / F_rated: folding over the mesh period, tooth separation, period statistics.

Engine-free: every function works on plain 1-D numpy arrays, so measured signals can be analysed the
same way as simulated ones (Bartelmus, sections 2-3, Figs. 5-8 and 12).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError

__all__ = [
    "INSTABILITY_KD",
    "FoldedSignal",
    "SeparationStats",
    "fold_over_mesh_period",
    "mesh_phase",
    "periods_stats",
    "separation_stats",
    "unstable",
]

INSTABILITY_KD: float = 2.0
"""The paper's criterion: the gearbox runs unstably (tooth separation) when max K_d > 2."""


def _as_1d(name: str, values: ArrayLike) -> NDArray[np.float64]:
    array = np.asarray(values, dtype=float)
    if array.ndim != 1:
        raise InputError(f"{name} must be 1-D, got shape {array.shape}")
    return array


def _same_length(**arrays: NDArray[np.float64]) -> None:
    lengths = {name: a.size for name, a in arrays.items()}
    if len(set(lengths.values())) > 1:
        raise InputError(f"arrays must have equal lengths, got {lengths}")


def mesh_phase(pinion_angle_rad: ArrayLike, pinion_teeth: int) -> NDArray[np.float64]:
    """Mesh phase p = frac(phi_1 * z_1 / (2 pi)) in [0, 1) from the pinion angle phi_1 [rad]."""
    if int(pinion_teeth) != pinion_teeth or pinion_teeth < 1:
        raise InputError(f"pinion_teeth must be a positive integer, got {pinion_teeth!r}")
    cycles = np.asarray(pinion_angle_rad, dtype=float) * int(pinion_teeth) / (2.0 * np.pi)
    phase = cycles - np.floor(cycles)
    # floor can leave exactly 1.0 after rounding for tiny negative inputs
    return np.where(phase >= 1.0, 0.0, phase)


@dataclass(frozen=True)
class FoldedSignal:
    """A signal folded over one mesh period (as K_d in the paper's Figs. 5-8).

    All arrays have one entry per bin. Bins with no samples hold NaN in mean/minimum/maximum.
    """

    percent_of_period: NDArray[np.float64]
    """Bin centres, % of the mesh period (0..100)."""
    mean: NDArray[np.float64]
    """Mean of the values in each bin (signal units)."""
    minimum: NDArray[np.float64]
    """Smallest value in each bin (signal units)."""
    maximum: NDArray[np.float64]
    """Largest value in each bin (signal units)."""
    count: NDArray[np.int64]
    """Number of samples in each bin."""

    @property
    def bins(self) -> int:
        """Number of bins over the mesh period."""
        return int(self.percent_of_period.size)


def fold_over_mesh_period(
    values: ArrayLike,
    pinion_angle_rad: ArrayLike,
    pinion_teeth: int,
    bins: int = 100,
) -> FoldedSignal:
    """Fold ``values`` over the mesh period using the (computed or measured) pinion angle.

    Each sample goes to bin ``floor(p * bins)`` of the mesh phase p = frac(phi_1 * z_1 / (2 pi)), so the
    actual angle (including torsional vibration) sets the phase, not a nominal speed. Pairs where either
    value or angle is not finite are ignored. Pass only the samples of interest (e.g. a steady period).

    Args:
        values: signal samples, e.g. K_d [-] or mesh force [N].
        pinion_angle_rad: pinion rotation angle phi_1 at the same instants [rad].
        pinion_teeth: number of pinion teeth z_1.
        bins: number of equal-width bins over one mesh period.
    """
    if int(bins) != bins or bins < 1:
        raise InputError(f"bins must be a positive integer, got {bins!r}")
    bins = int(bins)
    y = _as_1d("values", values)
    angle = _as_1d("pinion_angle_rad", pinion_angle_rad)
    _same_length(values=y, pinion_angle_rad=angle)
    keep = np.isfinite(y) & np.isfinite(angle)
    y, angle = y[keep], angle[keep]

    index = np.minimum((mesh_phase(angle, pinion_teeth) * bins).astype(np.int64), bins - 1)
    count = np.bincount(index, minlength=bins).astype(np.int64)
    total = np.bincount(index, weights=y, minlength=bins)
    minimum = np.full(bins, np.inf)
    maximum = np.full(bins, -np.inf)
    np.minimum.at(minimum, index, y)
    np.maximum.at(maximum, index, y)
    empty = count == 0
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(empty, np.nan, total / np.maximum(count, 1))
    minimum[empty] = np.nan
    maximum[empty] = np.nan
    centres = (np.arange(bins) + 0.5) * (100.0 / bins)
    return FoldedSignal(percent_of_period=centres, mean=mean, minimum=minimum, maximum=maximum, count=count)


def unstable(kd: ArrayLike, threshold: float = INSTABILITY_KD) -> bool:
    """True if max K_d > ``threshold`` (default 2, the paper's instability / tooth-separation criterion).

    Non-finite samples are ignored; an empty signal is not unstable.
    """
    array = np.asarray(kd, dtype=float).ravel()
    array = array[np.isfinite(array)]
    return bool(array.size > 0 and np.max(array) > threshold)


@dataclass(frozen=True)
class SeparationStats:
    """Tooth-separation statistics of a mesh force signal.

    A sample is "separated" when F <= threshold (0 N by default: no contact force).
    """

    separated_fraction: float
    """Fraction of the duration with F <= threshold [-] (sample-weighted by time, see separation_stats)."""
    separated_time_s: float
    """Total time with F <= threshold [s]."""
    duration_s: float
    """Duration covered by the signal [s]."""
    contact_losses: int
    """Number of transitions F > threshold -> F <= threshold."""
    impacts: int
    """Number of transitions F <= threshold -> F > threshold (re-contact)."""
    first_separation_s: float | None
    """Time of the first separated sample [s], None if never separated."""
    max_kd: float | None
    """max K_d if ``kd`` was given, else None."""
    kd_above_2: bool | None
    """max K_d > 2 (paper's instability criterion) if ``kd`` was given, else None."""


def _time_weights(time_s: NDArray[np.float64]) -> NDArray[np.float64]:
    """Duration represented by each sample [s]: half of each adjacent interval (sums to t[-1] - t[0])."""
    if time_s.size < 2:
        return np.zeros_like(time_s)
    dt = np.diff(time_s)
    if np.any(dt < 0):
        raise InputError("time_s must be non-decreasing")
    weights = np.zeros_like(time_s)
    weights[:-1] += 0.5 * dt
    weights[1:] += 0.5 * dt
    return weights


def separation_stats(
    mesh_force_N: ArrayLike,
    time_s: ArrayLike,
    kd: ArrayLike | None = None,
    threshold_N: float = 0.0,
) -> SeparationStats:
    """Count tooth separations in a sampled inter-tooth force F(t) [N].

    Each sample stands for half of each neighbouring time interval, so the separated fraction is exact
    for uniform sampling (count of separated samples / count) and sensible for non-uniform steps.
    A signal that starts separated (e.g. from rest with F = 0) counts an impact at first contact but
    no preceding contact loss.

    Args:
        mesh_force_N: inter-tooth force samples [N].
        time_s: sample times [s], non-decreasing, same length.
        kd: optional dynamic factor K_d samples [-] to fill ``max_kd`` and ``kd_above_2``.
        threshold_N: force at or below which the teeth count as separated [N].
    """
    force = _as_1d("mesh_force_N", mesh_force_N)
    time = _as_1d("time_s", time_s)
    _same_length(mesh_force_N=force, time_s=time)
    separated = force <= threshold_N
    weights = _time_weights(time)
    duration = float(time[-1] - time[0]) if time.size else 0.0
    separated_time = float(np.sum(weights[separated]))
    if duration > 0.0:
        fraction = separated_time / duration
    else:
        fraction = float(np.mean(separated)) if separated.size else 0.0
    change = np.diff(separated.astype(np.int8))
    first = float(time[np.argmax(separated)]) if np.any(separated) else None

    max_kd: float | None = None
    above: bool | None = None
    if kd is not None:
        kd_array = _as_1d("kd", kd)
        finite = kd_array[np.isfinite(kd_array)]
        max_kd = float(np.max(finite)) if finite.size else float("nan")
        above = unstable(finite)
    return SeparationStats(
        separated_fraction=fraction,
        separated_time_s=separated_time,
        duration_s=duration,
        contact_losses=int(np.count_nonzero(change == 1)),
        impacts=int(np.count_nonzero(change == -1)),
        first_separation_s=first,
        max_kd=max_kd,
        kd_above_2=above,
    )


def periods_stats(
    kd: ArrayLike,
    time_s: ArrayLike,
    boundaries_s: Sequence[float] | ArrayLike,
) -> list[dict[str, float | int]]:
    """K_d statistics in each operating period (as periods (1)-(4) of the paper's Fig. 12).

    Period i covers boundaries_s[i] <= t < boundaries_s[i+1]; the last period also includes its end time.
    Percentiles use numpy's default linear interpolation. Empty periods give NaN statistics.

    Returns:
        One dict per period with keys ``period`` (1-based), ``start_s``, ``end_s``, ``samples``,
        ``max``, ``p50``, ``p95``, ``p99`` (K_d values, [-]).
    """
    values = _as_1d("kd", kd)
    time = _as_1d("time_s", time_s)
    _same_length(kd=values, time_s=time)
    edges = _as_1d("boundaries_s", boundaries_s)
    if edges.size < 2:
        raise InputError("boundaries_s needs at least two times (start and end of one period)")
    if np.any(np.diff(edges) <= 0):
        raise InputError("boundaries_s must be strictly increasing")

    result: list[dict[str, float | int]] = []
    last = edges.size - 2
    for i, (start, end) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
        inside = (time >= start) & ((time <= end) if i == last else (time < end))
        chunk = values[inside]
        chunk = chunk[np.isfinite(chunk)]
        if chunk.size:
            p50, p95, p99 = (float(v) for v in np.percentile(chunk, [50.0, 95.0, 99.0]))
            peak = float(np.max(chunk))
        else:
            p50 = p95 = p99 = peak = float("nan")
        result.append(
            {
                "period": i + 1,
                "start_s": float(start),
                "end_s": float(end),
                "samples": int(chunk.size),
                "max": peak,
                "p50": p50,
                "p95": p95,
                "p99": p99,
            }
        )
    return result
