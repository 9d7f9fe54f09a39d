"""A rolling-element bearing ball by ball, with local defects and cage slip. Engine-free.

Each of the ``Z`` balls sits at its angle ``theta_i`` in the plane of the bearing and pushes on the
journal with a Hertzian contact ``K max(0, delta_i)^n`` along ``e_i = (cos theta_i, sin theta_i)``
(inner and outer contact in series, ``K`` the combined constant of one ball, n = 3/2 for balls, 10/9
for rollers), where

    delta_i = u . e_i - c - h_i,

``u`` the journal's displacement from the bearing centre, ``c`` the radial clearance and ``h_i`` the
depth the ball drops into a defect it meets. The force on the journal is ``-sum_i K max(0, delta_i)^n
e_i - C u'`` (a viscous damping ``C`` of the support, acting always, so that the law is continuous).

**Cage kinematics.** With the inner race turned by ``theta_in`` and the outer race by ``theta_out``
(rad, about the bearing axis in the frame of ``u``) the cage turns, rolling without slip, by
``theta_out + r_c (theta_in - theta_out)``, ``r_c = (1 - gamma) / 2`` and ``gamma = d cos(alpha) / D``
(d ball diameter, D pitch diameter, alpha contact angle): the fundamental train frequency. Ball i sits at
``theta_cage + 2 pi i / Z``. A real cage slips: the time between two ball passages varies by 1-2 %
(Sawalhi and Randall 2008). Here each ball spacing of the cage's travel, taken in turn, is covered at
``1 + eps_k`` of the kinematic rate, ``eps_k`` uniform in [-s, s] from a seed (``cage_slip`` = s), from a
table of :data:`SLIP_TABLE` spacings repeated; the cage angle stays continuous and a function of the
race angles alone, so a run-up, a reversal and an integrator's retried step all see the same cage.

**Defects.** A defect is a pit of ``depth_m`` over ``width_deg`` (an angle about the bearing centre for a
race defect, about the ball's centre for a ball defect): an outer-race spall fixed to the outer race at
``angle_deg``, an inner-race spall turning with the inner race, and a rolling-element defect on ball
``ball``, which spins relative to the cage by ``b_s (theta_in - theta_out)``, ``b_s = D / (2 d) (1 -
gamma^2)`` (the ball spin frequency), and meets the outer race when its spin angle from the outward
radial direction passes 0 and the inner race when it passes pi: twice per spin (2 x BSF). A contact at
the distance ``e`` inside the nearer edge of a pit drops by

    h = min(depth, rho - sqrt(rho^2 - e^2))      (rho when e >= rho),

the sagitta of the relative radius of curvature ``rho`` of the two surfaces (1/rho = 2/d - 2/D_o on the
outer race, 2/d + 2/D_i on the inner, D_o,i = D +- d cos(alpha) the race diameters), so a narrow defect
limits the drop to what the ball's geometry lets it reach and the drop rises smoothly from the edges.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

LAW_ROLLING = 3.0
"""Code of :class:`RollingElementBearing` in a law row (see gearbody.physics.bearings.law_force_xy)."""

SLIP_TABLE = 1024
"""Ball spacings with their own random slip before the sequence repeats."""

RACES = ("outer", "inner", "ball")
_HEAD = 10  # row: code, K, c, n, C, Z, r_c, b_s, slip table size, defects
_PER_DEFECT = 6  # race, centre angle, half arc, depth, ball, radius of the surface


@dataclass(frozen=True)
class BearingDefect:
    """A local defect: ``race`` 'outer' (fixed in the outer race), 'inner' (turning with the inner race)
    or 'ball' (on rolling element ``ball``); ``depth_m``, ``width_deg`` and where it sits, ``angle_deg``
    (a race defect: from the x axis of the outer race, or of the inner race at angle 0; a ball defect:
    its spin angle from the outward radial direction at angle 0)."""

    race: str
    depth_m: float
    width_deg: float
    angle_deg: float = 0.0
    ball: int = 0

    def __post_init__(self) -> None:
        if self.race not in RACES:
            raise ValueError(f"BearingDefect.race = {self.race!r}: must be one of {', '.join(RACES)}")
        if not (math.isfinite(self.depth_m) and 0 < self.depth_m <= 0.01):
            raise ValueError(f"BearingDefect.depth_m = {self.depth_m!r}: must be in (0, 0.01] m")
        if not (math.isfinite(self.width_deg) and 0 < self.width_deg <= 90):
            raise ValueError(f"BearingDefect.width_deg = {self.width_deg!r}: must be in (0, 90] deg")
        if not (math.isfinite(self.angle_deg) and -360 <= self.angle_deg <= 360):
            raise ValueError(f"BearingDefect.angle_deg = {self.angle_deg!r}: must be in [-360, 360] deg")
        if not self.ball >= 0:
            raise ValueError(f"BearingDefect.ball = {self.ball!r}: must be >= 0")


@dataclass(frozen=True)
class RollingElementBearing:
    """A rolling-element bearing ball by ball (module docstring): Hertzian balls, clearance, defects and a
    seeded cage slip. Needs the angles of its races: the engine passes the gear's rotation as the inner
    race's (``ROTATING``)."""

    STIFFNESS_PARAMETERS: ClassVar[tuple[str, str]] = ("ball_stiffness_N_per_m_n",) * 2
    DAMPING_PARAMETERS: ClassVar[tuple[str, str]] = ("damping_Ns_per_m",) * 2
    ROTATING: ClassVar[bool] = True
    GEOMETRY: ClassVar[tuple[str, ...]] = (
        "balls",
        "ball_diameter_m",
        "pitch_diameter_m",
        "contact_angle_deg",
    )

    ball_stiffness_N_per_m_n: float
    balls: int
    ball_diameter_m: float
    pitch_diameter_m: float
    contact_angle_deg: float = 0.0
    radial_clearance_m: float = 0.0
    exponent: float = 1.5
    damping_Ns_per_m: float = 0.0
    cage_slip: float = 0.015
    slip_seed: float = 0.0
    defects: tuple[BearingDefect, ...] = ()

    def __post_init__(self) -> None:
        def bad(name: str, allowed: str) -> ValueError:
            return ValueError(f"RollingElementBearing.{name} = {getattr(self, name)!r}: must be {allowed}")

        if not self.ball_stiffness_N_per_m_n > 0:
            raise bad("ball_stiffness_N_per_m_n", "> 0")
        if not (self.balls == int(self.balls) and 3 <= self.balls <= 100):
            raise bad("balls", "a whole number in [3, 100]")
        if not self.ball_diameter_m > 0:
            raise bad("ball_diameter_m", "> 0")
        if not self.pitch_diameter_m > self.ball_diameter_m:
            raise bad("pitch_diameter_m", f"> ball_diameter_m = {self.ball_diameter_m!r}")
        if not 0 <= self.contact_angle_deg < 90:
            raise bad("contact_angle_deg", "in [0, 90)")
        if not self.radial_clearance_m >= 0:
            raise bad("radial_clearance_m", ">= 0")
        if not 1.0 <= self.exponent <= 2.0:
            raise bad("exponent", "in [1, 2] (3/2 ball, 10/9 roller)")
        if not self.damping_Ns_per_m >= 0:
            raise bad("damping_Ns_per_m", ">= 0")
        if not 0 <= self.cage_slip <= 0.1:
            raise bad("cage_slip", "in [0, 0.1] (a fraction of the kinematic cage speed; 0.01-0.02 typical)")
        if not (self.slip_seed == int(self.slip_seed) and 0 <= self.slip_seed < 2**32):
            raise bad("slip_seed", "a whole number in [0, 2^32)")
        object.__setattr__(self, "defects", tuple(self.defects))
        for k, d in enumerate(self.defects):
            if d.race == "ball" and d.ball >= self.balls:
                raise ValueError(
                    f"defects[{k}].ball = {d.ball}: the bearing has balls 0..{int(self.balls) - 1}"
                )

    @property
    def gamma(self) -> float:
        """d cos(alpha) / D."""
        return self.ball_diameter_m * math.cos(math.radians(self.contact_angle_deg)) / self.pitch_diameter_m

    @property
    def cage_ratio(self) -> float:
        """Cage turns per turn of the inner race relative to the outer: (1 - gamma) / 2 (FTF / f_r)."""
        return 0.5 * (1.0 - self.gamma)

    @property
    def spin_ratio(self) -> float:
        """Ball spin turns relative to the cage per relative turn of the races: D / (2 d) (1 - gamma^2)."""
        return self.pitch_diameter_m / (2.0 * self.ball_diameter_m) * (1.0 - self.gamma**2)

    def slip_table(self) -> np.ndarray:
        """Cumulative cage angle (rad) at the start of each of the :data:`SLIP_TABLE` ball spacings and at
        the end of the last, with the seeded slip; empty without slip."""
        if self.cage_slip == 0.0:
            return np.zeros(0)
        spacing = 2.0 * math.pi / self.balls
        eps = np.random.default_rng(int(self.slip_seed)).uniform(-self.cage_slip, self.cage_slip, SLIP_TABLE)
        return np.concatenate(([0.0], np.cumsum(spacing * (1.0 + eps))))

    def _radii_m(self) -> tuple[float, float, float, float]:
        """Outer and inner race radii at the contact, and the relative radii of curvature of a ball on
        the outer and on the inner race (1/rho = 2/d -+ 2/D_o,i)."""
        d, D = self.ball_diameter_m, self.pitch_diameter_m
        dc = d * math.cos(math.radians(self.contact_angle_deg))
        r_outer, r_inner = 0.5 * (D + dc), 0.5 * (D - dc)
        return r_outer, r_inner, 1.0 / (2.0 / d - 1.0 / r_outer), 1.0 / (2.0 / d + 1.0 / r_inner)

    def law_row(self) -> np.ndarray:
        """This law as a row for the compiled law (gearbody.physics.bearings.law_force_xy): the head,
        per defect [race, centre angle, half arc, depth, ball, radius of its surface], the two relative
        radii of curvature and the slip table."""
        r_outer, r_inner, rho_outer, rho_inner = self._radii_m()
        table = self.slip_table()
        head = [LAW_ROLLING, self.ball_stiffness_N_per_m_n, self.radial_clearance_m, self.exponent]
        head += [self.damping_Ns_per_m, float(self.balls), self.cage_ratio, self.spin_ratio]
        head += [float(max(table.size - 1, 0)), float(len(self.defects))]
        rows: list[float] = []
        for defect in self.defects:
            race = RACES.index(defect.race)
            radius = (r_outer, r_inner, 0.5 * self.ball_diameter_m)[race]
            half_arc = 0.5 * math.radians(defect.width_deg) * radius
            rows += [race, math.radians(defect.angle_deg), half_arc, defect.depth_m, defect.ball, radius]
        return np.array([*head, *rows, rho_outer, rho_inner, *table], dtype=float)

    @functools.cached_property
    def row(self) -> np.ndarray:
        """:meth:`law_row`, made once."""
        return self.law_row()

    def force_xy(
        self, ux: float, uy: float, vx: float, vy: float, inner_rad: float = 0.0, outer_rad: float = 0.0
    ) -> tuple[float, float]:
        """Force on the journal (N) from its displacement (m) and velocity (m/s) with the inner and outer
        races turned by ``inner_rad`` and ``outer_rad``: the compiled law the engine calls."""
        return rolling_force_xy(self.row, ux, uy, vx, vy, inner_rad, outer_rad)

    def force_N(
        self, displacement_m, velocity_m_s, inner_rad: float = 0.0, outer_rad: float = 0.0
    ) -> np.ndarray:
        u, v = np.asarray(displacement_m, float), np.asarray(velocity_m_s, float)
        return np.array(
            self.force_xy(float(u[0]), float(u[1]), float(v[0]), float(v[1]), inner_rad, outer_rad)
        )

    def ball_angles_rad(self, inner_rad: float, outer_rad: float = 0.0) -> np.ndarray:
        """Angles of the balls (rad) with the races at these angles (the law's cage, slip included)."""
        row = self.row
        return np.array([ball_angle(row, i, inner_rad, outer_rad) for i in range(int(self.balls))])


@njit(cache=True)
def _wrap(x):
    """x in [-pi, pi)."""
    return x - 2.0 * math.pi * math.floor((x + math.pi) / (2.0 * math.pi))


@njit(cache=True)
def _cage_angle(row, inner_rad, outer_rad):
    """The cage's angle (rad): kinematic, or through the slip table."""
    z, r_c, m = row[5], row[6], int(row[8])
    phi = r_c * (inner_rad - outer_rad)
    if m == 0:
        return outer_rad + phi
    table = row[_HEAD + _PER_DEFECT * int(row[9]) + 2 :]
    spacing = 2.0 * math.pi / z
    k = math.floor(phi / spacing)
    cycles = math.floor(k / m)
    j = int(k - cycles * m)
    frac = phi / spacing - k
    return outer_rad + cycles * table[m] + table[j] + frac * (table[j + 1] - table[j])


@njit(cache=True)
def ball_angle(row, i, inner_rad, outer_rad):
    """Angle (rad) of ball ``i``."""
    return _cage_angle(row, inner_rad, outer_rad) + 2.0 * math.pi * i / row[5]


@njit(cache=True)
def _drop(e_m, half_arc, depth, rho):
    """Drop (m) of a contact ``e_m`` inside the nearer edge of a pit."""
    if e_m <= 0.0:
        return 0.0
    h = rho if e_m >= rho else rho - math.sqrt(rho * rho - e_m * e_m)
    return min(depth, h)


@njit(cache=True)
def _ball_drop(row, i, theta, inner_rad, outer_rad):
    """Total drop (m) of ball ``i`` at angle ``theta`` into the defects of the row."""
    nd = int(row[9])
    rho_outer, rho_inner = row[_HEAD + _PER_DEFECT * nd], row[_HEAD + _PER_DEFECT * nd + 1]
    h = 0.0
    for k in range(nd):
        o = _HEAD + _PER_DEFECT * k
        race, centre, half_arc, depth = row[o], row[o + 1], row[o + 2], row[o + 3]
        radius = row[o + 5]
        if race == 0.0:
            x = _wrap(theta - outer_rad - centre) * radius
            h += _drop(half_arc - abs(x), half_arc, depth, rho_outer)
        elif race == 1.0:
            x = _wrap(theta - inner_rad - centre) * radius
            h += _drop(half_arc - abs(x), half_arc, depth, rho_inner)
        elif int(row[o + 4]) == i:
            spin = row[7] * (inner_rad - outer_rad) + centre
            x_out = _wrap(spin) * radius
            x_in = _wrap(spin - math.pi) * radius
            h += _drop(half_arc - abs(x_out), half_arc, depth, rho_outer)
            h += _drop(half_arc - abs(x_in), half_arc, depth, rho_inner)
    return h


@njit(cache=True)
def rolling_force_xy(row, ux, uy, vx, vy, inner_rad, outer_rad):
    """Force (N) on the journal of the bearing in ``row`` (:meth:`RollingElementBearing.law_row`)."""
    k_ball, clearance, exponent, damping, z = row[1], row[2], row[3], row[4], int(row[5])
    cage = _cage_angle(row, inner_rad, outer_rad)
    fx, fy = -damping * vx, -damping * vy
    for i in range(z):
        theta = cage + 2.0 * math.pi * i / z
        c, s = math.cos(theta), math.sin(theta)
        delta = ux * c + uy * s - clearance
        if delta <= 0.0:
            continue  # out of contact, whatever the defects
        if row[9] > 0.0:
            delta -= _ball_drop(row, i, theta, inner_rad, outer_rad)
            if delta <= 0.0:
                continue
        f = k_ball * delta**exponent
        fx -= f * c
        fy -= f * s
    return fx, fy
