"""Components of a drive: motor, shafts and couplings, gears, bearings, driven machine."""

from __future__ import annotations

import dataclasses
import inspect
from dataclasses import dataclass

from ..physics.bearings import BEARINGS, make_bearing
from .params import Node, ScenarioError, check_ranges, param

MAX_TEETH = 2000
"""Largest tooth count of any gear (it sizes the per-tooth arrays of the mesh laws; large ring gears
have a few hundred)."""

RIGID = "rigid"
"""The bearing kind of a torsional gear's bearing table (gearbody.physics.bearings.RigidBearing)."""


@dataclass(frozen=True, kw_only=True)
class Motor(Node):
    """Induction motor with the Kloss characteristic M_s = 2 M_b s s_b / (s^2 + s_b^2)."""

    inertia_kg_m2: float = param(gt=0, doc="rotor inertia I_s")
    synchronous_speed_rad_s: float = param(gt=0, doc="rated synchronous speed w_s")
    breakdown_torque_Nm: float = param(gt=0, doc="breakdown (pull-out) torque M_b")
    breakdown_slip: float = param(gt=0, le=1, doc="breakdown slip s_b")


@dataclass(frozen=True, kw_only=True)
class Shaft(Node):
    """Torsional spring-damper between two inertias (coupling or shaft)."""

    stiffness_Nm_per_rad: float = param(gt=0, doc="torsional stiffness k")
    damping_Nms_per_rad: float = param(0.0, ge=0, doc="torsional damping C")


@dataclass(frozen=True, kw_only=True)
class RollingGeometry(Node):
    """The geometry of a rolling-element bearing that sets its defect frequencies (BPFO, BPFI, BSF, FTF):
    the ball-by-ball law ``"rolling-elements"`` reads it; for the other laws it is data for the analysis
    only and never changes a run."""

    balls: int = param(ge=3, le=100, doc="number of rolling elements (balls or rollers) N")
    ball_diameter_m: float = param(gt=0, doc="rolling-element diameter d (< pitch_diameter_m)")
    pitch_diameter_m: float = param(gt=0, doc="pitch diameter D of the rolling-element centres (> d)")
    contact_angle_deg: float = param(
        0.0, ge=0, lt=90, doc="contact angle alpha (0: deep-groove ball or cylindrical roller bearing)"
    )

    def __post_init__(self) -> None:
        check_ranges(self)  # built in Python as well as read from a file
        if not self.ball_diameter_m < self.pitch_diameter_m:
            raise ScenarioError(
                f"ball_diameter_m = {self.ball_diameter_m:g}: must be < pitch_diameter_m = "
                f"{self.pitch_diameter_m:g} (the ball must fit: its diameter d below the pitch diameter D "
                "of the ball centres)"
            )


@dataclass(frozen=True, kw_only=True)
class BearingDefectSpec(Node):
    """A local defect of a ``"rolling-elements"`` bearing (gearbody.physics.rolling_bearing): a pit of
    ``depth_m`` over ``width_deg`` on the outer race (fixed in the housing), the inner race (turning with
    the gear) or a ball, at ``angle_deg``."""

    race: str = param(choices=("outer", "inner", "ball"), doc="where the defect is: outer, inner or ball")
    depth_m: float = param(gt=0, le=0.01, doc="depth of the pit (the drop is also limited by the ball)")
    width_deg: float = param(
        gt=0, le=90, doc="angular width (about the bearing centre; a ball defect: about the ball's centre)"
    )
    angle_deg: float = param(
        0.0,
        ge=-360,
        le=360,
        doc="outer: from the housing's x axis; inner: on the inner race from the gear's zero angle; ball: "
        "spin angle from the outward radial direction, at the start",
    )
    ball: int = param(0, ge=0, le=99, doc="the defective ball (race 'ball'), 0 .. balls - 1")


@dataclass(frozen=True, kw_only=True)
class Bearing(Node):
    """Bearing between a gear centre and the housing: a registered law (gearbody.physics.bearings)
    with its keyword parameters, the effective housing mass seen at this bearing and, optionally, its
    rolling geometry (data for the bearing defect frequencies; not read by the law). Kind ``"rigid"``
    is the bearing of a torsional gear (lateral = "none"): it names the bearing and carries its
    geometry, and the gear centre stays fixed."""

    kind: str = param("linear", doc="registered bearing law, e.g. 'linear', 'hertzian' or 'rigid'")
    housing_mass_kg: float = param(
        50.0, gt=0, doc="effective housing mass for the housing acceleration (not used by 'rigid')"
    )
    parameters: dict[str, float] = param(default_factory=dict, doc="keyword parameters of the law")
    geometry: RollingGeometry | None = param(
        None,
        doc="rolling-element geometry: read by the 'rolling-elements' law, for the other laws data for "
        "the defect frequencies only",
    )
    defects: tuple[BearingDefectSpec, ...] = param(
        (), doc="local defects of a 'rolling-elements' bearing (race, depth_m, width_deg, angle_deg, ball)"
    )

    def __post_init__(self) -> None:
        law = self.law()  # refuse unknown kinds and bad parameters before anything runs
        if dataclasses.is_dataclass(law):  # resolve the law's defaults into the scenario
            own = set(getattr(law, "GEOMETRY", ())) | {"defects"}  # stated in geometry / defects
            fields = [f.name for f in dataclasses.fields(law) if f.name not in own]
            object.__setattr__(self, "parameters", {name: float(getattr(law, name)) for name in fields})

    def _table_arguments(self, cls) -> dict:
        """The law's arguments from the geometry and defects tables (the 'rolling-elements' law)."""
        reads = getattr(cls, "GEOMETRY", ())
        if self.defects and not reads:
            raise ScenarioError(
                f"bearing.defects: the {self.kind!r} law has no defects; a bearing with local defects is "
                "kind = 'rolling-elements' (ball by ball, with geometry)"
            )
        if not reads:
            return {}
        if self.geometry is None:
            raise ScenarioError(
                f"bearing.geometry: required by the {self.kind!r} law (balls, ball_diameter_m, "
                "pitch_diameter_m, contact_angle_deg)"
            )
        from ..physics.bearings import BearingDefect

        out = {name: getattr(self.geometry, name) for name in reads}
        for k, d in enumerate(self.defects):
            if d.race == "ball" and d.ball >= self.geometry.balls:
                raise ScenarioError(
                    f"defects.{k + 1}.ball = {d.ball}: the bearing has balls 0 .. {self.geometry.balls - 1}"
                )
        out["defects"] = tuple(
            BearingDefect(d.race, d.depth_m, d.width_deg, d.angle_deg, d.ball) for d in self.defects
        )
        return out

    def law(self):
        """The bearing law object (has ``force_N(displacement_m, velocity_m_s)``)."""
        if self.kind not in BEARINGS:
            raise ScenarioError(
                f"bearing.kind = {self.kind!r}: not a registered bearing law; registered: "
                f"{', '.join(sorted(BEARINGS))}"
            )
        cls = BEARINGS[self.kind]
        signature = inspect.signature(cls).parameters
        law = f"the {self.kind!r} law, which takes {', '.join(signature) or 'no parameters'}"
        if self.kind == RIGID:
            law += (
                " (it is a torsional gear's, lateral = 'none'; a gear that moves takes a law with parameters)"
            )
        tables = self._table_arguments(cls)
        for name, value in self.parameters.items():  # named as the user wrote them, not as Python's
            if name in tables:
                raise ScenarioError(
                    f"parameters.{name} = {value!r}: the {self.kind!r} law reads it from the bearing's "
                    f"{'defects' if name == 'defects' else 'geometry'} table"
                )
            if name not in signature:
                raise ScenarioError(f"parameters.{name} = {value!r}: not a parameter of {law}")
        for name, p in signature.items():
            if p.default is p.empty and name not in self.parameters and name not in tables:
                hint = "" if self.parameters else f"; a torsional gear's bearing table is kind = {RIGID!r}"
                raise ScenarioError(f"parameters.{name}: required by {law}{hint}")
        try:
            return make_bearing(self.kind, **self.parameters, **tables)
        except TypeError as exc:
            raise ScenarioError(f"bearing.parameters = {self.parameters}: {exc}; {law}") from None
        except ValueError as exc:  # the law's own check: 'LinearBearing.stiffness_x_N_per_m = ...'
            text = str(exc)
            if text.startswith(f"{cls.__name__}."):
                raise ScenarioError("parameters." + text.removeprefix(f"{cls.__name__}.")) from None
            raise ScenarioError(f"bearing.parameters: {text}") from None


LATERAL = ("none", "y", "xy")


@dataclass(frozen=True, kw_only=True)
class Gear(Node):
    teeth: int = param(ge=6, le=MAX_TEETH, doc="number of teeth z")
    base_radius_m: float | None = param(
        None, gt=0, doc="base radius r_b (required unless the mesh has a [geometry] table)"
    )
    inertia_kg_m2: float = param(gt=0, doc="polar moment of inertia")
    mass_kg: float = param(gt=0, doc="mass (lateral models)")
    lateral: str = param("none", choices=LATERAL, doc="free translations of the gear centre")
    bearing: Bearing | None = param(
        None, doc="bearing to the housing (required when lateral; kind 'rigid' when lateral = 'none')"
    )
    face_width_m: float | None = param(
        None, gt=0, le=2, doc="face width b (pictures; from the mesh geometry; unset: 10 modules)"
    )

    def __post_init__(self) -> None:
        if self.lateral != "none" and self.bearing is None:
            raise ScenarioError(
                f"lateral = {self.lateral!r} needs a bearing table (kind, housing_mass_kg, parameters)"
            )
        if self.bearing is None:
            return
        if self.lateral != "none" and self.bearing.kind == RIGID:
            raise ScenarioError(
                f"bearing.kind = 'rigid': a rigid bearing holds the gear centre fixed, but lateral = "
                f"{self.lateral!r} lets it move on its bearing; give a bearing law (e.g. 'linear' or "
                "'hertzian') with its parameters, or set lateral = 'none'"
            )
        if self.lateral == "none" and self.bearing.kind != RIGID:
            raise ScenarioError(
                f"bearing.kind = {self.bearing.kind!r}: the gear is torsional (lateral = 'none'), its "
                "centre fixed, so its bearing table only names the bearing and carries its geometry: set "
                "kind = 'rigid' (no parameters), or let the gear move on the law (lateral = 'y' or 'xy')"
            )

    @property
    def free_directions(self) -> tuple[int, ...]:
        """Indices (0 = x, 1 = y) of the free centre translations."""
        return {"none": (), "y": (1,), "xy": (0, 1)}[self.lateral]


@dataclass(frozen=True, kw_only=True)
class Machine(Node):
    inertia_kg_m2: float = param(gt=0, doc="driven machine inertia I_m")
    rated_torque_Nm: float = param(gt=0, doc="load torque at rated load on the machine shaft")


@dataclass(frozen=True)
class RollingBearingSpec:
    """A rolling bearing of the drive, as the analysis needs it for its defect frequencies
    (:meth:`gearbody.model.Scenario.rolling_bearings`).

    ``body`` is the rotation (a key of :func:`gearbody.assembly.operating_point.nominal_speeds_rad_s`:
    ``pinion``, ``wheel_2``, ``stage_2_carrier``, ``planet_1``) whose speed turns the bearing;
    ``reference`` the rotation that holds its other race (a planet bearing's pin on the carrier:
    ``carrier``), None for the housing. The bearing turns at ``speed(body) - speed(reference)``.
    ``body_race`` says which race the body turns: ``"inner"`` (a shaft in the housing) or ``"outer"``
    (a planet on its pin; the reference turns the inner race). ``key`` is the scenario key of its
    geometry (``design.stages.1.pinion.bearing.geometry``, ``design.stages.1.planet.bearing_geometry``);
    ``geometry`` the geometry stated there, None when none is."""

    name: str
    key: str
    body: str
    reference: str | None
    body_race: str
    geometry: RollingGeometry | None

    @property
    def relative(self) -> bool:
        """True when the bearing turns at its body's speed relative to another rotation (not the
        housing)."""
        return self.reference is not None
