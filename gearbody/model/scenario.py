"""The scenario: a validated, immutable description of a drive, in ONE canonical shape.

Every geared drive is a chain of gear stages (``design.stages``) joined by shafts (``design.shafts``);
a one-stage drive is a train of one stage. ``meta.topology`` says how the chain is modelled (``train``:
motor, shafts, stages and machine as their own inertias; ``two-wheel``: motor and machine lumped on the
gears; ``muller``: one reduced mass), ``meta.name`` names the scene. The single-stage TOML shorthand
(``design.pinion``, ``production.error_mode``, ...) is converted by :mod:`gearbody.model.shorthand`
when a scenario is loaded. The paper's DPTOCC factors: design (components, stages), production
technology and change of condition per stage (error mode, run-out, damaged and pitted teeth), operation
(speed and load profiles), condition (friction). docs/scenario.md gives every key and equation. The
solver section and its defaults are :mod:`gearbody.model.solver`; the checks a scenario makes of itself
when built, :mod:`gearbody.model.checks`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, ClassVar

from ..signals import gear_names
from .budget import check_resources
from .checks import check_planetary_in_drive, check_stage, check_topology, check_turning_senses
from .components import Gear, Machine, Motor, RollingBearingSpec, Shaft
from .faults import DamagedTooth, Eccentricity, ErrorMode, PittedTooth
from .instruments import Instruments, check_instruments_in_run
from .kinds import register_stage_kind, stage_kind
from .mesh import Mesh
from .operation import Operation
from .params import Node, ScenarioError, param, stage_key
from .planetary import PlanetaryStage
from .resolve import resolve_design, resolve_parallel_geometry, resolve_parallel_rating, resolve_planetary_iso
from .solver import ACCURACY_LEVELS as ACCURACY_LEVELS  # re-exported: imported from here before the split
from .solver import MULLER_TOLERANCE_SCALE as MULLER_TOLERANCE_SCALE
from .solver import PLANETARY_TOLERANCE_SCALE as PLANETARY_TOLERANCE_SCALE
from .solver import SOLVER_METHODS as SOLVER_METHODS
from .solver import Solver, default_solver

TOPOLOGIES = ("muller", "two-wheel", "train")


@dataclass(frozen=True, kw_only=True)
class Meta(Node):
    topology: str = param(
        doc="how the drive is modelled: 'train' (chain of stages and shafts), "
        "'two-wheel' (Fig. 2), 'muller' (Fig. 1)",
        choices=TOPOLOGIES,
    )
    name: str = param("", doc="scene name (loading a file: its name without .toml)")
    title: str = param("", doc="free text")
    sources: tuple[str, ...] = param((), doc="where the parameter values come from")
    seed: int = param(1, ge=0, doc="seed of the random per-tooth error factors l_i")


@dataclass(frozen=True, kw_only=True)
class Stage(Node):
    """One parallel-axis gear stage: its gears, mesh, error mode and tooth faults."""

    KIND: ClassVar[str] = "parallel"  # a design.stages item without ``type``, or type = "parallel"
    pinion: Gear
    wheel: Gear
    mesh: Mesh = param(default_factory=Mesh)
    error_mode: ErrorMode = param(default_factory=ErrorMode, doc="tooth error mode E(a, e, r)")
    damaged_teeth: tuple[DamagedTooth, ...] = param((), doc="per-tooth stiffness factors and damage")
    eccentricity: tuple[Eccentricity, ...] = param((), doc="once-per-revolution errors, one per gear")
    pitted_teeth: tuple[PittedTooth, ...] = param((), doc="local pitting errors (one per tooth)")

    @property
    def ratio(self) -> float:
        """z2 / z1."""
        return self.wheel.teeth / self.pinion.teeth

    def mesh_frequency_hz(self, input_speed_rad_s: float) -> float:
        """z1 times the pinion's speed in revolutions per second."""
        return self.pinion.teeth * input_speed_rad_s / (2 * math.pi)

    @property
    def transition_width(self) -> float:
        """The mesh's transition width."""
        return self.mesh.transition_width

    @property
    def mesh_count(self) -> int:
        """Meshes of the stage: one."""
        return 1

    @property
    def input_teeth(self) -> int:
        """Teeth that set the mesh period along the input's angle: the pinion's."""
        return self.pinion.teeth

    def mesh_periods_per_revolution(self) -> tuple[float, str]:
        """(mesh periods per revolution of the input: z1, the footnote of ``gearbody modes`` that says so)."""
        z1 = self.pinion.teeth
        return (
            z1,
            f"(w(k f_z) = pinion speed at which the k-th mesh harmonic z1 w k / 2 pi meets f_n; z1 = {z1})",
        )

    @property
    def input_arm_m(self) -> float:
        """The pinion's base radius: torque in per unit mesh force (as a planetary stage's r_eq)."""
        return self.pinion.base_radius_m

    @property
    def output_arm_m(self) -> float:
        """The wheel's base radius: torque out per unit mesh force."""
        return self.wheel.base_radius_m

    def rolling_bearings(self, k: int) -> list[RollingBearingSpec]:
        """The bearings of the stage at index ``k`` (from 0) that have a bearing table: the pinion's and
        the wheel's, each turning its inner race in the housing (named as in
        :func:`gearbody.signals.gear_names`: ``pinion``, ``wheel_2``)."""
        label = "" if k == 0 else f"stage {k + 1} "
        return [
            RollingBearingSpec(
                f"{label}{role} bearing",
                stage_key(k, f"{role}.bearing.geometry"),
                body,
                None,
                "inner",
                gear.bearing.geometry,
            )
            for role, body, gear in zip(
                ("pinion", "wheel"), gear_names(k), (self.pinion, self.wheel), strict=True
            )
            if gear.bearing is not None
        ]


@dataclass(frozen=True, kw_only=True)
class Design(Node):
    motor: Motor
    machine: Machine
    stages: tuple[Stage | PlanetaryStage, ...] = param(
        doc="gear stages in power-flow order (numbered from 1 in keys): parallel, or type = 'planetary'"
    )
    shafts: tuple[Shaft, ...] = param(
        (), doc="train: motor->stage 1, stage s->s+1, ..., last stage->machine (two-wheel, muller: none)"
    )

    def stage_rated_force_N(self, stage: int) -> float:
        """F_rated,s: the rated machine torque passed upstream through the base radii,
        F_N = M_rated / r_w,N and F_s = F_s+1 r_p,s+1 / r_w,s (static equilibrium, no friction); a
        planetary stage's torque arms r_eq in place of r_p and r_w (its F_rated is per planet mesh)."""
        stages = self.stages
        force = self.machine.rated_torque_Nm / stages[-1].output_arm_m
        for k in range(len(stages) - 1, stage, -1):
            force *= stages[k].input_arm_m / stages[k - 1].output_arm_m
        return force


@dataclass(frozen=True, kw_only=True)
class Condition(Node):
    friction_coefficient: float = param(0.0, ge=0, lt=1, doc="inter-tooth friction mu (every mesh)")
    friction_transition_speed_m_s: float = param(
        1e-3,
        ge=1e-6,
        le=1.0,
        doc="sliding speed v_0 below which the friction force's direction blends smoothly through 0 "
        "(T = -mu |F| sigma(v_sl / v_0), docs/scenario.md 'Friction')",
    )


@dataclass(frozen=True, kw_only=True)
class Visual(Node):
    """How pictures of the machine look (gearbody render); no effect on the simulation."""

    housing: bool = param(False, doc="draw a transparent gear housing")
    lateral_scale: float = param(
        1000.0, ge=0, le=1e6, doc="magnification of the gears' lateral motion in pictures (0: none)"
    )


@dataclass(frozen=True, kw_only=True)
class Scenario(Node):
    """Everything a run is made of, as the TOML tables of a scene: ``meta``, ``design`` (motor, stages,
    machine), ``operation``, ``condition``, ``solver``, ``visual`` and the optional ``instruments`` (virtual
    sensors, evaluated after the solve). Immutable; validated when built
    (a :class:`~gearbody.errors.ScenarioError` names the key); ``replace``/``with_stage`` make
    changed copies. :func:`~gearbody.model.load_scenario` reads one."""

    meta: Meta
    design: Design
    operation: Operation
    condition: Condition = param(default_factory=Condition)
    solver: Solver = param(default_factory=Solver)
    visual: Visual = param(default_factory=Visual)
    instruments: Instruments | None = param(
        None, doc="virtual housing accelerometers and a tacho, recorded after the solve (docs/scenario.md)"
    )

    @classmethod
    def prepare_fields(cls, fields: dict[str, Any]) -> dict[str, Any]:
        """Fields with every mesh stated by gear geometry resolved (gearbody.model.resolve); called
        before construction, so that a Scenario is never changed after it is built."""
        if "design" in fields:
            check_topology(fields["meta"].topology, fields["design"])
            fields = {**fields, "design": resolve_design(fields["design"])}
        solver = fields.get("solver", Solver())
        if solver.method is None or solver.absolute_tolerance is None:  # from the accuracy level
            planetary = "design" in fields and any(stage_kind(st).compound for st in fields["design"].stages)
            method, atol = default_solver(solver.accuracy, fields["meta"].topology, planetary)
            solver = dataclasses.replace(
                solver,
                method=solver.method or method,
                absolute_tolerance=atol if solver.absolute_tolerance is None else solver.absolute_tolerance,
            )
            fields = {**fields, "solver": solver}
        return fields

    @classmethod
    def create(cls, **fields: Any) -> Scenario:
        """A Scenario from its sections (Meta, Design, Operation, ...), with gear geometry and the solver
        defaults resolved (``Scenario(...)`` itself expects them resolved)."""
        return cls(**cls.prepare_fields(fields))

    def replace(self, **changes: Any) -> Scenario:
        """A copy with whole sections replaced (``operation=steady(0.3)``), resolved and validated."""
        fields = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        return Scenario.create(**{**fields, **changes})

    def with_stage(self, stage: int, **changes: Any) -> Scenario:
        """A copy with fields of stage ``stage`` (0-based) replaced, e.g.
        ``with_stage(0, error_mode=sc.stages[0].error_mode.replace(e_um=15))``."""
        if not 0 <= stage < len(self.stages):
            raise ScenarioError(
                f"stage {stage}: the drive has {len(self.stages)} stage(s), 0..{len(self.stages) - 1}"
            )
        stages = list(self.design.stages)
        stages[stage] = stages[stage].replace(**changes)
        return self.replace(design=self.design.replace(stages=tuple(stages)))

    def __post_init__(self) -> None:
        if self.solver.absolute_tolerance is None or self.solver.method is None:
            raise ScenarioError(
                "solver.method / absolute_tolerance unset: build a Scenario with load_scenario(...) or "
                "Scenario.create(...), which resolve them from solver.accuracy"
            )
        check_topology(self.meta.topology, self.design)
        for k, stage in enumerate(self.stages):
            check = stage_kind(stage).check
            if check is not None:
                check(k, self)
        if self.has_planetary:
            pass  # the turning sense of each member is the stage's own (docs/planetary.md)
        elif self.meta.topology == "train":
            check_turning_senses(self.stages)
        else:
            for name in ("pinion", "wheel"):
                if getattr(self.stages[0], name).lateral != "none":
                    raise ScenarioError(
                        f"{stage_key(0, name)}.lateral = {getattr(self.stages[0], name).lateral!r}: topology "
                        f"{self.meta.topology!r} has no lateral motion; use 'train'"
                    )
        if self.solver.output_rate_hz * self.operation.t_end_s < 2:
            raise ScenarioError(
                f"solver.output_rate_hz = {self.solver.output_rate_hz}: gives fewer than 2 "
                f"samples over t_end_s = {self.operation.t_end_s}"
            )
        if self.instruments is not None:
            check_instruments_in_run(self.instruments, self.solver.output_rate_hz)
        check_resources(self)

    # -- derived quantities used everywhere ------------------------------------------------
    @property
    def stages(self) -> tuple[Stage, ...]:
        """The gear stages in power-flow order."""
        return self.design.stages

    @property
    def name(self) -> str:
        """The scene's name (meta.name; its topology when unnamed)."""
        return self.meta.name or self.meta.topology

    @property
    def is_lateral(self) -> bool:
        """True when any gear of a parallel stage moves laterally on its bearing."""
        return any(g.lateral != "none" for st in self.parallel_stages for g in (st.pinion, st.wheel))

    @property
    def has_planetary(self) -> bool:
        """True when any stage is planetary (of a kind that needs the compound layout)."""
        return any(stage_kind(st).compound for st in self.stages)

    @property
    def parallel_stages(self) -> tuple[Stage, ...]:
        """The parallel stages (every stage of a drive without planetary ones)."""
        return tuple(st for st in self.stages if not stage_kind(st).compound)

    @property
    def gear_ratio(self) -> float:
        """Overall ratio, product of z2/z1 over the stages."""
        return math.prod(s.ratio for s in self.stages)

    def stage_rated_force_N(self, stage: int) -> float:
        """F_rated of stage ``stage`` (0-based); see :meth:`Design.stage_rated_force_N`."""
        return self.design.stage_rated_force_N(stage)

    @property
    def rated_mesh_force_N(self) -> float:
        """F_rated of the first stage."""
        return self.stage_rated_force_N(0)

    def rolling_bearings(self) -> list[RollingBearingSpec]:
        """Every bearing of the drive that the analysis may take defect frequencies of, in power-flow
        order: each gear's with a bearing table (a lateral gear's, or a torsional gear's 'rigid' one),
        each planetary member's. ``body`` (and ``reference``) name rotations of
        :func:`gearbody.assembly.operating_point.nominal_speeds_rad_s`; ``geometry`` is None where the
        scenario states none (see :class:`~gearbody.model.components.RollingBearingSpec`)."""
        out: list[RollingBearingSpec] = []
        for k, st in enumerate(self.stages):
            hook = stage_kind(st).rolling_bearings
            out += hook(st, k) if hook is not None else []
        return out


register_stage_kind(
    "parallel",
    Stage,
    compound=False,
    check=lambda k, scenario: check_stage(k, scenario.stages[k]),
    resolve_geometry=resolve_parallel_geometry,
    resolve_rating=resolve_parallel_rating,
    rolling_bearings=Stage.rolling_bearings,
)
register_stage_kind(
    "planetary",
    PlanetaryStage,
    compound=True,
    check=check_planetary_in_drive,
    resolve_rating=lambda stage, k, rated_force_N: resolve_planetary_iso(stage, rated_force_N, k),
    rolling_bearings=PlanetaryStage.rolling_bearings,
)
