"""Apache Parquet recordings (pyarrow; ``pip install "gearbody[files]"``).

gearbody's own: one float64 column per channel (named as the channel), no time column, and the
recording's description as JSON under the schema's key-value metadata key ``b"gearbody"``; bit-exact.

Another tool's: numeric columns of one length; a first column named like time (``time``, ``t``,
``time_s``) gives the start and the rate (as a CSV's, :mod:`.csv_format`), otherwise ``sample_rate_hz=``
is needed; units from ``name [unit]`` column names, a field's metadata ``b"unit"``, or ``units=``.

Columns are read by row groups into arrays allocated once (memory: the float64 result and one row group).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...errors import InputError
from ..container import Recording
from ._common import (
    ReadRequest,
    describe,
    foreign_recording,
    from_json,
    given_rate,
    is_time_name,
    need,
    own_recording,
    rate_of_time,
    split_unit,
    to_json,
)

_KEY = b"gearbody"
_ROW_GROUP = 1 << 20


def write(recording: Recording, path: Path) -> None:
    """The recording as gearbody's Parquet (see the module's docstring)."""
    pa = need("pyarrow", "parquet")
    pq = need("pyarrow.parquet", "parquet")
    arrays = [pa.array(ch.data, type=pa.float64()) for ch in recording.channels.values()]
    schema = pa.schema([pa.field(name, pa.float64()) for name in recording.channels],
                       metadata={_KEY: to_json(describe(recording)).encode()})  # fmt: skip
    pq.write_table(pa.Table.from_arrays(arrays, schema=schema), path, row_group_size=_ROW_GROUP)


def _column(pf, name: str, lo: int, hi: int) -> np.ndarray:
    """Rows ``lo:hi`` of column ``name``, read by row groups into one float64 array."""
    out = np.empty(hi - lo, dtype=np.float64)
    start = 0
    for g in range(pf.metadata.num_row_groups):
        rows = pf.metadata.row_group(g).num_rows
        a, b = max(lo, start), min(hi, start + rows)
        if a < b:
            col = pf.read_row_group(g, columns=[name]).column(0)
            if col.null_count:
                raise InputError(f"column {name!r} holds {col.null_count} missing value(s) (nulls)")
            values = col.slice(a - start, b - a).to_numpy()
            if values.dtype.kind not in "fiu":
                raise InputError(f"column {name!r} holds {values.dtype} values, not numbers")
            out[a - lo : b - lo] = values
        start += rows
    return out


def read(path: Path, req: ReadRequest) -> Recording:
    """A Parquet recording: gearbody's own (its metadata restores everything) or another tool's."""
    pq = need("pyarrow.parquet", "parquet")
    pf = pq.ParquetFile(path)
    n = pf.metadata.num_rows
    meta = pf.schema_arrow.metadata or {}
    if _KEY in meta:
        desc = from_json(meta[_KEY])
        names = [spec.get("name") for spec in desc["channels"]]
        missing = [name for name in names if name not in pf.schema_arrow.names]
        if missing:
            raise InputError(f"the description names column {missing[0]!r}, which the file does not hold")
        if n != desc.get("n_samples"):
            raise InputError(f"the file holds {n} rows, its description says {desc.get('n_samples')}")
        return own_recording(desc, lambda _i, name, lo, hi: _column(pf, name, lo, hi), req)
    fields = list(pf.schema_arrow)
    if not fields:
        raise InputError("the file holds no column")
    time_col = fields[0].name if is_time_name(split_unit(fields[0].name)[0]) else None
    found, column = {}, {}
    for field in fields:
        if field.name == time_col:
            continue
        name, unit = split_unit(field.name)
        if name in found:
            raise InputError(f"two columns are named {name!r}")
        found[name] = (field.metadata or {}).get(b"unit", b"").decode() or unit
        column[name] = field.name
    fs, t0 = _rate(pf, req, time_col, n)
    return foreign_recording(req, fs, t0, n, found, lambda name, lo, hi: _column(pf, column[name], lo, hi))


def _rate(pf, req: ReadRequest, time_col: str | None, n: int) -> tuple[float, float]:
    if req.sample_rate_hz is not None:
        fs = given_rate(req.sample_rate_hz)
        return fs, (float(_column(pf, time_col, 0, 1)[0]) if time_col and n else 0.0)
    if time_col is None:
        raise InputError("no time column (a first column named time, t or time_s) and no sample_rate_hz=")
    return rate_of_time(_column(pf, time_col, 0, n), f"time column {time_col!r}")
