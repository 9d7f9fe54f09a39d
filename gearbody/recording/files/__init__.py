"""Readers and writers of recordings: :func:`read_recording` and :func:`write_recording`, the format taken
from the file's suffix (or ``format=``), :func:`formats` lists them.

========  ==================  =====  =====  =========================================================
format    suffixes            read   write  library (extra)
========  ==================  =====  =====  =========================================================
csv       .csv                yes    yes    -
parquet   .parquet            yes    yes    pyarrow (``gearbody[files]``)
wav       .wav                yes    yes    scipy
mat       .mat                yes    yes    scipy (v5); h5py for v7.3 (``gearbody[files]``)
hdf5      .h5, .hdf5          yes    yes    h5py (``gearbody[files]``)
uff       .uff, .unv          yes    yes    pyuff (``gearbody[files]``)
tdms      .tdms               yes    no     npTDMS (``gearbody[tdms]``, LGPL)
========  ==================  =====  =====  =========================================================

What gearbody writes it reads back bit-exact (every sample, the rate, the start time, the tacho's pulse
times, every channel's unit, sensitivity, location, direction and the metadata): each file carries the
recording's description as JSON (a comment header, a schema's metadata, a RIFF chunk, a variable, an
attribute, a record). A file written by another tool is read by its format's conventions (each module's
docstring says which); the options it needs (``sample_rate_hz=``, ``units=``, ``calibration=``) are refused
by a format that cannot use them, and by gearbody's own files, which hold their own.
"""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from ...atomic_files import atomic_write
from ...errors import GearbodyError, InputError, OutputError
from ..container import Recording
from ..tacho import Tacho
from ._common import ReadRequest, check_writable, describe, to_json

__all__ = ["FileFormat", "formats", "read_recording", "write_recording"]


@dataclass(frozen=True)
class FileFormat:
    """A file format of recordings: its ``name``, file ``suffixes``, whether gearbody ``writes`` it, the
    read options it uses beyond the common ones (``options``), and the extra that installs its library."""

    name: str
    suffixes: tuple[str, ...]
    module: str
    writes: bool
    options: frozenset[str]
    extra: str
    summary: str


_FORMATS = (
    FileFormat("csv", (".csv",), "csv_format", True, frozenset({"sample_rate_hz", "units"}), "",
               "text: a time column (or sample_rate_hz=) and one column per channel"),
    FileFormat("parquet", (".parquet",), "parquet_format", True, frozenset({"sample_rate_hz", "units"}),
               "files", "Apache Parquet: one float64 column per channel"),
    FileFormat("wav", (".wav",), "wav_format", True, frozenset({"calibration", "units"}), "",
               "RIFF WAVE: PCM 8/16/24/32-bit or float, one channel per WAV channel"),
    FileFormat("mat", (".mat",), "mat_format", True, frozenset({"sample_rate_hz", "units"}), "files",
               "MATLAB v5 (scipy) or v7.3 (HDF5, h5py): a vector per channel or a data matrix, with fs"),
    FileFormat("hdf5", (".h5", ".hdf5"), "hdf5_format", True, frozenset({"sample_rate_hz", "units"}), "files",
               "HDF5: gearbody's /recording layout, or 1-D datasets of one length with a sample rate"),
    FileFormat("uff", (".uff", ".unv"), "uff_format", True, frozenset({"units"}), "files",
               "universal file format: one type-58 time-response record per channel"),
    FileFormat("tdms", (".tdms",), "tdms_format", False, frozenset({"sample_rate_hz", "units"}), "tdms",
               "NI TDMS (read only): waveform channels (wf_increment) or a time channel"),
)  # fmt: skip
_BY_NAME = {f.name: f for f in _FORMATS}
_BY_SUFFIX = {s: f for f in _FORMATS for s in f.suffixes}
_SPECIFIC = ("sample_rate_hz", "units", "calibration")


def formats() -> dict[str, FileFormat]:
    """The formats gearbody reads (and writes, ``FileFormat.writes``), by name."""
    return dict(_BY_NAME)


def _format_of(path: Path, fmt: str | None) -> FileFormat:
    if fmt is not None:
        key = str(fmt).lower().lstrip(".")
        found = _BY_NAME.get(key) or _BY_SUFFIX.get("." + key)
        if found is None:
            raise InputError(f"format = {fmt!r}: not a known format; formats: {', '.join(_BY_NAME)}")
        return found
    found = _BY_SUFFIX.get(path.suffix.lower())
    if found is None:
        raise InputError(
            f"{path}: the suffix {path.suffix!r} names no format; suffixes: {', '.join(_BY_SUFFIX)} "
            "(or give format=)"
        )
    return found


def _module(fmt: FileFormat):
    return importlib.import_module(f"{__name__}.{fmt.module}")


def read_recording(
    path: str | Path,
    *,
    format: str | None = None,
    sample_rate_hz: float | None = None,
    channels: Sequence[str] | None = None,
    units: Mapping[str, str] | None = None,
    calibration: float | Sequence[float] | None = None,
    tacho_channel: str | None = None,
    pulses_per_rev: int = 1,
    tacho_shaft: str = "input",
    start_s: float | None = None,
    end_s: float | None = None,
) -> Recording:
    """The recording in ``path`` (format from its suffix, or ``format=``: a name of :func:`formats`).

    Common options: ``channels`` (names to keep, in the file's order; a tacho channel is kept too),
    ``start_s``/``end_s`` (the samples of ``start_s <= t < end_s``, read by parts where the format
    allows), ``tacho_channel`` (a channel that is the tacho: a pulse train of ``pulses_per_rev`` pulses per
    revolution of shaft ``tacho_shaft``, or an encoder when its unit is an angle, ``rad``/``deg``/``rev``:
    pulses_per_rev 0; it replaces a tacho the file holds). Options for a foreign file, refused where the
    format cannot use them:
    ``sample_rate_hz`` (when the file gives none), ``units`` (``{channel: unit}``, a unit of
    :data:`~gearbody.recording.UNIT_SCALE`), ``calibration`` (WAV; see :mod:`.wav_format`).
    Errors are :class:`~gearbody.errors.InputError` naming the file, the option and what is allowed."""
    path = Path(path)
    fmt = _format_of(path, format)
    given = {"sample_rate_hz": sample_rate_hz, "units": units, "calibration": calibration}
    for key in _SPECIFIC:
        if given[key] is not None and key not in fmt.options:
            allowed = ", ".join(f"{k}=" for k in _SPECIFIC if k in fmt.options) or "none"
            raise InputError(
                f"{path}: {key}= cannot be used with format {fmt.name!r} (its own options: {allowed})"
            )
    try:
        _check_common(channels, units, tacho_channel, pulses_per_rev, tacho_shaft)
        if not path.is_file():
            raise InputError(f"{path}: no such file" if not path.exists() else f"{path}: not a file")
        if path.stat().st_size == 0:
            raise InputError(f"{path}: the file is empty (0 bytes)")
        req = ReadRequest(path, fmt.name, sample_rate_hz, channels, units, calibration, tacho_channel,
                          start_s, end_s)  # fmt: skip
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the libraries' warnings on chunks they skip
            recording = _module(fmt).read(path, req)
        return _with_tacho(recording, tacho_channel, pulses_per_rev, tacho_shaft)
    except GearbodyError as exc:
        if str(path) in str(exc):
            raise
        raise type(exc)(f"{path} ({fmt.name}): {exc}") from None
    except MemoryError:
        raise InputError(
            f"{path} ({fmt.name}): not enough memory to read it; read a part (start_s=/end_s=)"
        ) from None
    except Exception as exc:  # a library's own error on a damaged file: one line naming the file
        raise InputError(
            f"{path}: cannot be read as {fmt.name} ({type(exc).__name__}: {exc}); is it a damaged or "
            "truncated file?"
        ) from None


def _check_common(channels, units, tacho_channel, pulses_per_rev, tacho_shaft) -> None:
    if channels is not None and (isinstance(channels, str) or not all(isinstance(c, str) for c in channels)):
        raise InputError(f"channels = {channels!r}: must be a list of channel names")
    if channels is not None and not list(channels):
        raise InputError("channels = []: names no channel; leave it out to read every channel")
    if units is not None and not isinstance(units, Mapping):
        raise InputError(f"units = {units!r}: must be a mapping {{channel name: unit}}")
    if tacho_channel is None and (pulses_per_rev != 1 or tacho_shaft != "input"):
        raise InputError("pulses_per_rev=/tacho_shaft= describe tacho_channel=; give the tacho channel too")
    if tacho_channel is not None and not (isinstance(tacho_channel, str) and tacho_channel):
        raise InputError(f"tacho_channel = {tacho_channel!r}: must name a channel")


def _with_tacho(rec: Recording, name: str | None, pulses_per_rev: int, shaft: str) -> Recording:
    """The recording with ``name`` as its tacho (a pulse train, or an encoder when its unit is rad)."""
    if name is None:
        return rec
    ch = rec.channel(name)
    if ch.unit == "rad":
        if pulses_per_rev not in (0, 1):
            raise InputError(
                f"tacho_channel={name!r} is an angle (an encoder): pulses_per_rev must be 0, "
                f"got {pulses_per_rev}"
            )
        tacho = Tacho(shaft=shaft, pulses_per_rev=0, channel=name)
        ch = ch if ch.shaft else type(ch)(name, ch.data, ch.unit, ch.sensitivity, ch.location, ch.direction,
                                           shaft, dict(ch.meta))  # fmt: skip
    else:
        if pulses_per_rev == 0:
            raise InputError(
                f"pulses_per_rev=0 means an encoder, but tacho_channel={name!r} has unit {ch.unit!r}, not "
                "an angle (rad, deg, rev)"
            )
        tacho = Tacho(shaft=shaft, pulses_per_rev=pulses_per_rev, channel=name)
    return Recording(rec.sample_rate_hz, rec.with_channels(ch).channels, rec.t0_s, tacho, dict(rec.meta))


def write_recording(recording: Recording, path: str | Path, *, format: str | None = None) -> Path:
    """``recording`` to ``path`` (format from its suffix, or ``format=``), written whole or not at all;
    :func:`read_recording` gives it back bit-exact. Returns the path."""
    path = Path(path)
    fmt = _format_of(path, format)
    if not fmt.writes:
        writable = ", ".join(f.name for f in _FORMATS if f.writes)
        raise InputError(
            f"{path}: gearbody reads {fmt.name} but does not write it; formats it writes: {writable}"
        )
    to_json(describe(recording))  # a Recording, its metadata JSON-able, before anything is written
    check_writable(recording)
    module = _module(fmt)
    if not path.parent.is_dir():
        raise OutputError(f"cannot write {path}: no folder {path.parent}")
    try:
        return atomic_write(path, lambda tmp: module.write(recording, tmp))
    except GearbodyError as exc:
        if str(path) in str(exc):
            raise
        raise type(exc)(f"{path} ({fmt.name}): {exc}") from None
