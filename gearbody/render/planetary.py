"""The drawn parts of a planetary stage (no Exudyn): sun, planets and internal ring as toothed outlines,
the carrier as a plate with a pin through every planet, and the tooth phases that make the teeth mesh
at the nominal assembly (docs/render.md, "Planetary stages").

Members are drawn in the stage's frame, centred on its axis; every angle is the model's absolute
rotation (counter-clockwise), times the stage's ``mirror`` (-1 when the chain before it makes the input
turn the other way in the picture: the stage is then drawn mirrored, planets numbered clockwise).
"""

from __future__ import annotations

import math

import numpy as np

from ..model.kinds import register_stage_kind
from ..model.planetary import PlanetaryStage
from ..signals import stage_prefix
from .drive import Drive, shaft_radius_m
from .shapes import MARKER, SHAFT, STEEL, WHEEL, Body, Cylinder, GearShape, Orbit, Prism

RING = (0.5, 0.52, 0.56, 1.0)
CARRIER = (0.2, 0.45, 0.48, 1.0)
PIN = (0.3, 0.3, 0.33, 1.0)

PLATE_GAP = 0.08
"""Axial gap between the gears and the carrier plate (or ring drum), in face widths."""
PLATE_THICKNESS = 0.25
"""Carrier plate and ring drum thickness, in face widths."""
RIM = 2.5
"""Radial thickness of the ring's rim beyond its tooth roots, in modules."""


def tooth_outline(teeth: int, module_m: float, pressure_angle_deg: float, r_out: float, r_in: float):
    """Closed counter-clockwise outline (n, 2) of ``teeth`` involute lobes centred at 2 pi k / z.

    The half angular width of a lobe at radius rho >= r_b is pi / (2 z) + inv(alpha) - inv(alpha_rho),
    cos(alpha_rho) = r_b / rho, radial below r_b. An external gear's lobes are its teeth (r_out = tip,
    r_in = root); an internal gear's lobes are its tooth spaces (r_out = its root, r_in = its tip).
    """
    alpha = math.radians(pressure_angle_deg)
    r = 0.5 * module_m * teeth
    r_b = r * math.cos(alpha)

    def inv(a):
        return math.tan(a) - a

    def half(rho):
        a = math.acos(min(r_b / rho, 1.0))
        return max(math.pi / (2 * teeth) + inv(alpha) - inv(a), 0.02 * math.pi / teeth)

    rhos = np.linspace(max(r_in, r_b), r_out, 8)
    if r_in < r_b:
        rhos = np.concatenate([[r_in], rhos])
    pitch = 2 * math.pi / teeth
    lobe = [(rho, -half(rho)) for rho in rhos]  # up the first flank, across the tip, down the other
    lobe += [(rho, half(rho)) for rho in rhos[::-1]]
    gap_end = pitch - half(rhos[0])  # root (or tip) arc to the next lobe
    root = [(r_in, half(rhos[0]) + f * (gap_end - half(rhos[0]))) for f in (0.25, 0.5, 0.75)]
    points = []
    for k in range(teeth):
        for rho, a in lobe + root:
            points.append((rho * math.cos(k * pitch + a), rho * math.sin(k * pitch + a)))
    return np.array(points)


def tooth_phase(angle_rad: float, first_tooth_rad: float, teeth: int) -> float:
    """Where direction ``angle_rad`` falls on a gear's teeth, in pitches in [0, 1): 0 a tooth centre,
    0.5 a tooth space (for the ring: its teeth, not its spaces)."""
    return ((angle_rad - first_tooth_rad) * teeth / (2 * math.pi)) % 1.0


def first_teeth_rad(z_s: int, z_p: int, z_r: int, planet_angles_rad) -> tuple[float, list[float], float]:
    """Body-frame angles of tooth 0 of the sun, of each planet and of the ring, so that the teeth mesh
    in the nominal assembly: the sun has a tooth on +x; on each line sun-planet and planet-ring a tooth
    faces a space (tooth phases summing to 1/2 across the sun mesh, differing by 1/2 across the ring
    mesh, which rolling keeps). The assembly condition makes one ring phase fit every planet."""
    planets = []
    for psi in planet_angles_rad:
        u_s = tooth_phase(psi, 0.0, z_s)
        planets.append(psi + math.pi - (0.5 - u_s) * 2 * math.pi / z_p)
    u_p = tooth_phase(planet_angles_rad[0], planets[0], z_p)
    ring = planet_angles_rad[0] - (0.5 + u_p) * 2 * math.pi / z_r
    return 0.0, planets, ring


def convex_hull(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull of 2D points (monotone chain)."""
    pts = sorted(map(tuple, np.round(points, 12)))

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1])


def carrier_outline(carrier_radius_m: float, planet_angles_rad, lobe_m: float, hub_m: float) -> np.ndarray:
    """The carrier plate: the hull of a circle of radius ``lobe_m`` round every planet pin and a hub."""
    a = np.linspace(0, 2 * math.pi, 48, endpoint=False)
    circles = [np.column_stack([hub_m * np.cos(a), hub_m * np.sin(a)])]
    for psi in planet_angles_rad:
        c = carrier_radius_m * np.array([math.cos(psi), math.sin(psi)])
        circles.append(c + np.column_stack([lobe_m * np.cos(a), lobe_m * np.sin(a)]))
    return convex_hull(np.vstack(circles))


def side_depth_m(st: PlanetaryStage, face_m: float) -> float:
    """Axial room each side of the gears' mid-plane: the face, then the carrier plate and the ring's
    drum on their sides (input: front, output: back, a fixed carrier's plate at the back)."""
    slots = {"front": 0, "back": 0}
    slots["front" if st.input == "carrier" else "back"] += 1
    if st.fixed != "ring":
        slots["front" if st.input == "ring" else "back"] += 1
    return 0.5 * face_m + max(slots.values()) * (PLATE_GAP + PLATE_THICKNESS) * face_m


def slot_z_m(z_m: float, face_m: float, where: int, k: int) -> tuple[float, float]:
    """Axial extent of plate slot k (0 nearest the gears) on side ``where`` (-1 front, +1 back)."""
    z0 = z_m + (0.5 + PLATE_GAP + k * (PLATE_GAP + PLATE_THICKNESS)) * face_m
    z1 = z0 + PLATE_THICKNESS * face_m
    return (z0, z1) if where > 0 else (2 * z_m - z1, 2 * z_m - z0)


def _sides(st: PlanetaryStage) -> tuple[int, int]:
    """Sides (-1 front, +1 back) of the carrier plate and of the ring's drum."""
    c_side = -1 if st.input == "carrier" else 1
    return c_side, -1 if st.input == "ring" else 1


def attach_z_m(st: PlanetaryStage, member: str, z_m: float, face_m: float) -> float:
    """Where a member's shaft ends: the sun's mid-plane, the carrier plate or the ring's drum."""
    c_side, r_side = _sides(st)
    if member == "sun":
        return z_m
    if member == "carrier":
        return sum(slot_z_m(z_m, face_m, c_side, 0)) / 2
    return sum(slot_z_m(z_m, face_m, r_side, 1 if r_side == c_side else 0)) / 2


def stage_bodies(
    st: PlanetaryStage,
    stage: int,
    centre_xy_m: tuple[float, float],
    z_m: float,
    face_m: float,
    mirror: int,
    shaft_parts: dict[str, tuple],
    shaft_radius_m: dict[str, float],
    follows: tuple[str, float] | None,
) -> list[Body]:
    """Bodies of a planetary stage: sun, ring, carrier, planet_1..N (with the stage prefix).

    ``shaft_parts`` holds the input and output members' shafts (and couplings) from the drive's
    layout, ``shaft_radius_m`` their radii; ``follows`` the body (and ratio) the input member turns
    with when the result has no angle for it.
    """
    g = st.geometry
    psis = [mirror * a for a in g.planet_angles_rad]
    sun0, planet0, ring0 = first_teeth_rad(g.z_sun, g.z_planet, g.z_ring, psis)
    sun_shaft = shaft_radius_m.get("sun", 0.0)
    parts: dict[str, list] = {
        "sun": [_gear(st, z_m, face_m, g.z_sun, sun0, STEEL, 0.98 * sun_shaft if sun_shaft else 0.0)],
        "ring": [_gear(st, z_m, face_m, g.z_ring, ring0, RING, 0.0, internal=True)],
        "carrier": _carrier_parts(st, z_m, face_m, psis, sun_shaft),
    }
    if st.fixed != "ring":  # a turning ring: a drum from its rim to its shaft
        c_side, r_side = _sides(st)
        z0, z1 = slot_z_m(z_m, face_m, r_side, 1 if r_side == c_side else 0)
        parts["ring"].append(
            Cylinder(z0, z1, g.ring_pitch_radius_m + 1.25 * g.module_m + RIM * g.module_m, RING)
        )
    for member, extra in shaft_parts.items():
        parts[member] += list(extra)
    prefix = stage_prefix(stage)
    speeds = st.speeds(1.0)
    w_in = speeds.of(st.input)
    bodies = []
    for mbr in ("sun", "ring", "carrier"):
        if mbr == st.input:
            fol, ratio = follows if follows else (None, 1.0)
        else:
            fol, ratio = prefix + st.input, speeds.of(mbr) / w_in
        name = prefix + mbr
        lateral = (f"{name}_x_m", f"{name}_y_m")
        bodies.append(
            Body(
                name,
                centre_xy_m,
                mirror,
                f"{name}_angle_rad",
                tuple(parts[mbr]),
                lateral,
                fol,
                ratio,
                mirror=mirror,
            )
        )
    return bodies + _planet_bodies(st, prefix, centre_xy_m, z_m, face_m, mirror, psis, planet0)


def _gear(st: PlanetaryStage, z_m: float, face_m: float, teeth, first, colour, bore, internal=False):
    """A member's toothed outline in the stage's plane (the ring's with its rim)."""
    g = st.geometry
    m = g.module_m
    rim = g.ring_pitch_radius_m + 1.25 * m + RIM * m if internal else 0.0
    return GearShape(
        teeth,
        m,
        st.pressure_angle_deg,
        face_m,
        z_m,
        bore,
        first,
        colour,
        internal=internal,
        rim_radius_m=rim,
        outline="gearbody",
    )


def _carrier_parts(st: PlanetaryStage, z_m: float, face_m: float, psis, sun_shaft: float) -> list:
    """The carrier: a plate on its side with a pin through every planet (its bore lets the sun's shaft
    through when that shaft leaves on the plate's side)."""
    g, b = st.geometry, face_m
    r_p, r_c = g.planet_pitch_radius_m, g.carrier_radius_m
    side = {st.input: -1, st.output: 1}  # -1: front (motor side), +1: back
    c_side, _ = _sides(st)
    pin_r = 0.3 * r_p
    z0, z1 = slot_z_m(z_m, b, c_side, 0)
    bore = 1.3 * sun_shaft if side.get("sun") == c_side else 0.0
    plate = carrier_outline(r_c, psis, 0.55 * r_p, max(0.5 * g.sun_pitch_radius_m, 2 * bore))
    z_far = z_m - c_side * 0.55 * b  # the pins stand just proud of the planets' far face
    z_plate = z0 if c_side > 0 else z1
    pins = [
        Cylinder(
            min(z_far, z_plate), max(z_far, z_plate), pin_r, PIN, x_m=r_c * math.cos(a), y_m=r_c * math.sin(a)
        )
        for a in psis
    ]
    return [Prism(tuple(map(tuple, plate)), z0, z1, CARRIER, hole_radius_m=bore), *pins]


def _planet_bodies(st: PlanetaryStage, prefix, centre_xy_m, z_m, face_m, mirror, psis, planet0) -> list[Body]:
    """planet_1..N: each a gear with a marker, riding on the carrier at its angle."""
    g, b = st.geometry, face_m
    r_p, r_c = g.planet_pitch_radius_m, g.carrier_radius_m
    speeds = st.speeds(1.0)
    w_in = speeds.of(st.input)
    pin_r = 0.3 * r_p
    marker_r = 0.08 * r_p
    bodies = []
    for n, psi in enumerate(psis):
        name = f"{prefix}planet_{n + 1}"
        mark = Cylinder(
            z_m - 0.5 * b - 0.004 * b, z_m - 0.5 * b + 0.05 * b, marker_r, MARKER, x_m=0.6 * r_p, y_m=0.0
        )
        shape = _gear(st, z_m, face_m, g.z_planet, planet0[n], WHEEL, 1.02 * pin_r)
        axis = (centre_xy_m[0] + r_c * math.cos(psi), centre_xy_m[1] + r_c * math.sin(psi))
        orbit = Orbit(prefix + "carrier", centre_xy_m, r_c, psi, (f"{name}_centre_x_m", f"{name}_centre_y_m"))
        bodies.append(
            Body(
                name,
                axis,
                mirror,
                f"{name}_angle_rad",
                (shape, mark),
                None,
                prefix + st.input,
                speeds.planet_rad_s / w_in,
                mirror=mirror,
                orbit=orbit,
            )
        )
    return bodies


class PlanetaryParts:
    """A planetary stage's part of the 3D picture (the protocol of ``StageKind.render_parts``): coaxial,
    its members drawn in its modelled senses (mirrored when the chain before it turns the other way)."""

    fixes_sense = True  # the first planetary stage's input turns in its modelled sense

    def __init__(self, scenario, k: int):
        st = self.st = scenario.stages[k]
        self.k = k
        self.module_m = st.module_mm * 1e-3
        self.width_m = 10 * self.module_m
        # its axial room includes its carrier plate (and a turning ring's drum)
        self.face_m = 2 * side_depth_m(st, self.width_m)
        p = stage_prefix(k)
        self.ends = (p + st.input, st.input_sense, p + st.output, st.output_sense)
        self.mesh_pair = (p + "sun", p + "planet_1")  # the mesh camera follows the sun-planet 1 mesh
        self.input_sense = st.input_sense

    def turn(self, sense: int) -> tuple[int, int]:
        """(mirror, output sense): mirrored when its input turns against its modelled sense."""
        mirror = sense * self.st.input_sense
        return mirror, mirror * self.st.output_sense

    def output_axis(self, xy: tuple[float, float]) -> tuple[float, float]:
        """Coaxial: the output shaft continues the input's axis."""
        return xy

    def shaft_cap_m(self, end: int) -> float:
        """Largest drawn radius of the input (end 0) or output (end 1) shaft: 0.8 of the sun's root
        radius on the sun, none on the ring or the carrier."""
        st, m = self.st, self.module_m
        member = (st.input, st.output)[end]
        return 0.8 * (0.5 * m * st.sun.teeth - 1.25 * m) if member == "sun" else math.inf

    def bodies(self, drive: Drive) -> list[Body]:
        """Sun, ring, carrier and planets, the input shaft from the front (the coupling or the middle
        between stages) and the output shaft to the back."""
        st, k, b = self.st, self.k, self.width_m
        radius = {
            st.input: min(shaft_radius_m(drive.torques[k]), self.shaft_cap_m(0)),
            st.output: min(shaft_radius_m(drive.torques[k + 1]), self.shaft_cap_m(1)),
        }
        z_in, z_out = (attach_z_m(st, m, drive.z_stage[k], b) for m in (st.input, st.output))
        r_i, r_o = radius[st.input], radius[st.output]
        if k == 0:
            shaft_in = (Cylinder(drive.z_cpl_in, z_in, r_i, SHAFT), *drive.input_hub())
        else:
            shaft_in = (Cylinder(drive.between_m(k - 1), z_in, r_i, SHAFT),)
        if k == drive.last:
            z_cpl_out = drive.output_coupling_z_m(r_o)
            shaft_out = (Cylinder(z_out, z_cpl_out, r_o, SHAFT), *drive.output_hub(r_o))
        else:
            shaft_out = (Cylinder(z_out, drive.between_m(k), r_o, SHAFT),)
        follows = None if k == 0 else (drive.ends[k - 1][2], float(st.input_sense * drive.ends[k - 1][3]))
        shafts = {st.input: shaft_in, st.output: shaft_out}
        mirror = drive.mirrors[k]
        bodies = stage_bodies(st, k, drive.axes[k], drive.z_stage[k], b, mirror, shafts, radius, follows)
        drive.bearings.coaxial(k, r_i, r_o)
        return bodies

    @staticmethod
    def teeth(table: dict) -> tuple:
        """The teeth a saved stage table states: ('planetary', sun, planet, ring, planets)."""
        z = [table.get(m, {}).get("teeth") for m in ("sun", "planet", "ring")]
        return ("planetary", *z, table.get("planets"))


register_stage_kind("planetary", render_parts=PlanetaryParts)
