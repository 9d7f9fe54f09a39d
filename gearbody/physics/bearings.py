"""Bearing force laws: the extension point for bearing compliance. Engine-free.

A bearing law maps the relative displacement u = (u_x, u_y) in m and velocity v in m/s of a journal
(gear centre) with respect to its housing to the force (N) that the bearing exerts *on the journal*.
Any object with that ``force_N`` method is a bearing; register it under a name to make it available
to scenarios:

    @dataclass(frozen=True)
    class MyBearing:
        stiffness_N_per_m: float

        def force_N(self, displacement_m, velocity_m_s):
            return -self.stiffness_N_per_m * np.asarray(displacement_m, float)

    register_bearing("mine", MyBearing)

The engine wraps any law in one user-function connector between gear and housing; it never needs
to know which law it is. A law may also offer ``force_xy(ux, uy, vx, vy) -> (fx, fy)`` on plain floats,
which the engine then calls instead (cheaper per call); the linear law is built from Exudyn's own
spring-dampers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, Protocol, runtime_checkable

import numpy as np
from numba import njit

from .rolling_bearing import LAW_ROLLING, BearingDefect, RollingElementBearing, rolling_force_xy


@runtime_checkable
class BearingLaw(Protocol):
    def force_N(self, displacement_m: np.ndarray, velocity_m_s: np.ndarray) -> np.ndarray:
        """Force on the journal (N, 2 components) from its displacement and velocity."""
        ...


@dataclass(frozen=True)
class LinearBearing:
    """Linear spring-damper per direction (the paper's k_x, k_y, C_x, C_y of Figs. 17-18)."""

    STIFFNESS_PARAMETERS: ClassVar[tuple[str, str]] = ("stiffness_x_N_per_m", "stiffness_y_N_per_m")
    DAMPING_PARAMETERS: ClassVar[tuple[str, str]] = ("damping_x_Ns_per_m", "damping_y_Ns_per_m")

    stiffness_x_N_per_m: float
    stiffness_y_N_per_m: float
    damping_x_Ns_per_m: float = 0.0
    damping_y_Ns_per_m: float = 0.0

    def __post_init__(self) -> None:
        for name in ("stiffness_x_N_per_m", "stiffness_y_N_per_m"):
            if not getattr(self, name) > 0:
                raise ValueError(f"LinearBearing.{name} = {getattr(self, name)!r}: must be > 0")
        for name in ("damping_x_Ns_per_m", "damping_y_Ns_per_m"):
            if not getattr(self, name) >= 0:
                raise ValueError(f"LinearBearing.{name} = {getattr(self, name)!r}: must be >= 0")

    def law_row(self) -> np.ndarray:
        """This law as a row for the compiled :func:`law_force_xy`."""
        k, c = (
            (self.stiffness_x_N_per_m, self.stiffness_y_N_per_m),
            (self.damping_x_Ns_per_m, self.damping_y_Ns_per_m),
        )
        return np.array([LAW_LINEAR, k[0], k[1], c[0], c[1]])

    def force_N(self, displacement_m, velocity_m_s) -> np.ndarray:
        u = np.asarray(displacement_m, float)
        v = np.asarray(velocity_m_s, float)
        return -np.array(
            [
                self.stiffness_x_N_per_m * u[0] + self.damping_x_Ns_per_m * v[0],
                self.stiffness_y_N_per_m * u[1] + self.damping_y_Ns_per_m * v[1],
            ]
        )


@dataclass(frozen=True)
class HertzianBearing:
    """Rolling-element bearing with radial clearance and Hertzian contact.

    Radial force ``k_b max(0, |u| - c)^n`` towards the bearing centre, with n = 3/2 for ball bearings
    (10/9 is used for roller bearings), plus a radial damping ``C u_r'`` while in contact. This is the
    lumped (isotropic) form; a per-element model with ball passage is a later refinement.
    """

    STIFFNESS_PARAMETERS: ClassVar[tuple[str, str]] = ("contact_stiffness_N_per_m_n",) * 2
    DAMPING_PARAMETERS: ClassVar[tuple[str, str]] = ("damping_Ns_per_m",) * 2

    contact_stiffness_N_per_m_n: float
    radial_clearance_m: float = 0.0
    exponent: float = 1.5
    damping_Ns_per_m: float = 0.0

    def __post_init__(self) -> None:
        if not self.contact_stiffness_N_per_m_n > 0:
            raise ValueError(
                f"HertzianBearing.contact_stiffness_N_per_m_n = {self.contact_stiffness_N_per_m_n!r}: "
                "must be > 0"
            )
        if not self.radial_clearance_m >= 0:
            raise ValueError(
                f"HertzianBearing.radial_clearance_m = {self.radial_clearance_m!r}: must be >= 0"
            )
        if not 1.0 <= self.exponent <= 2.0:
            raise ValueError(
                f"HertzianBearing.exponent = {self.exponent!r}: must be in [1, 2] (3/2 ball, 10/9 roller)"
            )
        if not self.damping_Ns_per_m >= 0:
            raise ValueError(f"HertzianBearing.damping_Ns_per_m = {self.damping_Ns_per_m!r}: must be >= 0")

    def force_N(self, displacement_m, velocity_m_s) -> np.ndarray:
        u, v = displacement_m, velocity_m_s
        return np.array(self.force_xy(float(u[0]), float(u[1]), float(v[0]), float(v[1])))

    def force_xy(self, ux: float, uy: float, vx: float, vy: float) -> tuple[float, float]:
        """Scalar form of :meth:`force_N` (the engine calls it when a law has one: fewer conversions):
        the compiled :func:`hertz_force_xy`, the one the compiled path calls."""
        return hertz_force_xy(
            ux,
            uy,
            vx,
            vy,
            self.contact_stiffness_N_per_m_n,
            self.radial_clearance_m,
            self.exponent,
            self.damping_Ns_per_m,
        )

    def law_row(self) -> np.ndarray:
        """This law as a row for the compiled :func:`law_force_xy`."""
        p = (self.contact_stiffness_N_per_m_n, self.radial_clearance_m, self.exponent, self.damping_Ns_per_m)
        return np.array([LAW_HERTZIAN, *p])

    def potential_J(self, displacement_m) -> float:
        """Elastic energy stored in the contact (for checks): k_b p^(n+1) / (n+1)."""
        p = max(0.0, math.hypot(*np.asarray(displacement_m, float)) - self.radial_clearance_m)
        return self.contact_stiffness_N_per_m_n * p ** (self.exponent + 1) / (self.exponent + 1)


@njit(cache=True)
def hertz_force_xy(ux, uy, vx, vy, k_b, clearance_m, exponent, damping_Ns_per_m):
    """The Hertzian law on plain floats: radial ``k_b max(0, |u| - c)^n + C u_r'`` towards the centre
    while it pushes (N); (0, 0) out of contact."""
    r = math.hypot(ux, uy)
    penetration = r - clearance_m
    if penetration <= 0.0 or r == 0.0:
        return 0.0, 0.0
    ex, ey = ux / r, uy / r
    radial = k_b * penetration**exponent + damping_Ns_per_m * (vx * ex + vy * ey)
    if radial <= 0.0:
        return 0.0, 0.0  # a bearing pushes, it never pulls
    return -radial * ex, -radial * ey


LAW_LINEAR, LAW_HERTZIAN = 1.0, 2.0
"""Codes of the shipped laws in a law row ``[code, parameters...]`` (a law's ``law_row()``), read by
:func:`law_force_xy` where a compiled function needs a law chosen at run time (a planetary stage's
bearings); :data:`gearbody.physics.rolling_bearing.LAW_ROLLING` is the ball-by-ball law's."""


@njit(cache=True)
def law_force_xy(row, ux, uy, vx, vy, inner_rad, outer_rad):
    """Force (N) of the law in ``row`` (:data:`LAW_LINEAR` ``[k_x, k_y, C_x, C_y]``,
    :data:`LAW_HERTZIAN` ``[k_b, c, n, C]`` or the rolling-element law's row) on plain floats, the races
    turned by ``inner_rad`` and ``outer_rad`` (read by the rolling-element law only): the same arithmetic
    as the law's ``force_N``."""
    if row[0] == LAW_LINEAR:
        return -(row[1] * ux + row[3] * vx), -(row[2] * uy + row[4] * vy)
    if row[0] == LAW_ROLLING:
        return rolling_force_xy(row, ux, uy, vx, vy, inner_rad, outer_rad)
    return hertz_force_xy(ux, uy, vx, vy, row[1], row[2], row[3], row[4])


def tangent_stiffness_damping(
    law: BearingLaw, displacement_m: np.ndarray | tuple[float, float] = (0.0, 0.0)
) -> tuple[np.ndarray, np.ndarray]:
    """(k_xx, k_yy) [N/m] and (c_xx, c_yy) [N s/m]: the diagonal of -dF/du and -dF/dv of any bearing law
    at ``displacement_m`` at rest, by central differences (exact for the linear law; a Hertzian law's
    radial tangent n k_b p^(n-1) along the displacement and F / |u| across it, its damping while in
    contact). Steps: 1e-6 of |u| (at least 1e-12 m) and 1e-6 m/s."""
    u0 = np.asarray(displacement_m, dtype=float).reshape(2)
    h_u = max(1e-6 * float(np.hypot(*u0)), 1e-12)
    h_v = 1e-6
    k, c = np.zeros(2), np.zeros(2)
    zero = np.zeros(2)
    for d in range(2):
        e = np.zeros(2)
        e[d] = 1.0
        force = law.force_N
        k[d] = -(force(u0 + h_u * e, zero)[d] - force(u0 - h_u * e, zero)[d]) / (2.0 * h_u)
        c[d] = -(force(u0, h_v * e)[d] - force(u0, -h_v * e)[d]) / (2.0 * h_v)
    return k, c


@dataclass(frozen=True)
class RigidBearing:
    """A bearing that holds its gear centre fixed: no law, no dynamics. A torsional gear (lateral =
    "none") may carry a bearing table of this kind to name its bearing and state its rolling geometry
    (the defect frequencies of the analysis); the engine never builds it, and a gear that moves on its
    bearing cannot take it (gearbody.model.components.Gear)."""

    def force_N(self, displacement_m, velocity_m_s) -> np.ndarray:
        raise ValueError(
            "a 'rigid' bearing holds its gear centre fixed and has no force law: it belongs on a gear "
            "with lateral = 'none', which the engine builds without one"
        )


BEARINGS: dict[str, type] = {
    "linear": LinearBearing,
    "hertzian": HertzianBearing,
    "rolling-elements": RollingElementBearing,
    "rigid": RigidBearing,
}

__all__ = [
    "BEARINGS",
    "BearingDefect",
    "BearingLaw",
    "HertzianBearing",
    "LinearBearing",
    "RigidBearing",
    "RollingElementBearing",
    "law_force_xy",
    "make_bearing",
    "register_bearing",
    "tangent_stiffness_damping",
]


def register_bearing(kind: str, cls: type) -> None:
    """Make a bearing law available to scenarios under ``kind``."""
    if not hasattr(cls, "force_N"):
        raise TypeError(f"{cls.__name__} has no force_N(displacement_m, velocity_m_s) method")
    BEARINGS[kind] = cls


def make_bearing(kind: str, **parameters: float) -> BearingLaw:
    """Bearing of a registered kind; unknown kinds name the registered ones."""
    try:
        cls = BEARINGS[kind]
    except KeyError:
        raise ValueError(
            f"bearing kind {kind!r} is not registered; kinds: {', '.join(sorted(BEARINGS))}"
        ) from None
    return cls(**parameters)
