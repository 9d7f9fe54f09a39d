"""The scenario: a validated, immutable description of a drive, grouped as the paper's DPTOCC factors.

Design (components, mesh), production technology (error mode), operation (speed and load profiles),
change of condition (damaged teeth, friction). See ``docs/scenario.md`` for every key and equation.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from .params import ScenarioError, param

SCENES = ("muller", "two-wheel", "one-stage", "train")


@dataclass(frozen=True, kw_only=True)
class Meta:
    scene: str = param(doc="system topology", choices=SCENES)
    title: str = param("", doc="free text")
    sources: tuple[str, ...] = param((), doc="where the parameter values come from")
    seed: int = param(1, ge=0, doc="seed of the random per-tooth error factors l_i")


@dataclass(frozen=True, kw_only=True)
class Motor:
    """Induction motor with the Kloss characteristic M_s = 2 M_b s s_b / (s^2 + s_b^2)."""

    inertia_kg_m2: float = param(gt=0, doc="rotor inertia I_s")
    synchronous_speed_rad_s: float = param(gt=0, doc="rated synchronous speed w_s")
    breakdown_torque_Nm: float = param(gt=0, doc="breakdown (pull-out) torque M_b")
    breakdown_slip: float = param(gt=0, le=1, doc="breakdown slip s_b")


@dataclass(frozen=True, kw_only=True)
class Shaft:
    """Torsional spring-damper between two inertias (coupling or shaft)."""

    stiffness_Nm_per_rad: float = param(gt=0, doc="torsional stiffness k")
    damping_Nms_per_rad: float = param(0.0, ge=0, doc="torsional damping C")


@dataclass(frozen=True, kw_only=True)
class Bearing:
    """Bearing between a gear centre and the housing: a registered law (gearbody.physics.bearings)
    with its keyword parameters, and the effective housing mass seen at this bearing."""

    kind: str = param("linear", doc="registered bearing law, e.g. 'linear' or 'hertzian'")
    housing_mass_kg: float = param(50.0, gt=0, doc="effective housing mass for the housing acceleration")
    parameters: dict[str, float] = param(default_factory=dict, doc="keyword parameters of the law")

    def __post_init__(self) -> None:
        law = self.law()  # refuse unknown kinds and bad parameters before anything runs
        if dataclasses.is_dataclass(law):  # resolve the law's defaults into the scenario
            resolved = {f.name: float(getattr(law, f.name)) for f in dataclasses.fields(law)}
            object.__setattr__(self, "parameters", resolved)

    def law(self):
        """The bearing law object (has ``force_N(displacement_m, velocity_m_s)``)."""
        from ..physics.bearings import BEARINGS, make_bearing

        if self.kind not in BEARINGS:
            raise ScenarioError(
                f"bearing.kind = {self.kind!r}: not a registered bearing law; registered: "
                f"{', '.join(sorted(BEARINGS))}"
            )
        try:
            return make_bearing(self.kind, **self.parameters)
        except TypeError as exc:
            import inspect

            names = list(inspect.signature(BEARINGS[self.kind]).parameters)
            raise ScenarioError(
                f"bearing.parameters = {self.parameters}: {exc}; "
                f"the {self.kind!r} law takes {', '.join(names)}"
            ) from None
        except ValueError as exc:
            raise ScenarioError(f"bearing.parameters: {exc}") from None


LATERAL = ("none", "y", "xy")


@dataclass(frozen=True, kw_only=True)
class Gear:
    teeth: int = param(ge=6, doc="number of teeth z")
    base_radius_m: float | None = param(
        None, gt=0, doc="base radius r_b (required unless the mesh has a [geometry] table)"
    )
    inertia_kg_m2: float = param(gt=0, doc="polar moment of inertia")
    mass_kg: float = param(gt=0, doc="mass (lateral models)")
    lateral: str = param("none", choices=LATERAL, doc="free translations of the gear centre")
    bearing: Bearing | None = param(None, doc="bearing to the housing (required when lateral)")
    face_width_m: float | None = param(
        None, gt=0, le=2, doc="face width b (pictures; from the mesh geometry; unset: 10 modules)"
    )

    def __post_init__(self) -> None:
        if self.lateral != "none" and self.bearing is None:
            raise ScenarioError(
                f"lateral = {self.lateral!r} needs a bearing table (kind, housing_mass_kg, parameters)"
            )

    @property
    def free_directions(self) -> tuple[int, ...]:
        """Indices (0 = x, 1 = y) of the free centre translations."""
        return {"none": (), "y": (1,), "xy": (0, 1)}[self.lateral]


@dataclass(frozen=True, kw_only=True)
class Machine:
    inertia_kg_m2: float = param(gt=0, doc="driven machine inertia I_m")
    rated_torque_Nm: float = param(gt=0, doc="load torque at rated load on the machine shaft")


STIFFNESS_PROFILES = ("contact-ratio", "table", "iso-6336-b", "potential-energy")
FROM_GEOMETRY = ("iso-6336-b", "potential-energy")


@dataclass(frozen=True, kw_only=True)
class MeshGeometry:
    """Gear-pair geometry of a mesh (docs/scenario.md, "Gear geometry"): base radii, contact ratio,
    pitch point, working pressure angle, face width, backlash and the stiffness follow from it."""

    module_mm: float = param(gt=0, le=100, doc="normal module m_n")
    pressure_angle_deg: float = param(20.0, ge=10, le=35, doc="basic-rack (normal) pressure angle alpha_n")
    helix_angle_deg: float = param(0.0, ge=0, le=45, doc="helix angle beta (iso-6336-b only)")
    face_width_mm: float = param(gt=0, le=2000, doc="common face width b")
    profile_shift_pinion: float = param(0.0, ge=-1.5, le=1.5, doc="profile shift coefficient x_1")
    profile_shift_wheel: float = param(0.0, ge=-1.5, le=1.5, doc="profile shift coefficient x_2")
    addendum_coefficient: float = param(1.0, gt=0, le=2, doc="h_a* of the basic rack")
    dedendum_coefficient: float = param(1.25, gt=0, le=2, doc="h_f* of the basic rack")
    rack_tip_radius_coefficient: float | None = param(
        None, ge=0, le=1, doc="rho_fP* of the basic rack (unset: full round, 0.38 for ISO 53 A)"
    )
    centre_distance_mm: float | None = param(
        None, gt=0, doc="working centre distance (unset: from the shifts)"
    )
    bore_diameter_pinion_mm: float | None = param(
        None, gt=0, doc="pinion bore (potential-energy: fillet-foundation term)"
    )
    bore_diameter_wheel_mm: float | None = param(
        None, gt=0, doc="wheel bore (potential-energy: fillet-foundation term)"
    )
    youngs_modulus_GPa: float = param(206.0, gt=0, le=1000, doc="Young's modulus of both gears")
    poisson_ratio: float = param(0.3, ge=0, lt=0.5, doc="Poisson's ratio of both gears")
    thickness_allowance_pinion_um: float | None = param(
        None, ge=-2000, le=0, doc="E_sn1, normal tooth-thickness allowance (sets backlash_um)"
    )
    thickness_allowance_wheel_um: float | None = param(
        None, ge=-2000, le=0, doc="E_sn2, normal tooth-thickness allowance (sets backlash_um)"
    )
    centre_distance_deviation_um: float = param(
        0.0, ge=-2000, le=2000, doc="actual minus nominal centre distance (with the allowances)"
    )
    table_points: int = param(
        81, ge=11, le=2001, doc="potential-energy: points of the pair stiffness table over its contact"
    )

    @property
    def sets_backlash(self) -> bool:
        """True when tooth-thickness allowances are given (the mesh's backlash_um follows from them)."""
        return self.thickness_allowance_pinion_um is not None or self.thickness_allowance_wheel_um is not None


MESH_DEFAULTS = {
    "stiffness_single_N_per_m": 1.2e9,
    "stiffness_double_N_per_m": 1.3e9,
    "contact_ratio": 1.6,
    "pressure_angle_deg": 20.0,
    "pitch_point_phase": 0.5,
}


@dataclass(frozen=True, kw_only=True)
class Mesh:
    """Gear mesh: stiffness profile k_z(p), damping C_z, backlash l_u, friction geometry."""

    stiffness_profile: str = param(
        "contact-ratio", choices=STIFFNESS_PROFILES, doc="how k_z(p) is given (or computed from geometry)"
    )
    geometry: MeshGeometry | None = param(
        None, doc="gear-pair geometry; required by iso-6336-b and potential-energy"
    )
    stiffness_single_N_per_m: float | None = param(
        None, gt=0, doc="k_z with one tooth pair in contact (default 1.2e9; geometry: computed)"
    )
    stiffness_double_N_per_m: float | None = param(
        None, gt=0, doc="k_z with two tooth pairs in contact (default 1.3e9; geometry: computed)"
    )
    contact_ratio: float | None = param(
        None, ge=1, lt=2, doc="transverse contact ratio eps_alpha (default 1.6; geometry: computed)"
    )
    table_phase: tuple[float, ...] = param((), doc="mesh phases in [0, 1) of a k_z table")
    table_stiffness_N_per_m: tuple[float, ...] = param((), doc="k_z at table_phase")
    damping_Ns_per_m: float = param(0.0, ge=0, doc="mesh damping C_z")
    backlash_um: float | None = param(
        None, ge=0, doc="l_u: half-width of the dead zone of eq. (4) (default 0; geometry: from allowances)"
    )
    pressure_angle_deg: float | None = param(
        None, gt=0, lt=45, doc="operating pressure angle (default 20; geometry: working transverse angle)"
    )
    pitch_point_phase: float | None = param(
        None, ge=0, le=1, doc="mesh phase where friction reverses (default 0.5; geometry: computed)"
    )
    centre_line_deg: float = param(
        0.0, ge=-360, le=360, doc="direction from pinion to wheel centre (lateral models)"
    )
    line_of_action_deg: float = param(
        -90.0, ge=-360, le=360, doc="direction of the mesh force on the wheel (lateral models)"
    )
    transition_width: float = param(
        0.0,
        ge=0,
        le=0.1,
        doc="fraction of the mesh period over which each jump of the law (k_z switches, tooth change, "
        "friction reversal, pit edges) is spread; 0 = sharp",
    )

    def __post_init__(self) -> None:
        if self.stiffness_profile in FROM_GEOMETRY and self.geometry is None:
            raise ScenarioError(
                f"stiffness_profile = {self.stiffness_profile!r} computes k_z from the gears: add a "
                "[geometry] table (module_mm, face_width_mm, ...)"
            )
        if self.geometry is None:  # hand-given mesh: fill the documented defaults
            for key, value in MESH_DEFAULTS.items():
                if getattr(self, key) is None:
                    object.__setattr__(self, key, value)
        if self.backlash_um is None and (self.geometry is None or not self.geometry.sets_backlash):
            object.__setattr__(self, "backlash_um", 0.0)
        if self.contact_ratio is None:  # geometry not yet resolved (Scenario resolves it)
            return
        w = self.transition_width
        if w > 0:
            h = 0.5 * (self.contact_ratio - 1.0)
            if self.stiffness_profile != "table" and h > 0 and w > min(2 * h, 1 - 2 * h):
                raise ScenarioError(
                    f"transition_width = {w:g} with contact_ratio = {self.contact_ratio:g}: the width must "
                    f"not exceed the double or the single contact zone, <= {min(2 * h, 1 - 2 * h):g}"
                )
            if 0 < self.pitch_point_phase < 1 and not w / 2 <= self.pitch_point_phase <= 1 - w / 2:
                raise ScenarioError(
                    f"transition_width = {w:g} with pitch_point_phase = {self.pitch_point_phase:g}: the "
                    f"pitch point must lie in [{w / 2:g}, {1 - w / 2:g}] (or be 0 or 1)"
                )
        if abs(self.line_of_action_normal_projection) < 0.5:
            raise ScenarioError(
                f"line_of_action_deg = {self.line_of_action_deg:g} with centre_line_deg = "
                f"{self.centre_line_deg:g}: the line of action must lie within 60 deg of the normal "
                "of the centre line (for pressure angle alpha: centre_line_deg -+ (90 - alpha))"
            )
        if self.stiffness_profile == "table":
            ph, k = self.table_phase, self.table_stiffness_N_per_m
            if len(ph) < 2 or len(ph) != len(k):
                raise ScenarioError(
                    f"table_phase ({len(ph)} values) and table_stiffness_N_per_m ({len(k)} values) "
                    "must have the same length >= 2"
                )
            if any(not 0 <= p < 1 for p in ph) or any(b <= a for a, b in zip(ph, ph[1:], strict=False)):
                raise ScenarioError(f"table_phase = {list(ph)}: must increase strictly within [0, 1)")
            if any(v < 0 for v in k):
                raise ScenarioError(f"table_stiffness_N_per_m = {list(k)}: values must be >= 0")

    @property
    def line_of_action_normal_projection(self) -> float:
        """n . e_perp: n the line of action, e_perp the normal of the centre line."""
        lam, gam = math.radians(self.line_of_action_deg), math.radians(self.centre_line_deg)
        return math.cos(lam) * -math.sin(gam) + math.sin(lam) * math.cos(gam)


@dataclass(frozen=True, kw_only=True)
class Design:
    motor: Motor
    machine: Machine
    pinion: Gear | None = param(None, doc="pinion (single-stage scenes)")
    wheel: Gear | None = param(None, doc="wheel (single-stage scenes)")
    mesh: Mesh = param(default_factory=Mesh)
    coupling: Shaft | None = param(None, doc="motor-pinion coupling (one-stage)")
    output_shaft: Shaft | None = param(None, doc="wheel-machine shaft (one-stage)")
    stages: tuple[Stage, ...] = param((), doc="gear stages in power-flow order (scene 'train')")
    shafts: tuple[Shaft, ...] = param(
        (), doc="motor->stage 1, stage s->s+1, ..., last stage->machine ('train')"
    )


@dataclass(frozen=True, kw_only=True)
class ErrorMode:
    """Tooth error mode E(a, e, r) of the paper (Fig. 4, eq. 6)."""

    a: float = param(0.5, ge=0, le=1, doc="position of the maximum error in the mesh period")
    e_um: float = param(0.0, doc="maximum error e (negative allowed)")
    r: float = param(0.0, ge=0, le=1, doc="scope of the random per-tooth variation")


@dataclass(frozen=True, kw_only=True)
class Eccentricity:
    """Once-per-revolution error of one gear (eccentricity, run-out): A sin(phi + theta) along the line
    of action, phi the gear's angle."""

    gear: str = param(choices=("pinion", "wheel"))
    amplitude_um: float = param(ge=0, le=1000, doc="amplitude A along the line of action")
    phase_deg: float = param(0.0, ge=-360, le=360, doc="theta: phase at angle 0")


@dataclass(frozen=True, kw_only=True)
class Production:
    error_mode: ErrorMode = param(default_factory=ErrorMode)
    eccentricity: tuple[Eccentricity, ...] = param((), doc="once-per-revolution errors, one per gear at most")


@dataclass(frozen=True, kw_only=True)
class Profile:
    """Piecewise-linear fraction over time, held constant outside the given points."""

    time_s: tuple[float, ...] = param(doc="times, increasing")
    fraction: tuple[float, ...] = param(doc="fraction at those times, >= 0")

    def __post_init__(self) -> None:
        t, f = self.time_s, self.fraction
        if len(t) < 1 or len(t) != len(f):
            raise ScenarioError(
                f"time_s ({len(t)} values) and fraction ({len(f)} values) must have the same length >= 1"
            )
        if any(x < 0 for x in t) or any(b <= a for a, b in zip(t, t[1:], strict=False)):
            raise ScenarioError(f"time_s = {list(t)}: must be >= 0 and strictly increasing")
        if any(not (x >= 0 and math.isfinite(x)) for x in f):
            raise ScenarioError(f"fraction = {list(f)}: values must be finite and >= 0")


@dataclass(frozen=True, kw_only=True)
class Operation:
    t_end_s: float = param(gt=0, doc="simulated time")
    initial_state: str = param("rest", choices=("rest", "steady"), doc="start from rest or steady running")
    speed_profile: Profile = param(
        default_factory=lambda: Profile(time_s=(0.0,), fraction=(1.0,)),
        doc="fraction of the synchronous speed over time",
    )
    load_profile: Profile = param(
        default_factory=lambda: Profile(time_s=(0.0,), fraction=(1.0,)),
        doc="fraction of the rated load torque over time",
    )


@dataclass(frozen=True, kw_only=True)
class DamagedTooth:
    """A damaged tooth: a bare stiffness factor (the paper's Figs. 13-16) and/or, with the
    potential-energy stiffness, a root crack, a broken-off tip or a spall that give that tooth's pair its
    own stiffness profile over its contact (docs/scenario.md, "Tooth damage from geometry")."""

    gear: str = param(choices=("pinion", "wheel"))
    tooth: int = param(ge=0, doc="tooth index, 0-based")
    stiffness_factor: float = param(1.0, ge=0, le=1, doc="factor on k_z while this tooth meshes")
    crack_depth_mm: float = param(0.0, ge=0, le=100, doc="root crack depth q (potential-energy)")
    crack_angle_deg: float = param(45.0, gt=0, le=90, doc="crack angle to the tooth centre line")
    broken_height_fraction: float = param(
        0.0, ge=0, le=1, doc="part of the tooth height missing from the tip (potential-energy)"
    )
    broken_width_fraction: float = param(1.0, ge=0, le=1, doc="part of the face width it is missing over")
    spall_start_diameter_mm: float = param(0.0, ge=0, doc="spall from this diameter of the flank")
    spall_end_diameter_mm: float = param(0.0, ge=0, doc="spall up to this diameter")
    spall_width_fraction: float = param(0.0, ge=0, le=1, doc="part of the contact width lost in the spall")

    def __post_init__(self) -> None:
        if self.spall_width_fraction > 0 and not self.spall_end_diameter_mm > self.spall_start_diameter_mm:
            raise ScenarioError(
                f"spall_end_diameter_mm = {self.spall_end_diameter_mm:g}: must be > spall_start_diameter_mm "
                f"= {self.spall_start_diameter_mm:g} when spall_width_fraction > 0"
            )

    @property
    def has_geometric_damage(self) -> bool:
        """True when a crack, breakage or spall is given (needs the potential-energy stiffness)."""
        return self.crack_depth_mm > 0 or self.broken_height_fraction > 0 or self.spall_width_fraction > 0


@dataclass(frozen=True, kw_only=True)
class PittedTooth:
    """A pit (spall) on one tooth's flank: the pair deflects depth_um less while that tooth is in mesh
    between two mesh phases (material missing)."""

    gear: str = param(choices=("pinion", "wheel"))
    tooth: int = param(ge=0, doc="tooth index, 0-based")
    depth_um: float = param(ge=0, le=1000, doc="depth of the missing material along the line of action")
    start_phase: float = param(ge=0, lt=1, doc="mesh phase where the pit starts")
    end_phase: float = param(gt=0, le=1, doc="mesh phase where the pit ends (> start_phase)")


@dataclass(frozen=True, kw_only=True)
class Condition:
    friction_coefficient: float = param(0.0, ge=0, lt=1, doc="inter-tooth friction mu")
    damaged_teeth: tuple[DamagedTooth, ...] = param((), doc="per-tooth stiffness factors")
    pitted_teeth: tuple[PittedTooth, ...] = param((), doc="local pitting errors (one per tooth)")


@dataclass(frozen=True, kw_only=True)
class Stage:
    """One parallel-axis gear stage of a train: its gears, mesh, error mode and damaged teeth."""

    pinion: Gear
    wheel: Gear
    mesh: Mesh = param(default_factory=Mesh)
    error_mode: ErrorMode = param(default_factory=ErrorMode)
    damaged_teeth: tuple[DamagedTooth, ...] = param((), doc="per-tooth stiffness factors of this stage")
    eccentricity: tuple[Eccentricity, ...] = param((), doc="once-per-revolution errors of this stage")
    pitted_teeth: tuple[PittedTooth, ...] = param((), doc="local pitting errors of this stage")

    @property
    def ratio(self) -> float:
        """z2 / z1."""
        return self.wheel.teeth / self.pinion.teeth


SOLVER_METHODS = ("DOPRI5", "ODE23", "RK44", "RK67", "DVERK6")


@dataclass(frozen=True, kw_only=True)
class Solver:
    method: str = param("DOPRI5", choices=SOLVER_METHODS, doc="Exudyn explicit integrator")
    # The mesh force depends on r1 phi_p - r2 phi_w, a small difference of angles that grow past
    # 100 rad per simulated second. Exudyn scales each coordinate's error by atol + rtol * max(q0, q1)
    # (signed), so a relative tolerance loosens as the angles grow: rtol is kept negligible and the
    # absolute tolerance (SI units: rad, rad/s, m, m/s) sets the accuracy. atol 1e-8 meets the 0.5 %
    # validation tolerance on every case with a 10x margin (1e-7 fails the impacts of the Muller and
    # two-stage separation cases); docs/design-notes.md, "Solver tolerances".
    relative_tolerance: float = param(1e-14, gt=0, lt=1, doc="adaptive step relative tolerance")
    absolute_tolerance: float = param(1e-8, gt=0, doc="adaptive step absolute tolerance")
    max_step_s: float = param(1e-4, gt=0, doc="largest step")
    output_rate_hz: float = param(20000.0, gt=0, doc="results are sampled at k / output_rate_hz")
    # The mesh force jumps when the pair count changes; point samples of it alias (its 1/k harmonics
    # fold into the band of interest). docs/scenario.md, "Signals": which signals are band-limited.
    anti_aliasing: bool = param(
        True, doc="band-limit force and acceleration signals before sampling (measurement-chain filter)"
    )


@dataclass(frozen=True, kw_only=True)
class Visual:
    """How pictures of the machine look (gearbody render); no effect on the simulation."""

    housing: bool = param(False, doc="draw a transparent gear housing")
    lateral_scale: float = param(
        1000.0, ge=0, le=1e6, doc="magnification of the gears' lateral motion in pictures (0: none)"
    )


@dataclass(frozen=True, kw_only=True)
class Scenario:
    meta: Meta
    design: Design
    production: Production = param(default_factory=Production)
    operation: Operation
    condition: Condition = param(default_factory=Condition)
    solver: Solver = param(default_factory=Solver)
    visual: Visual = param(default_factory=Visual)

    def __post_init__(self) -> None:
        self._check_topology()
        self._resolve_geometry()
        for k, stage in enumerate(self.stages):
            where = f"design.stages[{k}]." if self.meta.scene == "train" else "design."
            pb1 = 2 * math.pi * stage.pinion.base_radius_m / stage.pinion.teeth
            pb2 = 2 * math.pi * stage.wheel.base_radius_m / stage.wheel.teeth
            if abs(pb2 / pb1 - 1) > 0.005:
                raise ScenarioError(
                    f"{where}wheel.base_radius_m = {stage.wheel.base_radius_m}: base pitch 2 pi r_b / z = "
                    f"{pb2 * 1e3:.4f} mm differs from the pinion's {pb1 * 1e3:.4f} mm by more than 0.5 %; "
                    f"meshing gears need equal base pitches (r_b2 = r_b1 z2 / z1 = "
                    f"{stage.pinion.base_radius_m * stage.wheel.teeth / stage.pinion.teeth:.6g} m)"
                )
            train = self.meta.scene == "train"
            per_tooth = (("damaged_teeth", stage.damaged_teeth), ("pitted_teeth", stage.pitted_teeth))
            for key, entries in per_tooth:
                where_t = f"design.stages[{k}]." if train else "condition."
                for t in entries:
                    z = getattr(stage, t.gear).teeth
                    if t.tooth >= z:
                        raise ScenarioError(
                            f"{where_t}{key}: tooth = {t.tooth} on the {t.gear}: must be < its {z} teeth"
                        )
                teeth = [(t.gear, t.tooth) for t in entries]
                if key == "pitted_teeth" and len(set(teeth)) < len(teeth):
                    raise ScenarioError(f"{where_t}pitted_teeth: one pit per tooth, got {teeth}")
            where_p = f"design.stages[{k}]." if train else "condition."
            for t in stage.pitted_teeth:
                if not t.end_phase > t.start_phase:
                    raise ScenarioError(
                        f"{where_p}pitted_teeth: end_phase = {t.end_phase} must be > start_phase = "
                        f"{t.start_phase} (a pit spans [start_phase, end_phase) of the mesh period)"
                    )
                w = stage.mesh.transition_width
                if t.end_phase - t.start_phase < w:
                    raise ScenarioError(
                        f"{where_p}pitted_teeth: the pit on {t.gear} tooth {t.tooth} spans "
                        f"{t.end_phase - t.start_phase:g} of the mesh period, less than the mesh's "
                        f"transition_width = {w:g}; narrow the width or widen the pit"
                    )
            gears = [e.gear for e in stage.eccentricity]
            if len(set(gears)) < len(gears):
                where_e = f"design.stages[{k}]." if train else "production."
                raise ScenarioError(f"{where_e}eccentricity: at most one entry per gear, got {gears}")
        if self.meta.scene == "train":
            # A stage's pinion turns with the previous stage's wheel, so the direction of its line of
            # action is fixed by the chain; on bearings (lateral) a contradicting direction would put
            # the mesh and friction forces on the wrong side of the gears.
            sense = 1 if self.stages[0].mesh.line_of_action_normal_projection > 0 else -1
            for k, st in enumerate(self.stages):
                own = 1 if st.mesh.line_of_action_normal_projection > 0 else -1
                lateral = st.pinion.lateral != "none" or st.wheel.lateral != "none"
                if k > 0 and lateral and own != sense:
                    turn = "counter-clockwise" if sense > 0 else "clockwise"
                    raise ScenarioError(
                        f"design.stages[{k}].mesh.line_of_action_deg = {st.mesh.line_of_action_deg:g}: this "
                        f"stage's pinion turns {turn} (with the previous wheel), so its line of action must "
                        f"point the other way: centre_line_deg {'+' if sense > 0 else '-'} (90 - pressure "
                        f"angle), e.g. {st.mesh.centre_line_deg + sense * 90:g} for a pure normal"
                    )
                sense = -sense
        if self.meta.scene in ("muller", "two-wheel"):
            for name in ("pinion", "wheel"):
                if getattr(self.design, name).lateral != "none":
                    raise ScenarioError(
                        f"design.{name}.lateral = {getattr(self.design, name).lateral!r}: scene "
                        f"{self.meta.scene!r} has no lateral motion; use 'one-stage' or 'train'"
                    )
        if self.solver.output_rate_hz * self.operation.t_end_s < 2:
            raise ScenarioError(
                f"solver.output_rate_hz = {self.solver.output_rate_hz}: gives fewer than 2 "
                f"samples over t_end_s = {self.operation.t_end_s}"
            )

    def _check_topology(self) -> None:
        d = self.design
        if self.meta.scene == "train":
            if (
                d.pinion is not None
                or d.wheel is not None
                or d.coupling is not None
                or d.output_shaft is not None
            ):
                raise ScenarioError(
                    "a 'train' describes its gears in [[design.stages]] and its shafts in "
                    "[[design.shafts]]; remove design.pinion/wheel/coupling/output_shaft"
                )
            if not d.stages:
                raise ScenarioError("design.stages: a 'train' needs at least one [[design.stages]] entry")
            if len(d.shafts) != len(d.stages) + 1:
                raise ScenarioError(
                    f"design.shafts has {len(d.shafts)} entries: a train of {len(d.stages)} "
                    f"stage(s) needs {len(d.stages) + 1} (motor->stage 1, ..., last stage->machine)"
                )
        else:
            if d.stages or d.shafts:
                raise ScenarioError(
                    f"design.stages / design.shafts belong to scene 'train', not {self.meta.scene!r}"
                )
            for name in ("pinion", "wheel"):
                if getattr(d, name) is None:
                    raise ScenarioError(f"design.{name} is required for scene {self.meta.scene!r}")
            if self.meta.scene == "one-stage":
                for name in ("coupling", "output_shaft"):
                    if getattr(d, name) is None:
                        raise ScenarioError(f"design.{name} is required for scene 'one-stage'")

    def _resolve_geometry(self) -> None:
        """Fill in what each mesh's [geometry] table fixes (gearbody.model.resolve)."""
        from .resolve import resolve_iso_stiffness, resolve_stage_geometry

        d, train = self.design, self.meta.scene == "train"
        if train:
            stages = []
            for k, st in enumerate(d.stages):
                p, w, m = resolve_stage_geometry(st.pinion, st.wheel, st.mesh, f"design.stages[{k}].mesh.")
                stages.append(dataclasses.replace(st, pinion=p, wheel=w, mesh=m))
            object.__setattr__(self, "design", dataclasses.replace(d, stages=tuple(stages)))
        else:
            p, w, m = resolve_stage_geometry(d.pinion, d.wheel, d.mesh, "design.mesh.")
            object.__setattr__(self, "design", dataclasses.replace(d, pinion=p, wheel=w, mesh=m))
        d = self.design
        for k, st in enumerate(self.stages):
            where = f"design.stages[{k}].mesh." if train else "design.mesh."
            if st.mesh.stiffness_profile == "iso-6336-b":
                mesh = resolve_iso_stiffness(
                    st.mesh, st.pinion.teeth, st.wheel.teeth, self.stage_rated_force_N(k), where
                )
                if train:
                    stages = list(d.stages)
                    stages[k] = dataclasses.replace(st, mesh=mesh)
                    d = dataclasses.replace(d, stages=tuple(stages))
                else:
                    d = dataclasses.replace(d, mesh=mesh)
                object.__setattr__(self, "design", d)
            where_t = f"design.stages[{k}]." if train else "condition."
            for tooth in st.damaged_teeth:
                if tooth.has_geometric_damage and st.mesh.stiffness_profile != "potential-energy":
                    raise ScenarioError(
                        f"{where_t}damaged_teeth: {tooth.gear} tooth {tooth.tooth} has a crack, breakage or "
                        f"spall; these need {where}stiffness_profile = 'potential-energy' (got "
                        f"{st.mesh.stiffness_profile!r})"
                    )
            if st.mesh.stiffness_profile == "potential-energy" and any(
                t.has_geometric_damage for t in st.damaged_teeth
            ):
                from ..physics.mesh_stiffness import stage_pair_table

                try:
                    stage_pair_table(st)
                except ValueError as exc:
                    raise ScenarioError(f"{where_t}damaged_teeth: {exc}") from None

    # -- derived quantities used everywhere ------------------------------------------------
    @property
    def stages(self) -> tuple[Stage, ...]:
        """The gear stages in power-flow order; a single-stage scene is one stage built from
        design.pinion/wheel/mesh, production.error_mode and condition.damaged_teeth."""
        d = self.design
        if self.meta.scene == "train":
            return d.stages
        return (
            Stage(
                pinion=d.pinion,
                wheel=d.wheel,
                mesh=d.mesh,
                error_mode=self.production.error_mode,
                damaged_teeth=self.condition.damaged_teeth,
                eccentricity=self.production.eccentricity,
                pitted_teeth=self.condition.pitted_teeth,
            ),
        )

    @property
    def is_lateral(self) -> bool:
        """True when any gear moves laterally on its bearing."""
        return any(g.lateral != "none" for st in self.stages for g in (st.pinion, st.wheel))

    @property
    def gear_ratio(self) -> float:
        """Overall ratio, product of z2/z1 over the stages."""
        return math.prod(s.ratio for s in self.stages)

    def stage_rated_force_N(self, stage: int) -> float:
        """F_rated,s: the rated machine torque passed upstream through the base radii,
        F_N = M_rated / r_w,N and F_s = F_s+1 r_p,s+1 / r_w,s (static equilibrium, no friction)."""
        force = self.design.machine.rated_torque_Nm / self.stages[-1].wheel.base_radius_m
        for k in range(len(self.stages) - 1, stage, -1):
            force *= self.stages[k].pinion.base_radius_m / self.stages[k - 1].wheel.base_radius_m
        return force

    @property
    def rated_mesh_force_N(self) -> float:
        """F_rated of the first stage (the only one in single-stage scenes)."""
        return self.stage_rated_force_N(0)
