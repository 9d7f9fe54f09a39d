"""What a ring- or housing-fixed sensor measures on a planetary stage, and which lines survive.

- :class:`HannPassWindow` is the planet-pass transfer window w(phi): the weight of a planet's mesh force
  in the sensor signal as a function of the angle phi between the planet and the sensor.
- :func:`ring_sensor_signal` sums the planets' mesh forces through it:
  y(t) = sum_n w(psi_n(t) - theta_s) F_n(t), optionally times the projection cos(psi_n + delta - theta_s)
  of the force direction on the sensor axis.
- :func:`surviving_lines` is McFadden and Smith's rule for equally spaced planets; :func:`phasing_excitation`
  is Parker's planet-phasing rule.

Why a Hann window: it is the shape McFadden & Smith (1985) used for the transfer path from a passing
planet to a fixed transducer (recalled from the paper, not re-read here); it has compact support (a planet
far from the sensor does not reach it), it is smooth (its Fourier coefficients fall off as 1/q^3, so the
sidebands stay near the mesh harmonic), and at full width 2 pi it is w = (1 + cos phi)/2, whose only
coefficients W_0 = 1/2 and W_+-1 = 1/4 give spectra one can work out by hand. Inalpolat & Kahraman (2009)
write the modulation as a general periodic function of the carrier angle; any callable window can be
passed to :func:`ring_sensor_signal`, and the rule below holds for every 2 pi periodic window.

The rule (McFadden & Smith 1985; docs/references.md): planet n at psi_n = theta_c + 2 pi n/N
meshes with a ring tooth Z_r psi_n / 2 pi mesh periods after planet 0. With the window's Fourier series
w(phi) = sum_q W_q e^(i q phi) and the mesh force F(Z_r psi) = sum_k F_k e^(i k Z_r psi), the sum over
planets keeps only e^(i (k Z_r + q) theta_c) with (k Z_r + q) = 0 mod N: lines at (k Z_r + q) f_c.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gearbody.analysis._validate import integer_at_least, is_real, positive_frequency

from ..errors import InputError

__all__ = [
    "Excitation",
    "HannPassWindow",
    "HarmonicPhasing",
    "RingSensorSignal",
    "phasing_excitation",
    "ring_sensor_signal",
    "surviving_lines",
    "wrap_angle_rad",
]


def wrap_angle_rad(angle_rad: ArrayLike) -> NDArray[np.float64]:
    """Angles wrapped to [-pi, pi)."""
    return (np.asarray(angle_rad, dtype=float) + math.pi) % (2.0 * math.pi) - math.pi


@dataclass(frozen=True)
class HannPassWindow:
    """Planet-pass transfer window w(phi) = cos^2(pi phi / width_rad) for |phi| < width_rad / 2, else 0.

    phi, the angle from the sensor to the planet, is wrapped to [-pi, pi); w(0) = 1 (planet at the
    sensor), w(+-width/4) = 1/2, w = 0 beyond +-width/2. width_rad = 2 pi gives (1 + cos phi) / 2.
    """

    width_rad: float
    """Full width of the window [rad], in (0, 2 pi]."""

    def __post_init__(self) -> None:
        w = self.width_rad
        if not (is_real(w) and math.isfinite(w) and 0 < w <= 2.0 * math.pi * (1 + 1e-12)):
            raise InputError(f"width_rad must be in (0, 2 pi] = (0, {2 * math.pi:.6f}] rad, got {w!r}")
        object.__setattr__(self, "width_rad", float(min(w, 2.0 * math.pi)))

    def __call__(self, angle_rad: ArrayLike) -> NDArray[np.float64]:
        phi = wrap_angle_rad(angle_rad)
        inside = np.abs(phi) < 0.5 * self.width_rad
        return np.where(inside, np.cos(math.pi * phi / self.width_rad) ** 2, 0.0)


@dataclass(frozen=True)
class RingSensorSignal:
    """The signal of a ring-fixed sensor and each planet's weight in it."""

    time_s: NDArray[np.float64]
    """Sample times [s], shape (n_samples,)."""
    signal_N: NDArray[np.float64]
    """sum over planets of weight * mesh force [N], shape (n_samples,)."""
    weights: NDArray[np.float64]
    """Per planet: window (times the direction projection if asked), shape (n_planets, n_samples)."""


def _finite_array(name: str, value: ArrayLike, ndim: int) -> NDArray[np.float64]:
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a numeric array, got {type(value).__name__}") from None
    if array.ndim != ndim:
        raise InputError(f"{name} must be {ndim}-D, got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise InputError(f"{name} must be finite, got {int(np.sum(~np.isfinite(array)))} non-finite values")
    return array


def ring_sensor_signal(
    time_s: ArrayLike,
    planet_angles_rad: ArrayLike,
    planet_mesh_forces_N: ArrayLike,
    sensor_angle_rad: float,
    window: Callable[[NDArray[np.float64]], ArrayLike],
    force_direction_offset_rad: float | None = None,
) -> RingSensorSignal:
    """y(t) = sum_n w(psi_n(t) - theta_s) F_n(t) [* cos(psi_n(t) + delta - theta_s)].

    Args:
        time_s: sample times [s], shape (n_samples,), increasing.
        planet_angles_rad: psi_n(t), each planet's position angle in the ring's frame [rad], shape
            (n_planets, n_samples).
        planet_mesh_forces_N: F_n(t), each planet's mesh force [N], same shape.
        sensor_angle_rad: theta_s, the sensor's angle in the same frame [rad].
        window: w(phi), e.g. :class:`HannPassWindow`; any callable mapping an array of angles
            phi = psi_n - theta_s, wrapped to [-pi, pi), to weights of the same shape.
        force_direction_offset_rad: None for the window alone; else delta, the angle of planet n's
            force direction minus psi_n, and the force is projected on the sensor axis (a radial
            sensor at theta_s): factor cos(psi_n + delta - theta_s). For the ring-planet mesh force on
            the ring, delta = pi/2 -+ pressure angle, the sign by the loaded flank.
    """
    t = _finite_array("time_s", time_s, 1)
    if t.size < 2 or np.any(np.diff(t) <= 0):
        raise InputError(f"time_s must hold at least 2 increasing samples, got {t.size} samples")
    psi = _finite_array("planet_angles_rad", planet_angles_rad, 2)
    force = _finite_array("planet_mesh_forces_N", planet_mesh_forces_N, 2)
    if psi.shape[1] != t.size or psi.shape[0] < 1:
        raise InputError(
            f"planet_angles_rad must have shape (n_planets, {t.size}) for {t.size} time samples, "
            f"got {psi.shape}"
        )
    if force.shape != psi.shape:
        raise InputError(
            f"planet_mesh_forces_N must have the shape of planet_angles_rad {psi.shape}, got {force.shape}"
        )
    if not (is_real(sensor_angle_rad) and math.isfinite(sensor_angle_rad)):
        raise InputError(f"sensor_angle_rad must be a finite angle [rad], got {sensor_angle_rad!r}")
    if not callable(window):
        raise InputError(f"window must be callable (e.g. HannPassWindow), got {type(window).__name__}")
    relative = wrap_angle_rad(psi - float(sensor_angle_rad))
    weights = np.asarray(window(relative), dtype=float)
    if weights.shape != psi.shape or not np.all(np.isfinite(weights)):
        raise InputError(f"window must return finite weights of shape {psi.shape}, got shape {weights.shape}")
    if force_direction_offset_rad is not None:
        delta = force_direction_offset_rad
        if not (is_real(delta) and math.isfinite(delta)):
            raise InputError(
                f"force_direction_offset_rad must be a finite angle [rad] or None, got {delta!r}"
            )
        weights = weights * np.cos(relative + float(delta))
    return RingSensorSignal(time_s=t, signal_N=np.sum(weights * force, axis=0), weights=weights)


@dataclass(frozen=True)
class HarmonicPhasing:
    """Which lines near the k-th mesh harmonic survive the sum over N equally spaced planets."""

    harmonic: int
    """k."""
    z_ring: int
    n_planets: int
    mesh_present: bool
    """k Z_r / N is an integer: the mesh harmonic itself (q = 0) survives."""
    q: tuple[int, ...]
    """The surviving offsets q in the asked range, ascending: (k Z_r + q) = 0 mod N."""
    nearest_q: tuple[int, ...]
    """The surviving q of least |q| (two if tied): the strongest line when the window's Fourier
    coefficients |W_q| fall off with |q| (a Hann window's main lobe)."""

    @property
    def carrier_orders(self) -> tuple[int, ...]:
        """k Z_r + q for each surviving q: the lines in multiples of the carrier frequency."""
        return tuple(self.harmonic * self.z_ring + q for q in self.q)

    def frequencies_hz(self, carrier_hz: float) -> NDArray[np.float64]:
        """|k Z_r + q| f_c [Hz] for each surviving q, with f_c the carrier speed relative to the ring."""
        f_c = positive_frequency("carrier_hz", carrier_hz)
        return np.abs(np.array(self.carrier_orders, dtype=float)) * f_c


def surviving_lines(
    z_ring: int, n_planets: int, harmonics: int | Sequence[int], q_range: int
) -> tuple[HarmonicPhasing, ...]:
    """McFadden and Smith's rule at a ring-fixed sensor, N equally spaced identical planets.

    For each mesh harmonic k (1 .. harmonics, or the given ones) the lines (k Z_r + q) f_c with
    |q| <= q_range and (k Z_r + q) = 0 mod N. The mesh harmonic is present iff k Z_r / N is an integer
    (then the sidebands sit at +-N f_c, +-2N f_c, ...); otherwise it is suppressed and the nearest
    surviving q, -(k Z_r mod N) or N - (k Z_r mod N), makes the sidebands asymmetric
    (McFadden & Smith 1985; docs/references.md).
    """
    z_ring = integer_at_least("z_ring", z_ring, 3)
    n = integer_at_least("n_planets", n_planets, 1)
    q_range = integer_at_least("q_range", q_range, 0)
    if isinstance(harmonics, Sequence) and not isinstance(harmonics, str):
        ks = [integer_at_least(f"harmonics[{i}]", k, 1) for i, k in enumerate(harmonics)]
        if not ks:
            raise InputError("harmonics must hold at least one harmonic number >= 1, got none")
    else:
        ks = list(range(1, integer_at_least("harmonics", harmonics, 1) + 1))
    out = []
    for k in ks:
        residue = (k * z_ring) % n
        below, above = -residue, (n - residue) % n
        if residue == 0:
            nearest: tuple[int, ...] = (0,)
        elif -below < above:
            nearest = (below,)
        elif -below > above:
            nearest = (above,)
        else:
            nearest = (below, above)
        q = tuple(q for q in range(-q_range, q_range + 1) if (k * z_ring + q) % n == 0)
        out.append(HarmonicPhasing(k, z_ring, n, residue == 0, q, nearest))
    return tuple(out)


Excitation = Literal["rotational", "translational", "planet"]


def phasing_excitation(z_sun: int, n_planets: int, harmonic: int) -> Excitation:
    """The modes the l-th mesh harmonic excites, by Parker's planet-phasing rule.

    With N equally spaced planets (Parker 2000, J. Sound Vib. 236:561-573; docs/references.md): mesh harmonic
    l excites only rotational modes if l Z_s / N is an integer, only translational modes if
    (l Z_s + 1) / N or (l Z_s - 1) / N is an integer, and only planet modes otherwise. (The ring meshes
    give the same answer: equal spacing needs (Z_s + Z_r)/N integer, so Z_r = -Z_s mod N.) The rule needs
    at least 2 planets; for N = 2 or 3 no harmonic excites planet modes (there are none).
    """
    z_sun = integer_at_least("z_sun", z_sun, 3)
    n = integer_at_least("n_planets", n_planets, 2)
    harmonic = integer_at_least("harmonic", harmonic, 1)
    residue = (harmonic * z_sun) % n
    if residue == 0:
        return "rotational"
    if residue in (1, n - 1):
        return "translational"
    return "planet"
