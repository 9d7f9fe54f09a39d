"""HDF5 recordings (h5py; ``pip install "gearbody[files]"``).

gearbody's layout::

    /recording                      group; attrs: format = "gearbody-recording", version = 1,
                                    sample_rate_hz, t0_s (float64), meta (JSON), channel_names (JSON list,
                                    the channels' order: dataset names)
    /recording/channels/<name>      float64 dataset per channel; attrs: name (the channel's name; the
                                    dataset's is the same with "/" as "_"), unit, sensitivity,
                                    location, direction, shaft, meta (JSON)
    /recording/tacho                group (when the recording has a tacho); attrs: shaft, pulses_per_rev,
                                    channel, level (NaN: none)
    /recording/tacho/pulse_times_s  float64 dataset (a pulse tacho)

bit-exact. Another tool's file: every numeric dataset with one dimension longer than 1 (of one length)
is a channel, named by its path; a time dataset (``t``, ``time``, ``time_s``) gives the start and rate,
else a sample-rate attribute of the dataset, one of its groups or the file (``fs``, ``sample_rate``,
``sample_rate_hz``, ``SampleRate``, ...) or such a scalar dataset, else ``sample_rate_hz=``; units from a
dataset's ``unit``/``units`` attribute or ``units=``. Samples are read by slices (``start_s``/``end_s``).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ...errors import InputError
from ..container import Recording
from ._common import (
    MARK,
    RATE_NAMES,
    VERSION,
    ReadRequest,
    foreign_recording,
    given_rate,
    is_time_name,
    need,
    own_recording,
    rate_of_time,
    same_lengths,
    to_json,
)

_UNIT_ATTRS = ("unit", "units", "Unit", "Units", "unit_string")


def _key(name: str, taken: set[str]) -> str:
    base = name.replace("/", "_")
    base = "_" if base in (".", "") else base
    out, k = base, 1
    while out in taken:
        k += 1
        out = f"{base}_{k}"
    taken.add(out)
    return out


def write(recording: Recording, path: Path) -> None:
    """The recording in gearbody's HDF5 layout (see the module's docstring)."""
    h5py = need("h5py", "hdf5")
    with h5py.File(path, "w") as h5:
        group = h5.create_group("recording")
        keys: list[str] = []
        taken: set[str] = set()
        chans = group.create_group("channels")
        for ch in recording.channels.values():
            keys.append(_key(ch.name, taken))
            ds = chans.create_dataset(keys[-1], data=ch.data, dtype=np.float64)
            for attr in ("name", "unit", "location", "direction", "shaft"):
                ds.attrs[attr] = getattr(ch, attr)
            ds.attrs["sensitivity"] = np.float64(ch.sensitivity)
            ds.attrs["meta"] = to_json(ch.meta)
        group.attrs.update(format=MARK, version=VERSION, channel_names=json.dumps(keys))
        group.attrs["sample_rate_hz"] = np.float64(recording.sample_rate_hz)
        group.attrs["t0_s"] = np.float64(recording.t0_s)
        group.attrs["meta"] = to_json(recording.meta)
        tacho = recording.tacho
        if tacho is not None:
            tg = group.create_group("tacho")
            tg.attrs.update(shaft=tacho.shaft, pulses_per_rev=tacho.pulses_per_rev, channel=tacho.channel)
            tg.attrs["level"] = np.float64(np.nan if tacho.level is None else tacho.level)
            if tacho.pulse_times_s is not None:
                tg.create_dataset("pulse_times_s", data=tacho.pulse_times_s, dtype=np.float64)


def _text(value) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def _own_description(group) -> tuple[dict, list]:
    """The description our layout's attributes make, and the channels' datasets in order."""
    keys = json.loads(_text(group.attrs["channel_names"]))
    chans = group.get("channels")
    if chans is None or any(k not in chans for k in keys):
        raise InputError("the /recording group lacks channel datasets its channel_names attribute lists")
    datasets = [chans[k] for k in keys]
    specs = []
    for ds in datasets:
        a = ds.attrs
        spec = {key: _text(a.get(key, "")) for key in ("name", "unit", "location", "direction", "shaft")}
        spec.update(sensitivity=float(a.get("sensitivity", 1.0)), meta=json.loads(_text(a.get("meta", "{}"))))
        specs.append(spec)
    lengths = {
        spec["name"]: ds.shape[0] if ds.ndim == 1 else -1 for spec, ds in zip(specs, datasets, strict=True)
    }
    desc = {
        "format": MARK,
        "version": int(group.attrs.get("version", VERSION)),
        "sample_rate_hz": float(group.attrs["sample_rate_hz"]),
        "t0_s": float(group.attrs["t0_s"]),
        "n_samples": same_lengths(lengths),
        "channels": specs,
        "meta": json.loads(_text(group.attrs.get("meta", "{}"))),
        "tacho": _own_tacho(group),
    }
    return desc, datasets


def _own_tacho(group) -> dict | None:
    tg = group.get("tacho")
    if tg is None:
        return None
    level = float(tg.attrs.get("level", np.nan))
    out = {
        "shaft": _text(tg.attrs.get("shaft", "input")),
        "pulses_per_rev": int(tg.attrs.get("pulses_per_rev", 1)),
        "channel": _text(tg.attrs.get("channel", "")),
        "level": None if np.isnan(level) else level,
    }
    if "pulse_times_s" in tg:
        out["pulse_times_s"] = np.asarray(tg["pulse_times_s"][()], dtype=np.float64)
    return out


def read(path: Path, req: ReadRequest) -> Recording:
    """An HDF5 recording: gearbody's layout (restores everything) or another tool's datasets."""
    h5py = need("h5py", "hdf5")
    with h5py.File(path, "r") as h5:
        group = h5.get("recording")
        if isinstance(group, h5py.Group) and _text(group.attrs.get("format", "")) == MARK:
            desc, datasets = _own_description(group)
            return own_recording(desc, lambda i, _name, lo, hi: np.asarray(datasets[i][lo:hi]), req)
        return _read_foreign(h5, h5py, req)


def _read_foreign(h5, h5py, req: ReadRequest) -> Recording:
    vectors, scalars = {}, {}

    def visit(name, obj):
        if not isinstance(obj, h5py.Dataset) or obj.dtype.kind not in "fiub":
            return
        long_dims = [s for s in obj.shape if s != 1]
        if len(long_dims) == 1 and obj.size > 1:
            vectors[name] = obj
        elif obj.size == 1:
            scalars[name.rsplit("/", 1)[-1]] = obj

    h5.visititems(visit)
    time = next((k for k in vectors if is_time_name(k.rsplit("/", 1)[-1])), None)
    channels = {k: ds for k, ds in vectors.items() if k != time}
    n = same_lengths({k: ds.size for k, ds in channels.items()})
    found = {
        k: _text(next((ds.attrs[a] for a in _UNIT_ATTRS if a in ds.attrs), "")) for k, ds in channels.items()
    }
    fs, t0 = _rate(h5, req, channels, vectors.get(time), scalars, n)
    return foreign_recording(req, fs, t0, n, found, lambda name, lo, hi: _slice(channels[name], lo, hi))


def _slice(ds, lo: int, hi: int) -> np.ndarray:
    axis = next(i for i, s in enumerate(ds.shape) if s != 1)
    index = [0] * ds.ndim
    index[axis] = slice(lo, hi)
    return np.asarray(ds[tuple(index)])


def _rate_attr(h5, channels) -> tuple[str, float] | None:
    places = []
    for ds in channels.values():
        obj = ds
        while True:
            places.append(obj)
            if obj.name == "/":
                break
            obj = obj.parent
    places.append(h5)
    for obj in places:
        for key in RATE_NAMES:
            if key in obj.attrs:
                return f"{obj.name}@{key}", float(np.asarray(obj.attrs[key]).reshape(-1)[0])
    return None


def _rate(h5, req, channels, time_ds, scalars, n: int) -> tuple[float, float]:
    if time_ds is not None and time_ds.size != n:
        raise InputError(f"time dataset {time_ds.name!r} holds {time_ds.size} values, the channels {n}")
    found = _rate_attr(h5, channels)
    if found is None:
        key = next((k for k in RATE_NAMES if k in scalars), None)
        found = (
            None if key is None else (scalars[key].name, float(np.asarray(scalars[key][()]).reshape(-1)[0]))
        )
    t0 = 0.0 if time_ds is None else float(_slice(time_ds, 0, 1)[0])
    if req.sample_rate_hz is not None:
        if found is not None or time_ds is not None:
            given = found[0] if found else time_ds.name
            raise InputError(f"sample_rate_hz= is for files without a rate; this file gives one ({given})")
        return given_rate(req.sample_rate_hz), t0
    if found is not None:
        try:
            return given_rate(found[1]), t0
        except InputError:
            raise InputError(f"the sample rate {found[0]} = {found[1]!r} is not in (0, 10 MHz]") from None
    if time_ds is not None:
        return rate_of_time(_slice(time_ds, 0, n), f"time dataset {time_ds.name!r}")
    raise InputError(
        f"no sample rate: no attribute or scalar dataset named {', '.join(RATE_NAMES[:6])}, no time dataset "
        "(t, time, time_s); give sample_rate_hz="
    )
