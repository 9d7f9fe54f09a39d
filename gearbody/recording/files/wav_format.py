"""WAV recordings (scipy.io.wavfile).

gearbody's own: IEEE float64 samples (one WAV channel per channel, bit-exact), the header's rate the
nearest integer to the recording's, and the recording's description (JSON, the exact rate included) in a
RIFF chunk ``gbdy`` after the data, which scipy and other WAV readers skip.

Another tool's WAV: PCM 8, 16, 24 or 32 bit, or float 32/64; channels named ``ch1``, ``ch2``, ...; the
start time 0. ``calibration`` (one number for every channel, or one per channel of the file) converts a
sample to a physical value in the channel's unit (``units={"ch1": "g"}``, default dimensionless ``""``)::

    integer WAV:  value = calibration * sample / full_scale,  full_scale = 2**(bits - 1)
                  (32768 for 16 bit, 2**31 for 24 and 32 bit; 8-bit samples are offset by 128 first),
                  i.e. calibration is the physical value of a full-scale sample [unit per full scale];
    float WAV:    value = calibration * sample  [unit per file unit].

Without ``calibration`` it is 1 (an integer WAV reads as a fraction of full scale). The channel's
sensitivity is what turns the value back into the file's samples: counts per SI unit for an integer
WAV, file units per SI unit for a float WAV. The samples are read through a memory map and converted by
blocks of :data:`BLOCK_SAMPLES` samples, so reading allocates the float64 result and one block (24-bit
files, which scipy cannot map, are read whole as int32 first: half the result's size more).
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ...errors import InputError
from ..channel import UNIT_SCALE, Channel
from ..container import MAX_SAMPLE_RATE_HZ, Recording
from ._common import ReadRequest, check_finite, check_size, describe, from_json, own_recording, to_json

CHUNK_ID = b"gbdy"
"""The RIFF chunk holding gearbody's description of the recording (JSON)."""
BLOCK_SAMPLES = 1 << 16
"""Samples per channel converted at a time."""
_MAX_WAV_BYTES = 2**32 - 1 - 1024


def write(recording: Recording, path: Path) -> None:
    """The recording as gearbody's WAV (see the module's docstring)."""
    from scipy.io import wavfile

    chans = list(recording.channels.values())
    if 8 * len(chans) * recording.n_samples > _MAX_WAV_BYTES:
        raise InputError(
            f"{len(chans)} channel(s) of {recording.n_samples} float64 samples exceed a WAV file's 4 GiB; "
            "write HDF5 or Parquet instead"
        )
    rate = min(max(round(recording.sample_rate_hz), 1), 2**32 - 1)
    wavfile.write(path, rate, np.column_stack([ch.data for ch in chans]))
    payload = to_json(describe(recording)).encode("ascii")
    payload += b" " * (len(payload) % 2)  # a RIFF chunk has an even size
    with open(path, "r+b") as fh:
        fh.seek(0, 2)
        fh.write(CHUNK_ID + struct.pack("<I", len(payload)) + payload)
        size = fh.tell()
        fh.seek(4)
        fh.write(struct.pack("<I", size - 8))


def _chunks(path: Path) -> dict[bytes, tuple[int, int]]:
    """``{chunk id: (offset, size)}`` of the RIFF file, checked against the file's length."""
    total = path.stat().st_size
    found = {}
    with open(path, "rb") as fh:
        head = fh.read(12)
        if len(head) < 12 or head[:4] != b"RIFF" or head[8:12] != b"WAVE":
            raise InputError(f"not a RIFF WAVE file (it starts with {head[:12]!r})")
        pos = 12
        while pos + 8 <= total:
            fh.seek(pos)
            cid, size = struct.unpack("<4sI", fh.read(8))
            found.setdefault(cid, (pos + 8, size))
            pos += 8 + size + (size % 2)
    if b"data" not in found or b"fmt " not in found:
        raise InputError("the WAV file has no 'fmt ' or no 'data' chunk (truncated?)")
    offset, size = found[b"data"]
    if offset + size > total:
        raise InputError(f"the data chunk declares {size} bytes, the file holds {total - offset} (truncated)")
    return found


def _own_description(path: Path, chunks) -> dict | None:
    if CHUNK_ID not in chunks:
        return None
    offset, size = chunks[CHUNK_ID]
    with open(path, "rb") as fh:
        fh.seek(offset)
        text = fh.read(size)
    if len(text) != size:
        raise InputError(f"the {CHUNK_ID.decode()} chunk is truncated")
    return from_json(text)


def _samples(path: Path) -> tuple[int, np.ndarray]:
    from scipy.io import wavfile

    try:
        fs, data = wavfile.read(path, mmap=True)
    except ValueError as exc:
        if "mmap" not in str(exc) and "24" not in str(exc):
            raise
        fs, data = wavfile.read(path)  # 24-bit PCM: scipy cannot map it
    data = data if data.ndim == 2 else data[:, None]
    if not 0 < fs <= MAX_SAMPLE_RATE_HZ:
        raise InputError(
            f"the WAV header gives a sample rate of {fs} Hz; allowed (0, {MAX_SAMPLE_RATE_HZ:g}]"
        )
    return int(fs), data


def read(path: Path, req: ReadRequest) -> Recording:
    """A WAV recording: gearbody's own (its ``gbdy`` chunk restores everything) or another tool's."""
    chunks = _chunks(path)
    desc = _own_description(path, chunks)
    fs, data = _samples(path)
    n, nch = data.shape
    if desc is not None:
        if data.dtype != np.float64 or nch != len(desc["channels"]) or n != desc.get("n_samples"):
            raise InputError(
                f"the samples ({n} x {nch} {data.dtype}) do not match the gbdy description "
                f"({desc.get('n_samples')} x {len(desc['channels'])} float64)"
            )
        return own_recording(desc, lambda i, _name, lo, hi: np.array(data[lo:hi, i]), req)
    return _read_foreign(data, float(fs), req)


def _calibration(value, nch: int) -> np.ndarray:
    if value is None:
        return np.ones(nch)
    values = [value] * nch if isinstance(value, (int, float, np.number)) else value
    if isinstance(values, (str, bytes)) or not isinstance(values, Sequence) or len(values) != nch:
        raise InputError(f"calibration = {value!r}: must be one number or a list of {nch} (one per channel)")
    out = np.array(values, dtype=np.float64) if all(
        isinstance(v, (int, float, np.number)) and not isinstance(v, bool) for v in values
    ) else None  # fmt: skip
    if out is None or not np.all(np.isfinite(out) & (out > 0)):
        raise InputError(f"calibration = {value!r}: every value must be a finite number > 0")
    return out


def _read_foreign(data: np.ndarray, fs: float, req: ReadRequest) -> Recording:
    n, nch = data.shape
    names = [f"ch{i + 1}" for i in range(nch)]
    wanted = req.wanted(names)
    cols = [names.index(name) for name in wanted]
    lo, hi, t0 = req.window(n, fs, 0.0)
    check_size(hi - lo, len(wanted))
    cal = _calibration(req.calibration, nch)[cols]
    units = [req.unit_of(name) for name in wanted]
    factor = np.array([UNIT_SCALE[u][1] for u in units])
    integer = data.dtype.kind in "iu"
    full_scale = float(2 ** (8 * data.dtype.itemsize - 1)) if integer else 1.0
    offset = full_scale if data.dtype.kind == "u" else 0.0  # 8-bit PCM is unsigned around 128
    scale = cal * factor / full_scale
    out = np.empty((len(wanted), hi - lo), dtype=np.float64)
    for a in range(lo, hi, BLOCK_SAMPLES):
        b = min(a + BLOCK_SAMPLES, hi)
        for j, col in enumerate(cols):  # a view of the map, cast into the result: no copy of the block
            seg = out[j, a - lo : b - lo]
            if offset:
                np.subtract(data[a:b, col], offset, out=seg)
                seg *= scale[j]
            else:
                np.multiply(data[a:b, col], scale[j], out=seg)
            if not integer:
                check_finite(wanted[j], seg, a)
    sensitivity = full_scale / (cal * factor) if integer else 1.0 / (cal * factor)
    chans = [
        Channel(name, out[j], UNIT_SCALE[units[j]][0], float(sensitivity[j])) for j, name in enumerate(wanted)
    ]
    return Recording(fs, chans, t0, None, {"source": str(req.path), "wav_dtype": str(data.dtype)})
