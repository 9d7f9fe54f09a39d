"""A planetary stage of the drive: sun, N planets, internal ring and carrier (issue 19). One more item
type of ``design.stages`` (``type = "planetary"``); the keys, coordinates and equations are the contract
of docs/planetary.md, "The stage in a drive". Its fault tables (damaged teeth, planet bearing defects)
and their check are :mod:`gearbody.model.planetary_faults`."""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar

from ..physics.planetary import PlanetaryGeometry, PlanetaryGeometryError, PlanetarySpeeds, planetary_speeds
from ..signals import stage_prefix
from .components import MAX_TEETH, RIGID, Bearing, RollingBearingSpec, RollingGeometry
from .faults import ErrorMode
from .params import Node, ScenarioError, param, stage_key
from .planetary_faults import PlanetaryDamagedTooth, PlanetBearingDefect, check_faults

MEMBERS = ("sun", "ring", "carrier")


@dataclass(frozen=True, kw_only=True)
class PlanetaryMember(Node):
    """A member of a planetary stage: teeth (not the carrier), mass, inertia, its bearing (the planet's:
    on the carrier; the others': to the housing) and, for the fixed member, its torsional support."""

    teeth: int | None = param(
        None, ge=6, le=MAX_TEETH, doc="number of teeth z (sun, planet, ring; not the carrier)"
    )
    inertia_kg_m2: float = param(gt=0, doc="polar moment of inertia")
    mass_kg: float = param(gt=0, doc="mass")
    bearing_stiffness_N_per_m: float | None = param(
        None, gt=0, doc="isotropic linear bearing stiffness (or a bearing law in `bearing`)"
    )
    bearing_damping_Ns_per_m: float = param(0.0, ge=0, doc="isotropic linear bearing damping")
    bearing: Bearing | None = param(
        None,
        doc="a registered bearing law instead of bearing_stiffness_N_per_m (a planet's acts in the carrier "
        "frame on its centre's offset from its pin; docs/planetary.md)",
    )
    bearing_geometry: RollingGeometry | None = param(
        None,
        doc="rolling-element geometry of the isotropic linear bearing, for the defect frequencies (data "
        "only; with a bearing law: bearing.geometry)",
    )
    torsion_stiffness_Nm_per_rad: float | None = param(
        None, gt=0, doc="torsional support to the housing (the fixed member only, required there)"
    )
    torsion_damping_Nms_per_rad: float = param(0.0, ge=0, doc="damping of the torsional support")

    @property
    def rolling_geometry(self) -> RollingGeometry | None:
        """The bearing's rolling geometry, from whichever form gives the bearing (None: not stated)."""
        return self.bearing_geometry if self.bearing is None else self.bearing.geometry

    def __post_init__(self) -> None:
        if self.bearing is not None and self.bearing.kind == RIGID:
            raise ScenarioError(
                "bearing.kind = 'rigid': the members of a planetary stage move in x and y on their "
                "bearings; give a bearing law (e.g. 'linear' or 'hertzian') or bearing_stiffness_N_per_m "
                "(its geometry: bearing.geometry or bearing_geometry)"
            )
        if (self.bearing_stiffness_N_per_m is None) == (self.bearing is None):
            raise ScenarioError(
                "bearing_stiffness_N_per_m = "
                + ("unset" if self.bearing is None else f"{self.bearing_stiffness_N_per_m:g}")
                + ": give either an isotropic linear bearing (bearing_stiffness_N_per_m > 0 N/m, "
                "bearing_damping_Ns_per_m) or a bearing law (bearing = { kind, parameters }), not both"
            )
        if self.bearing is not None and self.bearing_damping_Ns_per_m:
            raise ScenarioError(
                f"bearing_damping_Ns_per_m = {self.bearing_damping_Ns_per_m:g}: with a bearing law the "
                "damping is the law's (its parameters)"
            )
        if self.bearing is not None and self.bearing_geometry is not None:
            raise ScenarioError(
                "bearing_geometry: with a bearing law (bearing = { kind, parameters }) its geometry is "
                "bearing.geometry; move it there"
            )


@dataclass(frozen=True, kw_only=True)
class PlanetaryMesh(Node):
    """The law of every sun-planet (or ring-planet) mesh: the parallel mesh law's rectangular stiffness
    profile, damping, backlash and transition width."""

    stiffness_profile: str = param(
        "contact-ratio",
        choices=("contact-ratio", "iso-6336-b"),
        doc="k_z from the two stiffness values, or from ISO 6336-1 method B (face_width_mm; internal mesh "
        "approximated, docs/planetary.md)",
    )
    stiffness_single_N_per_m: float | None = param(
        None, gt=0, doc="k_z with one tooth pair in contact (contact-ratio; iso-6336-b: computed)"
    )
    stiffness_double_N_per_m: float | None = param(
        None, gt=0, doc="k_z with two tooth pairs in contact (contact-ratio; iso-6336-b: computed)"
    )
    face_width_mm: float | None = param(None, gt=0, le=2000, doc="face width b (iso-6336-b)")
    contact_ratio: float | None = param(
        None, ge=1, lt=2, doc="transverse contact ratio (unset: of the standard teeth)"
    )
    damping_Ns_per_m: float = param(0.0, ge=0, doc="mesh damping C_z")
    backlash_um: float = param(0.0, ge=0, le=1000, doc="half the flank clearance l_u")
    pitch_point_phase: float = param(0.5, gt=0, lt=1, doc="mesh phase of the pitch point")
    transition_width: float = param(
        0.0, ge=0, le=0.2, doc="fraction of the mesh period over which the tooth change is smoothed"
    )

    def __post_init__(self) -> None:
        given = (self.stiffness_single_N_per_m, self.stiffness_double_N_per_m)
        if self.stiffness_profile == "contact-ratio":
            if None in given:
                raise ScenarioError(
                    "stiffness_single_N_per_m and stiffness_double_N_per_m: required with stiffness_profile "
                    "= 'contact-ratio' (> 0 N/m), or set stiffness_profile = 'iso-6336-b' and face_width_mm"
                )
        elif self.face_width_mm is None:
            raise ScenarioError("face_width_mm: required with stiffness_profile = 'iso-6336-b' (> 0 mm)")


@dataclass(frozen=True, kw_only=True)
class PlanetaryStage(Node):
    """A simple planetary stage: standard spur teeth (z_r = z_s + 2 z_p), N planets, any of sun, ring
    and carrier as input, output or fixed (the third)."""

    KIND: ClassVar[str] = "planetary"

    type: str = param("planetary", choices=("planetary",), doc="stage type")
    planets: int = param(ge=1, le=12, doc="number of planets N")
    planet_angles_deg: tuple[float, ...] = param(
        (), doc="planet position angles, the first 0 (empty: equally spaced 360 (n - 1) / N)"
    )
    module_mm: float = param(gt=0, le=100, doc="module m")
    pressure_angle_deg: float = param(20.0, ge=10, le=35, doc="pressure angle alpha")
    input: str = param(choices=MEMBERS, doc="member driven by the previous shaft")
    output: str = param(choices=MEMBERS, doc="member driving the next shaft")
    sun: PlanetaryMember
    planet: PlanetaryMember
    ring: PlanetaryMember
    carrier: PlanetaryMember
    sun_mesh: PlanetaryMesh
    ring_mesh: PlanetaryMesh
    sensor_angle_deg: float = param(
        0.0,
        ge=-360,
        le=360,
        doc="angle of the ring-fixed vibration sensor (ring_sensor_N), from planet 1's nominal place",
    )
    sensor_window_deg: float = param(
        360.0, gt=0, le=360, doc="full width of the Hann planet-pass window of that sensor"
    )
    sun_error_mode: ErrorMode = param(default_factory=ErrorMode, doc="E(a, e, r) on the sun's teeth")
    ring_error_mode: ErrorMode = param(default_factory=ErrorMode, doc="E(a, e, r) on the ring's teeth")
    damaged_teeth: tuple[PlanetaryDamagedTooth, ...] = param((), doc="teeth with a stiffness factor")
    planet_position_errors_um: tuple[float, ...] = param(
        (), doc="tangential error of each planet pin along the carrier circle (empty: none)"
    )
    planet_bearing_defects: tuple[PlanetBearingDefect, ...] = param((), doc="weakened planet bearings")

    def __post_init__(self) -> None:
        if self.input == self.output:
            raise ScenarioError(f"output = {self.output!r}: must differ from input = {self.input!r}")
        for name in ("sun", "planet", "ring"):
            if getattr(self, name).teeth is None:
                raise ScenarioError(f"{name}.teeth: required (number of teeth, >= 6)")
        if self.carrier.teeth is not None:
            raise ScenarioError(f"carrier.teeth = {self.carrier.teeth}: the carrier has no teeth; remove it")
        for name in MEMBERS:
            member = getattr(self, name)
            if name == self.fixed and member.torsion_stiffness_Nm_per_rad is None:
                raise ScenarioError(
                    f"{name}.torsion_stiffness_Nm_per_rad: required on the fixed member ({name}: neither "
                    "input nor output), its torsional support to the housing (> 0)"
                )
            if name != self.fixed and member.torsion_stiffness_Nm_per_rad is not None:
                raise ScenarioError(
                    f"{name}.torsion_stiffness_Nm_per_rad = {member.torsion_stiffness_Nm_per_rad:g}: only "
                    f"the fixed member ({self.fixed}) has a torsional support; the {name} is the stage's "
                    f"{'input' if name == self.input else 'output'}"
                )
        if self.planet.torsion_stiffness_Nm_per_rad is not None:
            raise ScenarioError("planet.torsion_stiffness_Nm_per_rad: planets turn freely on the carrier")
        if self.planet_angles_deg:
            self._check_angles()
        check_faults(self)
        try:
            self.geometry  # noqa: B018  (assembly condition, spacing, overlap: refused before anything runs)
        except PlanetaryGeometryError as exc:
            raise ScenarioError(_stage_geometry_message(str(exc), self.planet_angles_deg)) from None

    def _check_angles(self) -> None:
        """Given planet angles, in degrees: one per planet, the first 0, increasing below 360, each on the
        mesh condition (z_s + z_r) psi / 360 an integer."""
        angles = self.planet_angles_deg
        if len(angles) != self.planets:
            raise ScenarioError(
                f"planet_angles_deg has {len(angles)} angles: planets = {self.planets} needs one per "
                "planet (or none: equally spaced)"
            )
        if angles[0] != 0.0:
            raise ScenarioError(f"planet_angles_deg.1 = {angles[0]:g}: planet 1 is the reference, at 0")
        for k in range(1, len(angles)):
            if not angles[k - 1] < angles[k] < 360.0:
                raise ScenarioError(
                    f"planet_angles_deg.{k + 1} = {angles[k]:g}: angles increase (planets numbered "
                    f"counter-clockwise); allowed: > {angles[k - 1]:g} and < 360"
                )
        total = self.sun.teeth + self.ring.teeth
        step = 360.0 / total
        for k, a in enumerate(angles):
            if abs(a / step - round(a / step)) > 1e-6:
                nearest = ", ".join(f"{round(b / step) * step:.6g}" for b in angles)
                raise ScenarioError(
                    f"planet_angles_deg.{k + 1} = {a:g}: off the mesh condition (z_s + z_r) psi / 360 "
                    f"integer (z_s + z_r = {total}); allowed: multiples of 360 / {total} = {step:.6g} deg, "
                    f"nearest valid angles [{nearest}]"
                )

    def tooth_factors(self, member: str, planet: int | None = None) -> tuple[float, ...]:
        """Stiffness factor per tooth of the sun, the ring or planet ``planet`` (1-based): 1 unless
        listed in ``damaged_teeth``."""
        f = [1.0] * getattr(self, member).teeth
        for t in self.damaged_teeth:
            if t.member == member and t.planet == planet:
                f[t.tooth] = t.stiffness_factor
        return tuple(f)

    def bearing_factors(self) -> tuple[float, ...]:
        """Factor on each planet's bearing stiffness and damping (1 unless defective)."""
        f = [1.0] * self.planets
        for d in self.planet_bearing_defects:
            f[d.planet - 1] = d.stiffness_factor
        return tuple(f)

    @property
    def has_faults(self) -> bool:
        """True when any tooth, pin or planet bearing fault is given."""
        return bool(
            self.damaged_teeth
            or any(e != 0.0 for e in self.planet_position_errors_um)
            or self.planet_bearing_defects
        )

    @property
    def fixed(self) -> str:
        """The member that is neither input nor output (held by its torsional support)."""
        return next(m for m in MEMBERS if m not in (self.input, self.output))

    @property
    def geometry(self) -> PlanetaryGeometry:
        """The checked geometry (teeth, module, pressure angle, planet angles)."""
        total = self.sun.teeth + self.ring.teeth
        return PlanetaryGeometry(
            z_sun=self.sun.teeth,
            z_planet=self.planet.teeth,
            z_ring=self.ring.teeth,
            n_planets=self.planets,
            module_m=self.module_mm * 1e-3,
            pressure_angle_deg=self.pressure_angle_deg,
            # on the mesh condition to 1e-6 of a tooth (checked): snapped to it exactly
            planet_angles_rad=tuple(
                2.0 * math.pi * round(a * total / 360.0) / total for a in self.planet_angles_deg
            ),
        )

    def torque_arm_m(self, member: str) -> float:
        """r_eq: a member's external torque per unit planet mesh force, N r_bs (sun), N r_br (ring),
        N (r_bs + r_br) (carrier)."""
        g = self.geometry
        arms = {"sun": g.sun_base_radius_m, "ring": g.ring_base_radius_m}
        arms["carrier"] = arms["sun"] + arms["ring"]
        return self.planets * arms[member]

    @property
    def input_arm_m(self) -> float:
        """r_eq of the input member (plays the pinion's base radius in the chain)."""
        return self.torque_arm_m(self.input)

    @property
    def output_arm_m(self) -> float:
        """r_eq of the output member (plays the wheel's base radius in the chain)."""
        return self.torque_arm_m(self.output)

    @property
    def ratio(self) -> float:
        """Speed ratio input / output (magnitude)."""
        return self.output_arm_m / self.input_arm_m

    @property
    def input_sense(self) -> int:
        """s_in: +1 when the input member turns counter-clockwise at positive power flow (sun or ring
        input), -1 for a carrier input: the sense that loads the modelled flanks (docs/planetary.md)."""
        return -1 if self.input == "carrier" else 1

    @property
    def output_sense(self) -> int:
        """s_out = s_in sign(w_out / w_in): the output turns with the input unless the carrier is fixed."""
        return self.input_sense * (-1 if self.fixed == "carrier" else 1)

    def speeds(self, input_speed_rad_s: float) -> PlanetarySpeeds:
        """Rigid-rolling speeds of every member (Willis) with the input at ``input_speed_rad_s``."""
        return planetary_speeds(self.geometry, self.input, self.output, self.fixed, input_speed_rad_s)

    def mesh_frequency_hz(self, input_speed_rad_s: float) -> float:
        """Mesh frequency z_s |w_s - w_c| / 2 pi at an input speed."""
        if input_speed_rad_s == 0.0:
            return 0.0
        return self.speeds(input_speed_rad_s).mesh_frequency_hz

    @property
    def transition_width(self) -> float:
        """The wider of the two meshes' transition widths."""
        return max(self.sun_mesh.transition_width, self.ring_mesh.transition_width)

    @property
    def coordinate_count(self) -> int:
        """x, y and rotation of sun, ring, carrier and every planet."""
        return 3 * (3 + self.planets)

    @property
    def mesh_count(self) -> int:
        """Meshes of the stage: every planet's sun and ring mesh."""
        return 2 * self.planets

    def mesh_periods_per_revolution(self) -> tuple[float, str]:
        """(mesh periods per revolution of the input member: f_m / f_in of rigid rolling (Willis),
        f_m = z_s |w_s - w_c| / 2 pi; the footnote of ``gearbody modes`` that says so)."""
        per_rev = 2 * math.pi * self.mesh_frequency_hz(1.0)
        return per_rev, (
            f"(w(k f_z) = {self.input} speed (the planetary first stage's input) at which the k-th mesh "
            f"harmonic k f_m meets f_n; f_m = z_s |w_s - w_c| / 2 pi = {per_rev:.5g} w / 2 pi with the "
            f"{self.fixed} fixed, z_s/z_p/z_r = {self.sun.teeth}/{self.planet.teeth}/{self.ring.teeth})"
        )

    @property
    def input_teeth(self) -> int:
        """Teeth that set the mesh period along the input member's angle (the carrier: the ring's)."""
        return self.sun.teeth if self.input == "sun" else self.ring.teeth

    def rolling_bearings(self, k: int) -> list[RollingBearingSpec]:
        """The bearings of the stage at index ``k`` (from 0): sun, ring and carrier in the housing (their
        inner races), then each planet's on its pin (the planet turns the outer race relative to the
        carrier); named by the rotations of :func:`gearbody.signals.stage_prefix` (``stage_2_carrier``)."""
        prefix, label = stage_prefix(k), "" if k == 0 else f"stage {k + 1} "
        rows = [(name, name, name, None, "inner") for name in MEMBERS]
        rows += [
            ("planet", f"planet {n}", f"planet_{n}", "carrier", "outer") for n in range(1, self.planets + 1)
        ]
        out = []
        for member, title, body, reference, race in rows:
            m = getattr(self, member)  # its geometry: bearing.geometry with a law, else bearing_geometry
            key = stage_key(k, f"{member}.bearing.geometry" if m.bearing else f"{member}.bearing_geometry")
            ref = None if reference is None else prefix + reference
            out.append(
                RollingBearingSpec(
                    f"{label}{title} bearing", key, prefix + body, ref, race, m.rolling_geometry
                )
            )
        return out


def _stage_geometry_message(text: str, angles_deg: Sequence[float] = ()) -> str:
    """A PlanetaryGeometry message in the stage's own key names: ``planet_angles_rad[k] = <rad>`` (0-based,
    radians) becomes ``planet_angles_deg.<k + 1> = <the degrees given>``."""

    def angle(match: re.Match) -> str:
        k = int(match[1])
        value = angles_deg[k] if k < len(angles_deg) else math.degrees(float(match[2]))
        return f"planet_angles_deg.{k + 1} = {value:g}"

    text = re.sub(r"planet_angles_rad\[(\d+)\] = ([-+0-9.eE]+)", angle, text)
    for old, new in (
        ("z_sun", "sun.teeth"),
        ("z_planet", "planet.teeth"),
        ("z_ring", "ring.teeth"),
        ("n_planets", "planets"),
        ("module_m ", "module_mm "),
        ("planet_angles_rad", "planet_angles_deg"),
    ):
        text = text.replace(old, new)
    return text
