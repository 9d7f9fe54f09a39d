"""One recording, the analysis a simulated run gets: per channel the labelled spectrum in Hz and in
orders, synchronous averages of every gear's shaft with the condition indicators, the fault bands, the
kurtogram's band and the envelope spectrum in it with the bearing lines, and cepstral peaks of the shaft
families. A :class:`Diagnosis` holds it all; ``features()`` flattens it into named numbers (what
``gearbody compare`` sets side by side and what calibration can take as targets)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..analysis import Spectrum, amplitude_spectrum, condition_indicators_from_average, label_peaks
from ..errors import InputError
from ..recording import Recording
from .bands import BandMetric, band_metrics
from .drive import DriveKinematics
from .speed import ShaftAngles, shaft_angles

__all__ = ["ChannelDiagnosis", "Diagnosis", "analyze_recording"]

KURTOGRAM_SAMPLES = 1 << 20
"""The kurtogram chooses the band from the first 2^20 samples at most (21 s at 50 kHz: kurtosis
estimates settle long before; the envelope spectrum then takes the whole record in that band)."""
MIN_TSA_REVOLUTIONS = 3
MIN_ENVELOPE_SAMPLES = 4096
"""Fewest samples for the kurtogram's levels and an envelope spectrum worth reading."""
TSA_ORDERS = 4
"""The tracked band (orders of the input shaft) over the labelled one: the averages keep 4 x 6.5 mesh
harmonics."""
HARMONICS = 6


def axis_spectrum(axis, amplitude, window: str) -> Spectrum:
    """A :class:`Spectrum` on a uniform ``axis`` from 0 (Hz, or orders), its resolution the axis step."""
    axis = np.asarray(axis, dtype=float)
    n = 2 * (axis.size - 1)
    return Spectrum(axis, np.asarray(amplitude, dtype=float), float(axis[1] - axis[0]) * n, str(window), n)


def truncated(spec: Spectrum, top: float) -> Spectrum:
    """``spec`` up to ``top`` (and 64 bins): what is labelled and drawn, not every bin of a long record."""
    k = int(np.searchsorted(spec.frequency_hz, top, side="right")) + 64
    return replace(spec, frequency_hz=spec.frequency_hz[:k].copy(), amplitude=spec.amplitude[:k].copy())


@dataclass
class ChannelDiagnosis:
    """What one channel shows (amplitudes in the channel's SI unit)."""

    name: str
    unit: str
    spectrum: Spectrum
    peaks: list
    order_spectrum: Spectrum | None = None
    """Amplitude over orders of the input shaft (``frequency_hz`` holds orders)."""
    order_peaks: list = field(default_factory=list)
    averages: dict[str, Any] = field(default_factory=dict)
    """Body -> SynchronousAverage of the channel over that body's revolutions."""
    indicators: dict[str, dict[str, float]] = field(default_factory=dict)
    bands: list[BandMetric] = field(default_factory=list)
    kurtogram: Any = None
    envelope: Any = None
    envelope_peaks: list = field(default_factory=list)
    envelope_bands: list[BandMetric] = field(default_factory=list)
    cepstral_peaks: dict[str, float] = field(default_factory=dict)
    rpm_order_map: Any = None
    """Amplitude over (speed, order) when the speed varies by more than 5 % (a run-up)."""
    prewhitened: bool = False
    """True when the kurtogram and the envelope spectrum are of the cepstrum-prewhitened channel."""
    notes: list[str] = field(default_factory=list)

    def envelope_spectrum(self) -> Spectrum | None:
        """The envelope spectrum as a :class:`Spectrum` (None when not computed)."""
        if self.envelope is None:
            return None
        return axis_spectrum(self.envelope.frequency_hz, self.envelope.amplitude, self.envelope.window)

    def features(self) -> dict[str, float]:
        """Named numbers (computed once): see :meth:`_features`."""
        if self._features_cache is None:
            self._features_cache = self._features()
        return dict(self._features_cache)

    def _features(self) -> dict[str, float]:
        """Named numbers: ``rms``, ``kurtosis``, ``crest_factor`` of the channel; ``<indicator>:<body>``;
        ``band_peak:<line>`` and ``band_power:<line>`` (order domain); ``envelope_peak:<line>``;
        ``cepstrum:<body>``."""
        from ..analysis import crest_factor, kurtosis, rms

        x = self._signal
        out = {"rms": rms(x), "kurtosis": kurtosis(x), "crest_factor": crest_factor(x)}
        for body, values in self.indicators.items():
            out.update({f"{k}:{body}": v for k, v in values.items()})
        for b in self.bands:
            out[f"band_peak:{b.label}"] = b.peak_amplitude
            out[f"band_power:{b.label}"] = b.band_power
        for b in self.envelope_bands:
            out[f"envelope_peak:{b.label}"] = b.peak_amplitude
        out.update({f"cepstrum:{body}": v for body, v in self.cepstral_peaks.items()})
        return {k: float(v) for k, v in out.items()}

    _signal: np.ndarray = field(default=None, repr=False)
    _features_cache: dict | None = field(default=None, repr=False)


@dataclass
class Diagnosis:
    """The analysis of a recording of a drive: its shaft angles and one :class:`ChannelDiagnosis` per
    analysed channel."""

    recording: Recording
    drive: DriveKinematics
    angles: ShaftAngles
    channels: dict[str, ChannelDiagnosis]
    notes: list[str] = field(default_factory=list)

    @property
    def mean_input_hz(self) -> float:
        return self.angles.mean_input_hz()

    def features(self) -> dict[str, float]:
        """Every channel's features as ``<channel>/<feature>``, plus ``input_speed_hz``."""
        out = {"input_speed_hz": self.mean_input_hz}
        for name, ch in self.channels.items():
            out.update({f"{name}/{k}": v for k, v in ch.features().items()})
        return out


def analyze_recording(
    recording: Recording,
    drive: DriveKinematics,
    channels: Sequence[str] | None = None,
    *,
    envelope: bool = True,
    kurtogram_level: int = 6,
    prewhiten: bool = False,
) -> Diagnosis:
    """The :class:`Diagnosis` of ``channels`` (default: a simulated recording's vibration signal, else the
    recording's vibration channels, at most 4)
    with the drive's kinematics ``drive`` (:meth:`DriveKinematics.from_scenario`); ``prewhiten``: the
    kurtogram and the envelope spectrum of the cepstrum-prewhitened channel (deterministic lines
    removed: the bearing's impacts stand out over the gears' tones; amplitudes then relative)."""
    if channels:
        names = list(channels)
    elif recording.meta.get("vibration_channel") in recording:  # a run: the signal its own report reads
        names = [recording.meta["vibration_channel"]]
    else:
        names = recording.vibration_channels[:4]
    if not names:
        raise InputError(f"the recording has no vibration channel; channels: {', '.join(recording.names)}")
    for name in names:
        recording.channel(name)  # a SignalError naming the channels there are
    angles = shaft_angles(recording, drive)
    diag = Diagnosis(recording, drive, angles, {})
    if angles.note:
        diag.notes.append(angles.note)
    constant = [n for n in names if np.ptp(recording[n]) == 0]
    if len(constant) == len(names):
        raise InputError(f"every channel asked for is constant (a dead sensor?): {', '.join(constant)}")
    live = []
    for name in names:
        data = recording[name]
        if not np.all(np.isfinite(data)):
            raise InputError(
                f"channel {name!r} holds {np.count_nonzero(~np.isfinite(data))} NaN or infinite samples"
            )
        if np.ptp(data) == 0:  # a dead sensor or an unconnected input: said, not analysed
            diag.notes.append(
                f"channel {name!r} is constant ({data[0]:g} {recording.channel(name).unit}): not analysed"
            )
        else:
            live.append(name)

    def one(name: str) -> ChannelDiagnosis:
        return _channel(recording, name, angles, envelope, kurtogram_level, prewhiten)

    # one channel after another: two at once (threads) were 15 % faster on two cores but 20 % over the
    # memory a 60 s, 50 kHz, 4-channel recording may take (benchmarks/bench_recording.py)
    diag.channels.update((name, one(name)) for name in live)
    return diag


def _channel(recording: Recording, name: str, angles: ShaftAngles, envelope: bool, level: int, white: bool):
    ch = recording.channel(name)
    x, fs, drive = ch.data, recording.sample_rate_hz, angles.drive
    f_in = angles.mean_input_hz()
    spec = amplitude_spectrum(x, fs, window="hann")
    f_top = max((abs(drive.speed_ratios[g.body]) * g.teeth for g in drive.gears if g.teeth), default=1.0)
    f_max = min(fs / 2, (HARMONICS + 0.5) * f_top * f_in)
    lines_hz = drive.lines(f_in, f_max)
    peaks = label_peaks(spec, lines_hz, min_prominence_db=12.0, max_peaks=40, f_max_hz=f_max)
    out = ChannelDiagnosis(name, ch.unit, truncated(spec, f_max), peaks, _signal=x)
    _orders(out, x, fs, angles, f_max / f_in)
    if envelope and x.size < MIN_ENVELOPE_SAMPLES:
        out.notes.append(
            f"no kurtogram and no envelope spectrum: {x.size} samples (they need {MIN_ENVELOPE_SAMPLES})"
        )
    elif envelope:
        if white:
            from ..analysis import cepstrum_prewhiten

            out.prewhitened = True
        _envelope(out, cepstrum_prewhiten(x) if white else x, fs, angles, level)
    return out


def _orders(out: ChannelDiagnosis, x, fs, angles: ShaftAngles, max_order: float) -> None:
    """The channel tracked once on the input shaft's angle (its whole band): the order spectrum up to
    ``max_order`` with its labels and fault bands, and from the same tracked signal the synchronous
    average of every gear's shaft (:mod:`.averages`)."""
    from ..analysis.order_maps import order_spectrum
    from ..analysis.orders import order_track
    from .averages import shaft_average

    revs = (angles.input_angle_rad[-1] - angles.input_angle_rad[0]) / (2 * np.pi)
    if revs < MIN_TSA_REVOLUTIONS:
        out.notes.append(
            f"no order spectrum and no averages: the input shaft turns {revs:.1f} revolutions "
            f"(needs {MIN_TSA_REVOLUTIONS})"
        )
        return
    # the band of the averages: TSA_ORDERS times the labelled orders (dozens of mesh harmonics), or what
    # the lowest speed's Nyquist order allows (order_track's default)
    f_lowest = float(np.min(np.diff(angles.input_angle_rad))) * fs / (2 * np.pi)
    nyquist_order = 0.8 * (fs / 2) / max(f_lowest, 1e-9) / 1.25
    try:
        tracked = order_track(
            x, fs, angles.input_angle_rad, max_order=min(TSA_ORDERS * max_order, nyquist_order)
        )
    except InputError:  # a wide speed range: the grid that band needs is over order_track's cap
        tracked = order_track(x, fs, angles.input_angle_rad)
    ospec = order_spectrum(tracked)
    spec = axis_spectrum(ospec.order, ospec.amplitude, ospec.window)
    top = min(max_order, float(spec.frequency_hz[-1]))
    lines = angles.drive.lines(1.0, top)
    out.order_spectrum = truncated(spec, top)
    out.order_peaks = label_peaks(spec, lines, min_prominence_db=12.0, max_peaks=40, f_max_hz=top)
    out.bands = band_metrics(spec, lines)
    _rpm_map(out, x, fs, angles, top, revs)
    drive = angles.drive
    for gear in drive.gears:
        ratio = abs(drive.ratio(gear.body, drive.input_body))
        n = revs * ratio
        if n < MIN_TSA_REVOLUTIONS or gear.teeth is None:
            out.notes.append(f"no synchronous average of {gear.body}: {n:.1f} revolutions (needs 3)")
            continue
        tsa = shaft_average(tracked, ratio, gear.teeth)
        out.averages[gear.body] = tsa
        out.indicators[gear.body] = condition_indicators_from_average(tsa).as_dict()
        out.cepstral_peaks[gear.body] = _cepstral(x, angles, gear.body)


SPEED_RANGE_FOR_MAP = 1.05
"""Highest over lowest speed (per revolution) above which the report shows the rpm-order map."""


def _rpm_map(out: ChannelDiagnosis, x, fs, angles: ShaftAngles, max_order: float, revs: float) -> None:
    from ..analysis import rpm_order_map

    per_rev = np.diff(
        np.interp(
            np.arange(
                np.ceil(angles.input_angle_rad[0] / (2 * np.pi)), angles.input_angle_rad[-1] / (2 * np.pi)
            )
            * 2
            * np.pi,
            angles.input_angle_rad,
            angles.time_s,
        )
    )
    if per_rev.size < 8 or per_rev.max() / per_rev.min() < SPEED_RANGE_FOR_MAP:
        return
    block = int(np.clip(revs // 60, 2, 32))
    try:
        out.rpm_order_map = rpm_order_map(
            x, fs, angles.input_angle_rad, revolutions_per_block=block, max_order=max_order
        )
    except InputError as exc:  # the speed range too wide for the band: said, not drawn
        out.notes.append(f"no rpm-order map: {exc}")


def _cepstral(x, angles: ShaftAngles, body: str) -> float:
    from ..analysis.cepstrum import cepstral_peak

    fs = 1.0 / float(angles.time_s[1] - angles.time_s[0])
    shaft_hz = angles.mean_input_hz() * abs(angles.drive.ratio(body, angles.drive.input_body))
    return float(cepstral_peak(x, fs, shaft_hz).prominence)


USABLE_BAND = 0.8
"""Share of the Nyquist band the kurtogram may choose from: a logger's anti-alias filter (and a run's
band-limited output) leave the top of the band to filter edges, whose ringing a kurtogram would pick."""


def _within(kurt, fs: float):
    """``kurt`` with its best band chosen among the bands below :data:`USABLE_BAND` of the Nyquist band."""
    from dataclasses import replace

    best = (-np.inf, kurt.level, kurt.centre_hz, kurt.bandwidth_hz)
    for row, level in enumerate(kurt.levels):
        centres, values = kurt.band_values(row)
        width = fs / 2 / kurt.n_bands[row]
        for centre, value in zip(centres, values, strict=True):
            if centre + width / 2 <= USABLE_BAND * fs / 2 + 1e-9 and value > best[0]:
                best = (float(value), float(level), float(centre), float(width))
    if not np.isfinite(best[0]):
        return kurt
    return replace(kurt, max_kurtosis=best[0], level=best[1], centre_hz=best[2], bandwidth_hz=best[3])


def _envelope(out: ChannelDiagnosis, x, fs, angles: ShaftAngles, level: int) -> None:
    from ..analysis.envelope import envelope_spectrum
    from ..analysis.kurtogram import fast_kurtogram

    head = x[:KURTOGRAM_SAMPLES]
    if head.size < x.size:
        out.notes.append(f"the kurtogram chose its band from the first {head.size / fs:.3g} s of the record")
    kurt = _within(fast_kurtogram(head, fs, max_level=min(level, max(1, int(np.log2(head.size)) - 7))), fs)
    out.kurtogram = kurt
    band = kurt.band_hz
    f_in = angles.mean_input_hz()
    env = envelope_spectrum(x, fs, band_hz=band, convention="squared", max_frequency_hz=kurt.bandwidth_hz / 2)
    out.envelope = env
    spec = axis_spectrum(env.frequency_hz, env.amplitude, env.window)
    f_max = min(float(spec.frequency_hz[-1]), kurt.bandwidth_hz / 2)
    lines = angles.drive.lines(f_in, f_max)
    out.envelope_peaks = label_peaks(spec, lines, min_prominence_db=12.0, max_peaks=20, f_max_hz=f_max)
    out.envelope_bands = band_metrics(spec, lines, families=("bearing",))
