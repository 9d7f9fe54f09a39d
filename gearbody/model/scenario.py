"""The scenario: a validated, immutable description of a drive, in ONE canonical shape.

Every geared drive is a chain of gear stages (``design.stages``) joined by shafts (``design.shafts``);
a one-stage drive is a train of one stage. ``meta.topology`` says how the chain is modelled (``train``:
motor, shafts, stages and machine as their own inertias; ``two-wheel``: motor and machine lumped on the
gears; ``muller``: one reduced mass), ``meta.name`` names the scene. The single-stage TOML shorthand
(``design.pinion``, ``production.error_mode``, ...) is converted by :mod:`gearbody.model.shorthand`
when a scenario is loaded. The paper's DPTOCC factors: design (components, stages), production
technology and change of condition per stage (error mode, run-out, damaged and pitted teeth), operation
(speed and load profiles), condition (friction). docs/scenario.md gives every key and equation.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, ClassVar

from .budget import check_resources
from .components import Gear, Machine, Motor, Shaft
from .faults import DamagedTooth, Eccentricity, ErrorMode, PittedTooth
from .kinds import register_stage_kind, stage_kind
from .mesh import Mesh
from .operation import Operation
from .params import Node, ScenarioError, param, stage_key
from .planetary import PlanetaryStage
from .resolve import resolve_design, resolve_parallel_geometry, resolve_parallel_rating, resolve_planetary_iso

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


SOLVER_METHODS = ("DOPRI5", "ODE23", "RK44", "RK67")
"""Exudyn's explicit integrators gearbody offers. DVERK6 is not among them: Exudyn 1.13.6 names it but
does not implement it (a run failed at its start with NotImplementedFeatureError)."""


ACCURACY_LEVELS = {
    # level: (method, absolute tolerance of rotations in rad); Muller's deflection coordinate (m) gets
    # MULLER_TOLERANCE_SCALE times it. Measured against the independent reference on the full validation
    # cases (benchmarks/RESULTS.md, "Accuracy levels").
    "draft": ("ODE23", 3e-5),  # loaded steady running, torsional studies of error modes and faults:
    #                            0.15-0.26 %; misses impacts (1-35 % on separations) and bearing forces
    "default": ("DOPRI5", 1e-8),  # every validation case <= 0.06 %, impacts included (2026-12-02)
    "tight": ("DOPRI5", 1e-10),  # a yardstick: ~1e-4 % of F_rated
}
MULLER_TOLERANCE_SCALE = 3e-3
"""Muller integrates the deflection in metres, the other topologies angles in radians (1e-8 rad is
r_b 1e-8 ~ 1e-9 m of deflection). At 1e-8 m Muller's full separation and run-up cases missed by 0.66 % and
10.3 % (the re-engagement impacts of the load ramp); 3e-11 m gives 0.0001 % and 0.031 % (1e-9: 0.0016 /
2.1 %, 1e-10: 0.0001 / 0.21 %)."""


PLANETARY_TOLERANCE_SCALE = 0.1
"""A drive with planetary stages integrates the planets' centres in the fixed frame (metres, moving by
r_c w_c per second) with the rotations: at 1e-8 the conveyor scene's separation case (speed x5.6, the
carrier at 43 rad/s) drifted from the reference by 0.9 % of F_rated within 0.06 s; 1e-9 gives 0.03 %,
1e-10 0.0008 % (validation/compare.py cases)."""


def default_solver(accuracy: str, topology: str, planetary: bool = False) -> tuple[str, float]:
    """(method, absolute tolerance) of an accuracy level for a topology's coordinates (``planetary``: a
    drive with planetary stages)."""
    method, atol = ACCURACY_LEVELS[accuracy]
    if planetary:
        atol *= PLANETARY_TOLERANCE_SCALE
    return method, atol * (MULLER_TOLERANCE_SCALE if topology == "muller" else 1.0)


@dataclass(frozen=True, kw_only=True)
class Solver(Node):
    accuracy: str = param(
        "default", choices=tuple(ACCURACY_LEVELS), doc="sets method and absolute_tolerance where unset"
    )
    method: str | None = param(
        None, choices=SOLVER_METHODS, doc="Exudyn explicit integrator (unset: from accuracy)"
    )
    # The mesh force depends on r1 phi_p - r2 phi_w, a small difference of angles that grow past
    # 100 rad per simulated second. Exudyn scales each coordinate's error by atol + rtol * max(q0, q1)
    # (signed), so a relative tolerance loosens as the angles grow: rtol is kept negligible and the
    # absolute tolerance (SI units: rad, rad/s, m, m/s) sets the accuracy, so its default depends on what
    # the coordinates are (MULLER_TOLERANCE_SCALE); docs/design-notes.md, "Solver tolerances".
    relative_tolerance: float = param(1e-14, gt=0, lt=1, doc="adaptive step relative tolerance")
    absolute_tolerance: float | None = param(
        None, gt=0, doc="adaptive step absolute tolerance (unset: from accuracy, in the coordinates' units)"
    )
    max_step_s: float = param(1e-4, gt=0, doc="largest step")
    output_rate_hz: float = param(20000.0, gt=0, doc="results are sampled at k / output_rate_hz")
    # The mesh force jumps when the pair count changes; point samples of it alias (its 1/k harmonics
    # fold into the band of interest). docs/scenario.md, "Signals": which signals are band-limited.
    anti_aliasing: bool = param(
        True, doc="band-limit force and acceleration signals before sampling (measurement-chain filter)"
    )
    # Resource limits (gearbody.model.budget): checked before a run from estimates, and during it.
    memory_limit_MiB: float | None = param(
        None,
        gt=0,
        doc="memory budget of a run: refused before it when the output grid and stored steps are "
        "estimated above it, stopped when the process grows by more while solving (unset: 2048)",
    )
    wall_time_limit_s: float | None = param(
        None, gt=0, doc="stop a run cleanly after this much wall-clock time solving (unset: no limit)"
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
    machine), ``operation``, ``condition``, ``solver`` and ``visual``. Immutable; validated when built
    (a :class:`~gearbody.errors.ScenarioError` names the key); ``replace``/``with_stage`` make
    changed copies. :func:`~gearbody.model.load_scenario` reads one."""

    meta: Meta
    design: Design
    operation: Operation
    condition: Condition = param(default_factory=Condition)
    solver: Solver = param(default_factory=Solver)
    visual: Visual = param(default_factory=Visual)

    @classmethod
    def prepare_fields(cls, fields: dict[str, Any]) -> dict[str, Any]:
        """Fields with every mesh stated by gear geometry resolved (gearbody.model.resolve); called
        before construction, so that a Scenario is never changed after it is built."""
        if "design" in fields:
            _check_topology(fields["meta"].topology, fields["design"])
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
        _check_topology(self.meta.topology, self.design)
        for k, stage in enumerate(self.stages):
            check = stage_kind(stage).check
            if check is not None:
                check(k, self)
        if self.has_planetary:
            pass  # the turning sense of each member is the stage's own (docs/planetary.md)
        elif self.meta.topology == "train":
            _check_turning_senses(self.stages)
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


def _check_planetary_in_drive(k: int, scenario: Scenario) -> None:
    """What a drive with a planetary stage cannot have yet (refused, never ignored)."""
    if scenario.meta.topology != "train":
        raise ScenarioError(
            f"{stage_key(k, 'type')} = 'planetary': only topology 'train' has planetary stages, "
            f"got {scenario.meta.topology!r}"
        )
    if scenario.is_lateral:
        raise ScenarioError(
            f"{stage_key(k, 'type')} = 'planetary': parallel stages on lateral bearings are not yet "
            "combined with planetary stages; set their gears' lateral = 'none'"
        )


def _check_topology(topology: str, design: Design) -> None:
    n = len(design.stages)
    if n < 1:
        raise ScenarioError("design.stages: a drive needs at least one gear stage")
    if topology == "train":
        if len(design.shafts) != n + 1:
            raise ScenarioError(
                f"design.shafts has {len(design.shafts)} entries: a train of {n} stage(s) needs {n + 1} "
                "(motor->stage 1, ..., last stage->machine)"
            )
    else:
        if n != 1:
            raise ScenarioError(f"design.stages: topology {topology!r} has exactly one stage, got {n}")
        if design.shafts:
            raise ScenarioError(
                f"design.shafts: topology {topology!r} has no shafts (motor and machine sit rigidly on the "
                "gears); remove them or use topology 'train'"
            )


def _check_stage(k: int, stage: Stage) -> None:
    pb1 = 2 * math.pi * stage.pinion.base_radius_m / stage.pinion.teeth
    pb2 = 2 * math.pi * stage.wheel.base_radius_m / stage.wheel.teeth
    if abs(pb2 / pb1 - 1) > 0.005:
        raise ScenarioError(
            f"{stage_key(k, 'wheel')}.base_radius_m = {stage.wheel.base_radius_m}: base pitch 2 pi r_b / z = "
            f"{pb2 * 1e3:.4f} mm differs from the pinion's {pb1 * 1e3:.4f} mm by more than 0.5 %; "
            f"meshing gears need equal base pitches (r_b2 = r_b1 z2 / z1 = "
            f"{stage.pinion.base_radius_m * stage.wheel.teeth / stage.pinion.teeth:.6g} m)"
        )
    for key, entries in (("damaged_teeth", stage.damaged_teeth), ("pitted_teeth", stage.pitted_teeth)):
        seen: dict[tuple[str, int], int] = {}
        for i, t in enumerate(entries, start=1):
            z = getattr(stage, t.gear).teeth
            if t.tooth >= z:
                raise ScenarioError(
                    f"{stage_key(k, key)}.{i}.tooth = {t.tooth} on the {t.gear}: must be < its {z} teeth "
                    f"(0..{z - 1})"
                )
            if (t.gear, t.tooth) in seen:
                what = "one pit per tooth" if key == "pitted_teeth" else "one entry per damaged tooth"
                raise ScenarioError(
                    f"{stage_key(k, key)}.{i}: {what}: {t.gear} tooth {t.tooth} is also entry "
                    f"{seen[t.gear, t.tooth]}"
                    + ("; give its damage in one entry" if key == "damaged_teeth" else "")
                )
            seen[t.gear, t.tooth] = i
    for i, t in enumerate(stage.pitted_teeth, start=1):
        if not t.end_phase > t.start_phase:
            raise ScenarioError(
                f"{stage_key(k, 'pitted_teeth')}.{i}.end_phase = {t.end_phase} must be > start_phase = "
                f"{t.start_phase} (a pit spans [start_phase, end_phase) of the mesh period)"
            )
        w = stage.mesh.transition_width
        if t.end_phase - t.start_phase < w:
            raise ScenarioError(
                f"{stage_key(k, 'pitted_teeth')}.{i}: the pit on {t.gear} tooth {t.tooth} spans "
                f"{t.end_phase - t.start_phase:g} of the mesh period, less than the mesh's "
                f"transition_width = {w:g}; narrow the width or widen the pit"
            )
    gears = [e.gear for e in stage.eccentricity]
    if len(set(gears)) < len(gears):
        raise ScenarioError(f"{stage_key(k, 'eccentricity')}: at most one entry per gear, got {gears}")


def _check_turning_senses(stages: tuple[Stage, ...]) -> None:
    """A stage's pinion turns with the previous stage's wheel, so the direction of its line of action is
    fixed by the chain; on bearings (lateral) a contradicting direction would put the mesh and friction
    forces on the wrong side of the gears."""
    sense = 1 if stages[0].mesh.line_of_action_normal_projection > 0 else -1
    for k, st in enumerate(stages):
        own = 1 if st.mesh.line_of_action_normal_projection > 0 else -1
        lateral = st.pinion.lateral != "none" or st.wheel.lateral != "none"
        if k > 0 and lateral and own != sense:
            turn = "counter-clockwise" if sense > 0 else "clockwise"
            raise ScenarioError(
                f"{stage_key(k, 'mesh')}.line_of_action_deg = {st.mesh.line_of_action_deg:g}: this "
                f"stage's pinion turns {turn} (with the previous wheel), so its line of action must "
                f"point the other way: centre_line_deg {'+' if sense > 0 else '-'} (90 - pressure "
                f"angle), e.g. {st.mesh.centre_line_deg + sense * 90:g} for a pure normal"
            )
        sense = -sense


register_stage_kind(
    "parallel",
    Stage,
    compound=False,
    check=lambda k, scenario: _check_stage(k, scenario.stages[k]),
    resolve_geometry=resolve_parallel_geometry,
    resolve_rating=resolve_parallel_rating,
)
register_stage_kind(
    "planetary",
    PlanetaryStage,
    compound=True,
    check=_check_planetary_in_drive,
    resolve_rating=lambda stage, k, rated_force_N: resolve_planetary_iso(stage, rated_force_N, k),
)
