"""NI TDMS recordings, read only (npTDMS, LGPL: ``pip install "gearbody[tdms]"``).

Every numeric channel of every group is a channel, named ``<channel>`` (one group) or
``<group>/<channel>`` (several); channels of other types (strings, timestamps) are left out and listed in
the recording's ``meta["tdms_skipped"]``. The rate is 1 / the channels' ``wf_increment`` property
(one for all), the start their ``wf_start_offset``; without it a numeric channel named ``time``, ``t``
or ``time_s`` gives start and rate (uniform to 1e-6 of a step), else ``sample_rate_hz=``. Units from a
channel's ``unit_string`` property or ``units=``. Samples are read by parts (``start_s``/``end_s``)
through npTDMS's streaming reader.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...errors import InputError
from ..container import Recording
from ._common import (
    ReadRequest,
    foreign_recording,
    given_rate,
    is_time_name,
    need,
    rate_of_time,
    same_lengths,
)


def read(path: Path, req: ReadRequest) -> Recording:
    """The recording in a TDMS file (the conventions of the module's docstring)."""
    nptdms = need("nptdms", "tdms", extra="tdms")
    with nptdms.TdmsFile.open(path) as tdms:
        groups = tdms.groups()
        several = len(groups) > 1
        chans, skipped = {}, []
        for group in groups:
            for ch in group.channels():
                name = f"{group.name}/{ch.name}" if several else ch.name
                if np.dtype(ch.dtype).kind in "fiu":
                    chans[name] = ch
                else:
                    skipped.append(name)
        time = next((k for k in chans if is_time_name(k.rsplit("/", 1)[-1])), None)
        time_ch = chans.pop(time) if time is not None else None
        n = same_lengths({k: len(ch) for k, ch in chans.items()})
        fs, t0 = _rate(req, chans, time_ch, n)
        units = {k: str(ch.properties.get("unit_string", "")).strip() for k, ch in chans.items()}
        meta = {"tdms_skipped": skipped} if skipped else {}
        return foreign_recording(
            req, fs, t0, n, units, lambda name, lo, hi: np.asarray(chans[name].read_data(lo, hi - lo)), meta
        )


def _rate(req: ReadRequest, chans, time_ch, n: int) -> tuple[float, float]:
    increments = {k: ch.properties.get("wf_increment") for k, ch in chans.items()}
    given = {k: float(v) for k, v in increments.items() if v is not None}
    if req.sample_rate_hz is not None:
        if given or time_ch is not None:
            what = "wf_increment" if given else f"time channel {time_ch.name!r}"
            raise InputError(f"sample_rate_hz= is for files without a rate; this file gives one ({what})")
        return given_rate(req.sample_rate_hz), 0.0
    if given:
        if len(given) != len(chans) or len(set(given.values())) > 1:
            shown = ", ".join(f"{k}: {v!r}" for k, v in list(increments.items())[:6])
            raise InputError(f"the channels' wf_increment differ ({shown}); a recording needs one rate")
        step = next(iter(given.values()))
        if not step > 0:
            raise InputError(f"wf_increment = {step!r} s: must be > 0")
        starts = {float(ch.properties.get("wf_start_offset", 0.0)) for ch in chans.values()}
        if len(starts) > 1:
            raise InputError(
                f"the channels' wf_start_offset differ ({sorted(starts)[:6]}); a recording has one start"
            )
        return given_rate(1.0 / step), starts.pop()
    if time_ch is not None:
        if len(time_ch) != n:
            raise InputError(f"time channel {time_ch.name!r} holds {len(time_ch)} values, the channels {n}")
        return rate_of_time(
            np.asarray(time_ch.read_data(), dtype=np.float64), f"time channel {time_ch.name!r}"
        )
    raise InputError("no sample rate: no wf_increment property and no time channel; give sample_rate_hz=")
