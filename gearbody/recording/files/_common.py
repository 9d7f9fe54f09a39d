"""What every reader and writer of :mod:`gearbody.recording.files` shares: the read request (options,
window, channel choice), gearbody's own description of a recording (JSON, exact), the checks of a
foreign file's samples, time column and units, and the optional libraries' import."""

from __future__ import annotations

import importlib
import json
import math
import os
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import InputError
from ..channel import UNIT_SCALE, Channel
from ..container import MAX_SAMPLE_RATE_HZ, Recording
from ..tacho import Tacho

MARK = "gearbody-recording"
"""What our own files carry (a header, a chunk, an attribute) to say they hold a gearbody description."""
VERSION = 1

TIME_NAMES = ("time_s", "time", "t", "times", "time [s]", "time (s)", "t [s]", "t (s)", "timestamp")
"""Names of a time column or vector (compared case-insensitively)."""
RATE_NAMES = ("fs", "Fs", "FS", "sample_rate", "sample_rate_hz", "SampleRate", "sampling_rate", "srate")
"""Names of a sample-rate variable, attribute or property."""
UNIFORM_RTOL = 1e-6
"""A time column is uniform when every instant lies within this fraction of a step of its grid."""


def memory_limit_bytes() -> int:
    """The most a reader allocates for a recording's float64 samples: half the machine's memory (8 GiB
    when it cannot be found)."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") // 2)
    except (ValueError, OSError, AttributeError):
        return 8 << 30


def check_size(n_samples: int, n_channels: int) -> None:
    """An InputError before allocating more than :func:`memory_limit_bytes` (a header claiming absurd
    sizes, or a file to read by parts with ``start_s``/``end_s``/``channels``)."""
    need = 8 * int(n_samples) * int(n_channels)
    if need > memory_limit_bytes():
        raise InputError(
            f"{n_channels} channel(s) of {n_samples} samples need {need / 2**30:.3g} GiB as float64, more "
            f"than half this machine's memory ({memory_limit_bytes() / 2**30:.3g} GiB); read a part with "
            "start_s=/end_s= or channels="
        )


def need(module: str, fmt: str, extra: str = "files") -> Any:
    """The optional library ``module``, or an InputError saying which extra installs it."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise InputError(
            f'format {fmt!r} needs the optional library {module!r}: pip install "gearbody[{extra}]"'
        ) from None


@dataclass
class ReadRequest:
    """The options of :func:`~gearbody.recording.files.read_recording` a reader uses."""

    path: Path
    format: str
    sample_rate_hz: float | None = None
    channels: Sequence[str] | None = None
    units: Mapping[str, str] | None = None
    calibration: float | Sequence[float] | None = None
    tacho_channel: str | None = None
    start_s: float | None = None
    end_s: float | None = None

    def refuse_for_own(self) -> None:
        """Our own files hold their rate, units and calibration: options that would change them are errors."""
        given = [k for k in ("sample_rate_hz", "units", "calibration") if getattr(self, k) is not None]
        if given:
            raise InputError(
                f"{', '.join(f'{k}=' for k in given)}: the file is a gearbody recording, which holds its own "
                "sample rate, units and calibration; leave these options out"
            )

    def wanted(self, available: Iterable[str], tacho_channel: str = "") -> list[str]:
        """The channels to read, in the file's order: ``channels=`` (each must be there) plus the tacho's
        channel (the file's own or ``tacho_channel=``); every channel when ``channels`` is None."""
        available = list(available)
        asked = [] if self.channels is None else list(self.channels)
        for extra in (self.tacho_channel, tacho_channel):
            if extra and extra not in asked and self.channels is not None:
                asked.append(extra)
        for name in [*asked, *([self.tacho_channel] if self.tacho_channel else [])]:
            if name not in available:
                raise InputError(
                    f"channel {name!r} (channels=/tacho_channel=) is not in the file; its channels: "
                    f"{', '.join(available)}"
                )
        if self.units:
            missing = [name for name in self.units if name not in available]
            if missing:
                raise InputError(
                    f"units= names {missing[0]!r}, not a channel of the file; its channels: "
                    f"{', '.join(available)}"
                )
        return available if self.channels is None else [n for n in available if n in asked]

    def window(self, n_samples: int, fs: float, t0: float) -> tuple[int, int, float]:
        """``(lo, hi, t0 of sample lo)``: the samples of ``start_s <= t < end_s`` as
        :meth:`Recording.window` picks them (the whole file when neither is given)."""
        lo = 0 if self.start_s is None else _first_at_or_after(self.start_s - 0.5 / fs, n_samples, fs, t0)
        hi = n_samples if self.end_s is None else _first_at_or_after(self.end_s - 0.5 / fs, n_samples, fs, t0)
        if hi - lo < 2:
            last = t0 + (n_samples - 1) / fs
            raise InputError(
                f"start_s={self.start_s!r}, end_s={self.end_s!r}: the window holds {max(hi - lo, 0)} samples "
                f"of the file ({t0:.6g}..{last:.6g} s); needs at least 2"
            )
        return lo, hi, (t0 + lo / fs if lo else t0)

    def unit_of(self, name: str, found: str = "") -> str:
        """A foreign channel's unit: ``units[name]``, else what the file says (``found``), checked."""
        unit = found
        if self.units and name in self.units:
            given = self.units[name]
            if found and found != given and UNIT_SCALE.get(found) != UNIT_SCALE.get(given):
                raise InputError(f"units[{name!r}] = {given!r}, but the file gives its unit as {found!r}")
            unit = given
        if unit not in UNIT_SCALE:
            known = ", ".join(repr(u) for u in UNIT_SCALE)
            raise InputError(
                f"channel {name!r}: unit {unit!r} is not a known unit; give units={{{name!r}: ...}} with one "
                f"of {known}"
            )
        return unit


def _first_at_or_after(x: float, n: int, fs: float, t0: float) -> int:
    """The first k in 0..n with ``t0 + k / fs >= x`` (n when none), as ``np.searchsorted`` on the grid."""
    if not math.isfinite(x):
        raise InputError(f"start_s/end_s = {x!r}: must be finite")
    k = min(max(math.ceil((x - t0) * fs), 0), n)
    while k > 0 and t0 + (k - 1) / fs >= x:
        k -= 1
    while k < n and t0 + k / fs < x:
        k += 1
    return k


# -- our own description: everything but the samples, as exact JSON --------------------------------------
def _jsonable(obj: Any) -> Any:
    if isinstance(obj, Mapping):
        return dict(obj)
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, (Path, tuple, set)):
        return str(obj) if isinstance(obj, Path) else list(obj)
    raise InputError(
        f"recording meta holds a {type(obj).__name__}, which a file cannot hold (JSON types only)"
    )


def describe(recording: Recording) -> dict[str, Any]:
    """The recording's description (:meth:`Recording.describe`) with the tacho's pulse times, marked."""
    if not isinstance(recording, Recording):
        raise InputError(
            f"recording: a gearbody.recording.Recording is needed, got {type(recording).__name__}"
        )
    out = {"format": MARK, "version": VERSION, **recording.describe()}
    if recording.tacho is not None and recording.tacho.pulse_times_s is not None:
        out["tacho"]["pulse_times_s"] = recording.tacho.pulse_times_s
    return out


def check_writable(recording: Recording) -> None:
    """Every sample finite (what the readers accept), before a file is written."""
    for name, ch in recording.channels.items():
        check_finite(name, ch.data)


def to_json(description: Mapping[str, Any]) -> str:
    """One line of JSON, floats as their shortest exact repr (they read back bit-exact)."""
    return json.dumps(description, default=_jsonable, separators=(",", ":"), allow_nan=True)


def from_json(text: str | bytes) -> dict[str, Any]:
    """A description read back, checked to be ours (InputError when it is not)."""
    try:
        out = json.loads(text)
    except (ValueError, UnicodeDecodeError) as exc:
        raise InputError(f"the gearbody description is not valid JSON ({exc})") from None
    if not isinstance(out, dict) or out.get("format") != MARK or not isinstance(out.get("channels"), list):
        raise InputError("the gearbody description is damaged (no channel list)")
    if out.get("version", 0) > VERSION:
        raise InputError(f"written by a newer gearbody (description version {out['version']} > {VERSION})")
    return out


def own_recording(
    desc: Mapping[str, Any], read: Callable[[int, str, int, int], np.ndarray], req: ReadRequest
) -> Recording:
    """The recording a description and its samples make: ``read(index, name, lo, hi)`` gives channel
    ``index``'s samples ``lo:hi`` (float64). Checks the rate and length the description states."""
    req.refuse_for_own()
    n = desc.get("n_samples")
    if not isinstance(n, int) or n < 2:
        raise InputError(f"the gearbody description gives n_samples = {n!r}")
    fs, t0 = desc.get("sample_rate_hz"), desc.get("t0_s", 0.0)
    if not isinstance(fs, (int, float)) or not 0 < fs <= MAX_SAMPLE_RATE_HZ:
        raise InputError(f"the gearbody description gives sample_rate_hz = {fs!r}")
    tacho = desc.get("tacho") or None
    specs = {spec["name"]: (i, spec) for i, spec in enumerate(desc["channels"])}
    names = req.wanted(specs, tacho.get("channel", "") if tacho else "")
    lo, hi, t0_read = req.window(n, float(fs), float(t0))
    check_size(hi - lo, len(names))
    chans = []
    for name in names:
        i, spec = specs[name]
        data = check_finite(name, read(i, name, lo, hi))
        if data.size != hi - lo:
            raise InputError(f"channel {name!r} holds {data.size} samples; the description says {n}")
        chans.append(
            Channel(name, data, spec.get("unit", ""), spec.get("sensitivity", 1.0), spec.get("location", ""),
                    spec.get("direction", ""), spec.get("shaft", ""), dict(spec.get("meta", {})))
        )  # fmt: skip
    return Recording(float(fs), chans, t0_read, _own_tacho(tacho), dict(desc.get("meta") or {}))


def _own_tacho(tacho: Mapping[str, Any] | None) -> Tacho | None:
    if not tacho:
        return None
    return Tacho(
        shaft=tacho.get("shaft", "input"),
        pulses_per_rev=tacho.get("pulses_per_rev", 1),
        pulse_times_s=tacho.get("pulse_times_s"),
        channel=tacho.get("channel", ""),
        level=tacho.get("level"),
    )


# -- a foreign file's samples and time ----------------------------------------------------------------------
def check_finite(name: str, data: np.ndarray, offset: int = 0) -> np.ndarray:
    """``data`` as a 1-D float array, or an InputError naming the channel and the first NaN/inf sample."""
    data = np.asarray(data)
    if data.dtype.kind not in "fiub":
        raise InputError(f"channel {name!r}: samples of type {data.dtype} are not numbers")
    if data.ndim != 1:
        raise InputError(f"channel {name!r}: samples must be one-dimensional, got shape {data.shape}")
    if data.dtype.kind == "f":
        bad = ~np.isfinite(data)
        if bad.any():
            k = int(np.argmax(bad))
            raise InputError(f"channel {name!r}: sample {offset + k} is {data[k]!r}; samples must be finite")
    return data if data.dtype == np.float64 else data.astype(np.float64)


def rate_of_time(time: np.ndarray, name: str = "time") -> tuple[float, float]:
    """``(sample_rate_hz, t0_s)`` of a time column: its mean step, every instant within
    :data:`UNIFORM_RTOL` of a step (or the column's float resolution) of the uniform grid."""
    time = check_finite(name, time)
    if time.size < 2:
        raise InputError(f"the {name} column holds {time.size} value(s); needs at least 2")
    span = float(time[-1] - time[0])
    if not span > 0:
        raise InputError(f"the {name} column does not increase ({time[0]!r} .. {time[-1]!r})")
    step = span / (time.size - 1)
    fs = 1.0 / step
    if not fs <= MAX_SAMPLE_RATE_HZ:
        raise InputError(
            f"the {name} column's step {step:.6g} s gives a sample rate of {fs:.6g} Hz, above "
            f"{MAX_SAMPLE_RATE_HZ:g} Hz"
        )
    tol = max(UNIFORM_RTOL * step, 4 * np.spacing(max(abs(float(time[0])), abs(float(time[-1])))))
    dev = 0.0
    for lo in range(0, time.size, 1 << 20):  # by parts: bounded memory on a long column
        k = np.arange(lo, min(lo + (1 << 20), time.size))
        dev = max(dev, float(np.max(np.abs(time[k] - (time[0] + k * step)))))
    if dev > tol:
        raise InputError(
            f"the {name} column is not uniform: an instant lies {dev / step:.3g} steps off the grid "
            f"of its mean step {step:.6g} s (allowed {UNIFORM_RTOL:g}); "
            "give sample_rate_hz= to use a rate of your own"
        )
    return fs, float(time[0])


def given_rate(fs: Any) -> float:
    """``sample_rate_hz=`` checked."""
    if isinstance(fs, bool) or not isinstance(fs, (int, float, np.integer, np.floating)):
        raise InputError(f"sample_rate_hz = {fs!r}: must be a number in (0, {MAX_SAMPLE_RATE_HZ:g}] Hz")
    if not (math.isfinite(fs) and 0 < fs <= MAX_SAMPLE_RATE_HZ):
        raise InputError(f"sample_rate_hz = {fs!r}: must be in (0, {MAX_SAMPLE_RATE_HZ:g}] Hz")
    return float(fs)


def is_time_name(name: str) -> bool:
    return name.strip().lower() in TIME_NAMES


def split_unit(header: str) -> tuple[str, str]:
    """``"acc [g]"`` / ``"acc (g)"`` -> ``("acc", "g")``; a header without a unit -> ``(header, "")``."""
    text = header.strip()
    for left, right in (("[", "]"), ("(", ")")):
        if text.endswith(right) and left in text:
            i = text.rindex(left)
            return text[:i].strip() or text, text[i + 1 : -1].strip()
    return text, ""


def same_lengths(lengths: Mapping[str, int]) -> int:
    """The channels' common length, or an InputError naming the lengths."""
    if not lengths:
        raise InputError("the file holds no channel (no numeric vector)")
    if len(set(lengths.values())) > 1:
        shown = ", ".join(f"{k}: {v}" for k, v in list(lengths.items())[:8])
        raise InputError(f"the channels have different lengths ({shown}); a recording needs one length")
    n = next(iter(lengths.values()))
    if n < 2:
        raise InputError(f"the channels hold {n} sample(s); a recording needs at least 2")
    return n


def foreign_recording(
    req: ReadRequest,
    fs: float,
    t0: float,
    n: int,
    found_units: Mapping[str, str],
    read: Callable[[str, int, int], np.ndarray],
    meta: Mapping[str, Any] | None = None,
) -> Recording:
    """The recording of a file not written by gearbody: channels ``found_units`` (name -> the unit the
    file gives, ``""`` if none) of ``n`` samples each, ``read(name, lo, hi)`` giving samples ``lo:hi``."""
    names = req.wanted(found_units)
    lo, hi, t0_read = req.window(n, fs, t0)
    check_size(hi - lo, len(names))
    chans = []
    for name in names:
        unit = req.unit_of(name, found_units[name])
        data = check_finite(name, read(name, lo, hi), lo)
        if data.size != hi - lo:
            raise InputError(f"channel {name!r} holds {data.size} samples, the others {hi - lo}")
        chans.append(Channel(name, data, unit))
    return Recording(fs, chans, t0_read, None, {"source": str(req.path), **(meta or {})})
