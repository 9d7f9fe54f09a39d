"""The parts a picture is made of (no Exudyn): colours, tubes, boxes, toothed gears, prisms, a planet's
orbit on its carrier, and the rotating bodies that carry them; :mod:`gearbody.render.layout` places them
for a drive, :mod:`gearbody.render.planetary` for a planetary stage."""

from __future__ import annotations

from dataclasses import dataclass

# Colours (RGBA).
STEEL = (0.55, 0.6, 0.7, 1.0)
WHEEL = (0.78, 0.72, 0.55, 1.0)
SHAFT = (0.35, 0.35, 0.38, 1.0)
MARKER = (0.95, 0.85, 0.1, 1.0)
MOTOR = (0.16, 0.33, 0.6, 1.0)
MACHINE = (0.25, 0.5, 0.3, 1.0)
BEARING = (0.6, 0.45, 0.25, 1.0)
HOUSING = (0.6, 0.62, 0.66, 0.22)
BASE = (0.3, 0.3, 0.3, 1.0)
DAMAGED = (0.9, 0.1, 0.1, 1.0)
PITTED = (1.0, 0.55, 0.0, 1.0)
COUPLING = (0.45, 0.45, 0.48, 1.0)


@dataclass(frozen=True)
class Cylinder:
    """Tube along z from z0_m to z1_m (body or world frame), centred on (x_m, y_m)."""

    z0_m: float
    z1_m: float
    radius_m: float
    colour: tuple[float, float, float, float]
    inner_radius_m: float = 0.0
    x_m: float = 0.0
    y_m: float = 0.0


@dataclass(frozen=True)
class Box:
    centre_m: tuple[float, float, float]
    size_m: tuple[float, float, float]
    colour: tuple[float, float, float, float]


@dataclass(frozen=True)
class GearShape:
    """Spur gear in its body frame: teeth at angles ``first_tooth_rad + 2 pi k / z``."""

    teeth: int
    module_m: float
    pressure_angle_deg: float
    face_width_m: float
    z_m: float
    bore_radius_m: float
    first_tooth_rad: float
    colour: tuple[float, float, float, float]
    # (body-frame angle of the tooth centre, colour) for damaged and pitted teeth
    marked_teeth: tuple[tuple[float, tuple[float, float, float, float]], ...] = ()
    # a planetary stage's gears: outline "gearbody" (render.planetary.tooth_outline; Exudyn's fails for
    # some teeth counts); an internal gear (the ring) has its teeth inside a rim of radius rim_radius_m
    internal: bool = False
    rim_radius_m: float = 0.0
    outline: str = "exudyn"

    @property
    def pitch_radius_m(self) -> float:
        return 0.5 * self.module_m * self.teeth

    @property
    def tip_radius_m(self) -> float:
        return self.pitch_radius_m + (-1 if self.internal else 1) * self.module_m

    @property
    def root_radius_m(self) -> float:
        return self.pitch_radius_m + (1 if self.internal else -1) * 1.25 * self.module_m

    @property
    def outer_radius_m(self) -> float:
        """Radius of the drawn solid: the tip circle, or an internal gear's rim."""
        return self.rim_radius_m if self.internal else self.tip_radius_m


@dataclass(frozen=True)
class Prism:
    """A plate along z from z0_m to z1_m with a polygon outline (body frame), an optional round hole."""

    outline_m: tuple[tuple[float, float], ...]
    z0_m: float
    z1_m: float
    colour: tuple[float, float, float, float]
    hole_radius_m: float = 0.0


@dataclass(frozen=True)
class Orbit:
    """A planet's path: round the carrier's axis ``centre_xy_m`` at ``radius_m``, angle ``angle_rad``
    from the carrier's x axis (drawn); ``centre_signals`` its absolute centre in the stage frame."""

    carrier: str
    centre_xy_m: tuple[float, float]
    radius_m: float
    angle_rad: float
    centre_signals: tuple[str, str]


@dataclass(frozen=True)
class Body:
    """A rotating inertia of the model and what is drawn on it.

    ``angle_signal`` names the result signal of its rotation; the drawn angle is ``sense * angle``
    (each model rotation is positive in its own driven direction, so meshing gears turn opposite).
    ``lateral_signals`` name its centre's x, y motion when the gear moves on bearings.
    """

    name: str
    axis_xy_m: tuple[float, float]
    sense: int
    angle_signal: str
    parts: tuple = ()
    lateral_signals: tuple[str, str] | None = None
    # kinematic fallback when the result has no angle signal for this body: angle = ratio * angle of
    # body `follows` (rigid gear ratio; used by the Muller and two-wheel scenes)
    follows: str | None = None
    ratio: float = 1.0
    # planetary members: -1 draws the stage mirrored (y offsets negated, see render.planetary)
    mirror: int = 1
    orbit: Orbit | None = None  # a planet: rides on the carrier
