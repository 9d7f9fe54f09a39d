"""CSV recordings.

gearbody's own CSV::

    # gearbody-recording {"format":"gearbody-recording","sample_rate_hz":20000.0,...}
    time_s,mesh_force_N [N],pinion_angle_rad [rad]
    0,1234.5678901234567,0
    ...

The comment line holds the recording's description (JSON: rate, start, channels with unit, sensitivity,
location, direction, the tacho with its pulse times, the metadata); the values are written ``%.17g``, so
they read back bit-exact. The time column is informative: the rate and start come from the description.

A logger's CSV: optional ``#`` comment lines, an optional header row, then one row per sample; the
delimiter (``,`` ``;`` or tab) is taken from the header row (or the first data row). A first column named
like time (``time``, ``t``, ``time_s``, ``time [s]``, ``time [ms]``) gives the start and the rate (its mean
step; every instant within 1e-6 of a step of the uniform grid), otherwise ``sample_rate_hz=`` is needed
(with a time column as well, it overrides the mean step and the column must lie within half a step of
it). Units come from ``name [unit]`` or ``name (unit)`` headers or ``units={name: unit}``; columns without
a header row are named ``ch1``, ``ch2``, ...
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from ...errors import InputError
from ..container import Recording
from ._common import (
    MARK,
    ReadRequest,
    describe,
    foreign_recording,
    from_json,
    given_rate,
    is_time_name,
    own_recording,
    rate_of_time,
    split_unit,
    to_json,
)

_PREFIX = f"# {MARK} "
_DELIMITERS = (",", ";", "\t")
_MAX_HEADER_LINES = 1000
_BLOCK_ROWS = 1 << 16
_TIME_SCALE = {"": 1.0, "s": 1.0, "ms": 1e-3, "us": 1e-6}


def write(recording: Recording, path: Path) -> None:
    """The recording as gearbody's CSV (see the module's docstring)."""
    chans = list(recording.channels.values())
    with open(path, "w", newline="", encoding="utf-8") as fh:
        fh.write(_PREFIX + to_json(describe(recording)) + "\n")
        csv.writer(fh, lineterminator="\n").writerow(
            ["time_s", *(f"{ch.name} [{ch.unit}]" if ch.unit else ch.name for ch in chans)]
        )
        time = recording.time_s
        for lo in range(0, recording.n_samples, _BLOCK_ROWS):
            hi = min(lo + _BLOCK_ROWS, recording.n_samples)
            block = np.column_stack([time[lo:hi], *(ch.data[lo:hi] for ch in chans)])
            np.savetxt(fh, block, fmt="%.17g", delimiter=",")


def _head(path: Path) -> tuple[list[str], str | None, int]:
    """``(comment lines, header row or None, number of lines before the data)``."""
    comments, count = [], 0
    with open(path, encoding="utf-8", errors="replace", newline="") as fh:
        for line in fh:
            count += 1
            if count > _MAX_HEADER_LINES:
                raise InputError(f"no data row in the first {_MAX_HEADER_LINES} lines")
            text = line.rstrip("\r\n")
            if not text.strip():
                continue
            if text.lstrip().startswith("#"):
                comments.append(text)
                continue
            if _is_numeric_row(text):
                return comments, None, count - 1
            return comments, text, count
    raise InputError("the file holds no data rows" if count else "the file is empty")


def _is_numeric_row(text: str) -> bool:
    fields = [f for f in _split(text, _delimiter(text)) if f.strip()]
    try:
        [float(f) for f in fields]
    except ValueError:
        return False
    return bool(fields)


def _delimiter(text: str) -> str:
    counts = {d: text.count(d) for d in _DELIMITERS}
    best = max(counts, key=counts.get)
    return best if counts[best] else ","


def _split(text: str, delimiter: str) -> list[str]:
    return next(csv.reader(io.StringIO(text), delimiter=delimiter))


def _table(path: Path, skip: int, delimiter: str, n_columns: int) -> np.ndarray:
    try:
        table = np.loadtxt(path, delimiter=delimiter, skiprows=skip, comments="#", ndmin=2, dtype=np.float64,
                           encoding="utf-8")  # fmt: skip
    except ValueError as exc:
        raise InputError(
            f"the values cannot be read as numbers with delimiter {delimiter!r} ({exc}); every row needs "
            f"{n_columns} numbers"
        ) from None
    if table.shape[0] == 0:
        raise InputError("the file holds no data rows")
    if table.shape[1] != n_columns:
        raise InputError(f"the rows hold {table.shape[1]} values, the header names {n_columns} columns")
    return table


def read(path: Path, req: ReadRequest) -> Recording:
    """A CSV recording: gearbody's own (its description restores everything) or a logger's."""
    comments, header, skip = _head(path)
    own = [c for c in comments if c.startswith(_PREFIX)]
    if own:
        desc = from_json(own[0][len(_PREFIX) :])
        table = _table(path, skip, ",", 1 + len(desc["channels"]))
        if table.shape[0] != desc.get("n_samples"):
            raise InputError(
                f"the file holds {table.shape[0]} rows, its description says "
                f"{desc.get('n_samples')} (truncated?)"
            )
        return own_recording(desc, lambda i, _name, lo, hi: np.ascontiguousarray(table[lo:hi, 1 + i]), req)
    return _read_foreign(path, req, header, skip)


def _read_foreign(path: Path, req: ReadRequest, header: str | None, skip: int) -> Recording:
    if header is None:
        with open(path, encoding="utf-8", errors="replace") as fh:
            first = [line for _, line in zip(range(skip + 1), fh, strict=False)][-1]
        delimiter = _delimiter(first)
        width = len(_split(first.strip(), delimiter))
        names, units = [f"ch{i + 1}" for i in range(width)], [""] * width
    else:
        delimiter = _delimiter(header)
        names, units = map(list, zip(*(split_unit(h) for h in _split(header, delimiter)), strict=True))
    if len(set(names)) != len(names):
        twice = next(n for n in names if names.count(n) > 1)
        raise InputError(f"the header names column {twice!r} twice")
    table = _table(path, skip, delimiter, len(names))
    time_col = 0 if is_time_name(names[0]) else None
    fs, t0 = _rate(req, table, names, units, time_col)
    columns = {name: j for j, name in enumerate(names) if j != time_col}
    found = {name: units[j] for name, j in columns.items()}
    return foreign_recording(
        req,
        fs,
        t0,
        table.shape[0],
        found,
        lambda name, lo, hi: _column(table, columns[name], lo, hi),
    )


def _column(table: np.ndarray, j: int, lo: int, hi: int) -> np.ndarray:
    return np.ascontiguousarray(table[lo:hi, j])


def _rate(req: ReadRequest, table: np.ndarray, names, units, time_col: int | None) -> tuple[float, float]:
    if time_col is None:
        if req.sample_rate_hz is None:
            raise InputError(
                f"no time column (a first column named one of time, t, time_s; the header has "
                f"{', '.join(names[:6])}) and no sample_rate_hz=; give one of them"
            )
        return given_rate(req.sample_rate_hz), 0.0
    unit = units[time_col]
    if unit not in _TIME_SCALE:
        raise InputError(f"time column {names[time_col]!r}: unit {unit!r} is not one of s, ms, us")
    time = table[:, time_col] * _TIME_SCALE[unit] if _TIME_SCALE[unit] != 1.0 else table[:, time_col]
    if req.sample_rate_hz is None:
        return rate_of_time(time, f"time column {names[time_col]!r}")
    fs = given_rate(req.sample_rate_hz)
    dev = np.max(np.abs(time - (time[0] + np.arange(time.size) / fs))) * fs
    if not dev <= 0.5:
        raise InputError(
            f"sample_rate_hz = {fs:g} does not fit the time column {names[time_col]!r}: an instant lies "
            f"{dev:.3g} steps off its grid"
        )
    return fs, float(time[0])
