"""Where every part of a drive sits in 3D, derived from the scenario alone (no Exudyn). One concern, the
placing rules, kept in one module (~400 lines) so that each size rule is stated once, where it is used.

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

from ..model import Scenario
from ..model.planetary import PlanetaryStage
from ..physics.lateral import mesh_directions
from ..signals import gear_names, stage_prefix
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

#: allowable torsional shear stress for the drawn shaft diameters, d = (16 T / (pi tau))^(1/3)
SHAFT_SHEAR_STRESS_PA = 30e6


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


def module_m(base_radius_m: float, teeth: int, pressure_angle_deg: float) -> float:
    """m = 2 r_b / (z cos alpha)."""
    return 2 * base_radius_m / (teeth * math.cos(math.radians(pressure_angle_deg)))


def shaft_radius_m(torque_Nm: float) -> float:
    """Solid shaft sized for the torque: d = (16 T / (pi tau))^(1/3), tau = 30 MPa."""
    return 0.5 * (16 * abs(torque_Nm) / (math.pi * SHAFT_SHEAR_STRESS_PA)) ** (1 / 3)


def tooth_angle_rad(gear: str, tooth: int, teeth: int, sense: int, centre_line_rad: float) -> float:
    """Body-frame angle of the centre of model tooth ``tooth`` (docs/render.md, "Teeth").

    The model meshes pinion tooth i = floor(phi_p z1 / 2 pi) mod z1 with wheel tooth j = the same
    pair count mod z2. The pinion tooth i is centred on the centre line in the middle of its mesh
    period; the wheel tooth j sits half a pitch ahead of it in the direction of motion, so the drawn
    teeth interleave.
    """
    pitch = 2 * math.pi / teeth
    if gear == "pinion":
        return centre_line_rad - sense * (tooth + 0.5) * pitch
    return centre_line_rad + math.pi - sense * tooth * pitch


def build_layout(scenario: Scenario) -> Layout:
    """The 3D layout of a scenario's drive (see the module docstring)."""
    from .planetary import attach_z_m, side_depth_m, stage_bodies

    stages = scenario.stages
    d = scenario.design
    planetary = [isinstance(st, PlanetaryStage) for st in stages]
    mods = [
        st.module_mm * 1e-3
        if planetary[k]
        else module_m(st.pinion.base_radius_m, st.pinion.teeth, st.mesh.pressure_angle_deg)
        for k, st in enumerate(stages)
    ]
    widths = [
        (10 * m, 10 * m)
        if planetary[k]
        else (st.pinion.face_width_m or 10 * m, st.wheel.face_width_m or 10 * m)
        for k, (st, m) in enumerate(zip(stages, mods, strict=True))
    ]
    # a planetary stage's axial room includes its carrier plate (and a turning ring's drum)
    faces = [
        2 * side_depth_m(st, widths[k][0]) if planetary[k] else max(widths[k]) for k, st in enumerate(stages)
    ]
    gap = 0.5 * max(faces)
    z_stage = [0.0]  # axial position of each stage's mid-plane
    for k in range(1, len(stages)):
        z_stage.append(z_stage[-1] + 0.5 * (faces[k - 1] + faces[k]) + gap)
    wall = 0.06 * max(faces) + 0.02
    z_front = z_stage[0] - faces[0] / 2 - gap - wall / 2
    z_back = z_stage[-1] + faces[-1] / 2 + gap + wall / 2

    # rated torque on each axis: the machine torque passed upstream through the ratios
    torques = [d.machine.rated_torque_Nm]
    for st in reversed(stages):
        torques.insert(0, torques[0] / st.ratio)
    axes = [(0.0, 0.0)]  # axis positions: one centre distance per stage along its centre line
    for k, st in enumerate(stages):
        if planetary[k]:  # coaxial: the output shaft continues the input's axis
            axes.append(axes[-1])
            continue
        gam = math.radians(st.mesh.centre_line_deg)
        a = (st.pinion.base_radius_m + st.wheel.base_radius_m) / math.cos(
            math.radians(st.mesh.pressure_angle_deg)
        )
        axes.append((axes[-1][0] + a * math.cos(gam), axes[-1][1] + a * math.sin(gam)))
    senses, mirrors = _axis_senses(stages)
    names = [gear_names(k) for k in range(len(stages))]
    # the bodies on each stage's input and output shaft, and their model angle per unit chain angle
    # (a planetary member's angle is absolute, counter-clockwise: s_in or s_out times the chain's)
    ends = []
    for k, st in enumerate(stages):
        if planetary[k]:
            p = stage_prefix(k)
            ends.append((p + st.input, st.input_sense, p + st.output, st.output_sense))
        else:
            ends.append((names[k][0], 1, names[k][1], 1))

    def root_radius(gear, m):
        return 0.5 * m * gear.teeth - 1.25 * m

    def shaft_cap(k: int, end: int) -> float:
        """Largest drawn radius of stage k's input (end 0) or output (end 1) shaft: 0.8 of its gear's
        root radius (a planetary stage's sun; its ring or carrier: none)."""
        st = stages[k]
        if planetary[k]:
            member = (st.input, st.output)[end]
            return 0.8 * (0.5 * mods[k] * st.sun.teeth - 1.25 * mods[k]) if member == "sun" else math.inf
        return 0.8 * root_radius((st.pinion, st.wheel)[end], mods[k])

    def hub(z0, z1, r):
        """Coupling half with a marker stripe that shows its rotation."""
        return (
            Cylinder(z0, z1, 1.9 * r, COUPLING),
            Box((1.75 * r, 0.0, 0.5 * (z0 + z1)), (0.4 * r, 0.5 * r, 1.02 * abs(z1 - z0)), MARKER),
        )

    layout = Layout(lateral_scale=scenario.visual.lateral_scale)
    if planetary[0]:
        layout.mesh_pair = ("sun", "planet_1")
    power_kW = d.machine.rated_torque_Nm / scenario.gear_ratio * d.motor.synchronous_speed_rad_s / 1e3
    frame_d = 0.13 * max(power_kW, 0.5) ** (1 / 3)  # IEC frame diameter ~ P^(1/3): 75 kW -> 0.55 m

    # motor rotor: shaft stub and coupling half
    r_in = min(shaft_radius_m(torques[0]), shaft_cap(0, 0))
    hub_len = 1.6 * r_in
    z_cpl_in = z_front - wall / 2 - 0.5 * gap - hub_len
    z_motor = z_cpl_in - hub_len - 0.4 * gap
    motor_len = 1.8 * frame_d
    layout.bodies.append(
        Body(
            "motor",
            axes[0],
            senses[0],
            "motor_angle_rad",
            (
                Cylinder(z_motor, z_cpl_in - hub_len, r_in, SHAFT),
                *hub(z_cpl_in - hub_len, z_cpl_in - 0.002, r_in),
            ),
            follows=ends[0][0],
            ratio=float(ends[0][1]),
        )
    )
    layout.input_signal, layout.input_factor = f"{ends[0][0]}_angle_rad", ends[0][1]

    # gears with their shafts; bearings in both housing walls, once per axis (coaxial axes share them)
    axis_shaft_r: dict[int, float] = {}
    wall_shaft_r: dict[int, list[float]] = {}  # an axis through a planetary stage: [front, back] shafts
    axis_key = list(range(len(axes)))  # a planetary stage's output axis is its input axis

    def add_planetary(k: int) -> None:
        """Stage k's sun, ring, carrier and planets, its input shaft from the front (the coupling or
        the middle between stages) and its output shaft to the back."""
        st, b = stages[k], widths[k][0]
        radius = {
            st.input: min(shaft_radius_m(torques[k]), shaft_cap(k, 0)),
            st.output: min(shaft_radius_m(torques[k + 1]), shaft_cap(k, 1)),
        }
        z_in, z_out = (attach_z_m(st, m, z_stage[k], b) for m in (st.input, st.output))
        r_i, r_o = radius[st.input], radius[st.output]
        if k == 0:
            shaft_in = (
                Cylinder(z_cpl_in, z_in, r_i, SHAFT),
                *hub(z_cpl_in + 0.002, z_cpl_in + hub_len, r_in),
            )
        else:
            shaft_in = (Cylinder(0.5 * (z_stage[k - 1] + z_stage[k]), z_in, r_i, SHAFT),)
        if k == len(stages) - 1:
            z_cpl_out = z_back + wall / 2 + 0.5 * gap + 1.6 * r_o
            shaft_out = (
                Cylinder(z_out, z_cpl_out, r_o, SHAFT),
                *hub(z_cpl_out - 1.6 * r_o, z_cpl_out - 0.002, r_o),
            )
        else:
            shaft_out = (Cylinder(z_out, 0.5 * (z_stage[k] + z_stage[k + 1]), r_o, SHAFT),)
        follows = None if k == 0 else (ends[k - 1][2], float(st.input_sense * ends[k - 1][3]))
        layout.bodies.extend(
            stage_bodies(
                st,
                k,
                axes[k],
                z_stage[k],
                b,
                mirrors[k],
                {st.input: shaft_in, st.output: shaft_out},
                radius,
                follows,
            )
        )
        axis_key[k + 1] = axis_key[k]
        key = axis_key[k]  # the front wall holds the axis's first shaft, the back wall this output's
        front = wall_shaft_r[key][0] if key in wall_shaft_r else axis_shaft_r.get(key, r_i)
        wall_shaft_r[key] = [front, r_o]
        axis_shaft_r[key] = max(axis_shaft_r.get(key, 0.0), r_i, r_o)

    for k, st in enumerate(stages):
        if planetary[k]:
            add_planetary(k)
            continue
        gam = math.radians(st.mesh.centre_line_deg)
        m = mods[k]
        marks = {(t.gear, t.tooth): DAMAGED for t in st.damaged_teeth if t.stiffness_factor < 1}
        marks.update({(t.gear, t.tooth): PITTED for t in st.pitted_teeth if t.depth_um > 0})
        for which, gear, b, colour in (
            ("pinion", st.pinion, widths[k][0], STEEL),
            ("wheel", st.wheel, widths[k][1], WHEEL),
        ):
            j = k if which == "pinion" else k + 1  # axis index
            name = names[k][0 if which == "pinion" else 1]
            shaft_r = min(shaft_radius_m(torques[j]), 0.8 * root_radius(gear, m))
            shape = GearShape(
                teeth=gear.teeth,
                module_m=m,
                pressure_angle_deg=st.mesh.pressure_angle_deg,
                face_width_m=b,
                z_m=z_stage[k],
                bore_radius_m=0.98 * shaft_r,
                first_tooth_rad=tooth_angle_rad(which, 0, gear.teeth, senses[j], gam),
                colour=colour,
                marked_teeth=tuple(
                    (tooth_angle_rad(which, i, gear.teeth, senses[j], gam), c)
                    for (g, i), c in sorted(marks.items())
                    if g == which
                ),
            )
            parts: list = [shape]
            if which == "pinion" and k == 0:  # input shaft from the coupling through the box
                parts += [
                    Cylinder(z_cpl_in, z_back, shaft_r, SHAFT),
                    *hub(z_cpl_in + 0.002, z_cpl_in + hub_len, r_in),
                ]
            elif which == "pinion":  # back half of the intermediate shaft
                parts.append(Cylinder(0.5 * (z_stage[k - 1] + z_stage[k]), z_back, shaft_r, SHAFT))
            elif k < len(stages) - 1:  # front half of the intermediate shaft
                parts.append(Cylinder(z_front, 0.5 * (z_stage[k] + z_stage[k + 1]), shaft_r, SHAFT))
            else:  # output shaft out of the back wall to the machine coupling
                z_cpl_out = z_back + wall / 2 + 0.5 * gap + 1.6 * shaft_r
                parts += [
                    Cylinder(z_front, z_cpl_out, shaft_r, SHAFT),
                    *hub(z_cpl_out - 1.6 * shaft_r, z_cpl_out - 0.002, shaft_r),
                ]
            follows, ratio = (
                (None, 1.0)
                if (which, k) == ("pinion", 0)
                else (
                    (names[k][0], st.pinion.teeth / st.wheel.teeth)
                    if which == "wheel"
                    else (ends[k - 1][2], float(ends[k - 1][3]))
                )
            )
            lateral = (f"{name}_x_m", f"{name}_y_m") if gear.lateral != "none" else None
            layout.bodies.append(
                Body(name, axes[j], senses[j], f"{name}_angle_rad", tuple(parts), lateral, follows, ratio)
            )
            if axis_key[j] in wall_shaft_r and which == "pinion":  # after a planetary stage
                wall_shaft_r[axis_key[j]][1] = shaft_r
            axis_shaft_r[axis_key[j]] = max(axis_shaft_r.get(axis_key[j], 0.0), shaft_r)

    for j, shaft_r in axis_shaft_r.items():
        for w, zw in enumerate((z_front, z_back)):
            if j in wall_shaft_r:
                shaft_r = wall_shaft_r[j][w]
            layout.ground.append(
                Cylinder(
                    zw - wall / 2,
                    zw + wall / 2,
                    1.8 * shaft_r,
                    BEARING,
                    inner_radius_m=1.05 * shaft_r,
                    x_m=axes[j][0],
                    y_m=axes[j][1],
                )
            )

    # driven machine: coupling half and shaft stub
    r_out = min(shaft_radius_m(torques[-1]), shaft_cap(len(stages) - 1, 1))
    z_cpl_out = z_back + wall / 2 + 0.5 * gap + 1.6 * r_out
    mach_d = 1.1 * frame_d
    z_mach = z_cpl_out + 1.6 * r_out + 0.4 * gap
    layout.bodies.append(
        Body(
            "machine",
            axes[-1],
            senses[-1],
            "machine_angle_rad",
            (
                *hub(z_cpl_out + 0.002, z_cpl_out + 1.6 * r_out, r_out),
                Cylinder(z_cpl_out + 1.6 * r_out, z_mach, r_out, SHAFT),
            ),
            follows=ends[-1][2],
            ratio=float(ends[-1][3]),
        )
    )

    # housing, motor and machine frames standing on a base plate
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
    return layout


def _axis_senses(stages) -> tuple[list[int], list[int]]:
    """Drawn turning sense of every axis (positive: counter-clockwise seen from the machine side) and
    the mirror of every stage (-1: a planetary stage drawn mirrored, 1 otherwise).

    Without planetary stages the input shaft turns as stage 1's line of action says (the lateral
    models' convention) and every further axis the other way. With them, the first planetary stage's
    input turns in its modelled sense s_in (parallel stages are then torsional, sense-free), the axes
    before it alternating back to the motor; a later planetary stage whose input turns the other way
    is drawn mirrored."""
    first = next((k for k, st in enumerate(stages) if isinstance(st, PlanetaryStage)), None)
    if first is None:
        senses = [mesh_directions(stages[0].mesh.centre_line_deg, stages[0].mesh.line_of_action_deg)[2]]
        for _ in stages:
            senses.append(-senses[-1])
        return senses, [1] * len(stages)
    senses, mirrors = [stages[first].input_sense * (-1) ** first], []
    for st in stages:
        if isinstance(st, PlanetaryStage):
            mirrors.append(senses[-1] * st.input_sense)
            senses.append(mirrors[-1] * st.output_sense)
        else:
            mirrors.append(1)
            senses.append(-senses[-1])
    return senses, mirrors
