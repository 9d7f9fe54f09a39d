"""Planetary-stage geometry, kinematics and mesh phasing (sun, internal ring, carrier, N planets).

Engine-free; math only. Lengths in metres, angles in radians (``*_rad``), degrees only as inputs
(``*_deg``). Standard (zero-shift) spur gears of basic rack h_a* = 1.

Geometry (:class:`PlanetaryGeometry`): pitch radii ``r = z m / 2``, base radii ``r_b = r cos(alpha)``,
carrier radius (planet-centre circle) ``a = m (z_s + z_p) / 2``, planet tip radius ``r_p + m``.
Planet n (n = 1..N, numbered counterclockwise) sits at position angle ``psi_n`` in the carrier frame,
``psi_1 = 0``. Checks (:class:`PlanetaryGeometryError`, a ``ValueError``, naming teeth and N):

- coaxiality ``z_r = z_s + 2 z_p`` for standard gears; profile-shifted sets may differ by at most
  ``ring_teeth_tolerance`` teeth (0 unless told; at most 2). The shifts that restore equal sun-planet and
  ring-planet centre distances are not computed here: the carrier radius stays the sun-planet one;
- equal spacing ``psi_n = 2 pi (n - 1) / N`` needs ``(z_s + z_r) / N`` an integer; given angles need
  ``(z_s + z_r) psi_n / (2 pi)`` an integer (within 1e-9 of a tooth; the error lists the nearest valid
  angles);
- planets' tip circles do not overlap: ``2 a sin(dpsi / 2) > 2 (r_p + m)`` for neighbours.

Kinematics (:func:`planetary_speeds`): the Willis equation ``(w_s - w_c) / (w_r - w_c) = -z_r / z_s``
with one member fixed; the planet's spin relative to the carrier ``w_p - w_c = -(z_s / z_p)(w_s - w_c)
= (z_r / z_p)(w_r - w_c)``; mesh frequency ``f_m = z_r |f_r - f_c| = z_s |f_s - f_c|``.

Mesh phasing (:func:`planet_mesh_phases`; Parker & Lin 2004, "Mesh phasing relationships in planetary
and epicyclic gears", J. Mech. Des. 126:365-370): ``gamma_sn = z_s psi_n / (2 pi) mod 1`` and
``gamma_rn = z_r psi_n / (2 pi) mod 1``, fractions of a mesh period. Convention: rotating the stage by
``psi_n`` maps mesh 1 onto mesh n, so the state of mesh n at member angle ``theta`` (relative to the
carrier) is the state of mesh 1 at ``theta - psi_n``. When the member (sun or ring) turns
counterclockwise relative to the carrier, mesh n therefore repeats mesh 1 ``gamma_n`` mesh periods later
(``k_n(t) = k_1(t - gamma_n T_m)``); turning clockwise, ``gamma_n`` periods earlier. Sun and ring turn in
opposite senses relative to the carrier, and the assembly condition makes ``gamma_rn = -gamma_sn mod 1``,
so in time both meshes of planet n lag (or lead) those of planet 1 by the same fraction
(:meth:`PlanetMeshPhases.delays`).

Ring-sun offset ``gamma_rs`` (at one planet): the fraction of a mesh period from a planet flank passing
the sun-planet pitch point to a planet flank passing the ring-planet pitch point. The sun and the ring
push the planet with parallel tangential forces at opposite ends of a diameter, so the two meshes load
opposite flanks of the planet's teeth; with pitch-circle tooth thickness p/2 (zero shift, zero backlash)
the arc from one such flank to the other is ``p (z_p / 2 - 1/2)`` modulo p, hence ``gamma_rs = 0`` for odd
``z_p`` and ``1/2`` for even ``z_p`` (Parker & Lin 2004, Sect. 3, pitch points as reference). gearbody's
mesh phase puts a pair at the middle of its single-contact zone at 0.5
(:meth:`~.gear_pair.GearPairGeometry.pitch_point_phase` converts to the pitch-point reference).
"""

from __future__ import annotations

import dataclasses
import math

from .exceptions import GearGeometryError

__all__ = [
    "MEMBERS",
    "PlanetMeshPhases",
    "PlanetaryGeometry",
    "PlanetaryGeometryError",
    "PlanetarySpeeds",
    "planet_mesh_phases",
    "planetary_speeds",
]

MEMBERS = ("sun", "ring", "carrier")
MIN_TEETH = 5
MAX_RING_TEETH_TOLERANCE = 2
MESH_CONDITION_TOLERANCE_TEETH = 1e-9  # |(z_s + z_r) psi_n / 2 pi - nearest integer| allowed


class PlanetaryGeometryError(GearGeometryError):
    """Impossible planetary-stage geometry: teeth, spacing or assembly condition (message names them)."""


def _fmt(value) -> str:
    return f"{value:.6g}" if isinstance(value, float) and not value.is_integer() else repr(value)


def _error(name: str, value, reason: str, allowed: str) -> PlanetaryGeometryError:
    return PlanetaryGeometryError(f"{name} = {_fmt(value)}: {reason}; allowed: {allowed}")


@dataclasses.dataclass(frozen=True)
class PlanetaryGeometry:
    """Teeth, module, pressure angle and planet position angles of a simple planetary stage.

    ``planet_angles_rad`` empty means equally spaced, ``2 pi (n - 1) / N``; given angles start at 0 and
    increase below 2 pi. Derived radii are properties.
    """

    z_sun: int
    z_planet: int
    z_ring: int
    n_planets: int
    module_m: float
    pressure_angle_deg: float = 20.0
    planet_angles_rad: tuple[float, ...] = ()
    ring_teeth_tolerance: int = 0

    def __post_init__(self) -> None:
        for name in ("z_sun", "z_planet", "z_ring"):
            z = getattr(self, name)
            if isinstance(z, bool) or not isinstance(z, int) or z < MIN_TEETH:
                raise _error(name, z, "tooth count must be a whole number", f"integer >= {MIN_TEETH}")
        n = self.n_planets
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise _error("n_planets", n, "number of planets must be a whole number", "integer >= 1")
        if not (math.isfinite(self.module_m) and self.module_m > 0.0):
            raise _error("module_m", float(self.module_m), "module must be positive", "> 0 m")
        if not 0.0 < self.pressure_angle_deg < 45.0:
            raise _error(
                "pressure_angle_deg",
                float(self.pressure_angle_deg),
                "pressure angle out of range",
                "> 0 and < 45",
            )
        tol = self.ring_teeth_tolerance
        if isinstance(tol, bool) or not isinstance(tol, int) or not 0 <= tol <= MAX_RING_TEETH_TOLERANCE:
            raise _error(
                "ring_teeth_tolerance",
                tol,
                "tooth-count mismatch allowance",
                f"integer 0..{MAX_RING_TEETH_TOLERANCE}",
            )
        mismatch = self.z_ring - (self.z_sun + 2 * self.z_planet)
        if abs(mismatch) > tol:
            raise _error(
                "z_ring",
                self.z_ring,
                f"standard gears need z_ring = z_sun + 2 z_planet = {self.z_sun} + 2*{self.z_planet} = "
                f"{self.z_sun + 2 * self.z_planet} (off by {mismatch}; ring_teeth_tolerance = {tol})",
                f"{self.z_sun + 2 * self.z_planet - tol}..{self.z_sun + 2 * self.z_planet + tol}",
            )
        self._check_ring_flanks()
        given = bool(self.planet_angles_rad)
        if not given:
            self._check_equal_spacing()
            angles = tuple(2.0 * math.pi * k / n for k in range(n))
            object.__setattr__(self, "planet_angles_rad", angles)
        else:
            object.__setattr__(self, "planet_angles_rad", tuple(float(a) for a in self.planet_angles_rad))
            self._check_given_angles()
        self._check_no_overlap(given)

    # ----------------------------------------------------------------------------------------- checks
    def _check_ring_flanks(self) -> None:
        """The ring's tips point inwards (r_r - m): they must end outside its base circle, where the
        involute flank begins, z_r (1 - cos alpha) > 2 (standard teeth)."""
        if self.ring_tip_radius_m > self.ring_base_radius_m:
            return
        fewest = math.floor(2.0 / (1.0 - math.cos(self.pressure_angle_rad))) + 1
        raise _error(
            "z_ring",
            self.z_ring,
            f"the ring's tip circle (radius {self.ring_tip_radius_m * 1e3:.5g} mm) lies inside its base "
            f"circle ({self.ring_base_radius_m * 1e3:.5g} mm) at pressure_angle_deg = "
            f"{self.pressure_angle_deg:g}: its teeth would have no involute flank",
            f"z_ring >= {fewest} at this pressure angle",
        )

    def _check_equal_spacing(self) -> None:
        total = self.z_sun + self.z_ring
        if total % self.n_planets:
            valid = [k for k in range(1, 13) if total % k == 0]
            raise _error(
                "n_planets",
                self.n_planets,
                f"equally spaced planets need (z_sun + z_ring) / N an integer; "
                f"(z_sun + z_ring) = {self.z_sun} + {self.z_ring} = {total} is not divisible by N = "
                f"{self.n_planets}",
                f"N dividing {total} (e.g. {valid}), or planet_angles_rad given",
            )

    def _check_given_angles(self) -> None:
        angles = self.planet_angles_rad
        if len(angles) != self.n_planets:
            raise _error(
                "planet_angles_rad",
                angles,
                f"{len(angles)} angles for n_planets = {self.n_planets}",
                f"exactly {self.n_planets} angles",
            )
        if angles[0] != 0.0:
            raise _error("planet_angles_rad[0]", angles[0], "planet 1 is the reference", "0.0")
        for k in range(1, len(angles)):
            if not angles[k - 1] < angles[k] < 2.0 * math.pi:
                raise _error(
                    f"planet_angles_rad[{k}]",
                    angles[k],
                    "angles must increase (planets numbered counterclockwise)",
                    f"> {angles[k - 1]:.6g} and < 2 pi rad",
                )
        total = self.z_sun + self.z_ring
        step = 2.0 * math.pi / total
        bad = [
            k
            for k, a in enumerate(angles)
            if abs(a / step - round(a / step)) > MESH_CONDITION_TOLERANCE_TEETH
        ]
        if bad:
            nearest = [round(a / step) * step for a in angles]
            shown = ", ".join(f"{a:.9g}" for a in nearest)
            raise _error(
                f"planet_angles_rad[{bad[0]}]",
                angles[bad[0]],
                f"mesh condition (z_sun + z_ring) psi_n / (2 pi) integer fails for z_sun = {self.z_sun}, "
                f"z_ring = {self.z_ring}, N = {self.n_planets} (psi_n a multiple of 2 pi / {total})",
                f"multiples of {step:.9g} rad; nearest valid angles [{shown}] rad",
            )

    def _check_no_overlap(self, given: bool) -> None:
        if self.n_planets < 2:
            return
        angles = self.planet_angles_rad + (2.0 * math.pi,)
        gaps = [angles[k + 1] - angles[k] for k in range(self.n_planets)]
        k = min(range(self.n_planets), key=gaps.__getitem__)
        distance = 2.0 * self.carrier_radius_m * math.sin(gaps[k] / 2.0)
        tip_diameter = 2.0 * self.planet_tip_radius_m
        if not distance > tip_diameter:
            moved = k + 1 if k + 1 < self.n_planets else k  # the later planet; planet 1 stays at 0
            raise _error(
                f"planet_angles_rad[{moved}]" if given else "n_planets",
                self.planet_angles_rad[moved] if given else self.n_planets,
                f"planets {k + 1} and {(k + 1) % self.n_planets + 1} overlap: centres {distance:.6g} m "
                f"apart, tip diameter {tip_diameter:.6g} m (z_planet = {self.z_planet})",
                "centre distance between neighbouring planets > planet tip diameter",
            )

    # ------------------------------------------------------------------------------------ derived
    @property
    def pressure_angle_rad(self) -> float:
        return math.radians(self.pressure_angle_deg)

    @property
    def equally_spaced(self) -> bool:
        n = self.n_planets
        return all(abs(a - 2.0 * math.pi * k / n) <= 1e-12 for k, a in enumerate(self.planet_angles_rad))

    @property
    def sun_pitch_radius_m(self) -> float:
        return self.z_sun * self.module_m / 2.0

    @property
    def planet_pitch_radius_m(self) -> float:
        return self.z_planet * self.module_m / 2.0

    @property
    def ring_pitch_radius_m(self) -> float:
        return self.z_ring * self.module_m / 2.0

    @property
    def sun_base_radius_m(self) -> float:
        return self.sun_pitch_radius_m * math.cos(self.pressure_angle_rad)

    @property
    def planet_base_radius_m(self) -> float:
        return self.planet_pitch_radius_m * math.cos(self.pressure_angle_rad)

    @property
    def ring_base_radius_m(self) -> float:
        return self.ring_pitch_radius_m * math.cos(self.pressure_angle_rad)

    @property
    def carrier_radius_m(self) -> float:
        """Radius of the planet-centre circle, the sun-planet centre distance ``m (z_s + z_p) / 2``."""
        return self.module_m * (self.z_sun + self.z_planet) / 2.0

    @property
    def planet_tip_radius_m(self) -> float:
        return self.planet_pitch_radius_m + self.module_m

    @property
    def ring_tip_radius_m(self) -> float:
        """Internal gear: the tips point inwards, ``r_r - m``."""
        return self.ring_pitch_radius_m - self.module_m


# ------------------------------------------------------------------------------------------- speeds
@dataclasses.dataclass(frozen=True)
class PlanetarySpeeds:
    """Absolute angular speeds (rad/s, counterclockwise positive) and the mesh frequency of a stage."""

    sun_rad_s: float
    ring_rad_s: float
    carrier_rad_s: float
    planet_rad_s: float  # absolute spin of a planet about its own axis
    planet_relative_rad_s: float  # spin relative to the carrier, w_p - w_c
    mesh_frequency_hz: float
    ratio: float  # input speed / output speed

    def of(self, member: str) -> float:
        return {"sun": self.sun_rad_s, "ring": self.ring_rad_s, "carrier": self.carrier_rad_s}[member]


def planetary_speeds(
    geometry: PlanetaryGeometry, input: str, output: str, fixed: str, input_speed_rad_s: float
) -> PlanetarySpeeds:
    """Speeds of all members from the Willis equation, ``fixed`` member at rest, ``input`` at the given
    speed; ``output`` is the third member (checked)."""
    roles = {"input": input, "output": output, "fixed": fixed}
    for role, member in roles.items():
        if member not in MEMBERS:
            raise _error(role, member, "unknown member", f"one of {MEMBERS}")
    if len(set(roles.values())) != 3:
        raise _error(
            "input/output/fixed",
            (input, output, fixed),
            "each member takes exactly one role",
            "a permutation of ('sun', 'ring', 'carrier')",
        )
    if not math.isfinite(input_speed_rad_s) or input_speed_rad_s == 0.0:
        raise _error(
            "input_speed_rad_s", float(input_speed_rad_s), "input must turn", "finite and != 0 rad/s"
        )
    zs, zr, zp = geometry.z_sun, geometry.z_ring, geometry.z_planet
    w = {fixed: 0.0, input: float(input_speed_rad_s)}
    # Willis: z_s (w_s - w_c) + z_r (w_r - w_c) = 0, i.e. z_s w_s + z_r w_r = (z_s + z_r) w_c
    if output == "carrier":
        w["carrier"] = (zs * w["sun"] + zr * w["ring"]) / (zs + zr)
    elif output == "sun":
        w["sun"] = ((zs + zr) * w["carrier"] - zr * w["ring"]) / zs
    else:
        w["ring"] = ((zs + zr) * w["carrier"] - zs * w["sun"]) / zr
    relative = -(zs / zp) * (w["sun"] - w["carrier"])
    mesh_hz = zs * abs(w["sun"] - w["carrier"]) / (2.0 * math.pi)
    return PlanetarySpeeds(
        sun_rad_s=w["sun"],
        ring_rad_s=w["ring"],
        carrier_rad_s=w["carrier"],
        planet_rad_s=w["carrier"] + relative,
        planet_relative_rad_s=relative,
        mesh_frequency_hz=mesh_hz,
        ratio=w[input] / w[output],
    )


# --------------------------------------------------------------------------------------- mesh phases
@dataclasses.dataclass(frozen=True)
class PlanetMeshPhases:
    """Relative mesh phases of a stage in fractions of a mesh period (module docstring, conventions)."""

    sun: tuple[float, ...]  # gamma_sn = z_s psi_n / 2 pi mod 1 (gamma_s1 = 0)
    ring: tuple[float, ...]  # gamma_rn = z_r psi_n / 2 pi mod 1
    ring_sun: float  # gamma_rs: ring-planet pitch-point passage after the sun-planet one, same planet

    def delays(self, sun_ccw_relative_to_carrier: bool) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """Time delays (sun meshes, ring meshes), in mesh periods in [0, 1), of mesh n after mesh 1 for
        the given sense of ``w_s - w_c``; the ring turns the other way relative to the carrier."""
        s = 1.0 if sun_ccw_relative_to_carrier else -1.0
        sun = tuple((s * g) % 1.0 for g in self.sun)
        ring = tuple((-s * g) % 1.0 for g in self.ring)
        return sun, ring


def _phase_fraction(teeth: int, angle_rad: float) -> float:
    """``teeth * angle / 2 pi mod 1``, snapped to 0 within 1e-9 of a whole tooth."""
    x = teeth * angle_rad / (2.0 * math.pi)
    frac = x - math.floor(x)
    return 0.0 if min(frac, 1.0 - frac) < 1e-9 else frac


def planet_mesh_phases(geometry: PlanetaryGeometry) -> PlanetMeshPhases:
    """Sun-planet and ring-planet mesh phases of every planet relative to planet 1, and the ring-sun
    offset at a planet (Parker & Lin 2004; conventions in the module docstring)."""
    psi = geometry.planet_angles_rad
    return PlanetMeshPhases(
        sun=tuple(_phase_fraction(geometry.z_sun, a) for a in psi),
        ring=tuple(_phase_fraction(geometry.z_ring, a) for a in psi),
        ring_sun=0.0 if geometry.z_planet % 2 else 0.5,
    )
