"""Gear condition indicators: RMS, crest factor, kurtosis, FM0, FM4, NA4, M6A, M8A, energy ratio, SER.

Engine-free: plain 1-D numpy arrays in (the TSA and its difference, residual and regular signals, e.g. from
gearbody.analysis.tsa, or measured ones), floats or a frozen dataclass out. Definitions follow Lebold,
McClintic, Campbell, Byington & Maynard 2000, "Review of vibration analysis methods for gearbox
diagnostics and prognostics" (Proc. 54th MFPT), who collect Stewart 1977 (FM0, FM4), Zakrajsek, Townsend &
Decker 1993 (NA4), Martin 1989 (M6A, M8A) and Swansson 1980 (energy ratio); the sideband energy ratio is
the common definition of Hanson et al.

Moments are about the mean: with d' = d - mean(d) and N samples, the n-th normalised moment is
N^(n/2 - 1) sum d'^n / (sum d'^2)^(n/2), so kurtosis (FM4) is 3 for Gaussian noise and 1.5 for a sine,
M6A 15 and 2.5, M8A 105 and 4.375.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError

if TYPE_CHECKING:
    from gearbody.analysis.tsa import SynchronousAverage

__all__ = [
    "ConditionIndicators",
    "condition_indicators",
    "condition_indicators_from_average",
    "crest_factor",
    "energy_ratio",
    "fm0",
    "fm4",
    "kurtosis",
    "m6a",
    "m8a",
    "na4",
    "na4_trend",
    "peak_to_peak",
    "rms",
    "sideband_energy_ratio",
]


def _as_1d(name: str, values: ArrayLike, min_size: int = 2) -> NDArray[np.float64]:
    array = np.asarray(values, dtype=float)
    if array.ndim != 1 or array.size < min_size:
        raise InputError(f"{name} must be 1-D with at least {min_size} samples, got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        first = int(np.flatnonzero(~np.isfinite(array))[0])
        raise InputError(f"{name} must be finite, sample {first} is {array[first]!r}")
    return array


def _check_teeth(teeth: int) -> int:
    if isinstance(teeth, bool) or int(teeth) != teeth or teeth < 1:
        raise InputError(f"teeth must be a positive integer, got {teeth!r}")
    return int(teeth)


def _central_moments(name: str, values: ArrayLike, order: int) -> tuple[float, float]:
    """(mean of d'^2, mean of d'^order) with d' = values - mean(values); refuses zero variance."""
    x = _as_1d(name, values)
    d = x - x.mean()
    m2 = float(np.mean(d * d))
    if not m2 > 0.0:
        raise InputError(f"{name} has zero variance (constant signal), its normalised moments are undefined")
    return m2, float(np.mean(d**order))


def _normalised_moment(name: str, values: ArrayLike, order: int) -> float:
    m2, mn = _central_moments(name, values, order)
    return mn / m2 ** (order // 2)


def rms(signal: ArrayLike) -> float:
    """Root mean square sqrt(mean(x^2)) [signal units] (not about the mean)."""
    x = _as_1d("signal", signal, min_size=1)
    return float(np.sqrt(np.mean(x * x)))


def peak_to_peak(signal: ArrayLike) -> float:
    """max(x) - min(x) [signal units]."""
    x = _as_1d("signal", signal, min_size=1)
    return float(np.max(x) - np.min(x))


def crest_factor(signal: ArrayLike) -> float:
    """Crest factor max|x| / RMS [-] (sine sqrt 2, square wave 1); refuses an all-zero signal."""
    x = _as_1d("signal", signal, min_size=1)
    value = rms(x)
    if not value > 0.0:
        raise InputError("signal is all zero, its crest factor is undefined")
    return float(np.max(np.abs(x)) / value)


def kurtosis(signal: ArrayLike) -> float:
    """Kurtosis N sum (x - xbar)^4 / (sum (x - xbar)^2)^2 [-], not excess: Gaussian 3, sine 1.5, square 1."""
    return _normalised_moment("signal", signal, 4)


def fm0(tsa: ArrayLike, teeth: int) -> float:
    """FM0 (Stewart 1977) = peak-to-peak of the TSA / sum of the amplitudes of the mesh orders [-].

    ``tsa`` must hold exactly one shaft revolution on a uniform angle grid, so FFT bin k is order k. The
    sum runs over the mesh orders k * teeth, k = 1 .. H, up to the Nyquist order len(tsa) // 2 (peak
    amplitudes; the mean is not included). A pure mesh tone A sin(z theta) gives 2A / A = 2; damage that
    raises peaks without raising the mesh orders increases FM0.
    """
    teeth = _check_teeth(teeth)
    x = _as_1d("tsa", tsa)
    n = x.size
    if n < 2 * teeth:
        raise InputError(
            f"tsa must have at least 2 * teeth = {2 * teeth} points per revolution to hold the mesh order, "
            f"got {n}"
        )
    spectrum = np.abs(np.fft.rfft(x)) / n
    orders = np.arange(teeth, n // 2 + 1, teeth)
    amplitude = 2.0 * spectrum[orders]
    if n % 2 == 0 and orders[-1] == n // 2:
        amplitude[-1] /= 2.0  # Nyquist bin is not doubled
    total = float(np.sum(amplitude))
    spread = peak_to_peak(x)
    if not total > 1e-12 * spread:  # nothing but rounding at the mesh orders (or a constant tsa)
        raise InputError(
            f"tsa has no content at the mesh orders (sum of amplitudes {total:.3g}), FM0 is undefined"
        )
    return spread / total


def fm4(difference: ArrayLike) -> float:
    """FM4 (Stewart 1977) = kurtosis of the difference signal [-]; about 3 for a healthy gear."""
    return _normalised_moment("difference", difference, 4)


def m6a(difference: ArrayLike) -> float:
    """M6A (Martin 1989) = N^2 sum (d - dbar)^6 / (sum (d - dbar)^2)^3 of the difference signal [-]."""
    return _normalised_moment("difference", difference, 6)


def m8a(difference: ArrayLike) -> float:
    """M8A (Martin 1989) = N^3 sum (d - dbar)^8 / (sum (d - dbar)^2)^4 of the difference signal [-]."""
    return _normalised_moment("difference", difference, 8)


def _records(residual_records: Sequence[ArrayLike] | NDArray[np.float64]) -> list[NDArray[np.float64]]:
    if isinstance(residual_records, np.ndarray) and residual_records.ndim == 1:
        raise InputError(
            "residual_records must be a sequence of 1-D records (or a 2-D array, one record per row), "
            f"got a 1-D array of shape {residual_records.shape}; wrap a single record as [record]"
        )
    records = [_as_1d(f"residual_records[{j}]", r) for j, r in enumerate(residual_records)]
    if not records:
        raise InputError("residual_records must hold at least 1 record, got 0")
    return records


def na4_trend(residual_records: Sequence[ArrayLike] | NDArray[np.float64]) -> NDArray[np.float64]:
    """NA4 after each record M = 1, 2, ...: element M-1 is the NA4 of record M (see na4) [-]."""
    records = _records(residual_records)
    variances = np.empty(len(records))
    fourth = np.empty(len(records))
    for j, record in enumerate(records):
        variances[j], fourth[j] = _central_moments(f"residual_records[{j}]", record, 4)
    running_mean_variance = np.cumsum(variances) / np.arange(1, len(records) + 1)
    return fourth / running_mean_variance**2


def na4(residual_records: Sequence[ArrayLike] | NDArray[np.float64]) -> float:
    """NA4 (Zakrajsek, Townsend & Decker 1993, as in Lebold et al. 2000) of the last of M residual records.

    NA4 = N sum_i (r_iM - rbar_M)^4 / ( (1/M) sum_j sum_i (r_ij - rbar_j)^2 )^2: the fourth moment of the
    current (last) record over the square of the variance averaged over records 1 .. M (the run so far),
    so NA4 grows when damage raises the residual's variance, unlike the kurtosis. Computed with moments
    (mean over each record's own samples), which equals that formula when all records have N samples.
    Stationary Gaussian residuals give about 3; a single record gives its kurtosis.

    Args:
        residual_records: residual signals (one TSA revolution each, e.g. SynchronousAverage.residual())
            in time order, as a sequence of 1-D arrays or a 2-D array with one record per row.
    """
    return float(na4_trend(residual_records)[-1])


def energy_ratio(difference: ArrayLike, regular: ArrayLike) -> float:
    """Energy ratio (Swansson 1980) = RMS(difference) / RMS(regular) [-] (plain RMS; pass zero-mean
    signals such as SynchronousAverage.difference() and .regular())."""
    d = _as_1d("difference", difference, min_size=1)
    r = _as_1d("regular", regular, min_size=1)
    denominator = rms(r)
    if not denominator > 0.0:
        raise InputError("regular is all zero, the energy ratio is undefined")
    return rms(d) / denominator


def sideband_energy_ratio(
    spectrum_frequency_hz: ArrayLike,
    spectrum_amplitude: ArrayLike,
    mesh_hz: float,
    shaft_hz: float,
    n_sidebands: int = 6,
) -> float:
    """Sideband energy ratio SER = sum_{k=1..n} (A(f_m - k f_s) + A(f_m + k f_s)) / A(f_m) [-].

    The common definition (Hanson et al.): the amplitudes of the first ``n_sidebands`` sidebands on each
    side of the mesh frequency f_m, spaced by the shaft frequency f_s, over the amplitude at f_m. Each
    amplitude is read at the bin nearest its frequency (no peak search), so use an amplitude spectrum
    (e.g. spectrum.amplitude_spectrum) whose resolution is well below f_s. A healthy gear gives a small
    SER (sidebands much lower than the mesh line); it rises as the modulation grows.

    Args:
        spectrum_frequency_hz: increasing bin frequencies [Hz].
        spectrum_amplitude: amplitude per bin [signal units].
        mesh_hz: mesh frequency f_m [Hz].
        shaft_hz: frequency f_s of the shaft whose gear is assessed (the sideband spacing) [Hz].
        n_sidebands: number of sidebands taken on each side (>= 1).
    """
    f = _as_1d("spectrum_frequency_hz", spectrum_frequency_hz)
    a = _as_1d("spectrum_amplitude", spectrum_amplitude)
    if f.size != a.size:
        raise InputError(
            f"spectrum_frequency_hz and spectrum_amplitude must have equal lengths, got {f.size} and {a.size}"
        )
    step = np.diff(f)
    if np.any(step <= 0.0):
        raise InputError("spectrum_frequency_hz must be strictly increasing")
    if isinstance(n_sidebands, bool) or int(n_sidebands) != n_sidebands or n_sidebands < 1:
        raise InputError(f"n_sidebands must be a positive integer, got {n_sidebands!r}")
    resolution_hz = float(np.median(step))
    if not shaft_hz >= resolution_hz:
        raise InputError(
            f"shaft_hz must be >= the spectrum resolution {resolution_hz:.6g} Hz to separate the sidebands, "
            f"got {shaft_hz!r}"
        )
    low_hz, high_hz = mesh_hz - n_sidebands * shaft_hz, mesh_hz + n_sidebands * shaft_hz
    if not (low_hz >= f[0] - 0.5 * resolution_hz and high_hz <= f[-1] + 0.5 * resolution_hz):
        raise InputError(
            f"mesh_hz +- n_sidebands * shaft_hz = {low_hz:.6g} .. {high_hz:.6g} Hz must lie within the "
            f"spectrum {f[0]:.6g} .. {f[-1]:.6g} Hz (mesh_hz={mesh_hz!r}, shaft_hz={shaft_hz!r}, "
            f"n_sidebands={n_sidebands!r})"
        )

    def at(target_hz: float) -> float:
        return float(a[int(np.argmin(np.abs(f - target_hz)))])

    carrier = at(mesh_hz)
    if not carrier > 0.0:
        raise InputError(f"spectrum amplitude at mesh_hz={mesh_hz!r} is {carrier!r}, SER is undefined")
    k = np.arange(1, int(n_sidebands) + 1)
    sidebands = sum(at(mesh_hz - kk * shaft_hz) + at(mesh_hz + kk * shaft_hz) for kk in k)
    return float(sidebands / carrier)


@dataclass(frozen=True)
class ConditionIndicators:
    """The time-domain condition indicators of one gear, for reports (all dimensionless except rms and
    peak_to_peak, which are in signal units)."""

    rms: float
    """RMS of the TSA [signal units]."""
    peak_to_peak: float
    """Peak-to-peak of the TSA [signal units]."""
    crest_factor: float
    """Crest factor of the TSA [-]."""
    kurtosis: float
    """Kurtosis of the TSA [-]."""
    fm0: float
    """Peak-to-peak of the TSA over the sum of its mesh-order amplitudes [-]."""
    fm4: float
    """Kurtosis of the difference signal [-]."""
    m6a: float
    """Sixth normalised moment of the difference signal [-]."""
    m8a: float
    """Eighth normalised moment of the difference signal [-]."""
    na4: float
    """NA4 of the residual signal, normalised by the mean variance over the history given [-]."""
    energy_ratio: float
    """RMS(difference) / RMS(regular) [-]."""

    def as_dict(self) -> dict[str, float]:
        """The indicators as a name -> value dict."""
        return {name: float(value) for name, value in asdict(self).items()}


def condition_indicators(
    tsa_average: ArrayLike,
    difference: ArrayLike,
    residual: ArrayLike,
    regular: ArrayLike,
    teeth: int,
    residual_history: Sequence[ArrayLike] = (),
) -> ConditionIndicators:
    """All time-domain indicators of one gear from its TSA (one revolution) and derived signals.

    NA4 uses ``residual`` as the current record and ``residual_history`` (earlier records, oldest first)
    for the mean variance; without history it equals the kurtosis of ``residual``.
    """
    x = _as_1d("tsa_average", tsa_average)
    return ConditionIndicators(
        rms=rms(x),
        peak_to_peak=peak_to_peak(x),
        crest_factor=crest_factor(x),
        kurtosis=_normalised_moment("tsa_average", x, 4),
        fm0=fm0(x, teeth),
        fm4=fm4(difference),
        m6a=m6a(difference),
        m8a=m8a(difference),
        na4=na4([*residual_history, residual]),
        energy_ratio=energy_ratio(difference, regular),
    )


def condition_indicators_from_average(
    average: SynchronousAverage,
    shaft_orders: int = 2,
    residual_history: Sequence[ArrayLike] = (),
) -> ConditionIndicators:
    """condition_indicators of a SynchronousAverage (which must know its ``teeth``), with the regular,
    difference and residual signals derived with ``shaft_orders`` low shaft orders removed."""
    if average.teeth is None:
        raise InputError("average.teeth is required for the condition indicators, got None")
    return condition_indicators(
        average.average,
        average.difference(shaft_orders),
        average.residual(shaft_orders),
        average.regular(shaft_orders),
        average.teeth,
        residual_history=residual_history,
    )
