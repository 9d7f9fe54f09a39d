"""Where every part of a drive sits in 3D, derived from the scenario alone (no Exudyn): the drive's frame
(stage planes, axes, walls, turning senses), the motor, the driven machine and the housing here; each
stage's own bodies from its kind's ``render_parts`` (:mod:`gearbody.render.parallel`,
:mod:`gearbody.render.planetary`), so that each size rule is stated once, where it is used.

Gear axes are parallel to z. Stage s's wheel axis lies one centre distance a_s = r_1 + r_2 (pitch
radii r = r_b / cos(alpha), standard gears without profile shift) from its pinion axis, in the
direction ``mesh.centre_line_deg`` of that stage, so a train of any length lays itself out. Stages
follow each other along +z; the motor stands on the -z side of the input axis and the driven machine
on the +z side of the output axis; bearings sit in the housing walls at both ends of every axis.

Moving parts are grouped into :class:`Body` objects: one per rotating inertia of the model (motor
rotor, each gear with its shaft, machine rotor). A body's parts are given in its own frame (origin on
its axis at z = 0, rotating about +z); ground parts in the world frame. Sizes that the scenario does
not give (shaft diameters, motor frame, housing) follow simple engineering rules stated where they
are computed. Everything here is plain numbers so that the layout is testable without a renderer.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..errors import RenderError
from ..model import Scenario
from ..model.kinds import stage_kind
from .drive import SHAFT_SHEAR_STRESS_PA, Bearings, Drive, hub, shaft_radius_m  # noqa: F401  (re-exported)
from .parallel import module_m, tooth_angle_rad  # noqa: F401  (re-exported; registers the parallel parts)
from .planetary import PlanetaryParts  # noqa: F401  (registers the planetary kind's render parts)
from .shapes import (  # noqa: F401  (the parts are re-exported: render code and tests import them here)
    BASE,
    BEARING,
    COUPLING,
    DAMAGED,
    HOUSING,
    MACHINE,
    MARKER,
    MOTOR,
    PITTED,
    SHAFT,
    STEEL,
    WHEEL,
    Body,
    Box,
    Cylinder,
    GearShape,
    Orbit,
    Prism,
)

MESH_WINDOW_MODULES = 6.0
"""Half-size of the ``frame="mesh"`` camera box in modules: the teeth in contact and 2-3 pairs each side."""


@dataclass
class Layout:
    """A drive laid out in 3D from its scenario (:func:`build_layout`): the bodies with their parts,
    the ground, the housing, and which signal turns the input shaft."""

    bodies: list[Body] = field(default_factory=list)
    ground: list = field(default_factory=list)
    machines: list = field(default_factory=list)  # motor and driven-machine frames (ground)
    housing: Box | None = None
    show_housing: bool = False
    lateral_scale: float = 1000.0
    input_signal: str = "pinion_angle_rad"  # the input shaft's rotation (frame window, kinematic motion)
    input_factor: int = 1  # that signal per unit input-shaft rotation in its driven direction
    mesh_pair: tuple[str, str] | None = None  # bodies of the first mesh (None: the first two gears)

    def body(self, name: str) -> Body:
        for b in self.bodies:
            if b.name == name:
                return b
        raise KeyError(f"no body {name!r}; bodies: {', '.join(b.name for b in self.bodies)}")

    @property
    def gears(self) -> list[tuple[Body, GearShape]]:
        return [(b, p) for b in self.bodies for p in b.parts if isinstance(p, GearShape)]

    def mesh_bounds_m(
        self, modules: float = MESH_WINDOW_MODULES, pose=None
    ) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """Box around the first stage's mesh: ``modules`` modules each side of the pitch point in the
        gears' plane (the teeth in contact and their neighbours), the face width along the axes. For a
        planetary first stage the sun-planet 1 mesh, where the pose row ``pose`` puts it (default: the
        nominal assembly)."""
        if self.mesh_pair is None:
            (pinion, gp), (wheel, gw) = self.gears[:2]
        else:
            gears = dict((b.name, (b, p)) for b, p in self.gears)
            (pinion, gp), (wheel, gw) = (gears[n] for n in self.mesh_pair)
        (px, py), (wx, wy) = pinion.axis_xy_m, wheel.axis_xy_m
        if pose is not None and self.mesh_pair is not None:
            names = [b.name for b in self.bodies]
            i, j = (3 * names.index(n) for n in self.mesh_pair)
            px, py, wx, wy = px + pose[i], py + pose[i + 1], wx + pose[j], wy + pose[j + 1]
        share = gp.teeth / (gp.teeth + gw.teeth)  # the operating pitch point divides the centre distance
        cx, cy = px + share * (wx - px), py + share * (wy - py)
        h = modules * max(gp.module_m, gw.module_m)
        z0 = min(gp.z_m - gp.face_width_m / 2, gw.z_m - gw.face_width_m / 2)
        z1 = max(gp.z_m + gp.face_width_m / 2, gw.z_m + gw.face_width_m / 2)
        return (cx - h, cy - h, z0), (cx + h, cy + h, z1)

    def bounds_m(
        self, gears_only: bool = False
    ) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """Axis-aligned box around everything drawn, or around the gears only (for the camera)."""
        lo, hi = [math.inf] * 3, [-math.inf] * 3

        def grow(x0, x1, y0, y1, z0, z1):
            for k, (a, b) in enumerate(((x0, x1), (y0, y1), (z0, z1))):
                lo[k], hi[k] = min(lo[k], a, b), max(hi[k], a, b)

        for b in self.bodies:
            bx, by = b.axis_xy_m
            for p in b.parts:
                if isinstance(p, GearShape):
                    r = p.outer_radius_m
                    grow(
                        bx - r, bx + r, by - r, by + r, p.z_m - p.face_width_m / 2, p.z_m + p.face_width_m / 2
                    )
                elif isinstance(p, Cylinder) and not gears_only:
                    r = p.radius_m
                    grow(bx - r, bx + r, by - r, by + r, p.z0_m, p.z1_m)
                elif isinstance(p, Prism) and not gears_only:
                    r = max(math.hypot(x, y) for x, y in p.outline_m)
                    grow(bx - r, bx + r, by - r, by + r, p.z0_m, p.z1_m)
        if gears_only:
            return (tuple(lo), tuple(hi))
        for p in [*self.ground, *self.machines, *([self.housing] if self.housing else [])]:
            if isinstance(p, Box):
                c, s = p.centre_m, p.size_m
                grow(
                    c[0] - s[0] / 2,
                    c[0] + s[0] / 2,
                    c[1] - s[1] / 2,
                    c[1] + s[1] / 2,
                    c[2] - s[2] / 2,
                    c[2] + s[2] / 2,
                )
            elif isinstance(p, Cylinder):
                grow(
                    p.x_m - p.radius_m,
                    p.x_m + p.radius_m,
                    p.y_m - p.radius_m,
                    p.y_m + p.radius_m,
                    p.z0_m,
                    p.z1_m,
                )
        return (tuple(lo), tuple(hi))


def build_layout(scenario: Scenario) -> Layout:
    """The 3D layout of a scenario's drive (see the module docstring)."""
    parts = _render_parts(scenario)
    drive = _drive(scenario, parts)
    d = scenario.design
    layout = Layout(lateral_scale=scenario.visual.lateral_scale)
    if parts[0].mesh_pair is not None:
        layout.mesh_pair = parts[0].mesh_pair
    power_kW = d.machine.rated_torque_Nm / scenario.gear_ratio * d.motor.synchronous_speed_rad_s / 1e3
    frame_d = 0.13 * max(power_kW, 0.5) ** (1 / 3)  # IEC frame diameter ~ P^(1/3): 75 kW -> 0.55 m

    # motor rotor: shaft stub and coupling half
    z_motor = drive.z_cpl_in - drive.hub_len - 0.4 * drive.gap
    motor_len = 1.8 * frame_d
    first = drive.ends[0]
    layout.bodies.append(
        Body(
            "motor",
            drive.axes[0],
            drive.senses[0],
            "motor_angle_rad",
            (
                Cylinder(z_motor, drive.z_cpl_in - drive.hub_len, drive.r_in, SHAFT),
                *hub(drive.z_cpl_in - drive.hub_len, drive.z_cpl_in - 0.002, drive.r_in),
            ),
            follows=first[0],
            ratio=float(first[1]),
        )
    )
    layout.input_signal, layout.input_factor = f"{first[0]}_angle_rad", first[1]

    # each stage's bodies (gears with their shafts); bearings in both housing walls, once per axis
    for part in parts:
        layout.bodies.extend(part.bodies(drive))
    layout.ground.extend(drive.bearings.parts(drive.axes, (drive.z_front, drive.z_back), drive.wall))

    # driven machine: coupling half and shaft stub
    r_out = min(shaft_radius_m(drive.torques[-1]), parts[-1].shaft_cap_m(1))
    z_cpl_out = drive.output_coupling_z_m(r_out)
    mach_d = 1.1 * frame_d
    z_mach = z_cpl_out + 1.6 * r_out + 0.4 * drive.gap
    last = drive.ends[-1]
    layout.bodies.append(
        Body(
            "machine",
            drive.axes[-1],
            drive.senses[-1],
            "machine_angle_rad",
            (
                *hub(z_cpl_out + 0.002, z_cpl_out + 1.6 * r_out, r_out),
                Cylinder(z_cpl_out + 1.6 * r_out, z_mach, r_out, SHAFT),
            ),
            follows=last[2],
            ratio=float(last[3]),
        )
    )
    _frames(layout, scenario, drive, (z_motor, motor_len, frame_d), (z_mach, mach_d))
    return layout


def _render_parts(scenario: Scenario) -> list:
    """Each stage's render parts, from its kind; a kind without them is refused in one line."""
    parts = []
    for k, st in enumerate(scenario.stages):
        kind = stage_kind(st)
        if kind.render_parts is None:
            raise RenderError(
                f"stage {k + 1} (type {kind.name!r}) has no 3D parts: its kind registers no render_parts, "
                "so gearbody render cannot draw this drive"
            )
        parts.append(kind.render_parts(scenario, k))
    return parts


def _drive(scenario: Scenario, parts: list) -> Drive:
    """The drive's frame: stage planes along +z, walls, axes, senses, rated torques, input coupling."""
    stages = scenario.stages
    faces = [p.face_m for p in parts]  # each stage's axial room
    gap = 0.5 * max(faces)
    z_stage = [0.0]  # axial position of each stage's mid-plane
    for k in range(1, len(stages)):
        z_stage.append(z_stage[-1] + 0.5 * (faces[k - 1] + faces[k]) + gap)
    wall = 0.06 * max(faces) + 0.02
    z_front = z_stage[0] - faces[0] / 2 - gap - wall / 2
    z_back = z_stage[-1] + faces[-1] / 2 + gap + wall / 2

    # rated torque on each axis: the machine torque passed upstream through the ratios
    torques = [scenario.design.machine.rated_torque_Nm]
    for st in reversed(stages):
        torques.insert(0, torques[0] / st.ratio)
    axes = [(0.0, 0.0)]  # axis positions: each stage places its output axis from its input axis
    for p in parts:
        axes.append(p.output_axis(axes[-1]))
    senses, mirrors = _axis_senses(parts)
    r_in = min(shaft_radius_m(torques[0]), parts[0].shaft_cap_m(0))
    hub_len = 1.6 * r_in
    return Drive(
        stages=stages,
        z_stage=z_stage,
        z_front=z_front,
        z_back=z_back,
        wall=wall,
        gap=gap,
        axes=axes,
        senses=senses,
        mirrors=mirrors,
        torques=torques,
        # the bodies on each stage's input and output shaft, and their model angle per unit chain angle
        ends=[p.ends for p in parts],
        r_in=r_in,
        z_cpl_in=z_front - wall / 2 - 0.5 * gap - hub_len,
        hub_len=hub_len,
        bearings=Bearings(list(range(len(axes)))),
    )


def _frames(layout: Layout, scenario: Scenario, drive: Drive, motor: tuple, machine: tuple) -> None:
    """The housing, the motor and machine frames and the gearbox feet, standing on a base plate."""
    (z_motor, motor_len, frame_d), (z_mach, mach_d) = motor, machine
    z_front, z_back, wall, axes = drive.z_front, drive.z_back, drive.wall, drive.axes
    rmax = max(p.outer_radius_m for _, p in layout.gears)
    margin = 0.1 * rmax + 0.03
    xs, ys = [x for x, _ in axes], [y for _, y in axes]
    hx0, hx1 = min(xs) - rmax - margin, max(xs) + rmax + margin
    hy0, hy1 = min(ys) - rmax - margin, max(ys) + rmax + margin
    housing = Box(
        ((hx0 + hx1) / 2, (hy0 + hy1) / 2, (z_front + z_back) / 2),
        (hx1 - hx0, hy1 - hy0, z_back - z_front + wall),
        HOUSING,
    )
    layout.housing, layout.show_housing = housing, scenario.visual.housing
    (x0, y0), (xo, yo) = axes[0], axes[-1]
    floor = min(hy0, y0 - frame_d / 2, yo - mach_d / 2) - 0.02
    layout.machines += [
        Cylinder(z_motor - motor_len, z_motor, frame_d / 2, MOTOR, x_m=x0, y_m=y0),
        Box(
            (x0, 0.5 * (floor + y0), z_motor - motor_len / 2),
            (0.75 * frame_d, y0 - floor, 0.8 * motor_len),
            MOTOR,
        ),
        Box((xo, yo, z_mach + 0.6 * mach_d), (mach_d, mach_d, 1.2 * mach_d), MACHINE),
        Box(
            (xo, 0.5 * (floor + yo), z_mach + 0.6 * mach_d), (0.8 * mach_d, yo - floor, 1.1 * mach_d), MACHINE
        ),
    ]
    # gearbox feet under the housing
    layout.ground.append(
        Box(
            ((hx0 + hx1) / 2, 0.5 * (floor + hy0), (z_front + z_back) / 2),
            (0.999 * (hx1 - hx0), max(hy0 - floor, 0.01) - 0.002, 0.999 * (z_back - z_front)),
            HOUSING[:3] + (1.0,),
        )
    )
    zlo, zhi = z_motor - motor_len - 0.1, z_mach + 1.2 * mach_d + 0.1
    xlo = min(hx0, x0 - frame_d / 2, xo - mach_d / 2) - 0.1
    xhi = max(hx1, x0 + frame_d / 2, xo + mach_d / 2) + 0.1
    layout.ground.append(
        Box(((xlo + xhi) / 2, floor - 0.02, (zlo + zhi) / 2), (xhi - xlo, 0.04, zhi - zlo), BASE)
    )


def _axis_senses(parts: list) -> tuple[list[int], list[int]]:
    """Drawn turning sense of every axis (positive: counter-clockwise seen from the machine side) and
    the mirror of every stage (-1: a stage drawn mirrored, 1 otherwise).

    When no stage fixes the sense of its input (parallel stages: torsional ones are sense-free), the
    input shaft turns as stage 1 says (its line of action: the lateral models' convention). Otherwise
    the first stage that fixes it (a planetary stage: its modelled sense s_in) sets it, the axes before
    it turning back to the motor; every stage turns its output from its input (a later planetary stage
    whose input turns the other way is drawn mirrored)."""
    first = next((k for k, p in enumerate(parts) if p.fixes_sense), None)
    if first is None:
        sense = parts[0].input_sense
    else:
        chain = 1  # the sense at the first fixing stage's input per unit sense of the input shaft
        for p in parts[:first]:
            chain = p.turn(chain)[1]
        sense = parts[first].input_sense * chain
    senses, mirrors = [sense], []
    for p in parts:
        mirror, sense = p.turn(senses[-1])
        mirrors.append(mirror)
        senses.append(sense)
    return senses, mirrors
