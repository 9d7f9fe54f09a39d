"""Power spectral density and labelled spectrum peaks: which line is which shaft order, mesh harmonic,
sideband or cross-modulation line.

A drive is described by its shafts (rotation frequencies) and gear meshes (mesh frequency and the two
shafts each mesh couples), :class:`KinematicSources`. :func:`kinematic_lines` turns that into a catalogue
of labelled frequencies; :func:`label_peaks` finds the prominent local maxima of an amplitude spectrum
and names each one after the catalogue lines within a tolerance. Peaks that no line explains are kept
with an empty label, so they stay visible. :func:`peaks_table`, :func:`peaks_to_rows` and
:func:`plot_labelled_spectrum` present the result.

Engine-free: works on any uniformly sampled 1-D signal, simulated or measured. matplotlib is imported
only inside :func:`plot_labelled_spectrum`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.ndimage import median_filter
from scipy.signal import find_peaks, welch

from gearbody.analysis.spectrum import Spectrum

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = [
    "GearMesh",
    "KinematicLine",
    "KinematicSources",
    "LabelledPeak",
    "Psd",
    "Shaft",
    "kinematic_lines",
    "label_peaks",
    "peaks_table",
    "peaks_to_rows",
    "plot_labelled_spectrum",
    "power_spectral_density",
]

LABEL_SEPARATOR = "; "
"""Joins several labels of one peak (not "/": "f_z1/2" already means half the mesh frequency)."""


def _is_real(value: object) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)


def _positive_frequency(name: str, value: float) -> float:
    if not (_is_real(value) and math.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a positive frequency [Hz], got {value!r}")
    return float(value)


def _count(name: str, value: int, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


# --- power spectral density -----------------------------------------------------------------------------


@dataclass(frozen=True)
class Psd:
    """One-sided power spectral density (Welch average of windowed, overlapping segments)."""

    frequency_hz: NDArray[np.float64]
    """Bin frequencies 0 .. sample_rate_hz / 2 [Hz]."""
    psd: NDArray[np.float64]
    """Power spectral density [signal units^2 / Hz]."""
    sample_rate_hz: float
    """Sample rate of the analysed signal [Hz]."""
    window: str
    """Window name passed to scipy.signal.get_window."""
    segment_samples: int
    """Samples per segment (one FFT)."""
    overlap_samples: int
    """Samples shared by consecutive segments (half a segment)."""
    n_averages: int
    """Number of segments averaged."""

    @property
    def resolution_hz(self) -> float:
        """Bin spacing sample_rate_hz / segment_samples [Hz]."""
        return self.sample_rate_hz / self.segment_samples

    @property
    def segment_s(self) -> float:
        """Segment duration [s]."""
        return self.segment_samples / self.sample_rate_hz


def _checked_signal(signal: ArrayLike, sample_rate_hz: float) -> NDArray[np.float64]:
    x = np.asarray(signal, dtype=float)
    if x.ndim != 1 or x.size < 2:
        raise ValueError(f"signal must be 1-D with at least 2 samples, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError("signal contains non-finite samples")
    _positive_frequency("sample_rate_hz", sample_rate_hz)
    return x


def power_spectral_density(
    signal: ArrayLike,
    sample_rate_hz: float,
    window: str | tuple = "hann",
    segment_s: float | None = None,
    detrend: bool | Literal["constant", "linear"] = "constant",
) -> Psd:
    """One-sided power spectral density by Welch's method (scipy.signal.welch, density scaling).

    The signal is cut into segments of ``segment_s`` overlapping by half a segment; each is detrended,
    multiplied by the window w[n] (periodic, M samples) and transformed, X = rfft(w x). The estimate is the
    mean over segments of ``2 |X|^2 / (sample_rate_hz * sum(w^2))`` [signal units^2 / Hz] (the DC bin and,
    for even M, the Nyquist bin are not doubled).

    Scaling: by Parseval, ``sum(psd) * resolution_hz`` equals the mean over segments of
    ``sum((w x)^2) / sum(w^2)``, the window-weighted mean square of the detrended signal; so the integral of
    the PSD over frequency is the variance. White noise of variance s^2 has PSD 2 s^2 / sample_rate_hz;
    a sine A sin(2 pi f t) integrated over its line (a few bins) gives A^2 / 2, its mean square, exactly
    when it completes an integer number (>= 2) of periods per Hann segment. The PSD does not depend on the
    segment length for noise; a line's peak PSD grows with it (its power sits in fewer, narrower bins).
    Use :func:`gearbody.analysis.spectrum.amplitude_spectrum` to read line amplitudes.

    Args:
        signal: samples in any unit (m/s^2, N, K_d, ...).
        sample_rate_hz: sample rate [Hz].
        window: window for scipy.signal.get_window ("hann", "boxcar", ("kaiser", 8), ...).
        segment_s: segment duration [s], between 2 samples and the whole signal; resolution 1 / segment_s.
            Default: a quarter of the signal, which gives 7 averages.
        detrend: True or "constant" removes each segment's mean, "linear" a least-squares line, False none.
    """
    x = _checked_signal(signal, sample_rate_hz)
    n = x.size
    if segment_s is None:
        nperseg = max(2, n // 4)
    else:
        if not (_is_real(segment_s) and math.isfinite(segment_s) and segment_s > 0):
            raise ValueError(f"segment_s must be a positive duration [s], got {segment_s!r}")
        nperseg = int(round(segment_s * sample_rate_hz))
        if not 2 <= nperseg <= n:
            raise ValueError(
                f"segment_s must lie in [{2 / sample_rate_hz:.6g}, {n / sample_rate_hz:.6g}] s "
                f"(2 samples .. the whole signal), got {segment_s!r} s = {nperseg} samples"
            )
    if detrend is True:
        detrend = "constant"
    if not (detrend is False or detrend in ("constant", "linear")):
        raise ValueError(f"detrend must be a bool, 'constant' or 'linear', got {detrend!r}")
    noverlap = nperseg // 2
    frequency_hz, psd = welch(
        x,
        fs=sample_rate_hz,
        window=window,
        nperseg=nperseg,
        noverlap=noverlap,
        detrend=detrend,
        return_onesided=True,
        scaling="density",
        average="mean",
    )
    return Psd(
        frequency_hz=np.asarray(frequency_hz, dtype=float),
        psd=np.asarray(psd, dtype=float),
        sample_rate_hz=float(sample_rate_hz),
        window=str(window),
        segment_samples=int(nperseg),
        overlap_samples=int(noverlap),
        n_averages=int(1 + (n - nperseg) // (nperseg - noverlap)),
    )


# --- kinematic line catalogue ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Shaft:
    """A rotating shaft: its lines are the orders m * rotation_hz."""

    name: str
    """Used in labels, e.g. "pinion" gives "1x pinion"."""
    rotation_hz: float
    """Rotation frequency [Hz]."""
    symbol: str = ""
    """Symbol in sideband labels; default "f_" + name with blanks as "_", e.g. "f_pinion"."""

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise ValueError(f"Shaft name must be a non-empty string, got {self.name!r}")
        object.__setattr__(self, "rotation_hz", _positive_frequency("Shaft rotation_hz", self.rotation_hz))
        if not self.symbol:
            object.__setattr__(self, "symbol", "f_" + "_".join(self.name.split()))


@dataclass(frozen=True)
class GearMesh:
    """A gear mesh: its lines are the harmonics k * mesh_hz, modulated by the rotation of both gears."""

    name: str
    """Its symbol in labels, e.g. "f_z1" gives "2 f_z1" and "f_z1 + f_pinion"."""
    mesh_hz: float
    """Mesh frequency = teeth * rotation frequency of either gear [Hz]."""
    shafts: tuple[str, str]
    """Names of the two shafts carrying the meshing gears (pinion's first)."""

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise ValueError(f"GearMesh name must be a non-empty string, got {self.name!r}")
        object.__setattr__(self, "mesh_hz", _positive_frequency("GearMesh mesh_hz", self.mesh_hz))
        shafts = tuple(self.shafts)
        if len(shafts) != 2 or shafts[0] == shafts[1]:
            raise ValueError(f"GearMesh shafts must name two different shafts, got {self.shafts!r}")
        object.__setattr__(self, "shafts", shafts)


@dataclass(frozen=True)
class KinematicSources:
    """The drive's shafts and gear meshes, the sources of the kinematic lines in its spectra."""

    shafts: tuple[Shaft, ...]
    meshes: tuple[GearMesh, ...] = ()

    def __post_init__(self) -> None:
        shafts, meshes = tuple(self.shafts), tuple(self.meshes)
        object.__setattr__(self, "shafts", shafts)
        object.__setattr__(self, "meshes", meshes)
        if not shafts:
            raise ValueError("shafts must hold at least one Shaft, got none")
        names = [s.name for s in shafts]
        if len(set(names)) < len(names):
            raise ValueError(f"shafts must have distinct names, got {names}")
        symbols = [s.symbol for s in shafts] + [m.name for m in meshes]
        if len(set(symbols)) < len(symbols):
            raise ValueError(f"shaft symbols and mesh names must be distinct, got {symbols}")
        for mesh in meshes:
            for shaft in mesh.shafts:
                if shaft not in names:
                    raise ValueError(f"mesh {mesh.name!r}: shaft {shaft!r} is not one of the shafts {names}")

    def shaft(self, name: str) -> Shaft:
        """The shaft called ``name``."""
        for s in self.shafts:
            if s.name == name:
                return s
        raise ValueError(f"name must be one of {[s.name for s in self.shafts]}, got {name!r}")

    @classmethod
    def gear_train(
        cls,
        input_hz: float,
        teeth: Sequence[tuple[int, int]],
        shaft_names: Sequence[str] | None = None,
    ) -> KinematicSources:
        """A train of parallel-axis stages from tooth numbers.

        Stage i has ``teeth[i] = (z_pinion, z_wheel)``; its pinion sits on shaft i, its wheel on shaft i + 1,
        so f_{i+1} = f_i z_pinion / z_wheel and the mesh "f_z{i+1}" runs at z_pinion f_i. Default shaft
        names: ("pinion", "wheel") for one stage, ("input", "intermediate", "output") for two,
        "shaft1", "shaft2", ... otherwise.
        """
        f = _positive_frequency("input_hz", input_hz)
        stages = [tuple(t) for t in teeth]
        if not stages:
            raise ValueError("teeth must hold at least one (z_pinion, z_wheel) pair, got none")
        for i, stage in enumerate(stages):
            if len(stage) != 2 or not all(
                isinstance(z, (int, np.integer)) and not isinstance(z, bool) and z >= 1 for z in stage
            ):
                raise ValueError(
                    f"teeth[{i}] must be a pair of positive integers (z_pinion, z_wheel), got {stage}"
                )
        if shaft_names is None:
            defaults = {1: ("pinion", "wheel"), 2: ("input", "intermediate", "output")}
            shaft_names = defaults.get(len(stages), tuple(f"shaft{i + 1}" for i in range(len(stages) + 1)))
        shaft_names = tuple(shaft_names)
        if len(shaft_names) != len(stages) + 1:
            raise ValueError(
                f"shaft_names must hold {len(stages) + 1} names (stages + 1), got {len(shaft_names)}"
            )
        shafts, meshes = [Shaft(shaft_names[0], f)], []
        for i, (z_pinion, z_wheel) in enumerate(stages):
            meshes.append(GearMesh(f"f_z{i + 1}", z_pinion * f, (shaft_names[i], shaft_names[i + 1])))
            f = f * z_pinion / z_wheel
            shafts.append(Shaft(shaft_names[i + 1], f))
        return cls(tuple(shafts), tuple(meshes))


Family = Literal["shaft", "mesh", "sideband", "cross"]


@dataclass(frozen=True)
class KinematicLine:
    """A labelled frequency where kinematics puts a spectral line."""

    frequency_hz: float
    """sum(order * frequency of its symbol) [Hz], > 0."""
    label: str
    """E.g. "2x wheel", "1 f_z1", "2 f_z1 - f_pinion", "f_z1 + f_z2"."""
    family: Family
    """"shaft" (shaft order), "mesh" (mesh harmonic), "sideband" (mesh harmonic +- shaft orders) or
    "cross" (harmonic of one mesh +- orders of another)."""
    orders: tuple[tuple[str, int], ...]
    """(symbol, integer order) terms, e.g. (("f_z1", 2), ("f_pinion", -1))."""


def _term(symbol: str, order: int, first: bool) -> str:
    size = abs(order)
    text = symbol if size == 1 else f"{size} {symbol}"
    if first:
        return text if order > 0 else f"-{text}"
    return f"{'+' if order > 0 else '-'} {text}"


def _combination_label(orders: tuple[tuple[str, int], ...]) -> str:
    """ "2 f_z1 - f_pinion": positive terms first, order 1 not written."""
    ordered = [t for t in orders if t[1] > 0] + [t for t in orders if t[1] < 0]
    return " ".join(_term(s, k, i == 0) for i, (s, k) in enumerate(ordered))


def kinematic_lines(
    sources: KinematicSources,
    f_max_hz: float,
    harmonics: int = 3,
    sidebands: int = 2,
    shaft_orders: int = 3,
) -> list[KinematicLine]:
    """Catalogue of kinematic lines in (0, f_max_hz], sorted by frequency.

    - "shaft": m f_shaft, m = 1 .. shaft_orders, labelled "1x pinion", "2x wheel", ...
    - "mesh": k f_z, k = 1 .. harmonics, labelled "1 f_z1", "2 f_z1", ...
    - "sideband": k f_z +- n f_shaft for both shafts of the mesh, n = 1 .. sidebands, labelled
      "f_z1 + 2 f_pinion", "2 f_z1 - f_wheel", ...
    - "cross": for every pair of meshes, k f_c +- n f_m with f_c the higher and f_m the lower mesh
      frequency, k = 1 .. harmonics, n = 1 .. sidebands, labelled "f_z1 - f_z2", ... A combination that
      comes out negative shows at its absolute value and is labelled accordingly ("2 f_z2 - f_z1").

    Lines of different origin may coincide (29 f_pinion is f_z1 for a 29-tooth pinion); all are kept.
    """
    if not isinstance(sources, KinematicSources):
        raise ValueError(f"sources must be a KinematicSources, got {type(sources).__name__}")
    f_max_hz = _positive_frequency("f_max_hz", f_max_hz)
    harmonics = _count("harmonics", harmonics, 1)
    sidebands = _count("sidebands", sidebands, 0)
    shaft_orders = _count("shaft_orders", shaft_orders, 0)
    frequency = {s.symbol: s.rotation_hz for s in sources.shafts}
    frequency.update({m.name: m.mesh_hz for m in sources.meshes})
    limit = f_max_hz * (1.0 + 1e-12)
    tiny = 1e-9 * max(frequency.values())
    lines: list[KinematicLine] = []

    def add(family: Family, orders: tuple[tuple[str, int], ...], label: str = "") -> None:
        f = sum(k * frequency[s] for s, k in orders)
        if f < 0:
            f, orders = -f, tuple((s, -k) for s, k in orders)
        if tiny < f <= limit:
            lines.append(KinematicLine(float(f), label or _combination_label(orders), family, orders))

    for shaft in sources.shafts:
        for m in range(1, shaft_orders + 1):
            add("shaft", ((shaft.symbol, m),), f"{m}x {shaft.name}")
    for mesh in sources.meshes:
        for k in range(1, harmonics + 1):
            add("mesh", ((mesh.name, k),), f"{k} {mesh.name}")
            for shaft_name in mesh.shafts:
                symbol = sources.shaft(shaft_name).symbol
                for n in range(1, sidebands + 1):
                    for sign in (1, -1):
                        add("sideband", ((mesh.name, k), (symbol, sign * n)))
    for i, first in enumerate(sources.meshes):
        for second in sources.meshes[i + 1 :]:
            carrier, modulation = (first, second) if first.mesh_hz >= second.mesh_hz else (second, first)
            for k in range(1, harmonics + 1):
                for n in range(1, sidebands + 1):
                    for sign in (1, -1):
                        add("cross", ((carrier.name, k), (modulation.name, sign * n)))
    lines.sort(key=lambda line: line.frequency_hz)
    return lines


# --- labelled peaks -------------------------------------------------------------------------------------


@dataclass(frozen=True)
class LabelledPeak:
    """A prominent local maximum of an amplitude spectrum and the kinematic lines that explain it."""

    frequency_hz: float
    """Frequency of the maximum bin [Hz]."""
    amplitude: float
    """Its amplitude [signal units] (the bin value: off-bin lines read low by the window's scalloping)."""
    prominence_db: float
    """20 log10(amplitude / local median amplitude) [dB]."""
    labels: tuple[str, ...]
    """Labels of the kinematic lines within the tolerance, nearest first; () if none explains the peak."""
    offset_hz: float
    """frequency_hz minus the nearest explaining line's frequency [Hz]; nan if unexplained."""

    @property
    def label(self) -> str:
        """The labels joined by "; ", "" if unexplained."""
        return LABEL_SEPARATOR.join(self.labels)

    @property
    def explained(self) -> bool:
        """At least one kinematic line lies within the tolerance."""
        return bool(self.labels)


def label_peaks(
    spectrum: Spectrum,
    lines: Sequence[KinematicLine],
    tolerance_hz: float | None = None,
    min_prominence_db: float = 6.0,
    max_peaks: int | None = 50,
    floor_bins: int = 32,
    f_max_hz: float | None = None,
) -> list[LabelledPeak]:
    """Prominent local maxima of ``spectrum``, each labelled with the kinematic lines near it.

    A peak is a local maximum (scipy.signal.find_peaks) whose amplitude is at least ``min_prominence_db``
    above the local floor, the median amplitude of the bins within +- ``floor_bins`` of it. Of those, the
    ``max_peaks`` most prominent are kept, returned in order of frequency. Bins 0 and 1 are not searched
    (DC and its leakage through the window). Each gets the labels of all
    ``lines`` within ``tolerance_hz`` (default 1.5 bins), nearest first; a peak no line explains gets no
    label (``labels == ()``, ``label == ""``) and stays in the list so it can be investigated.

    The threshold is relative to a noise floor: Rayleigh-distributed noise amplitudes exceed r times their
    median with probability 2^(-r^2), so at 6 dB (r = 2) about 6 % of noise bins qualify, at 10 dB 0.1 %,
    at 12 dB 0.002 %. On noisy spectra raise ``min_prominence_db`` or rely on ``max_peaks``.

    Args:
        spectrum: amplitude spectrum (:func:`gearbody.analysis.spectrum.amplitude_spectrum`).
        lines: kinematic lines (:func:`kinematic_lines`); may be empty.
        tolerance_hz: largest |peak - line| frequency distance for a label [Hz], default 1.5 resolution_hz.
        min_prominence_db: least amplitude over the local floor [dB], >= 0.
        max_peaks: most peaks returned (the most prominent), None for all.
        floor_bins: half-width of the band whose median amplitude is the local floor [bins], >= 1.
        f_max_hz: ignore peaks above this frequency [Hz]; None for all up to Nyquist.
    """
    if not isinstance(spectrum, Spectrum):
        raise ValueError(f"spectrum must be a Spectrum, got {type(spectrum).__name__}")
    f = np.asarray(spectrum.frequency_hz, dtype=float)
    a = np.asarray(spectrum.amplitude, dtype=float)
    if a.ndim != 1 or a.size < 3 or f.shape != a.shape:
        raise ValueError(f"spectrum must hold at least 3 bins, got amplitude shape {a.shape}")
    df = spectrum.resolution_hz
    if tolerance_hz is None:
        tolerance_hz = 1.5 * df
    else:
        tolerance_hz = _positive_frequency("tolerance_hz", tolerance_hz)
    if not (_is_real(min_prominence_db) and math.isfinite(min_prominence_db) and min_prominence_db >= 0):
        raise ValueError(f"min_prominence_db must be a finite number >= 0 [dB], got {min_prominence_db!r}")
    if max_peaks is not None:
        max_peaks = _count("max_peaks", max_peaks, 1)
    floor_bins = _count("floor_bins", floor_bins, 1)
    if f_max_hz is not None:
        f_max_hz = _positive_frequency("f_max_hz", f_max_hz)
    lines = list(lines)
    for i, line in enumerate(lines):
        if not isinstance(line, KinematicLine):
            raise ValueError(f"lines[{i}] must be a KinematicLine, got {type(line).__name__}")

    floor = median_filter(a, size=2 * floor_bins + 1, mode="reflect")
    index, _ = find_peaks(a, height=floor * 10.0 ** (min_prominence_db / 20.0))
    index = index[index >= 2]  # bin 1 holds the window's leakage of the DC bin (the record's residual mean)
    if f_max_hz is not None:
        index = index[f[index] <= f_max_hz]
    with np.errstate(divide="ignore"):
        prominence_db = 20.0 * np.log10(a[index] / floor[index])
    keep = np.argsort(-prominence_db, kind="stable")[:max_peaks]
    keep = np.sort(keep)

    line_hz = np.array([line.frequency_hz for line in lines], dtype=float)
    within_hz = tolerance_hz * (1.0 + 1e-9)
    out = []
    for j in keep:
        peak_hz = float(f[index[j]])
        distance_hz = peak_hz - line_hz
        near = np.flatnonzero(np.abs(distance_hz) <= within_hz)
        near = near[np.argsort(np.abs(distance_hz[near]), kind="stable")]
        out.append(
            LabelledPeak(
                frequency_hz=peak_hz,
                amplitude=float(a[index[j]]),
                prominence_db=float(prominence_db[j]),
                labels=tuple(lines[i].label for i in near),
                offset_hz=float(distance_hz[near[0]]) if near.size else float("nan"),
            )
        )
    return out


# --- presentation ---------------------------------------------------------------------------------------


def _checked_peaks(peaks: Sequence[LabelledPeak]) -> list[LabelledPeak]:
    peaks = list(peaks)
    for i, peak in enumerate(peaks):
        if not isinstance(peak, LabelledPeak):
            raise ValueError(f"peaks[{i}] must be a LabelledPeak, got {type(peak).__name__}")
    return peaks


UNEXPLAINED = "(unexplained)"
"""What :func:`peaks_table` shows in the label column of a peak no kinematic line explains."""


def peaks_table(peaks: Sequence[LabelledPeak], unit: str = "", max_rows: int | None = None) -> str:
    """Plain-text table of labelled peaks, one row each, in the given order.

    Columns: f [Hz], amplitude [unit], prominence [dB], label, offset [Hz] (peak minus the nearest
    explaining line). Unexplained peaks read "(unexplained)" with no offset. With ``max_rows`` only the
    most prominent rows are shown (still in the given order) and a last line counts those left out.
    """
    peaks = _checked_peaks(peaks)
    if max_rows is not None:
        max_rows = _count("max_rows", max_rows, 0)
    shown = peaks
    if max_rows is not None and len(peaks) > max_rows:
        order = sorted(range(len(peaks)), key=lambda i: -peaks[i].prominence_db)[:max_rows]
        shown = [peaks[i] for i in sorted(order)]
    header = [
        "f [Hz]",
        f"amplitude [{unit}]" if unit else "amplitude",
        "prominence [dB]",
        "label",
        "offset [Hz]",
    ]
    rows = [
        [
            f"{p.frequency_hz:.3f}",
            f"{p.amplitude:.4g}",
            f"{p.prominence_db:.1f}",
            p.label or UNEXPLAINED,
            "" if math.isnan(p.offset_hz) else f"{p.offset_hz:+.3f}",
        ]
        for p in shown
    ]
    widths = [max(len(r[c]) for r in [header, *rows]) for c in range(len(header))]
    left = {3}  # labels left-aligned, numbers right-aligned

    def line(cells: list[str]) -> str:
        return "  ".join(
            cell.ljust(w) if c in left else cell.rjust(w)
            for c, (cell, w) in enumerate(zip(cells, widths, strict=True))
        ).rstrip()

    text = [line(header), line(["-" * w for w in widths]), *(line(r) for r in rows)]
    if len(shown) < len(peaks):
        text.append(f"({len(peaks) - len(shown)} less prominent peaks not shown)")
    return "\n".join(text)


def peaks_to_rows(peaks: Sequence[LabelledPeak]) -> list[dict[str, float | str | None]]:
    """One flat dict per peak for csv.DictWriter or json.dumps.

    Keys: frequency_hz, amplitude, prominence_db, label (labels joined by "; ", "" if unexplained),
    offset_hz. Non-finite numbers (no offset, infinite prominence over a zero floor) become None.
    """

    def finite(x: float) -> float | None:
        return float(x) if math.isfinite(x) else None

    return [
        {
            "frequency_hz": p.frequency_hz,
            "amplitude": p.amplitude,
            "prominence_db": finite(p.prominence_db),
            "label": p.label,
            "offset_hz": finite(p.offset_hz),
        }
        for p in _checked_peaks(peaks)
    ]


def plot_labelled_spectrum(
    spectrum: Spectrum,
    peaks: Sequence[LabelledPeak],
    ax: Axes | None = None,
    title: str = "",
    unit: str = "",
    f_max_hz: float | None = None,
    log: bool = True,
) -> Axes:
    """Amplitude spectrum with its peaks marked: explained peaks with their labels (rotated, small, red),
    unexplained ones in grey with their frequency.

    Draws into ``ax``, or into a new Agg figure (no pyplot, global backend untouched) when None; returns
    the axes (``ax.figure.savefig(...)`` writes it). matplotlib is imported here only.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    if not isinstance(spectrum, Spectrum):
        raise ValueError(f"spectrum must be a Spectrum, got {type(spectrum).__name__}")
    peaks = _checked_peaks(peaks)
    if f_max_hz is not None:
        f_max_hz = _positive_frequency("f_max_hz", f_max_hz)
    if ax is None:
        fig = Figure(figsize=(10, 6), dpi=100, layout="constrained")
        FigureCanvasAgg(fig)
        ax = fig.add_subplot()
    f = np.asarray(spectrum.frequency_hz, dtype=float)
    a = np.asarray(spectrum.amplitude, dtype=float)
    keep = f <= (f_max_hz if f_max_hz is not None else f[-1])
    if log:
        a = np.where(a > 0, a, np.nan)
    ax.plot(f[keep], a[keep], linewidth=0.6, color="tab:blue")
    shown = [p for p in peaks if f_max_hz is None or p.frequency_hz <= f_max_hz]
    for p in shown:
        colour = "tab:red" if p.explained else "0.5"
        text = p.label if p.explained else f"{p.frequency_hz:.1f} Hz"
        ax.plot([p.frequency_hz], [p.amplitude], marker="v", markersize=3, linestyle="none", color=colour)
        ax.annotate(
            text,
            (p.frequency_hz, p.amplitude),
            xytext=(0, 5),
            textcoords="offset points",
            rotation=90,
            fontsize=6,
            ha="center",
            va="bottom",
            color=colour,
        )
    if log:
        ax.set_yscale("log")
    top = np.nanmax(a[keep]) if np.any(np.isfinite(a[keep])) else None
    if top is not None and top > 0:
        ax.set_ylim(top=top * (300.0 if log else 1.4))  # room for the rotated labels
    ax.set_xlim(0.0, f_max_hz if f_max_hz is not None else f[-1])
    ax.set_xlabel("Frequency f [Hz]")
    ax.set_ylabel(f"Amplitude [{unit}]" if unit else "Amplitude")
    if title:
        ax.set_title(title)
    return ax
