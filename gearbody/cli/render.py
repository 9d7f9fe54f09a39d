"""``gearbody render SCENE``: 3D frames and an animated GIF/MP4 of the drive moving as simulated
(:mod:`gearbody.render`)."""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import time
import zipfile
from pathlib import Path

from .common import (
    EXIT_OK,
    add_out,
    add_overwrite,
    add_set,
    add_wall_limit,
    check_out,
    check_wall_time,
    default_out,
    load,
    number,
    scenario_labels,
    scenario_overrides,
    usage_error,
    warn_if_backwards,
)

MAX_FRAMES = 2000  # gearbody.render.MAX_FRAMES (not imported here: the renderer loads on use)


def register(sub) -> argparse.ArgumentParser:
    """Add the command's parser to ``sub`` (the subparsers of ``gearbody``)."""
    # size: a flat list of add_argument calls, one per option, read top to bottom like --help
    rd = sub.add_parser(
        "render",
        help="3D pictures and an animated GIF/MP4 of the drive moving as simulated (no display needed)",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=(
            "Lay SCENE out in 3D from its own numbers (teeth, base radii, face widths, centre distances) "
            "and render N frames of it moving as in a result: DIR/frame_0000.png ... and "
            "DIR/animation.gif (or .mp4 with --format mp4 where ffmpeg is installed), with Exudyn's "
            "software raytracer: no display needed. Without --result, SCENE is simulated first "
            "and its result.npz and scenario.toml are kept in DIR (--kinematic: rigid rotation, no "
            "simulation). Lateral gear motion is magnified by "
            "--lateral-scale. --interactive replays in Exudyn's viewer instead (needs a display). DIR "
            "must be empty, hold a render of the same motion (the same resolved scenario, simulated, "
            "--kinematic, or the same --result file: the frames are drawn again with the new options) or "
            "be replaced with --overwrite. See docs/render.md."
        ),
    )
    rd.add_argument("scene", metavar="SCENE", help="scene name or .toml path")
    rd.add_argument("--result", type=Path, metavar="DIR", help="a 'gearbody run' folder (or its result.npz)")
    rd.add_argument(
        "--kinematic", action="store_true", help="no simulation: rigid rotation at synchronous speed"
    )
    add_set(rd, "override a scenario value (as for run)")
    rd.add_argument(
        "--t-end", type=number(gt=0), metavar="SECONDS", help="simulated time when simulating first"
    )
    rd.add_argument(
        "--frames",
        type=number(whole=True, ge=1, le=MAX_FRAMES),
        metavar="N",
        help=f"number of frames, at most {MAX_FRAMES} (default 24; --interactive: 400)",
    )
    rd.add_argument(
        "--start",
        type=number(ge=0),
        metavar="SECONDS",
        help="time of the first frame (default: one input-shaft revolution before --end)",
    )
    rd.add_argument(
        "--end", type=number(ge=0), metavar="SECONDS", help="time of the last frame (default: end of result)"
    )
    add_out(rd, "output folder (default: runs/SCENE/render)")
    add_overwrite(rd, "motion (resolved scenario, and simulated, --kinematic or the same --result)")
    rd.add_argument(
        "--format", choices=("gif", "mp4", "none"), default="gif", help="movie format (default gif)"
    )
    rd.add_argument(
        "--fps", type=number(ge=0.1, le=120), default=20.0, help="movie frames per second (default 20)"
    )
    rd.add_argument("--width", type=int, default=800, help="image width in pixels (default 800)")
    rd.add_argument("--height", type=int, default=600, help="image height in pixels (default 600)")
    rd.add_argument("--view", default="iso", help="camera preset: iso, front, back, side, top (default iso)")
    rd.add_argument(
        "--azimuth", type=number(), metavar="DEG", help="camera azimuth about the vertical, overrides --view"
    )
    rd.add_argument(
        "--elevation", type=number(ge=-90, le=90), metavar="DEG", help="camera elevation, overrides --view"
    )
    rd.add_argument(
        "--zoom",
        type=number(ge=0.05, le=50),
        default=1.0,
        help="magnification about the centre of the --frame box (default 1: the box fills the picture)",
    )
    rd.add_argument(
        "--frame",
        choices=("drive", "gears", "mesh"),
        default="drive",
        help="what the camera fits: the whole drive (default), the gears, or the first stage's mesh (its "
        "pitch point +- 6 modules: the teeth in contact; planetary: sun-planet 1, followed as it revolves); "
        "gears and mesh hide motor and machine",
    )
    rd.add_argument(
        "--housing",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="draw the transparent housing (default: the scenario's visual.housing)",
    )
    rd.add_argument(
        "--lateral-scale",
        type=number(ge=0, le=1e6),
        metavar="X",
        help="magnification of lateral gear motion (default: the scenario's visual.lateral_scale)",
    )
    rd.add_argument(
        "--lateral-static",
        action="store_true",
        help="magnify the whole lateral displacement, static deflection included "
        "(default: the motion about its mean over the frames)",
    )
    rd.add_argument(
        "--background", default="1,1,1", metavar="R,G,B", help="background colour, 0-1 each (default white)"
    )
    rd.add_argument("--interactive", action="store_true", help="replay in Exudyn's viewer (needs a display)")
    rd.add_argument("--quiet", action="store_true", help="no progress display")
    add_wall_limit(rd, "a simulation (SCENE without --result or --kinematic)")
    rd.set_defaults(handler=execute)
    return rd


def _sha256(path: Path) -> str:
    """The SHA-256 of a file (read in 1 MiB blocks)."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def execute(args) -> int:
    """Run ``gearbody render`` with the parsed ``args``; the exit code."""
    background = _background(args.background)
    if background is None:
        return usage_error("render", f"--background = {args.background!r}: give R,G,B in [0, 1]")
    out_dir = args.out or default_out(args.scene, "render")
    if not args.interactive:
        check_out(out_dir)
    from gearbody.folders import atomic_write
    from gearbody.render import RenderError, check_frames, render, view
    from gearbody.render.scene3d import has_display

    if args.interactive and not has_display():  # before a scene is simulated for a viewer never shown
        return usage_error(
            "render",
            "--interactive: no display to open Exudyn's viewer on (neither DISPLAY nor WAYLAND_DISPLAY is "
            "set); leave out --interactive to write the frames and the animation",
        )

    scenario = load(args.scene, scenario_overrides(args), scenario_labels(args))
    options = _options(args, background)
    folder = None
    stack = contextlib.ExitStack()  # the claim on the output folder, released at the end
    try:
        options.check()
        if args.frames is not None:  # before anything is simulated
            check_frames(args.frames, args.width, args.height, "none" if args.interactive else args.format)
        if args.t_end is not None and (args.result is not None or args.kinematic):
            raise RenderError(
                "--t-end applies only when SCENE is simulated first (not with --result or --kinematic)"
            )
        result, path, inside, motion = _motion(args, out_dir)
        if not args.interactive and (args.result is not None or args.kinematic):
            # the motion is known: whatever render would refuse is refused before the folder is claimed
            _check_known_motion(args, scenario, result, options)
        if not args.interactive:  # locked while it writes; the old outputs go just before the new ones
            folder = _claim(args, scenario, out_dir, motion, inside, stack)
        if args.result is None and not args.kinematic:
            result = _simulate(args, scenario)
        if folder is not None:  # the result read from --out stays (with its scenario.toml)
            folder.begin(keep=[path, path.with_name("scenario.toml")] if args.result is not None else [])
        if args.result is None and not args.kinematic and not args.interactive:
            from gearbody.model import dump_scenario

            # keep what was simulated: re-render with --result
            atomic_write(out_dir / "result.npz", result.save_npz)
            atomic_write(out_dir / "scenario.toml", lambda p: dump_scenario(scenario, p))
        if args.interactive:
            frames = 400 if args.frames is None else max(args.frames, 2)
            view(scenario, result, frames=frames, **_motion_options(args, options))
            return EXIT_OK
        t0 = time.perf_counter()
        frames = 24 if args.frames is None else args.frames
        out = render(
            scenario,
            result,
            out_dir=out_dir,
            frames=frames,
            **_motion_options(args, options),
            movie=args.format,
            progress=not args.quiet,
        )
        folder.finish()
    except RenderError as exc:
        message = str(exc)
        if args.result is not None and message.startswith("result: "):  # name the file the user gave
            message = f"--result = {args.result}: " + message.removeprefix("result: ")
        return usage_error("render", message)
    finally:
        stack.close()
    if not args.quiet:
        per = out.render_s / max(len(out.frames), 1)
        print(
            f"wrote {len(out.frames)} frames ({args.width}x{args.height}) to {out_dir}"
            + (f" and {out.movie.name}" if out.movie else "")
            + f" in {time.perf_counter() - t0:.1f} s ({per:.2f} s per frame, scene build {out.build_s:.1f} s)"
        )
    return EXIT_OK


def _background(text: str) -> tuple[float, ...] | None:
    """``--background R,G,B`` as three numbers in [0, 1], or None."""
    try:
        background = tuple(float(v) for v in text.split(","))
        if len(background) != 3 or not all(0 <= v <= 1 for v in background):
            raise ValueError
    except ValueError:
        return None
    return background


def _options(args, background: tuple[float, ...]):
    """The :class:`~gearbody.render.RenderOptions` of the command line."""
    from gearbody.render import RenderOptions

    return RenderOptions(
        width_px=args.width,
        height_px=args.height,
        view=args.view,
        azimuth_deg=args.azimuth,
        elevation_deg=args.elevation,
        zoom=args.zoom,
        frame=args.frame,
        housing=args.housing,
        background=background,
    )


def _motion_options(args, options) -> dict:
    """The options the viewer and the renderer share: the time span, the look, the lateral scale, fps."""
    return {
        "start_s": args.start,
        "end_s": args.end,
        "options": options,
        "lateral_scale": args.lateral_scale,
        "lateral_about_mean": not args.lateral_static,
        "fps": args.fps,
    }


def _motion(args, out_dir: Path) -> tuple:
    """``(result, its path, whether it is in --out, the motion's identity)``: the result of ``--result``
    read (None, None, False otherwise), the motion ``kinematic``, ``simulated`` or the result file's hash."""
    from gearbody.render import RenderError
    from gearbody.result import Result

    if args.result is None:
        return None, None, False, "kinematic" if args.kinematic else "simulated"
    path = args.result / "result.npz" if args.result.is_dir() else args.result
    if not path.is_file():
        raise RenderError(f"--result = {args.result}: no result.npz there (write one with 'gearbody run')")
    try:
        result = Result.load_npz(path)
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):  # not gearbody's npz
        raise RenderError(
            f"--result = {args.result}: {path.name} is not a result written by 'gearbody run'"
        ) from None
    inside = not args.interactive and path.resolve().parent == out_dir.resolve()
    # the same result file: the same motion; the result a render simulated into --out: its motion
    motion = "simulated" if inside else f"result sha256 {_sha256(path)}"
    return result, path, inside, motion


def _check_known_motion(args, scenario, result, options) -> None:
    """Whatever the renderer would refuse of a motion known before the run (--result, --kinematic)."""
    from gearbody.render import check_render

    check_render(
        scenario,
        result if args.result is not None else None,
        frames=24 if args.frames is None else args.frames,
        start_s=args.start,
        end_s=args.end,
        options=options,
        lateral_scale=args.lateral_scale,
        movie=args.format,
        fps=args.fps,
    )


def _claim(args, scenario, out_dir: Path, motion: str, inside: bool, stack: contextlib.ExitStack):
    """The claim on ``out_dir`` (entered on ``stack``) for this render's identity: the scenario and the
    motion, or the identity recorded there when it draws its own simulated result again."""
    from gearbody.folders import claim, read_manifest
    from gearbody.model import scenario_to_dict
    from gearbody.render import RenderError

    identity = {"scenario": scenario_to_dict(scenario), "motion": motion}
    recorded = read_manifest(out_dir) if args.result is not None and inside else None
    if (
        recorded
        and recorded["command"] == "render"
        and (recorded.get("identity") or {}).get("motion") == motion
    ):
        identity = recorded["identity"]  # its own simulated result, drawn again: the same run
    folder = stack.enter_context(claim(out_dir, "render", identity, overwrite=args.overwrite))
    if args.result is not None and inside and folder.mode != "same":
        raise RenderError(
            f"--result = {args.result}: it is in --out {out_dir}, which holds another run "
            "(--overwrite would remove it); render into another --out"
        )
    return folder


def _simulate(args, scenario):
    """The scene simulated (its wall time checked first), warned about if it ran backwards."""
    from gearbody.engine import simulate

    check_wall_time(scenario, args)
    if not args.quiet:
        print(f"simulating {args.scene} ({scenario.operation.t_end_s:g} s) ...")
    result = simulate(scenario, progress=not args.quiet)
    warn_if_backwards(result)
    return result
