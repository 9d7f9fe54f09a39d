"""Universal File Format recordings: type-58 records (pyuff; ``pip install "gearbody[files]"``).

gearbody writes one binary double-precision record (58b) per channel: function type 1 (time response),
even abscissa from the start time in steps of 1/fs (abscissa type 17, time, in s), the ordinate's unit
label the channel's unit and its data type the channel's quantity (12 acceleration, 11 velocity, 8
displacement, 13 force, 0 other); ``rsp_node`` the channel's number (from 1), ``rsp_dir`` its direction
(``x``/``y``/``z`` with an optional sign: 1, 2, 3, -1, ...; 0 otherwise); id lines: 1 the channel's name,
2 its location, 4 ``direction <direction>``, 5 ``gearbody-recording``. The header's 6-digit abscissa step
cannot hold the rate exactly, so a last record (function type 0, id1 ``gearbody-recording``) holds the
recording's description as JSON, one byte per value: the file reads back bit-exact. Other UFF readers see
it as one more general function.

Another tool's file: every type-58 record of function type 1 (or 0) with real data is a channel, named by
its id1 line (else ``<node><direction>``), its unit from the ordinate's unit label (or ``units=``), the
start from the abscissa minimum, the rate 1/step (rounded to a whole Hz when within the header's 6-digit
precision of one; uneven records: from their abscissa, uniform to 1e-6 of a step); every record of one
length and rate.
"""

from __future__ import annotations

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
    need,
    own_recording,
    rate_of_time,
    same_lengths,
    to_json,
)

_DIRECTIONS = {"x": 1, "y": 2, "z": 3, "rx": 4, "ry": 5, "rz": 6}
_ORDINATE_TYPE = {"acceleration": 12, "velocity": 11, "displacement": 8, "force": 13}
_NONE = ("", "NONE")


def _direction_code(direction: str) -> int:
    text = direction.strip().lower()
    sign = -1 if text.startswith("-") else 1
    return sign * _DIRECTIONS.get(text.lstrip("+-"), 0)


def _record(data: np.ndarray, x: np.ndarray, func_type: int, node: int, direction: int, **extra) -> dict:
    if data.tobytes().find(b"    -1") >= 0:  # pyuff finds records by this tag: it must not be in the data
        raise InputError(
            "the samples hold the bytes of a UFF record tag ('    -1'); the file could not be read back "
            "(write HDF5 or Parquet instead)"
        )
    out = {
        "type": 58, "binary": 1, "func_type": func_type, "rsp_node": node, "rsp_dir": direction,
        "ref_node": 0, "ref_dir": 0, "data": data, "x": x, "abscissa_spacing": 1, "id5": MARK,
        "abscissa_spec_data_type": 17, "abscissa_axis_units_lab": "s", "abscissa_axis_lab": "time",
        "ordinate_spec_data_type": 0, "orddenom_spec_data_type": 0,
    }  # fmt: skip
    out.update(extra)
    return out


def write(recording: Recording, path: Path) -> None:
    """The recording as UFF 58b records (see the module's docstring)."""
    pyuff = need("pyuff", "uff")
    time = recording.time_s
    sets = []
    for k, ch in enumerate(recording.channels.values()):
        extra = {
            "id1": ch.name[:80],
            "ordinate_axis_units_lab": ch.unit[:20],
            "ordinate_axis_lab": ch.name[:20],
        }
        extra["ordinate_spec_data_type"] = _ORDINATE_TYPE.get(ch.quantity, 0)
        if ch.location:
            extra["id2"] = ch.location[:80]
        if ch.direction:
            extra["id4"] = f"direction {ch.direction}"[:80]
        sets.append(_record(ch.data, time, 1, k + 1, _direction_code(ch.direction), **extra))
    text = np.frombuffer(to_json(describe(recording)).encode("ascii"), dtype=np.uint8).astype(np.float64)
    sets.append(_record(text, np.arange(text.size, dtype=np.float64), 0, 0, 0, id1=MARK))
    # 'add' to the new file: pyuff's 'overwrite' of a binary record truncates the header it just wrote
    pyuff.UFF(str(path)).write_sets(sets, mode="add")


def _records(path: Path) -> list[dict]:
    pyuff = need("pyuff", "uff")
    uff = pyuff.UFF(str(path))
    types = list(uff.get_set_types()) if uff.get_n_sets() else []
    index = [i for i, t in enumerate(types) if t == 58]
    if not index:
        raise InputError(
            f"no type-58 record in the file (data set types found: {sorted(set(types)) or 'none'})"
        )
    sets = uff.read_sets(index)
    return sets if isinstance(sets, list) else [sets]


def read(path: Path, req: ReadRequest) -> Recording:
    """A UFF recording: gearbody's own (its description record restores everything) or another tool's."""
    records = _records(path)
    own = [r for r in records if str(r.get("id1", "")).strip() == MARK and r.get("func_type") == 0]
    if own:
        desc = from_json(np.asarray(own[0]["data"]).astype(np.uint8).tobytes())
        chans = [r for r in records if r is not own[0]]
        if len(chans) != len(desc["channels"]):
            raise InputError(f"the file holds {len(chans)} records, its description {len(desc['channels'])}")
        return own_recording(desc, lambda i, _name, lo, hi: np.asarray(chans[i]["data"][lo:hi]), req)
    if any(str(r.get("id5", "")).strip() == MARK for r in records):
        raise InputError(
            "the file's records are gearbody's, but its description record is missing (truncated?)"
        )
    return _read_foreign(records, req)


def _name(record: dict, taken: set[str]) -> str:
    name = str(record.get("id1", "")).strip()
    if name in _NONE:
        code = int(record.get("rsp_dir", 0))
        label = next((k for k, v in _DIRECTIONS.items() if v == abs(code)), "")
        name = f"{record.get('rsp_node', 0)}{'-' if code < 0 else '+' if label else ''}{label}"
    base, k = name, 1
    while name in taken:
        k += 1
        name = f"{base} ({k})"
    taken.add(name)
    return name


def _read_foreign(records: list[dict], req: ReadRequest) -> Recording:
    taken: set[str] = set()
    chans, units, rates = {}, {}, {}
    for k, rec in enumerate(records):
        if rec.get("func_type") not in (0, 1):
            raise InputError(
                f"record {k + 1} is of function type {rec.get('func_type')}, not a time response (1)"
            )
        data = np.asarray(rec.get("data"))
        if np.iscomplexobj(data):
            raise InputError(f"record {k + 1} holds complex data, not a time response")
        name = _name(rec, taken)
        chans[name] = data
        unit = str(rec.get("ordinate_axis_units_lab", "")).strip()
        units[name] = "" if unit in _NONE else unit
        rates[name] = _record_rate(rec, k)
    n = same_lengths({name: data.size for name, data in chans.items()})
    if len({fs for fs, _ in rates.values()}) > 1:
        shown = ", ".join(f"{name}: {fs:g} Hz" for name, (fs, _) in list(rates.items())[:6])
        raise InputError(f"the records have different sample rates ({shown})")
    fs, t0 = next(iter(rates.values()))
    return foreign_recording(req, fs, t0, n, units, lambda name, lo, hi: chans[name][lo:hi])


def _record_rate(rec: dict, k: int) -> tuple[float, float]:
    if int(rec.get("abscissa_spacing", 1)) == 0:
        return rate_of_time(np.asarray(rec["x"], dtype=np.float64), f"abscissa of record {k + 1}")
    step = float(rec.get("abscissa_inc", 0.0))
    if not step > 0:
        raise InputError(f"record {k + 1}: abscissa step {step!r} s, must be > 0")
    fs = 1.0 / step
    whole = round(fs)
    if whole and abs(fs - whole) <= 1e-5 * fs:  # the header's %13.5e step: 6 significant digits
        fs = float(whole)
    return fs, float(rec.get("abscissa_min", 0.0))
