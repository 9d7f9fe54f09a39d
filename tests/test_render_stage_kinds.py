"""gearbody render draws each stage from its kind's render parts (issue 27, D1): the shipped kinds register
theirs from the render modules, a kind registered from a test module alone (the belt drive of
test_stage_kind_plugin) is drawn from its own, and a kind without them is refused in one line, before
anything is drawn or written."""

from __future__ import annotations

import math

import pytest
import test_stage_kind_plugin as belt
from PIL import Image

from gearbody.cli import main
from gearbody.errors import GearbodyError
from gearbody.model import load_scenario
from gearbody.model.kinds import register_stage_kind, stage_kind, unregister_stage_kind
from gearbody.render import RenderError, RenderOptions, build_layout, render
from gearbody.render.drive import Drive
from gearbody.render.parallel import ParallelParts
from gearbody.render.planetary import PlanetaryParts
from gearbody.render.shapes import SHAFT, STEEL, WHEEL, Body, Cylinder
from gearbody.signals import stage_prefix


class BeltParts:
    """The belt stage drawn: two pulleys (discs) on their shafts, side by side along +x, turning the same
    way; the driven pulley follows the driver at the belt's ratio."""

    fixes_sense = False
    input_sense = 1
    mesh_pair = None

    def __init__(self, scenario, k: int):
        self.st, self.k = scenario.stages[k], k
        self.face_m = 0.04
        p = stage_prefix(k)
        self.ends = (p + "driver", 1, p + "driven", 1)

    def turn(self, sense: int) -> tuple[int, int]:
        return 1, sense

    def output_axis(self, xy):
        return (xy[0] + 3 * (self.st.driver_radius_m + self.st.driven_radius_m), xy[1])

    def shaft_cap_m(self, end: int) -> float:
        return math.inf

    def bodies(self, drive: Drive) -> list[Body]:
        k, st, (driver, _, driven, _) = self.k, self.st, self.ends
        z, r = drive.z_stage[k], 0.01
        previous = (drive.ends[k - 1][2], float(drive.ends[k - 1][3])) if k else (None, 1.0)
        out = []
        for j, name, radius, colour, (follows, ratio) in (
            (k, driver, st.driver_radius_m, STEEL, previous),
            (k + 1, driven, st.driven_radius_m, WHEEL, (driver, st.driver_radius_m / st.driven_radius_m)),
        ):
            parts = (
                Cylinder(z - 0.02, z + 0.02, radius, colour),
                Cylinder(drive.z_front, drive.z_back, r, SHAFT),
            )
            out.append(
                Body(name, drive.axes[j], drive.senses[j], f"{name}_angle_rad", parts, None, follows, ratio)
            )
            drive.bearings.shaft(j, r)
        return out


@pytest.fixture
def drawn_belt():
    """The belt kind with its check and its render parts (drawing needs no engine hooks)."""
    register_stage_kind(
        "belt", belt.BeltStage, compound=True, check=lambda k, sc: None, render_parts=BeltParts
    )
    yield
    unregister_stage_kind("belt")


@pytest.fixture
def planetary_without_parts():
    """The planetary kind with its render parts taken away (restored afterwards)."""
    register_stage_kind("planetary", render_parts=None)
    yield
    register_stage_kind("planetary", render_parts=PlanetaryParts)


def test_the_shipped_kinds_register_their_render_parts():
    conveyor = load_scenario("planetary-conveyor")  # a parallel stage, then a planetary one
    assert [stage_kind(st).render_parts for st in conveyor.stages] == [ParallelParts, PlanetaryParts]
    names = [b.name for b in build_layout(conveyor).bodies]
    assert names[:3] == ["motor", "pinion", "wheel"] and "stage_2_planet_1" in names


def test_a_kind_without_render_parts_is_refused_in_one_line(planetary_without_parts):
    with pytest.raises(RenderError) as exc:
        build_layout(load_scenario("planetary-conveyor"))
    text = str(exc.value)
    assert isinstance(exc.value, GearbodyError) and "\n" not in text
    assert "stage 2 (type 'planetary') has no 3D parts" in text


def test_gearbody_render_refuses_it_before_writing(planetary_without_parts, tmp_path, capsys):
    out = tmp_path / "render"
    assert main(["render", "planetary", "--kinematic", "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert "stage 1 (type 'planetary') has no 3D parts" in err and len(err.splitlines()) == 1
    assert not out.exists() or not any(out.iterdir())


def test_a_kind_registered_from_outside_is_drawn_from_its_own_parts(drawn_belt, tmp_path):
    sc = belt._one_stage_and_belt()
    layout = build_layout(sc)
    driver, driven = layout.body("stage_2_driver"), layout.body("stage_2_driven")
    assert driver.axis_xy_m == layout.body("wheel").axis_xy_m  # on the gear stage's output shaft
    assert math.dist(driver.axis_xy_m, driven.axis_xy_m) == pytest.approx(3 * (0.05 + 0.12))
    assert layout.body("machine").follows == "stage_2_driven" and driven.sense == driver.sense
    out = render(sc, None, out_dir=tmp_path, frames=1, options=RenderOptions(width_px=64, height_px=48))
    assert Image.open(out.frames[0]).size == (64, 48)
