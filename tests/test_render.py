"""Headless pictures of a simulated drive (Exudyn's software raytracer, no display)."""

import contextlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from gearbody.cli import main
from gearbody.engine import simulate
from gearbody.model import load_scenario
from gearbody.render import RenderError, RenderOptions, build_layout, render, render_images, view
from gearbody.render.poses import body_poses
from gearbody.render.scene3d import VisualSystem

W, H = 320, 240


@pytest.fixture(scope="module")
def one_stage():
    sc = load_scenario("one-stage", ["operation.t_end_s=0.03", 'operation.initial_state="steady"'])
    return sc, simulate(sc)


def _moving_mask(scenario, result, t, options):
    """Pixels covered by the moving bodies at time t: full picture vs the ground-only picture."""
    layout = build_layout(scenario)
    pose = body_poses(layout, result, np.array([t]))[0]
    images = []
    for bodies in (True, False):
        vs = VisualSystem(layout, options, bodies=bodies)
        vs.set_camera()
        vs.set_pose(pose, t)
        images.append(vs.image().astype(int))
    return np.abs(images[0] - images[1]).sum(axis=2) > 0


def test_two_frames_of_one_stage_have_size_content_and_differ_where_gears_turn(one_stage, tmp_path):
    sc, res = one_stage
    times = [0.02, 0.023]  # the pinion turns ~0.32 rad = 1.5 tooth pitches in between
    options = RenderOptions(width_px=W, height_px=H, view="front", frame="gears")
    out = render(sc, res, out_dir=tmp_path, frames=2, start_s=times[0], end_s=times[1], options=options)
    assert [p.name for p in out.frames] == ["frame_0000.png", "frame_0001.png"]
    a, b = (np.asarray(Image.open(p).convert("RGB")).astype(int) for p in out.frames)
    assert a.shape == b.shape == (H, W, 3)
    # not blank: a good part of the picture is not background, in several colours
    background = np.all(a == 255, axis=2)
    assert 0.1 < 1 - background.mean() < 0.98
    assert len(np.unique(a.reshape(-1, 3), axis=0)) >= 5  # gears, shafts, hubs, bearings, background
    # the frames differ, and only where the moving bodies are (gears, shafts, hubs)
    changed = np.abs(a - b).sum(axis=2) > 0
    assert changed.mean() > 0.002  # teeth and hub markers move; discs look the same
    moving = _moving_mask(sc, res, times[0], options) | _moving_mask(sc, res, times[1], options)
    assert (changed & ~moving).sum() <= 0.01 * changed.sum()
    # the animation holds both frames at the requested size
    gif = Image.open(out.movie)
    assert gif.size == (W, H) and gif.n_frames == 2


def test_same_pose_gives_the_same_picture(one_stage):
    sc, res = one_stage
    opts = RenderOptions(width_px=160, height_px=120)
    ((_, a),) = render_images(sc, res, [0.02], opts)
    ((_, b),) = render_images(sc, res, [0.02], opts)
    assert np.array_equal(a, b)


def test_damaged_tooth_shows_red(tmp_path):
    sc = load_scenario(
        "one-stage", ['condition.damaged_teeth=[{gear="pinion", tooth=0, stiffness_factor=0.5}]']
    )
    layout = build_layout(sc)
    opts = RenderOptions(width_px=W, height_px=H, view="back", frame="gears")

    def red_pixels(scenario):
        vs = VisualSystem(build_layout(scenario), opts)
        vs.set_camera()
        vs.set_pose(np.zeros(3 * len(layout.bodies)))
        img = vs.image().astype(int)
        return ((img[..., 0] > 150) & (img[..., 1] < 80) & (img[..., 2] < 80)).sum()

    assert red_pixels(sc) > 20 and red_pixels(load_scenario("one-stage")) == 0


def test_a_gear_exudyn_cannot_outline_is_drawn_from_gearbodys_outline_with_its_damaged_tooth():
    """Exudyn's involute generator leaves no root between 96 teeth at 20 deg (the idler gear of
    scenes/phm2009.toml); such a gear takes gearbody's outline, its marked teeth drawn as on the others."""
    import exudyn.machines as machines

    from gearbody.render.layout import DAMAGED, GearShape
    from gearbody.render.scene3d import _gear_graphics

    m = 0.0254 / 16
    with pytest.raises(ValueError):
        machines.InvoluteGear(module=m, nTeeth=96, pressureAngleDeg=20.0).GenerateGear()
    for teeth in (32, 96):  # Exudyn's outline, gearbody's
        gear = GearShape(teeth, m, 20.0, 0.0127, 0.0, 0.008, 0.0, (0.6, 0.6, 0.5, 1.0), ((0.1, DAMAGED),))
        assert len(_gear_graphics(gear)) == 2, teeth  # the gear and its damaged tooth
    sc = load_scenario(
        "phm2009", ['design.stages.1.damaged_teeth=[{gear="wheel",tooth=0,stiffness_factor=0.8}]']
    )
    vs = VisualSystem(build_layout(sc), RenderOptions(width_px=W, height_px=H, view="front", frame="gears"))
    vs.set_camera()
    vs.set_pose(np.zeros(3 * len(build_layout(sc).bodies)))
    img = vs.image().astype(int)
    assert ((img[..., 0] > 150) & (img[..., 1] < 80) & (img[..., 2] < 80)).sum() > 5


def test_cli_render_writes_frames_and_gif_without_display(tmp_path, monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    out = tmp_path / "pics"
    code = main(
        [
            "render",
            "one-stage",
            "--kinematic",
            "--frames",
            "3",
            "--width",
            "160",
            "--height",
            "120",
            "--out",
            str(out),
            "--quiet",
        ]
    )
    assert code == 0
    assert sorted(p.name for p in out.glob("*.png")) == ["frame_0000.png", "frame_0001.png", "frame_0002.png"]
    assert Image.open(out / "animation.gif").n_frames == 3


@pytest.mark.parametrize(
    "args, message",
    [
        (["--frames", "0"], "frames = 0"),
        (["--view", "sideways"], "view = 'sideways'"),
        (["--width", "5"], "width_px = 5"),
        (["--zoom", "0"], "zoom = 0"),
        (["--start", "5.0"], "start_s = 5"),
        (["--background", "1,1"], "--background"),
    ],
)
def test_cli_render_bad_options_name_the_value(tmp_path, capsys, args, message):
    code = main(["render", "one-stage", "--kinematic", "--out", str(tmp_path), "--quiet", *args])
    assert code == 2
    assert message in capsys.readouterr().err


def test_cli_render_refuses_missing_result(tmp_path, capsys):
    assert main(["render", "one-stage", "--result", str(tmp_path), "--quiet"]) == 2
    assert "no result.npz" in capsys.readouterr().err


def test_interactive_view_needs_a_display_and_its_solution_replays_the_poses(one_stage, monkeypatch):
    import exudyn as exu
    from exudyn.basicUtilities import SetSolutionState

    sc, res = one_stage
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(RenderError, match="display"):
        view(sc, res)
    layout = build_layout(sc)
    times = np.array([0.01, 0.02])
    poses = body_poses(layout, res, times)
    vs = VisualSystem(layout, RenderOptions(width_px=64, height_px=48))
    solution = vs.solution(times, poses)
    SetSolutionState(vs.mbs, solution, 1, exu.ConfigurationType.Visualization, sendRedrawSignal=False)
    assert vs.mbs.systemData.GetODE2Coordinates(exu.ConfigurationType.Visualization) == pytest.approx(
        poses[1]
    )


def test_cli_render_simulates_keeps_the_result_and_rerenders_it(tmp_path):
    out = tmp_path / "r"
    args = [
        "render",
        "one-stage",
        "--set",
        'operation.initial_state="steady"',
        "--width",
        "96",
        "--height",
        "72",
    ]
    assert main([*args, "--t-end", "0.02", "--frames", "2", "--out", str(out), "--quiet"]) == 0
    assert (out / "result.npz").is_file() and (out / "scenario.toml").is_file()
    assert (
        main([*args, "--result", str(out), "--frames", "1", "--format", "none", "--out", str(out), "--quiet"])
        == 0
    )
    assert sorted(p.name for p in out.glob("frame_*.png")) == ["frame_0000.png"]
    assert not (out / "animation.gif").exists()  # the old movie went with the old frames
    assert main([*args, "--result", str(out), "--t-end", "1", "--out", str(out), "--quiet"]) == 2


def test_the_mesh_frame_is_centred_on_the_pitch_point_and_shows_both_gears_teeth(one_stage):
    """Issue 17: a large --zoom of --frame gears centred inside the wheel and showed its hub."""
    sc, res = one_stage
    layout = build_layout(sc)
    (pinion, gp), (wheel, gw) = layout.gears[:2]
    lo, hi = (np.array(v) for v in layout.mesh_bounds_m())
    centre = 0.5 * (lo + hi)[:2]
    to_pinion = np.hypot(*(centre - np.array(pinion.axis_xy_m)))
    to_wheel = np.hypot(*(centre - np.array(wheel.axis_xy_m)))
    assert to_pinion / to_wheel == pytest.approx(gp.teeth / gw.teeth)  # the operating pitch point
    assert to_pinion == pytest.approx(gp.pitch_radius_m, rel=1e-4)
    assert hi[0] - lo[0] == pytest.approx(12 * gp.module_m)
    ((_, img),) = render_images(
        sc, res, [0.02], RenderOptions(width_px=W, height_px=H, view="front", frame="mesh")
    )
    colours, counts = np.unique(img.reshape(-1, 3), axis=0, return_counts=True)
    top = colours[np.argsort(counts)[::-1][:3]]
    shares = np.sort(counts)[::-1][:3] / counts.sum()
    assert shares[1] > 0.2  # two gears each fill a good part of the picture (the third: background)
    assert not any(np.all(c == 255) for c in top[:2])
    # the teeth interleave: along the middle column the colour changes several times
    col = img[:, W // 2].astype(int)
    changes = np.count_nonzero(np.abs(np.diff(col, axis=0)).sum(axis=1) > 60)
    assert changes >= 4


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the parent-death signal is Linux's")
def test_a_render_killed_while_it_encodes_leaves_no_encoder_running(tmp_path):
    """SIGKILL to gearbody while ffmpeg encodes its MP4: the encoder dies with it (a fake ffmpeg on PATH
    that waits; the real one would be left running, writing a movie nobody reads)."""
    fake = tmp_path / "bin" / "ffmpeg"
    fake.parent.mkdir()
    pid_file = tmp_path / "ffmpeg.pid"
    fake.write_text(f'#!/bin/sh\necho $$ > "{pid_file}"\nexec sleep 120\n')
    fake.chmod(0o755)
    env = {**os.environ, "PATH": f"{fake.parent}{os.pathsep}{os.environ['PATH']}", "MPLBACKEND": "Agg"}
    args = ["render", "one-stage", "--kinematic", "--frames", "2", "--format", "mp4", "--width", "32"]
    args += ["--height", "24", "--quiet", "--out", str(tmp_path / "out")]
    proc = subprocess.Popen([sys.executable, "-m", "gearbody.cli", *args], env=env, start_new_session=True)
    try:
        t0 = time.monotonic()
        while not (pid_file.exists() and pid_file.read_text().strip()):
            assert proc.poll() is None and time.monotonic() - t0 < 120, "the encoder never started"
            time.sleep(0.05)
        encoder = int(pid_file.read_text())
        proc.kill()
        proc.wait()
        t0 = time.monotonic()
        while _alive(encoder) and time.monotonic() - t0 < 10:
            time.sleep(0.05)
        assert not _alive(encoder), "the encoder outlived the render"
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        with contextlib.suppress(OSError, ValueError):
            os.kill(int(pid_file.read_text()), signal.SIGKILL)


def _alive(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False
