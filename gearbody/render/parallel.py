"""The drawn parts of a parallel stage (no Exudyn): pinion and wheel as involute gears on their shafts,
one centre distance apart along the stage's centre line, damaged and pitted teeth coloured
(docs/render.md, "Teeth"). Registered as the "parallel" kind's ``render_parts``.
"""

from __future__ import annotations

import math

from ..model.kinds import register_stage_kind
from ..physics.lateral import mesh_directions
from ..signals import gear_names
from .drive import Drive, shaft_radius_m
from .shapes import DAMAGED, PITTED, SHAFT, STEEL, WHEEL, Body, Cylinder, GearShape


def module_m(base_radius_m: float, teeth: int, pressure_angle_deg: float) -> float:
    """m = 2 r_b / (z cos alpha)."""
    return 2 * base_radius_m / (teeth * math.cos(math.radians(pressure_angle_deg)))


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


def _root_radius_m(gear, m: float) -> float:
    return 0.5 * m * gear.teeth - 1.25 * m


class ParallelParts:
    """A parallel stage's part of the 3D picture (the protocol of ``StageKind.render_parts``)."""

    fixes_sense = False  # a torsional stage turns either way; the first stage's line of action decides
    mesh_pair = None  # the first mesh is the first two gears

    def __init__(self, scenario, k: int):
        st = self.st = scenario.stages[k]
        self.k = k
        self.names = gear_names(k)
        self.module_m = module_m(st.pinion.base_radius_m, st.pinion.teeth, st.mesh.pressure_angle_deg)
        m = self.module_m
        self.widths = (st.pinion.face_width_m or 10 * m, st.wheel.face_width_m or 10 * m)
        self.face_m = max(self.widths)
        self.ends = (self.names[0], 1, self.names[1], 1)

    @property
    def input_sense(self) -> int:
        """The pinion's drawn sense when no stage fixes one: as its line of action says (the lateral
        models' convention)."""
        return mesh_directions(self.st.mesh.centre_line_deg, self.st.mesh.line_of_action_deg)[2]

    def turn(self, sense: int) -> tuple[int, int]:
        """(mirror, output sense): the wheel turns the other way."""
        return 1, -sense

    def output_axis(self, xy: tuple[float, float]) -> tuple[float, float]:
        """The wheel's axis: one centre distance a = r_1 + r_2 (pitch radii) along the centre line."""
        st = self.st
        gam = math.radians(st.mesh.centre_line_deg)
        a = (st.pinion.base_radius_m + st.wheel.base_radius_m) / math.cos(
            math.radians(st.mesh.pressure_angle_deg)
        )
        return (xy[0] + a * math.cos(gam), xy[1] + a * math.sin(gam))

    def shaft_cap_m(self, end: int) -> float:
        """Largest drawn radius of the input (end 0) or output (end 1) shaft: 0.8 of its gear's root
        radius."""
        return 0.8 * _root_radius_m((self.st.pinion, self.st.wheel)[end], self.module_m)

    def _shaft(self, drive: Drive, which: str, shaft_r: float) -> list:
        """The gear's shaft: the input shaft from the coupling through the box, the back (pinion) or
        front (wheel) half of an intermediate shaft, or the output shaft to the machine coupling."""
        k = self.k
        if which == "pinion" and k == 0:
            return [Cylinder(drive.z_cpl_in, drive.z_back, shaft_r, SHAFT), *drive.input_hub()]
        if which == "pinion":
            return [Cylinder(drive.between_m(k - 1), drive.z_back, shaft_r, SHAFT)]
        if k < drive.last:
            return [Cylinder(drive.z_front, drive.between_m(k), shaft_r, SHAFT)]
        z_cpl_out = drive.output_coupling_z_m(shaft_r)
        return [Cylinder(drive.z_front, z_cpl_out, shaft_r, SHAFT), *drive.output_hub(shaft_r)]

    def _gear(self, drive: Drive, which: str, gear, b: float, colour, shaft_r: float) -> GearShape:
        st, j = self.st, self.k + (which == "wheel")
        gam = math.radians(st.mesh.centre_line_deg)
        marks = {(t.gear, t.tooth): DAMAGED for t in st.damaged_teeth if t.stiffness_factor < 1}
        marks.update({(t.gear, t.tooth): PITTED for t in st.pitted_teeth if t.depth_um > 0})
        return GearShape(
            teeth=gear.teeth,
            module_m=self.module_m,
            pressure_angle_deg=st.mesh.pressure_angle_deg,
            face_width_m=b,
            z_m=drive.z_stage[self.k],
            bore_radius_m=0.98 * shaft_r,
            first_tooth_rad=tooth_angle_rad(which, 0, gear.teeth, drive.senses[j], gam),
            colour=colour,
            marked_teeth=tuple(
                (tooth_angle_rad(which, i, gear.teeth, drive.senses[j], gam), c)
                for (g, i), c in sorted(marks.items())
                if g == which
            ),
        )

    def bodies(self, drive: Drive) -> list[Body]:
        """Pinion and wheel, each with its shaft; their shafts size the bearings of their axes."""
        st, k, out = self.st, self.k, []
        for which, gear, b, colour in (
            ("pinion", st.pinion, self.widths[0], STEEL),
            ("wheel", st.wheel, self.widths[1], WHEEL),
        ):
            j = k if which == "pinion" else k + 1  # axis index
            name = self.names[0 if which == "pinion" else 1]
            shaft_r = min(shaft_radius_m(drive.torques[j]), self.shaft_cap_m(j - k))
            parts = (self._gear(drive, which, gear, b, colour, shaft_r), *self._shaft(drive, which, shaft_r))
            if which == "wheel":
                follows, ratio = self.names[0], st.pinion.teeth / st.wheel.teeth
            elif k == 0:
                follows, ratio = None, 1.0
            else:
                follows, ratio = drive.ends[k - 1][2], float(drive.ends[k - 1][3])
            lateral = (f"{name}_x_m", f"{name}_y_m") if gear.lateral != "none" else None
            out.append(
                Body(
                    name, drive.axes[j], drive.senses[j], f"{name}_angle_rad", parts, lateral, follows, ratio
                )
            )
            drive.bearings.shaft(j, shaft_r)
        return out

    @staticmethod
    def teeth(table: dict) -> tuple:
        """The teeth a saved stage table states: (pinion, wheel)."""
        return (table.get("pinion", {}).get("teeth"), table.get("wheel", {}).get("teeth"))


register_stage_kind("parallel", render_parts=ParallelParts)
