"""gearbody render draws planetary stages: layout by hand, teeth meshing at the nominal assembly, poses
from the result (planets riding on the carrier), drives mixing planetary and parallel stages, pictures
and the CLI."""

import copy
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import gearbody
from gearbody.cli import main
from gearbody.engine import simulate
from gearbody.model import load_scenario, scene_path
from gearbody.model.io import read_toml
from gearbody.render import RenderError, RenderOptions, build_layout, check_result_matches, render
from gearbody.render.layout import GearShape, Prism
from gearbody.render.planetary import RING, first_teeth_rad, tooth_outline, tooth_phase
from gearbody.render.poses import body_angles_rad, body_poses, frame_times, kinematic_result
from gearbody.result import Result

M, Z_S, Z_P, Z_R = 3e-3, 29, 37, 103  # scenes/planetary.toml
R_C = M * (Z_S + Z_P) / 2


def _gear(layout, name) -> GearShape:
    return next(p for p in layout.body(name).parts if isinstance(p, GearShape))


def _stage_dict(**changes) -> dict:
    d = read_toml(scene_path("planetary"))
    d["meta"]["name"] = "planetary"
    d["design"]["stages"][0].update(changes)
    return d


def _with_parallel(d: dict, first: bool) -> dict:
    """The planetary scene with the two-stage scene's stage added after it (or before, ``first``)."""
    two = read_toml(scene_path("two-stage"))
    par = copy.deepcopy(two["design"]["stages"][0 if first else 1])
    par.pop("error_mode", None)
    d["design"]["stages"].insert(0 if first else len(d["design"]["stages"]), par)
    d["design"]["shafts"].insert(1, {"stiffness_Nm_per_rad": 2.0e6, "damping_Nms_per_rad": 50.0})
    return d


@pytest.fixture(scope="module")
def simulated():
    sc = load_scenario("planetary", ["operation.t_end_s=0.01"])
    return sc, simulate(sc)


def test_members_sit_at_their_radii_coaxial_with_motor_and_machine():
    layout = build_layout(load_scenario("planetary"))
    ring, sun, planet = _gear(layout, "ring"), _gear(layout, "sun"), _gear(layout, "planet_2")
    assert ring.internal and ring.pitch_radius_m == pytest.approx(M * Z_R / 2, rel=1e-12)
    assert ring.tip_radius_m == pytest.approx(M * Z_R / 2 - M) and ring.root_radius_m < ring.rim_radius_m
    assert sun.pitch_radius_m == pytest.approx(M * Z_S / 2) and planet.pitch_radius_m == pytest.approx(
        M * Z_P / 2
    )
    centre = layout.body("sun").axis_xy_m
    for name in ("motor", "ring", "carrier", "machine"):
        assert layout.body(name).axis_xy_m == centre  # sun in, carrier out: one axis
    for n in range(3):  # planets on the carrier circle at 0, 120, 240 deg
        x, y = layout.body(f"planet_{n + 1}").axis_xy_m
        psi = 2 * math.pi * n / 3
        assert (x, y) == pytest.approx((R_C * math.cos(psi), R_C * math.sin(psi)), abs=1e-15)
        assert layout.body(f"planet_{n + 1}").orbit.angle_rad == pytest.approx(psi)
    plate = next(p for p in layout.body("carrier").parts if isinstance(p, Prism))
    assert max(math.hypot(*p) for p in plate.outline_m) == pytest.approx(R_C + 0.55 * M * Z_P / 2, rel=1e-3)
    assert plate.z0_m > sun.z_m + sun.face_width_m / 2  # the plate behind the gears (output side)
    assert layout.mesh_pair == ("sun", "planet_1") and layout.input_signal == "sun_angle_rad"
    # the housing holds the ring; one bearing pair on the common axis (front: sun shaft, back: carrier's)
    hx = layout.housing
    assert hx.size_m[0] / 2 > ring.rim_radius_m and hx.size_m[1] / 2 > ring.rim_radius_m
    bearings = [g for g in layout.ground if getattr(g, "inner_radius_m", 0) > 0]
    assert len(bearings) == 2 and bearings[0].radius_m < bearings[1].radius_m


@pytest.mark.parametrize(
    "changes",
    [
        {},
        {"planet_angles_deg": [0.0, 40 * 360 / 132, 90 * 360 / 132]},  # unequal spacing
        {  # even planet teeth: the ring mesh half a pitch off the sun mesh
            "sun": {**_stage_dict()["design"]["stages"][0]["sun"], "teeth": 30},
            "planet": {**_stage_dict()["design"]["stages"][0]["planet"], "teeth": 36},
            "ring": {**_stage_dict()["design"]["stages"][0]["ring"], "teeth": 102},
        },
    ],
)
def test_teeth_mesh_at_the_nominal_assembly(changes):
    """On every planet's line to the sun a tooth faces a space (phases sum to 1/2), and on its line to
    the ring too (the ring's phase 1/2 off the planet's): one ring phase fits every planet."""
    layout = build_layout(load_scenario(_stage_dict(**changes)))
    sun, ring = _gear(layout, "sun"), _gear(layout, "ring")
    n = sum(b.orbit is not None for b in layout.bodies)
    for k in range(n):
        body = layout.body(f"planet_{k + 1}")
        planet, psi = _gear(layout, body.name), body.orbit.angle_rad
        across_sun = tooth_phase(psi, sun.first_tooth_rad, sun.teeth) + tooth_phase(
            psi + math.pi, planet.first_tooth_rad, planet.teeth
        )
        across_ring = tooth_phase(psi, ring.first_tooth_rad, ring.teeth) - tooth_phase(
            psi, planet.first_tooth_rad, planet.teeth
        )
        assert math.remainder(across_sun - 0.5, 1.0) == pytest.approx(0.0, abs=1e-9)
        assert math.remainder(across_ring - 0.5, 1.0) == pytest.approx(0.0, abs=1e-9)


def test_tooth_outline_has_its_radii_and_lobe_widths():
    pts = tooth_outline(Z_S, M, 24.6, M * Z_S / 2 + M, M * Z_S / 2 - 1.25 * M)
    r = np.hypot(pts[:, 0], pts[:, 1])
    assert r.max() == pytest.approx(M * Z_S / 2 + M) and r.min() == pytest.approx(M * Z_S / 2 - 1.25 * M)
    # at the pitch circle a lobe is half a pitch wide (standard teeth): sample the polygon there
    a = np.unwrap(np.arctan2(pts[:, 1], pts[:, 0]))
    cross = np.flatnonzero(np.diff(np.sign(r - M * Z_S / 2)))[:2]
    width = []
    for i in cross:
        f = (M * Z_S / 2 - r[i]) / (r[i + 1] - r[i])
        width.append(a[i] + f * (a[i + 1] - a[i]))
    assert width[1] - width[0] == pytest.approx(math.pi / Z_S, rel=0.02)
    assert first_teeth_rad(Z_S, Z_P, Z_R, [0.0])[0] == 0.0


def test_planets_ride_on_the_carrier_and_follow_their_centre_signals():
    layout = build_layout(load_scenario("planetary"))
    t = np.linspace(0.0, 0.01, 11)
    w_c = 30.0
    sig = {"sun_angle_rad": 150.0 * t, "carrier_angle_rad": w_c * t, "ring_angle_rad": 0 * t}
    sig.update({"carrier_x_m": 4e-6 * np.sin(900 * t), "carrier_y_m": 1e-6 + 0 * t})
    for n in range(3):
        psi = w_c * t + 2 * math.pi * n / 3
        sig[f"planet_{n + 1}_centre_x_m"] = (R_C + 2e-6) * np.cos(psi) + sig["carrier_x_m"]
        sig[f"planet_{n + 1}_centre_y_m"] = (R_C + 2e-6) * np.sin(psi) + sig["carrier_y_m"]
        sig[f"planet_{n + 1}_angle_rad"] = -60.0 * t
    res = Result(time_s=t, signals=sig)
    names = [b.name for b in layout.bodies]

    def centre(poses, name):
        k = names.index(name)
        return np.asarray(layout.body(name).axis_xy_m) + poses[:, 3 * k : 3 * k + 2]

    exact = body_poses(layout, res, t, lateral_scale=1.0, lateral_about_mean=False)
    for n in (1, 2, 3):
        drawn = centre(exact, f"planet_{n}")
        assert drawn[:, 0] == pytest.approx(sig[f"planet_{n}_centre_x_m"], abs=1e-15)
        assert drawn[:, 1] == pytest.approx(sig[f"planet_{n}_centre_y_m"], abs=1e-15)
        assert exact[:, 3 * names.index(f"planet_{n}") + 2] == pytest.approx(-60.0 * t)
    # magnified: the carrier's vibration x1000 about its mean, the planets carried along with it
    big = body_poses(layout, res, t, lateral_scale=1000.0)
    ic = names.index("carrier")
    cx = sig["carrier_x_m"]
    assert big[:, 3 * ic] == pytest.approx(1000.0 * (cx - cx.mean()))
    shift = centre(big, "planet_1") - centre(exact, "planet_1")
    assert shift[:, 0] == pytest.approx(1000.0 * (cx - cx.mean()) - cx, abs=1e-15)
    # no centre signals (kinematic): on the carrier circle at the carrier's angle, turning by Willis
    kin = kinematic_result(157.08, 0.05, signal="sun_angle_rad")
    poses = body_poses(layout, kin, t)
    for n in (1, 2, 3):
        psi = 157.08 * t * Z_S / (Z_S + Z_R) + 2 * math.pi * (n - 1) / 3
        drawn = centre(poses, f"planet_{n}")
        assert drawn == pytest.approx(R_C * np.column_stack([np.cos(psi), np.sin(psi)]), abs=1e-12)
    ang = body_angles_rad(layout, kin, t)
    w_p = (1 - Z_R / Z_P) * Z_S / (Z_S + Z_R)  # absolute planet speed per sun speed, ring fixed
    assert ang["planet_1"] == pytest.approx(w_p * ang["sun"]) and ang["ring"] == pytest.approx(0 * t)
    assert ang["motor"] == pytest.approx(ang["sun"]) and ang["machine"] == pytest.approx(ang["carrier"])


def test_simulated_planets_are_drawn_at_their_centre_signals(simulated):
    sc, res = simulated
    layout = build_layout(sc)
    times = frame_times(res, 5, input_signal=layout.input_signal)
    assert times[-1] == pytest.approx(res.time_s[-1])
    poses = body_poses(layout, res, times, lateral_scale=1.0, lateral_about_mean=False)
    names = [b.name for b in layout.bodies]
    for n in (1, 2, 3):
        k = names.index(f"planet_{n}")
        for d, axis in enumerate("xy"):
            want = np.interp(times, res.time_s, res[f"planet_{n}_centre_{axis}_m"])
            assert layout.body(f"planet_{n}").axis_xy_m[d] + poses[:, 3 * k + d] == pytest.approx(
                want, abs=1e-15
            )
        assert poses[:, 3 * k + 2] == pytest.approx(
            np.interp(times, res.time_s, res[f"planet_{n}_angle_rad"])
        )
    check_result_matches(sc, res)


def test_a_result_of_another_planetary_stage_is_refused(simulated):
    sc, _ = simulated
    other = _stage_dict()
    saved = Result(time_s=np.zeros(2), signals={}, meta={"scenario": other})
    check_result_matches(sc, saved)
    other["design"]["stages"][0]["planets"] = 4
    with pytest.raises(RenderError, match="teeth"):
        check_result_matches(sc, Result(time_s=np.zeros(2), signals={}, meta={"scenario": other}))


def test_the_mesh_window_follows_the_sun_planet_1_mesh():
    layout = build_layout(load_scenario("planetary"))
    lo, hi = layout.mesh_bounds_m()
    assert ((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2) == pytest.approx((M * Z_S / 2, 0.0), abs=1e-12)
    assert hi[0] - lo[0] == pytest.approx(12 * M)
    kin = kinematic_result(157.08, 0.05, signal="sun_angle_rad")
    row = body_poses(layout, kin, np.array([0.02]))[0]
    lo, hi = layout.mesh_bounds_m(pose=row)
    psi = 157.08 * 0.02 * Z_S / (Z_S + Z_R)  # planet 1 has moved on with the carrier
    mid = ((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2)
    assert mid == pytest.approx((M * Z_S / 2 * math.cos(psi), M * Z_S / 2 * math.sin(psi)), abs=1e-12)


def _drawn(layout, name, poses):
    return poses[:, 3 * [b.name for b in layout.bodies].index(name) + 2]


def test_planetary_then_parallel_drive_is_laid_out_along_the_chain():
    d = _with_parallel(_stage_dict(), first=False)
    d["design"]["machine"]["rated_torque_Nm"] = 3000.0
    sc = load_scenario(d)
    layout = build_layout(sc)
    st = sc.stages[1]
    a = (st.pinion.base_radius_m + st.wheel.base_radius_m) / math.cos(
        math.radians(st.mesh.pressure_angle_deg)
    )
    assert layout.body("pinion_2").axis_xy_m == layout.body("carrier").axis_xy_m == (0.0, 0.0)
    assert math.dist(layout.body("wheel_2").axis_xy_m, (0.0, 0.0)) == pytest.approx(a)
    assert layout.body("machine").axis_xy_m == layout.body("wheel_2").axis_xy_m
    ring, pinion = _gear(layout, "ring"), _gear(layout, "pinion_2")
    assert pinion.z_m - ring.z_m > ring.face_width_m  # stage 2 behind the carrier plate
    # the carrier and the pinion on its shaft turn together in the picture, the wheel the other way
    t = np.linspace(0, 0.02, 5)
    poses = body_poses(layout, kinematic_result(157.08, 0.05, signal=layout.input_signal), t)
    assert _drawn(layout, "pinion_2", poses) == pytest.approx(_drawn(layout, "carrier", poses))
    assert _drawn(layout, "motor", poses) == pytest.approx(_drawn(layout, "sun", poses))
    assert np.all(np.diff(_drawn(layout, "wheel_2", poses)) < 0) and np.all(
        np.diff(_drawn(layout, "sun", poses)) > 0
    )


def test_parallel_then_planetary_and_a_mirrored_later_stage():
    sc = load_scenario(_with_parallel(_stage_dict(), first=True))
    layout = build_layout(sc)
    assert (
        layout.body("stage_2_sun").axis_xy_m
        == layout.body("wheel").axis_xy_m
        == layout.body("machine").axis_xy_m
    )
    t = np.linspace(0, 0.02, 5)
    poses = body_poses(layout, kinematic_result(-157.08, 0.05), t)
    assert _drawn(layout, "stage_2_sun", poses) == pytest.approx(_drawn(layout, "wheel", poses))
    assert _drawn(layout, "machine", poses) == pytest.approx(_drawn(layout, "stage_2_carrier", poses))
    assert layout.body("stage_2_sun").mirror == 1  # the first planetary stage sets the senses
    # planetary -> parallel -> planetary: the second planetary input turns clockwise in the picture,
    # so that stage is drawn mirrored (planets at -psi), still turning with its shaft
    d = _with_parallel(_stage_dict(), first=False)
    d["design"]["stages"].append(copy.deepcopy(d["design"]["stages"][0]))
    d["design"]["shafts"].insert(2, {"stiffness_Nm_per_rad": 2.0e6, "damping_Nms_per_rad": 50.0})
    d["design"]["machine"]["rated_torque_Nm"] = 10000.0
    layout = build_layout(load_scenario(d))
    assert layout.body("stage_3_sun").mirror == -1
    assert layout.body("stage_3_planet_2").orbit.angle_rad == pytest.approx(-2 * math.pi / 3)
    poses = body_poses(layout, kinematic_result(157.08, 0.05, signal=layout.input_signal), t)
    assert _drawn(layout, "stage_3_sun", poses) == pytest.approx(_drawn(layout, "wheel_2", poses))


def test_the_picture_shows_ring_carrier_and_moving_teeth(simulated, tmp_path):
    sc, res = simulated
    options = RenderOptions(width_px=320, height_px=240, view="front", frame="gears", threads=1)
    out = render(sc, res, out_dir=tmp_path, frames=2, start_s=0.006, end_s=0.01, options=options)
    a, b = (np.asarray(Image.open(p).convert("RGB")).astype(int) for p in out.frames)
    assert a.shape == (240, 320, 3)
    background = np.all(a == 255, axis=2)
    assert 0.3 < 1 - background.mean() < 0.9  # the ring's disc fills much of the picture, open inside
    assert len(np.unique(a.reshape(-1, 3), axis=0)) >= 6
    assert np.abs(a - b).sum(axis=2).astype(bool).mean() > 0.01  # planets and sun have moved
    # the ring's grey rim is on the picture's edge circle; the carrier's teal between the planets
    ring_grey = np.array(RING[:3]) * 255
    assert (np.abs(a - ring_grey).sum(axis=2) < 60).mean() > 0.01
    mesh = RenderOptions(width_px=160, height_px=120, view="front", frame="mesh", threads=1)
    out = render(sc, res, out_dir=tmp_path / "mesh", frames=2, options=mesh, movie="none")
    img = np.asarray(Image.open(out.frames[-1]).convert("RGB"))
    assert not np.all(img == 255, axis=2).all()


def test_cli_render_planetary_from_a_clean_state(tmp_path):
    """A fresh interpreter: simulate the scene briefly, draw 2 frames and the GIF, exit 0; then render the
    kept result again."""
    out = tmp_path / "pics"
    root = Path(gearbody.__file__).resolve().parents[1]
    env = {**os.environ, "PYTHONPATH": str(root)}
    env.pop("DISPLAY", None)
    cmd = [sys.executable, "-m", "gearbody.cli", "render", "planetary", "--frames", "2", "--t-end", "0.01"]
    cmd += ["--width", "160", "--height", "120", "--out", str(out), "--quiet"]
    done = subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in out.glob("frame_*.png")) == ["frame_0000.png", "frame_0001.png"]
    assert Image.open(out / "animation.gif").n_frames == 2
    again = ["render", "planetary", "--result", str(out), "--frames", "1", "--format", "none", "--quiet"]
    assert main([*again, "--out", str(tmp_path / "again"), "--width", "64", "--height", "48"]) == 0
    assert (
        main(
            [
                "render",
                "planetary",
                "--kinematic",
                "--frames",
                "1",
                "--format",
                "none",
                "--quiet",
                "--width",
                "64",
                "--height",
                "48",
                "--out",
                str(tmp_path / "kin"),
            ]
        )
        == 0
    )
