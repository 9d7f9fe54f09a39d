"""A measured frequency-response function from bearing forces to a housing accelerometer, and its impulse
response: the sensor path of a virtual instrument when a hammer test (or a model) gives it.

The file (CSV; ``#`` comment lines; a header row; ``,`` between values) holds accelerance
A(f) / F_b(f) [(m/s^2)/N] of the sensor per force signal b of a run, at frequencies f [Hz]::

    # hammer test at the pinion bearing, sensor on the housing top (y)
    frequency_hz,pinion_bearing_force_y_N.re,pinion_bearing_force_y_N.im,wheel_bearing_force_y_N.mag,wheel_bearing_force_y_N.phase_deg
    0,0,0,0,0
    1,-1.4e-7,2.1e-9,3.2e-8,180.1
    ...

Each force signal gives its complex values as ``.re`` and ``.im`` or as ``.mag`` and ``.phase_deg``.
The sign convention is the engineering one: a(t) = Re{A e^(+i 2 pi f t)} for F(t) = Re{F e^(+i 2 pi f
t)}, so a lightly damped mode's accelerance turns through +90 deg at its resonance (a file written with
e^(-i ...) has the conjugate and is refused: its impulse response runs backwards in time).

From FRF to impulse response, at the run's sample rate fs (:meth:`MeasuredFRF.kernels`):

1. The grid f_k = k fs / L, k = 0 .. L/2, L the smallest power of two with fs / L at most the file's
   finest frequency step (at least 256, at most 2^21).
2. A(f_k) interpolated linearly in real and imaginary part; below the file's first frequency it falls
   linearly to 0 at 0 Hz (a supported structure's accelerance vanishes at DC), above its last it falls to
   0 over a tenth of that frequency (raised cosine), and it is 0 beyond; the bin at fs / 2 keeps its real
   part only. The file must resolve its resonances (several points per half-power bandwidth 2 zeta f_n).
3. h = inverse real FFT of length L: a circular response of L / fs seconds. Its last P samples, P = max(16,
   ceil(20 fs / f_band)) (at most L / 8; f_band the file's last frequency or fs / 2), are the acausal
   pre-ring a band-limited response has (t = -P / fs .. 0); the rest is the response at t >= 0.
4. A window: the pre-ring's outer half rises as a half Hann from 0, the causal part's last tenth falls as a
   half Hann to 0. What the window removes must be small: the share of |h|^2 in the causal part's last
   tenth and before the pre-ring's half must stay below :data:`MAX_LOST_ENERGY`, else the file is refused
   (its resolution cannot hold the response's decay: 1 / df seconds; or it has the opposite sign
   convention).

The acceleration is then y = sum_b h_b * (F_b - F_b(0)) (a direct convolution by FFT), the force taken
from static equilibrium at its first sample (held at its last value for the pre-ring's P samples past the
end), as :func:`gearbody.recording.instruments.housing_acceleration` does for modes.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError, SignalError

__all__ = ["MAX_FRF_BYTES", "MAX_LOST_ENERGY", "MIN_POINTS_PER_PEAK", "MeasuredFRF", "read_frf", "write_frf"]

MAX_FRF_BYTES = 64 << 20
"""Largest FRF file read [bytes], 64 MiB (a 100,000-line file of ten signals is ~30 MB)."""

MAX_LOST_ENERGY = 0.02
"""Largest share of the impulse response's energy its window may remove (module docstring, step 4)."""

MIN_POINTS_PER_PEAK = 3
"""Fewest frequencies of a measured FRF in a resonance's half-power band
(:meth:`MeasuredFRF.check_resolution`)."""

_PARTS = (("re", "im"), ("mag", "phase_deg"))
_MIN_POINTS = 8
_MAX_GRID = 1 << 21


@dataclass(frozen=True)
class MeasuredFRF:
    """Accelerance [(m/s^2)/N] of one sensor per force signal (``accelerance``: name -> complex values) at
    ``frequency_hz`` (strictly increasing, >= 0); ``source`` names where it came from."""

    frequency_hz: np.ndarray
    accelerance: Mapping[str, np.ndarray]
    source: str = ""
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self) -> None:
        f = np.asarray(self.frequency_hz, dtype=float)
        where = f"{self.source}: " if self.source else ""
        if f.ndim != 1 or f.size < _MIN_POINTS:
            raise InputError(f"{where}an FRF needs at least {_MIN_POINTS} frequencies, got {f.size}")
        if not np.all(np.isfinite(f)) or f[0] < 0 or np.any(np.diff(f) <= 0):
            raise InputError(f"{where}frequency_hz must be finite, >= 0 and strictly increasing")
        if not self.accelerance:
            raise InputError(f"{where}the FRF names no force signal")
        for name, values in self.accelerance.items():
            v = np.asarray(values)
            if v.shape != f.shape or not np.all(np.isfinite(v)):
                raise InputError(f"{where}accelerance of {name!r}: {f.size} finite values needed")
        object.__setattr__(self, "frequency_hz", f)

    @property
    def signals(self) -> list[str]:
        """The force signals the FRF names."""
        return list(self.accelerance)

    @classmethod
    def from_modes(cls, modes, frequency_hz, source: str = "modes") -> MeasuredFRF:
        """The accelerance of ``modes`` (:class:`~gearbody.recording.instruments.HousingMode`) sampled at
        ``frequency_hz``: sum_m phi_(m,b) s^2 / (s^2 + 2 zeta_m w_m s + w_m^2), s = i 2 pi f."""
        f = np.asarray(frequency_hz, dtype=float)
        return cls(f, modal_accelerance(modes, 2j * np.pi * f), source)

    def kernels(self, sample_rate_hz: float) -> tuple[dict[str, np.ndarray], int]:
        """({force signal: windowed impulse response [(m/s^2)/N per sample], starting P samples before t =
        0}, P) at ``sample_rate_hz`` (module docstring, steps 1-4); InputError when the window would
        remove more than MAX_LOST_ENERGY of a response."""
        fs = float(sample_rate_hz)
        if fs not in self._cache:
            f = self.frequency_hz
            step = float(np.min(np.diff(f)))
            n = min(1 << max(8, math.ceil(math.log2(fs / step))), _MAX_GRID)
            band = min(float(f[-1]), fs / 2)
            pre = int(min(n // 8, max(16, math.ceil(20 * fs / max(band, fs / n)))))
            grid = np.arange(n // 2 + 1) * fs / n
            values = {
                name: self._on_grid(np.asarray(v, dtype=complex), grid)
                for name, v in self.accelerance.items()
            }
            label = f"{self.source or 'FRF'} (frequency step {step:g} Hz)"
            self.check_resolution()
            self._cache[fs] = (impulse_responses(values, n, pre, fs, label), pre)
        return self._cache[fs]

    def check_resolution(self, points: int = MIN_POINTS_PER_PEAK) -> None:
        """InputError unless every resonance of every signal (a peak of |A| with a prominence of at least a
        tenth of the largest |A|) has at least ``points`` frequencies where |A| >= peak / sqrt(2) (its
        half-power band): linear interpolation of fewer flattens the peak (one point in the band of a
        zeta = 0.03 mode read it 21 % low)."""
        from scipy.signal import find_peaks

        for name, values in self.accelerance.items():
            mag = np.abs(np.asarray(values))
            top = float(np.max(mag))
            for i in find_peaks(mag, prominence=0.1 * top)[0] if top > 0 else []:
                lo, hi = i, i
                while lo > 0 and mag[lo - 1] >= mag[i] / math.sqrt(2):
                    lo -= 1
                while hi < mag.size - 1 and mag[hi + 1] >= mag[i] / math.sqrt(2):
                    hi += 1
                if hi - lo + 1 < points:
                    raise InputError(
                        f"{self.source or 'FRF'}: the resonance of {name!r} at {self.frequency_hz[i]:g} Hz "
                        f"has {hi - lo + 1} frequencies in its half-power band; needs at least {points}: "
                        "measure with a finer frequency step"
                    )

    def _on_grid(self, values: np.ndarray, grid: np.ndarray) -> np.ndarray:
        f = self.frequency_hz
        fx, vx = f, values
        if f[0] > 0:  # falls linearly to 0 at DC
            fx, vx = np.concatenate([[0.0], f]), np.concatenate([[0.0], values])
        inside = np.interp(grid, fx, vx.real) + 1j * np.interp(grid, fx, vx.imag)
        top, width = f[-1], 0.1 * f[-1]
        fade = np.where(grid < top + width, 0.5 * (1 + np.cos(np.pi * (grid - top) / width)), 0.0)
        return np.where(grid > top, values[-1] * fade, inside)

    def response(self, time_s: np.ndarray, forces: Mapping[str, np.ndarray]) -> np.ndarray:
        """The acceleration [m/s^2] at the samples ``time_s`` (uniform) for ``forces`` (signal -> samples
        [N]): sum over the FRF's signals of the impulse response convolved with the force, from static
        equilibrium at the first sample."""
        fs = uniform_rate(time_s)
        kernels, pre = self.kernels(fs)
        return convolve(kernels, pre, len(time_s), forces, self.source or "the FRF")


def modal_kernels(modes, sample_rate_hz: float) -> tuple[dict[str, np.ndarray], int]:
    """The impulse responses of ``modes`` (HousingMode) as :meth:`MeasuredFRF.kernels` gives them, from
    their exact accelerance on the grid (L long enough for the slowest mode's |h|^2 to fall by 1e-6 in
    0.9 of the causal part: 6.9 / (zeta w) seconds; P = 40 samples)."""
    fs = float(sample_rate_hz)
    decay_s = max(6.9 / (m.damping_ratio * 2 * math.pi * m.frequency_hz) for m in modes)
    pre = 40
    needed = decay_s * fs / 0.9 + pre
    if needed > _MAX_GRID:
        slow = min(modes, key=lambda m: m.damping_ratio * m.frequency_hz)
        raise InputError(
            f"HousingMode {slow.frequency_hz:g} Hz, damping_ratio {slow.damping_ratio:g}: rings for "
            f"{decay_s:.3g} s, longer than {_MAX_GRID} samples at {fs:g} Hz; give it more damping"
        )
    n = 1 << max(8, math.ceil(math.log2(needed)))
    values = modal_accelerance(modes, 2j * np.pi * np.arange(n // 2 + 1) * fs / n)
    return impulse_responses(values, n, pre, fs, "housing modes"), pre


def modal_accelerance(modes, s: np.ndarray) -> dict[str, np.ndarray]:
    """{force signal: sum_m phi_(m,b) s^2 / (s^2 + 2 zeta_m w_m s + w_m^2)} of ``modes`` (HousingMode)
    at the Laplace points ``s`` (i 2 pi f)."""
    out: dict[str, np.ndarray] = {}
    for mode in modes:
        w, z = 2 * math.pi * mode.frequency_hz, mode.damping_ratio
        shape = s**2 / (s**2 + 2 * z * w * s + w**2)
        for name, phi in mode.participation.items():
            out[name] = out.get(name, 0) + phi * shape
    return out


def impulse_responses(values: Mapping[str, np.ndarray], n: int, pre: int, fs: float, label: str):
    """{signal: windowed impulse response from t = -pre / fs} of accelerance ``values`` on the grid k fs /
    n, k = 0 .. n / 2 (module docstring, steps 3-4); InputError naming ``label`` when the window would
    remove more than MAX_LOST_ENERGY of one."""
    window = _window(n, pre)
    causal = n - pre
    out = {}
    for name, on_grid in values.items():
        on_grid = np.array(on_grid, dtype=complex)
        on_grid[-1] = on_grid[-1].real  # the bin at fs / 2 of a real response
        h = np.fft.irfft(on_grid, n)
        energy = float(np.sum(h**2)) or 1.0
        tail = float(np.sum(h[int(0.9 * causal) : causal] ** 2))
        early = float(np.sum(h[causal : causal + pre // 2] ** 2))
        lost = (tail + early) / energy
        if lost > MAX_LOST_ENERGY:
            raise InputError(
                f"{label}: the impulse response of {name!r} has {lost:.1%} of its energy where it should "
                f"have decayed (after {0.9 * causal / fs:.3g} s) or before t = {-pre / 2 / fs:.3g} s "
                f"(allowed: {MAX_LOST_ENERGY:.0%}): measure with a finer frequency step, or check the phase "
                "convention (a(t) = Re{A e^(+i 2 pi f t)}: a mode turns through +90 deg at resonance)"
            )
        h = h * window
        out[name] = np.concatenate([h[causal:], h[:causal]])
    return out


def uniform_rate(time_s) -> float:
    """The sample rate of uniform instants ``time_s`` (InputError when they are not uniform)."""
    t = np.asarray(time_s, dtype=float)
    if t.size < 2:
        raise InputError(f"time_s: needs at least 2 samples, got {t.size}")
    dt = np.diff(t)
    if not (dt[0] > 0 and np.allclose(dt, dt[0], rtol=1e-6, atol=0)):
        raise InputError("time_s: the sensor path needs uniform, increasing samples")
    return 1.0 / float(dt[0])


def convolve(kernels, pre: int, size: int, forces: Mapping[str, np.ndarray], label: str) -> np.ndarray:
    """sum_b kernels[b] * (F_b - F_b(0)), ``size`` samples (the force held at its last value past the
    end); SignalError naming the force signals there are when ``forces`` lacks one."""
    from scipy.signal import fftconvolve

    total = np.zeros(size)
    for name, h in kernels.items():
        if name not in forces:
            raise SignalError(f"{label} names force signal {name!r}; force signals: {', '.join(forces)}")
        x = np.asarray(forces[name], dtype=float)
        x = np.concatenate([x - x[0], np.full(pre, x[-1] - x[0])])
        total += fftconvolve(x, h)[pre : pre + size]
    return total


def _window(n: int, pre: int) -> np.ndarray:
    """1 over the response, a half Hann rising over the pre-ring's outer half and one falling over the
    causal part's last tenth (in the circular order of the inverse FFT)."""
    w = np.ones(n)
    causal = n - pre
    fall = max(1, causal // 10)
    w[causal - fall : causal] = 0.5 * (1 + np.cos(np.pi * (np.arange(fall) + 1) / fall))
    rise = max(1, pre // 2)
    w[causal : causal + rise] = 0.5 * (1 - np.cos(np.pi * np.arange(rise) / rise))
    return w


def read_frf(path: str | Path) -> MeasuredFRF:
    """The FRF file at ``path`` (module docstring); InputError naming the file, the line or column and what
    is allowed."""
    path = Path(path)
    try:
        size = os.stat(path).st_size
        if not path.is_file():
            raise InputError(f"{path}: not a file (an FRF file is a CSV text file)")
        if size > MAX_FRF_BYTES:
            raise InputError(f"{path}: {size} bytes; an FRF file may hold at most {MAX_FRF_BYTES} bytes")
        text = path.read_bytes().decode("utf-8")
    except FileNotFoundError:
        raise InputError(f"{path}: no such FRF file") from None
    except UnicodeDecodeError:
        raise InputError(f"{path}: not UTF-8 text (an FRF file is a CSV text file)") from None
    except OSError as exc:
        raise InputError(f"{path}: cannot read the FRF file: {exc.strerror or exc}") from None
    rows = [
        (n, line)
        for n, line in enumerate(text.removeprefix("\ufeff").splitlines(), 1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not rows:
        raise InputError(f"{path}: holds no header row (frequency_hz,<signal>.re,<signal>.im,...)")
    columns = [c.strip() for c in rows[0][1].split(",")]
    pairs = _signal_columns(path, columns)
    values = np.empty((len(rows) - 1, len(columns)))
    for i, (n, line) in enumerate(rows[1:]):
        cells = line.split(",")
        if len(cells) != len(columns):
            raise InputError(f"{path}, line {n}: {len(cells)} values; the header names {len(columns)}")
        try:
            values[i] = [float(c) for c in cells]
        except ValueError:
            raise InputError(f"{path}, line {n}: a value is not a number: {line.strip()[:80]!r}") from None
        if not np.all(np.isfinite(values[i])):
            raise InputError(f"{path}, line {n}: values must be finite")
    accelerance = {}
    for name, (kind, a, b) in pairs.items():
        if kind == "re":
            accelerance[name] = values[:, a] + 1j * values[:, b]
        else:
            if np.any(values[:, a] < 0):
                raise InputError(f"{path}: column {name}.mag: a magnitude must be >= 0")
            accelerance[name] = values[:, a] * np.exp(1j * np.radians(values[:, b]))
    try:
        return MeasuredFRF(values[:, 0], accelerance, str(path))
    except InputError as exc:
        raise InputError(f"{exc} (column frequency_hz, {values.shape[0]} rows)") from None


def _signal_columns(path: Path, columns: list[str]) -> dict[str, tuple[str, int, int]]:
    """{signal: ("re" or "mag", column of re/mag, column of im/phase_deg)} from the header."""
    if columns[0] != "frequency_hz":
        raise InputError(f"{path}: the first column must be frequency_hz, got {columns[0]!r}")
    found: dict[str, dict[str, int]] = {}
    for j, column in enumerate(columns[1:], 1):
        name, dot, part = column.rpartition(".")
        if not dot or not name or part not in {p for pair in _PARTS for p in pair}:
            raise InputError(
                f"{path}: column {column!r}: expected <force signal>.re / .im or <force signal>.mag / "
                ".phase_deg"
            )
        if part in found.setdefault(name, {}):
            raise InputError(f"{path}: column {column!r} appears twice")
        found[name][part] = j
    if not found:
        raise InputError(f"{path}: the header names no force signal after frequency_hz")
    out = {}
    for name, parts in found.items():
        pair = next((p for p in _PARTS if set(parts) == set(p)), None)
        if pair is None:
            raise InputError(
                f"{path}: signal {name!r} has columns {', '.join(sorted(parts))}; give .re and .im, or .mag "
                "and .phase_deg"
            )
        out[name] = (pair[0], parts[pair[0]], parts[pair[1]])
    return out


def write_frf(frf: MeasuredFRF, path: str | Path) -> Path:
    """``frf`` as an FRF file (``.re`` and ``.im`` columns, ``%.17g``: read back exactly)."""
    path = Path(path)
    names = frf.signals
    header = ",".join(["frequency_hz", *(f"{n}.{p}" for n in names for p in ("re", "im"))])
    cols = [frf.frequency_hz]
    for n in names:
        v = np.asarray(frf.accelerance[n], dtype=complex)
        cols += [v.real, v.imag]
    np.savetxt(path, np.column_stack(cols), delimiter=",", header=header, comments="", fmt="%.17g")
    return path
