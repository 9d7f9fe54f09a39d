"""MATLAB recordings: v5 .mat (scipy.io) and v7.3 .mat (HDF5, h5py; ``pip install "gearbody[files]"``).

gearbody writes v5: one double vector per channel (its name made a MATLAB identifier), ``fs`` (the rate)
and ``gearbody`` (a char row: the recording's description as JSON, which maps the variables to the
channels); bit-exact.

Another tool's file, either convention (v5 or v7.3, whose arrays HDF5 stores transposed, each with a
``MATLAB_class`` attribute):

- one numeric vector per channel (named as the variable), of one length, with a sample-rate scalar
  (``fs``, ``Fs``, ``sample_rate``, ``sample_rate_hz``, ``SampleRate``) or a time vector (``t``, ``time``,
  ``time_s``: start and mean step, uniform to 1e-6 of a step);
- a matrix ``data``, ``x`` or ``X`` of samples x channels (channels ``ch1``, ``ch2``, ...) with ``fs``.

``sample_rate_hz=`` gives the rate of a file holding neither; ``units={name: unit}`` the units (MATLAB
files carry none).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import InputError
from ..container import MAX_SAMPLE_RATE_HZ, Recording
from ._common import (
    RATE_NAMES,
    ReadRequest,
    describe,
    foreign_recording,
    from_json,
    given_rate,
    need,
    own_recording,
    rate_of_time,
    same_lengths,
    to_json,
)

_TIME_VARS = ("t", "time", "time_s")
_MATRIX_VARS = ("data", "x", "X")
_RESERVED = ("fs", "gearbody")


def _identifier(name: str, taken: set[str]) -> str:
    base = re.sub(r"\W", "_", name, flags=re.ASCII)
    base = base if base[:1].isalpha() else f"ch_{base}"
    base, k, out = base[:59], 1, base[:59]
    while out in taken or out in _RESERVED:
        k += 1
        out = f"{base}_{k}"
    taken.add(out)
    return out


def write(recording: Recording, path: Path) -> None:
    """The recording as a v5 .mat file (see the module's docstring)."""
    from scipy.io import savemat

    taken: set[str] = set()
    variables = {_identifier(name, taken): ch.data for name, ch in recording.channels.items()}
    desc = {**describe(recording), "variables": list(variables)}
    with open(path, "wb") as fh:
        savemat(fh, {**variables, "fs": recording.sample_rate_hz, "gearbody": to_json(desc)},
                oned_as="column", do_compression=False)  # fmt: skip


@dataclass
class _Var:
    """A variable in MATLAB's orientation, squeezed: shape () scalar, (n,) vector, (n, m) matrix."""

    shape: tuple[int, ...]
    kind: str  # "num", "char" or "other"
    part: Callable[[int, int, int | None], np.ndarray]  # (lo, hi, column) -> samples
    text: Callable[[], str] = str


def _v5_vars(path: Path) -> dict[str, _Var]:
    from scipy.io import loadmat

    out = {}
    for name, value in loadmat(path, squeeze_me=True, chars_as_strings=True).items():
        if name.startswith("__"):
            continue
        arr = np.asarray(value)
        if arr.dtype.kind == "U":
            out[name] = _Var((), "char", lambda lo, hi, c: np.empty(0), lambda a=arr: str(a))
        elif arr.dtype.kind in "fiub" and arr.ndim <= 2:
            out[name] = _Var(
                arr.shape,
                "num",
                lambda lo, hi, c, a=arr: (
                    a.reshape(-1)[lo:hi] if a.ndim == 0 else (a[lo:hi] if c is None else a[lo:hi, c])
                ),
            )
        else:
            out[name] = _Var(arr.shape, "other", lambda lo, hi, c: np.empty(0))
    return out


def _v73_vars(h5) -> dict[str, _Var]:
    out = {}
    for name, ds in h5.items():
        cls = ds.attrs.get("MATLAB_class", b"") if hasattr(ds, "attrs") else b""
        cls = cls.decode() if isinstance(cls, bytes) else str(cls)
        if name.startswith("#") or not hasattr(ds, "dtype"):
            continue
        shape = tuple(reversed(ds.shape))  # HDF5 holds MATLAB's arrays transposed
        squeezed = tuple(s for s in shape if s != 1)
        if cls == "char":
            out[name] = _Var((), "char", lambda lo, hi, c: np.empty(0),
                             lambda d=ds: "".join(map(chr, np.asarray(d[()]).ravel())))  # fmt: skip
        elif ds.dtype.kind in "fiub" and len(squeezed) <= 2 and ds.attrs.get("MATLAB_empty", 0) == 0:
            out[name] = _Var(squeezed, "num", _v73_part(ds, squeezed))
        else:
            out[name] = _Var(shape, "other", lambda lo, hi, c: np.empty(0))
    return out


def _v73_part(ds, squeezed: tuple[int, ...]):
    """Slices of a v7.3 dataset in MATLAB's orientation, read by parts."""
    if len(squeezed) <= 1:
        axis = next((i for i, s in enumerate(ds.shape) if s != 1), 0)

        def part(lo, hi, c):
            index = [0] * ds.ndim
            index[axis] = slice(lo, hi)
            return np.asarray(ds[tuple(index)]) if squeezed else np.asarray(ds[()]).reshape(())

        return part
    return lambda lo, hi, c: np.asarray(ds[c, lo:hi]) if c is not None else np.asarray(ds[:, lo:hi]).T


def read(path: Path, req: ReadRequest) -> Recording:
    """A .mat recording (v5 or v7.3): gearbody's own (its ``gearbody`` variable restores everything) or
    another tool's (the conventions of the module's docstring)."""
    from scipy.io.matlab import matfile_version

    with open(path, "rb") as fh:
        major, _minor = matfile_version(fh)
    if major == 2:
        h5py = need("h5py", "mat")
        with h5py.File(path, "r") as h5:
            return _read_vars(_v73_vars(h5), req)
    if major != 1:
        raise InputError(f"MATLAB v{major + 3} (v4) files are not read; save the file as v5 or v7.3")
    return _read_vars(_v5_vars(path), req)


def _read_vars(variables: dict[str, _Var], req: ReadRequest) -> Recording:
    own = variables.get("gearbody")
    if own is not None and own.kind == "char":
        desc = from_json(own.text())
        names = desc.get("variables", [])
        if len(names) != len(desc["channels"]) or any(variables.get(v) is None for v in names):
            raise InputError("the gearbody description names variables the file does not hold")
        return own_recording(
            desc, lambda i, _name, lo, hi: _vector(variables[names[i]], names[i], lo, hi), req
        )
    fs = _rate_var(variables)
    matrix = next((m for m in _MATRIX_VARS if m in variables and len(variables[m].shape) == 2), None)
    if matrix is not None:
        n, m = variables[matrix].shape
        if m > n:
            raise InputError(f"{matrix!r} is {n} x {m}: it must be samples x channels; transpose it")
        found = {f"ch{j + 1}": "" for j in range(m)}
        read = lambda name, lo, hi: variables[matrix].part(lo, hi, int(name[2:]) - 1)  # noqa: E731
    else:
        skip = {*RATE_NAMES, *_TIME_VARS}
        found = {
            k: "" for k, v in variables.items() if v.kind == "num" and len(v.shape) == 1 and k not in skip
        }
        n = same_lengths({k: variables[k].shape[0] for k in found})
        read = lambda name, lo, hi: variables[name].part(lo, hi, None)  # noqa: E731
    fs, t0 = _rate(req, variables, fs, n)
    return foreign_recording(req, fs, t0, n, found, read)


def _vector(var: _Var, name: str, lo: int, hi: int) -> np.ndarray:
    if var.kind != "num" or len(var.shape) != 1:
        raise InputError(f"variable {name!r} is not a vector (shape {var.shape})")
    return var.part(lo, hi, None)


def _rate_var(variables: dict[str, _Var]) -> tuple[str, float] | None:
    for key in RATE_NAMES:
        var = variables.get(key)
        if var is not None and var.kind == "num" and var.shape == ():
            value = float(np.asarray(var.part(0, 1, None)).reshape(-1)[0])
            if not 0 < value <= MAX_SAMPLE_RATE_HZ:
                raise InputError(
                    f"variable {key!r} = {value!r} is not a sample rate in (0, {MAX_SAMPLE_RATE_HZ:g}] Hz"
                )
            return key, value
    return None


def _rate(req: ReadRequest, variables, fs_var, n: int) -> tuple[float, float]:
    time = next((k for k in _TIME_VARS if k in variables and variables[k].kind == "num"), None)
    t0 = 0.0
    if time is not None and variables[time].shape != (n,):
        raise InputError(
            f"time vector {time!r} has shape {variables[time].shape}; the channels hold {n} samples"
        )
    if req.sample_rate_hz is not None:
        if fs_var is not None or time is not None:
            given: Any = fs_var[0] if fs_var else time
            raise InputError(f"sample_rate_hz= is for files without a rate; this file gives one ({given!r})")
        return given_rate(req.sample_rate_hz), t0
    if fs_var is not None:
        if time is not None:
            t0 = float(variables[time].part(0, 1, None)[0])
        return fs_var[1], t0
    if time is not None:
        return rate_of_time(variables[time].part(0, n, None), f"time vector {time!r}")
    raise InputError(
        f"no sample rate: the file holds no {', '.join(RATE_NAMES[:5])} scalar nor a time vector "
        f"({', '.join(_TIME_VARS)}); give sample_rate_hz="
    )
