"""3D pictures and animations of a drive, laid out from the scenario and moved by a Result.

``render(scenario, result, out_dir=...)`` writes PNG frames and an animated GIF (MP4 with ffmpeg)
without a display, using Exudyn's software raytracer; ``view(scenario, result)`` replays the result
in Exudyn's interactive viewer. See docs/render.md.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..model import Scenario, scenario_to_dict
from ..model.kinds import stage_kinds
from ..result import Result
from .layout import Layout, build_layout
from .movie import FORMATS, ffmpeg_available, write_gif, write_mp4, write_png
from .poses import (
    MAX_FRAMES,
    RenderError,
    body_poses,
    check_drawable,
    check_frames,
    frame_times,
    kinematic_result,
)
from .scene3d import VIEWS, RenderOptions, has_display

__all__ = [
    "FORMATS",
    "MAX_FRAMES",
    "VIEWS",
    "Layout",
    "RenderError",
    "RenderOptions",
    "RenderOutput",
    "build_layout",
    "check_frames",
    "check_render",
    "check_result_matches",
    "kinematic_result",
    "render",
    "render_images",
    "view",
]


@dataclass
class RenderOutput:
    """What :func:`render` wrote: the frame PNGs, their times [s], the movie (or None), and the seconds
    spent building the visual system and rendering."""

    frames: list[Path] = field(default_factory=list)
    times_s: np.ndarray | None = None
    movie: Path | None = None
    build_s: float = 0.0
    render_s: float = 0.0


def check_result_matches(scenario: Scenario, result: Result) -> None:
    """Refuse a result simulated from a different drive (other teeth counts or stage count)."""
    saved = result.meta.get("scenario") if isinstance(result.meta, dict) else None
    if not isinstance(saved, dict):
        return
    design = saved.get("design", {})
    stages = design.get("stages") or [{"pinion": design.get("pinion", {}), "wheel": design.get("wheel", {})}]
    ours = [_teeth(st) for st in scenario_to_dict(scenario)["design"]["stages"]]
    theirs = [_teeth(st) for st in stages]
    if theirs != ours:
        raise RenderError(
            f"result: simulated for teeth {theirs}, but the scene has {ours}; render the result with its "
            "own scenario (DIR/scenario.toml)"
        )


def _teeth(table: dict) -> tuple:
    """The teeth a stage table states, as its kind's render parts read them (``render_parts.teeth``:
    (pinion, wheel), or ('planetary', sun, planet, ring, planets)); a kind without: its type alone.
    A table without a type is of the first kind (as the scenario reads it)."""
    kinds = {kind.name: kind for kind in stage_kinds()}
    kind = kinds.get(table.get("type", stage_kinds()[0].name))
    teeth = getattr(kind.render_parts, "teeth", None) if kind is not None else None
    return teeth(table) if teeth is not None else (table.get("type"),)


def _motion(scenario: Scenario, result: Result | None, layout: Layout, until_s: float = 0.0) -> Result:
    """The result to draw: the given one (checked against the drive), or rigid rotation at the
    synchronous speed for one input revolution (at least until ``until_s``)."""
    if result is None:
        speed = scenario.design.motor.synchronous_speed_rad_s
        duration = max(2 * np.pi / speed, until_s)
        return kinematic_result(layout.input_factor * speed, duration, signal=layout.input_signal)
    check_result_matches(scenario, result)
    check_drawable(layout, result)
    return result


def _images(layout: Layout, result: Result, times_s, options, lateral_scale, lateral_about_mean):
    from .scene3d import VisualSystem

    poses = body_poses(layout, result, np.asarray(times_s, dtype=float), lateral_scale, lateral_about_mean)
    system = VisualSystem(layout, options)
    # the sun-planet 1 mesh revolves with the carrier: the mesh camera follows it
    follow = system.options.frame == "mesh" and layout.mesh_pair is not None
    system.set_camera()
    for t, row in zip(times_s, poses, strict=True):
        if follow:
            system.set_camera(row)
        system.set_pose(row, t)
        yield float(t), system.image()


def render_images(
    scenario: Scenario,
    result: Result | None,
    times_s: np.ndarray,
    options: RenderOptions | None = None,
    lateral_scale: float | None = None,
    lateral_about_mean: bool = True,
):
    """Yield (time, RGB image) for each time: the drive in the result's pose, raytraced (no result:
    rigid rotation at the synchronous speed)."""
    layout = build_layout(scenario)
    result = _motion(scenario, result, layout, float(np.max(times_s)))
    yield from _images(layout, result, times_s, options, lateral_scale, lateral_about_mean)


def _plan(scenario, result, frames, start_s, end_s, options, lateral_scale, movie, fps):
    """(layout, motion, frame times) of a render, every refusal of :func:`render` raised first."""
    if movie not in FORMATS:
        raise RenderError(f"movie = {movie!r}: must be one of {', '.join(FORMATS)}")
    if not 0.1 <= fps <= 120:
        raise RenderError(f"fps = {fps:g}: must lie in [0.1, 120]")
    if movie == "mp4" and not ffmpeg_available():
        raise RenderError("movie = 'mp4': ffmpeg is not installed (use 'gif', or install ffmpeg)")
    if lateral_scale is not None and not 0 <= lateral_scale <= 1e6:
        raise RenderError(f"lateral_scale = {lateral_scale:g}: must lie in [0, 1e6]")
    options = options or RenderOptions()
    options.check()
    check_frames(frames, options.width_px, options.height_px, movie)
    layout = build_layout(scenario)
    result = _motion(scenario, result, layout)
    return layout, result, frame_times(result, frames, start_s, end_s, layout.input_signal)


def check_render(
    scenario: Scenario,
    result: Result | None = None,
    *,
    frames: int = 24,
    start_s: float | None = None,
    end_s: float | None = None,
    options: RenderOptions | None = None,
    lateral_scale: float | None = None,
    movie: str = "gif",
    fps: float = 20.0,
) -> None:
    """RenderError for everything :func:`render` would refuse with these arguments (the movie, its
    frames, the frame times in the result, the result against the drive), before anything is drawn
    or written: the command line checks before it claims its output folder."""
    _plan(scenario, result, frames, start_s, end_s, options, lateral_scale, movie, fps)


def render(
    scenario: Scenario,
    result: Result | None = None,
    *,
    out_dir: str | Path,
    frames: int = 24,
    start_s: float | None = None,
    end_s: float | None = None,
    options: RenderOptions | None = None,
    lateral_scale: float | None = None,
    lateral_about_mean: bool = True,
    movie: str = "gif",
    fps: float = 20.0,
    progress: bool = False,
) -> RenderOutput:
    """Render ``frames`` pictures of the drive moving as in ``result`` into ``out_dir``.

    Writes ``frame_0000.png`` ... and ``animation.gif`` (``movie='gif'``) or ``animation.mp4``
    (``movie='mp4'``, needs ffmpeg), or no movie (``'none'``). Without a result, the drive turns
    rigidly at its synchronous speed (no simulation). Lateral gear motion is magnified by
    ``lateral_scale`` (default: the scenario's ``visual.lateral_scale``), about its mean over the
    frames unless ``lateral_about_mean`` is False (then the static deflection is magnified too).
    """
    plan = _plan(scenario, result, frames, start_s, end_s, options, lateral_scale, movie, fps)
    layout, result, times = plan
    options = options or RenderOptions()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    for old in [*out.glob("frame_*.png"), out / "animation.gif", out / "animation.mp4"]:
        old.unlink(missing_ok=True)
    output = RenderOutput(times_s=times)
    t0 = time.perf_counter()
    images = _images(layout, result, times, options, lateral_scale, lateral_about_mean)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(times), unit="frame", desc="render")
    first = True
    for k, (_, image) in enumerate(images):
        if first:
            output.build_s = time.perf_counter() - t0
            t1, first = time.perf_counter(), False
        output.frames.append(write_png(image, out / f"frame_{k:04d}.png"))
        if bar is not None:
            bar.update()
    if bar is not None:
        bar.close()
    output.render_s = time.perf_counter() - t1
    if movie == "gif" and len(output.frames) > 1:
        output.movie = write_gif(output.frames, out / "animation.gif", fps)
    elif movie == "mp4" and len(output.frames) > 1:
        output.movie = write_mp4(out / "frame_%04d.png", out / "animation.mp4", fps)
    return output


def view(
    scenario: Scenario,
    result: Result | None = None,
    *,
    frames: int = 400,
    start_s: float | None = None,
    end_s: float | None = None,
    options: RenderOptions | None = None,
    lateral_scale: float | None = None,
    lateral_about_mean: bool = True,
    fps: float = 25.0,
) -> None:
    """Replay the result in Exudyn's interactive viewer (needs a display), ``fps`` frames per second."""
    from .scene3d import VisualSystem

    if not has_display():
        raise RenderError("no display: the interactive viewer needs one; use render() for pictures")
    layout = build_layout(scenario)
    result = _motion(scenario, result, layout)
    times = frame_times(result, frames, start_s, end_s, layout.input_signal)
    poses = body_poses(layout, result, times, lateral_scale, lateral_about_mean)
    VisualSystem(layout, options).view_interactive(times, poses, 1.0 / fps)
