"""The 3D layout and the poses of gearbody render, checked by hand without a renderer."""

import dataclasses
import math

import numpy as np
import pytest

from gearbody.model import DamagedTooth, ScenarioError, load_scenario
from gearbody.model.scenario import PittedTooth
from gearbody.render import RenderError, build_layout, check_result_matches, kinematic_result
from gearbody.render.layout import DAMAGED, PITTED, GearShape, shaft_radius_m, tooth_angle_rad
from gearbody.render.poses import body_angles_rad, body_poses, frame_times
from gearbody.result import Result


def _gear(layout, name) -> GearShape:
    return next(p for p in layout.body(name).parts if isinstance(p, GearShape))


def test_one_stage_geometry_from_module_and_teeth():
    layout = build_layout(load_scenario("one-stage"))
    # the scene's comment: spur pair module 5 mm, 20 deg, z = 29/88 -> a = m (z1 + z2) / 2
    assert _gear(layout, "pinion").module_m == pytest.approx(0.005, rel=1e-4)
    assert _gear(layout, "wheel").module_m == pytest.approx(0.005, rel=1e-4)
    ax_p, ax_w = layout.body("pinion").axis_xy_m, layout.body("wheel").axis_xy_m
    assert math.dist(ax_p, ax_w) == pytest.approx(0.005 * (29 + 88) / 2, rel=1e-4)
    assert ax_w[1] == pytest.approx(0.0)  # centre_line_deg = 0: wheel along +x
    assert _gear(layout, "pinion").face_width_m == pytest.approx(10 * 0.005, rel=1e-4)  # default 10 m
    assert layout.body("motor").axis_xy_m == ax_p and layout.body("machine").axis_xy_m == ax_w
    # line of action -90 deg (the paper's drawing): the pinion turns clockwise
    assert [b.sense for b in layout.bodies] == [-1, -1, 1, 1]


def test_trains_lay_themselves_out_by_centre_distance():
    sc = load_scenario("three-stage")
    layout = build_layout(sc)
    axes = [layout.body(n).axis_xy_m for n in ("pinion", "wheel", "wheel_2", "wheel_3")]
    for k, st in enumerate(sc.stages):
        a = (st.pinion.base_radius_m + st.wheel.base_radius_m) / math.cos(
            math.radians(st.mesh.pressure_angle_deg)
        )
        assert math.dist(axes[k], axes[k + 1]) == pytest.approx(a, rel=1e-9)
    # wheel s and pinion s+1 share an axis; stages follow along +z; senses alternate per axis
    assert layout.body("pinion_2").axis_xy_m == layout.body("wheel").axis_xy_m
    zs = [_gear(layout, n).z_m for n in ("pinion", "pinion_2", "pinion_3")]
    assert zs[0] < zs[1] < zs[2]
    assert [
        layout.body(n).sense for n in ("pinion", "wheel", "pinion_2", "wheel_2", "wheel_3", "machine")
    ] == [
        -1,
        1,
        1,
        -1,
        1,
        1,
    ]
    # gears of different stages on neighbouring axes do not collide: the faces are apart along z
    for k in range(len(sc.stages) - 1):
        a, b = _gear(layout, ("wheel", "wheel_2")[k]), _gear(layout, ("pinion_2", "pinion_3")[k])
        assert abs(a.z_m - b.z_m) >= 0.5 * (a.face_width_m + b.face_width_m)


def test_centre_line_direction_is_followed():
    sc = load_scenario(
        "one-stage", ["design.mesh.centre_line_deg=90.0", "design.mesh.line_of_action_deg=-20.0"]
    )
    layout = build_layout(sc)
    x, y = layout.body("wheel").axis_xy_m
    assert x == pytest.approx(0.0, abs=1e-12) and y == pytest.approx(0.2925, rel=1e-4)


def test_face_width_and_visual_keys_are_checked():
    sc = load_scenario("one-stage", ["design.pinion.face_width_m=0.07"])
    assert _gear(build_layout(sc), "pinion").face_width_m == 0.07
    with pytest.raises(ScenarioError, match="face_width_m"):
        load_scenario("one-stage", ["design.pinion.face_width_m=-0.01"])
    with pytest.raises(ScenarioError, match="lateral_scale"):
        load_scenario("one-stage", ["visual.lateral_scale=-1.0"])


def test_shaft_radius_from_torsion_by_hand():
    # d = (16 T / (pi tau))^(1/3), T = 700 N m, tau = 30 MPa -> d = 49.16 mm
    assert 2 * shaft_radius_m(700.0) == pytest.approx((16 * 700 / (math.pi * 30e6)) ** (1 / 3), rel=1e-12)
    assert 2 * shaft_radius_m(700.0) == pytest.approx(0.04916, abs=1e-5)


@pytest.mark.parametrize("sense", [1, -1])
def test_tooth_in_mesh_sits_on_the_centre_line(sense):
    z1, z2, gam = 29, 88, math.radians(30)
    for i in (0, 5, 28):
        # pinion tooth i is mid-mesh at phi_p = 2 pi (i + 0.5) / z1: drawn on the centre line
        phi = 2 * math.pi * (i + 0.5) / z1
        world = tooth_angle_rad("pinion", i, z1, sense, gam) + sense * phi
        assert math.remainder(world - gam, 2 * math.pi) == pytest.approx(0.0, abs=1e-12)
        # the wheel tooth of that pair is half a wheel pitch ahead of the centre line (teeth interleave)
        phi_w = phi * z1 / z2
        world_w = tooth_angle_rad("wheel", i, z2, -sense, gam) - sense * phi_w
        off = math.remainder(world_w - (gam + math.pi), 2 * math.pi)
        assert abs(off) == pytest.approx(math.pi / z2, rel=1e-9)


def test_damaged_and_pitted_teeth_are_coloured():
    sc = load_scenario("one-stage")
    layout = build_layout(
        sc.with_stage(
            0,
            damaged_teeth=(DamagedTooth(gear="pinion", tooth=3, stiffness_factor=0.5),),
            pitted_teeth=(PittedTooth(gear="wheel", tooth=7, depth_um=20.0, start_phase=0.2, end_phase=0.4),),
        )
    )
    p, w = _gear(layout, "pinion"), _gear(layout, "wheel")
    assert p.marked_teeth == ((tooth_angle_rad("pinion", 3, 29, -1, 0.0), DAMAGED),)
    assert w.marked_teeth == ((tooth_angle_rad("wheel", 7, 88, 1, 0.0), PITTED),)
    assert _gear(build_layout(sc), "pinion").marked_teeth == ()


def test_housing_follows_the_scenario_and_bounds_hold_every_gear():
    ind = build_layout(load_scenario("industrial-two-stage"))
    assert ind.show_housing and not build_layout(load_scenario("two-stage")).show_housing
    lo, hi = ind.bounds_m()
    glo, ghi = ind.bounds_m(gears_only=True)
    assert all(a <= b for a, b in zip(lo, glo, strict=True)) and all(
        a >= b for a, b in zip(hi, ghi, strict=True)
    )
    for body, gear in ind.gears:
        x, y = body.axis_xy_m
        assert glo[0] <= x - gear.tip_radius_m and x + gear.tip_radius_m <= ghi[0]
        hx = ind.housing
        assert abs(x - hx.centre_m[0]) + gear.tip_radius_m < hx.size_m[0] / 2
        assert abs(y - hx.centre_m[1]) + gear.tip_radius_m < hx.size_m[1] / 2


def test_poses_follow_signals_and_magnify_lateral_motion():
    sc = load_scenario("lateral-8dof")
    layout = build_layout(sc)
    t = np.linspace(0.0, 0.01, 11)
    sig = {
        f"{n}_angle_rad": (k + 1) * 10.0 * t for k, n in enumerate(("motor", "pinion", "wheel", "machine"))
    }
    sig.update({"pinion_x_m": 1e-6 * np.ones_like(t), "pinion_y_m": -2e-6 * np.ones_like(t)})
    res = Result(time_s=t, signals=sig)
    poses = body_poses(layout, res, np.array([0.005]), lateral_scale=1000.0, lateral_about_mean=False)
    names = [b.name for b in layout.bodies]
    ip, iw = names.index("pinion"), names.index("wheel")
    assert poses[0, 3 * ip : 3 * ip + 3] == pytest.approx([1e-3, -2e-3, -20.0 * 0.005])
    assert poses[0, 3 * iw + 2] == pytest.approx(30.0 * 0.005)  # the wheel turns the other way
    assert poses[0, 3 * iw] == 0.0  # no wheel_x_m signal: no lateral offset


def test_muller_scene_turns_rigidly_with_the_pinion():
    layout = build_layout(load_scenario("muller"))
    t = np.linspace(0, 0.1, 5)
    res = Result(time_s=t, signals={"pinion_angle_rad": 100.0 * t})
    ang = body_angles_rad(layout, res, t)
    assert ang["wheel"] == pytest.approx(ang["pinion"] * 29 / 88)
    assert ang["motor"] == pytest.approx(ang["pinion"]) and ang["machine"] == pytest.approx(ang["wheel"])
    with pytest.raises(RenderError, match="pinion_angle_rad"):
        body_angles_rad(layout, Result(time_s=t, signals={}), t)


def test_frame_window_defaults_to_one_input_revolution():
    res = kinematic_result(100.0, 0.5)
    times = frame_times(res, 10)
    span = 2 * math.pi / 100.0  # one input revolution; the frame at its start is left out (loops cleanly)
    assert times[-1] == pytest.approx(0.5)
    assert np.diff(times) == pytest.approx(np.full(9, span / 10), rel=1e-3)
    assert times[0] == pytest.approx(0.5 - 0.9 * span, rel=1e-3)
    assert frame_times(res, 3, 0.1, 0.2) == pytest.approx([0.1, 0.15, 0.2])
    for bad, match in (((0,), "frames"), ((3, 0.3, 0.2), "end_s"), ((3, -1.0, None), "start_s")):
        with pytest.raises(RenderError, match=match):
            frame_times(res, *bad)


def test_result_of_another_drive_is_refused():
    sc = load_scenario("one-stage")
    res = Result(
        time_s=np.zeros(2),
        signals={},
        meta={"scenario": {"design": {"stages": [{"pinion": {"teeth": 23}, "wheel": {"teeth": 71}}]}}},
    )
    with pytest.raises(RenderError, match="teeth"):
        check_result_matches(sc, res)
    ok = Result(
        time_s=np.zeros(2),
        signals={},
        meta={"scenario": {"design": {"pinion": {"teeth": 29}, "wheel": {"teeth": 88}}}},
    )
    check_result_matches(sc, ok)


def test_lateral_motion_is_drawn_about_its_mean_by_default():
    layout = build_layout(load_scenario("lateral-8dof"))
    t = np.linspace(0.0, 0.01, 101)
    x = 20e-6 + 1e-6 * np.sin(2 * np.pi * 500 * t)  # static deflection + vibration
    res = Result(time_s=t, signals={"pinion_angle_rad": 100 * t, "pinion_x_m": x, "pinion_y_m": 0 * t})
    ip = [b.name for b in layout.bodies].index("pinion")
    about_mean = body_poses(layout, res, t, lateral_scale=1000.0)[:, 3 * ip]
    total = body_poses(layout, res, t, lateral_scale=1000.0, lateral_about_mean=False)[:, 3 * ip]
    assert about_mean == pytest.approx(1000.0 * (x - x.mean()))
    assert total == pytest.approx(1000.0 * x)


def _with_stage2_line_of_action(sc, deg):
    st0, st1 = sc.design.stages
    st1 = dataclasses.replace(st1, mesh=dataclasses.replace(st1.mesh, line_of_action_deg=deg))
    return dataclasses.replace(sc, design=dataclasses.replace(sc.design, stages=(st0, st1)))


def test_lateral_train_must_turn_consistently():
    ok = load_scenario("industrial-two-stage")
    assert build_layout(ok).body("pinion_2").sense == -build_layout(ok).body("pinion").sense
    message = r"design.stages.2.mesh.line_of_action_deg = -90.*counter-clockwise"
    with pytest.raises(ScenarioError, match=message):
        _with_stage2_line_of_action(ok, -90.0)
    # torsional trains have no such constraint (no forces on the housing frame)
    _with_stage2_line_of_action(load_scenario("two-stage"), -90.0)
