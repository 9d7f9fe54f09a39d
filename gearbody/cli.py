"""Command line: ``gearbody list | run | modes | validate | sweep | render``."""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

EPILOG = """examples:
  gearbody list
  gearbody run one-stage --out runs/one-stage
  gearbody run one-stage --set production.error_mode.e_um=15 --set design.coupling.damping_Nms_per_rad=1000
  gearbody run my-drive.toml --t-end 1.0 --out runs/mine
  gearbody modes one-stage
  gearbody mesh one-stage-geometry --set 'condition.damaged_teeth=[{gear="pinion",tooth=0,crack_depth_mm=2}]'
  gearbody validate one-stage
  gearbody render industrial-two-stage --frames 100 --out runs/pictures
  gearbody render one-stage --result runs/one-stage --view front --frame gears --zoom 3
"""


def _add_set(parser: argparse.ArgumentParser, help: str) -> None:
    parser.add_argument(
        "--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE", help=help
    )


def _overrides(args) -> list[str]:
    """The --set overrides, plus operation.t_end_s from --t-end when given."""
    overrides = list(args.overrides)
    if args.t_end is not None:
        overrides.append(f"operation.t_end_s={args.t_end!r}")
    return overrides


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="gearbody",
        description="Gearbox vibration simulation for diagnostics (Exudyn multibody engine).",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    sub.add_parser("list", help="list the shipped scenes, one per line (name first, then its title)")

    run = sub.add_parser(
        "run",
        help="simulate a scene or scenario file and write results and plots",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=(
            "Simulate SCENE and write DIR/result.npz (named arrays: time, mesh_force_N, kd, "
            "angles, speeds, accelerations, ...), DIR/scenario.toml (fully resolved, re-runnable "
            "with 'gearbody run DIR/scenario.toml'), DIR/summary.json and PNG plots (K_d over "
            "time, K_d folded over the mesh period, spectrum of the pinion acceleration)."
        ),
    )
    run.add_argument(
        "scene", metavar="SCENE", help="scene name (see 'gearbody list') or path to a .toml scenario"
    )
    _add_set(
        run,
        "override a scenario value by its dotted key, e.g. production.error_mode.e_um=15 "
        '(repeatable; values are TOML: numbers, true/false, [arrays], "strings")',
    )
    run.add_argument("--t-end", type=float, metavar="SECONDS", help="simulated time (sets operation.t_end_s)")
    run.add_argument("--out", type=Path, metavar="DIR", help="output folder (default: runs/SCENE)")
    run.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    run.add_argument(
        "--report",
        action="store_true",
        help="also write DIR/report.html: summary, labelled spectrum, folded K_d, TSA and indicators",
    )
    run.add_argument("--quiet", action="store_true", help="no progress display and no summary on screen")

    modes = sub.add_parser(
        "modes", help="natural frequencies (Hz) at mean mesh stiffness, and resonance speeds"
    )
    modes.add_argument("scene", metavar="SCENE", help="scene name or .toml path")
    _add_set(modes, "override a scenario value (as for run)")
    modes.add_argument("--harmonics", type=int, default=3, help="mesh harmonics to list resonance speeds for")

    me = sub.add_parser(
        "mesh",
        help="gear mesh report: geometry table, k_z over the mesh cycle (healthy, damaged teeth), static TE",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=(
            "Print each stage's gear geometry and stiffness table (teeth, module, pressure angles, radii, "
            "contact ratios, backlash, k_z single/double/mean, ISO 6336-1 method B, potential-energy mean) "
            "and write DIR/mesh_stage<N>.png: k_z over the mesh cycle, k_z around each damaged tooth next "
            "to the healthy curve, and the static transmission error F/k - E + l_u under load over a "
            "pinion turn. Evaluated with the solver's own mesh law, no simulation. See docs/mesh.md."
        ),
    )
    me.add_argument("scene", metavar="SCENE", help="scene name or .toml path")
    _add_set(me, "override a scenario value (as for run)")
    me.add_argument(
        "--stage", type=int, metavar="N", help="only stage N (1 = first in power-flow order; default: all)"
    )
    me.add_argument("--out", type=Path, metavar="DIR", help="output folder (default: runs/SCENE/mesh)")
    me.add_argument(
        "--load",
        type=float,
        default=1.0,
        metavar="FRACTION",
        help="static TE at this fraction of each stage's rated force (default 1)",
    )
    me.add_argument("--no-plots", action="store_true", help="print the tables only, write no PNGs")

    val = sub.add_parser(
        "validate", help="compare gearbody with the independent ODE reference (exit 1 above tolerance)"
    )
    val.add_argument("scenes", metavar="SCENE", nargs="*", help="scenes to validate (default: all)")
    val.add_argument("--short", action="store_true", help="short runs (as in the test suite)")
    val.add_argument("--tolerance", type=float, default=0.5, help="max |dF|/F_rated in %% (default 0.5)")

    sw = sub.add_parser(
        "sweep",
        help="parameter study: many runs with scenario keys varied (grid, Monte-Carlo, seeds), resumable",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=(
            "Run SCENE once per case of a study: the grid of the --vary lists, times --samples random "
            "draws of the --random keys, times meta.seed = 1..N of --seeds. Writes DIR/study.json, "
            "DIR/cases/<id>/ (result.npz, scenario.toml, summary.json, or error.json), DIR/summary.csv "
            "and DIR/<value>_vs_<key>.png. Rerunning the same command on DIR resumes the study. Exit "
            "code 0: all cases ran; 1: some failed; 2: bad input. See docs/sweep.md."
        ),
        epilog="examples:\n"
        "  gearbody sweep one-stage --vary production.error_mode.e_um=0:20:5 --out runs/kd-vs-e\n"
        "  gearbody sweep two-wheel --vary production.error_mode.e_um=5,10 --seeds 4 --t-end 0.2 \\\n"
        "      --out runs/seeds\n"
        "  gearbody sweep one-stage --random 'production.error_mode.a=uniform(0.2,0.8)' --samples 50 \\\n"
        "      --scheduler tcp://head:8786 --no-results --out runs/mc\n",
    )
    sw.add_argument("scene", metavar="SCENE", help="scene name or .toml path")
    sw.add_argument(
        "--vary",
        action="append",
        default=[],
        metavar="KEY=SPEC",
        help="grid key: KEY=start:stop:count (linspace, both ends included) or KEY=v1,v2,... "
        "(TOML values); repeatable, the cases are the cartesian product",
    )
    sw.add_argument(
        "--random",
        action="append",
        default=[],
        metavar="KEY=DIST",
        help="Monte-Carlo key: KEY=uniform(a,b) | normal(mu,sigma) | choice(v1,v2,...); repeatable",
    )
    sw.add_argument("--samples", type=int, metavar="N", help="random draws of the --random keys")
    sw.add_argument(
        "--study-seed", type=int, default=0, metavar="S", help="seed of the random draws (default 0)"
    )
    sw.add_argument("--seeds", type=int, metavar="N", help="vary meta.seed (random tooth errors) over 1..N")
    _add_set(sw, "fixed override of every case (as for run)")
    sw.add_argument("--t-end", type=float, metavar="SECONDS", help="simulated time of every case")
    sw.add_argument(
        "--workers", type=int, metavar="N", help="local processes (default: all cores; 1: serial)"
    )
    sw.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on a Dask cluster, e.g. tcp://host:8786 (needs: pip install gearbody[sweep])",
    )
    sw.add_argument(
        "--plot-value",
        default="kd_max_final",
        metavar="NAME",
        help="summary value to plot (default kd_max_final)",
    )
    sw.add_argument("--plot-key", metavar="KEY", help="varied key on the plot's x axis (default: the first)")
    sw.add_argument("--no-results", action="store_true", help="do not keep result.npz (summaries only)")
    sw.add_argument("--retry-failed", action="store_true", help="on resume, rerun the cases that failed")
    sw.add_argument("--quiet", action="store_true", help="no progress bar and no table")
    sw.add_argument("--out", type=Path, required=True, metavar="DIR", help="output folder of the study")
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
            "--lateral-scale. --interactive replays in Exudyn's viewer instead (needs a display). "
            "See docs/render.md."
        ),
    )
    rd.add_argument("scene", metavar="SCENE", help="scene name or .toml path")
    rd.add_argument("--result", type=Path, metavar="DIR", help="a 'gearbody run' folder (or its result.npz)")
    rd.add_argument(
        "--kinematic", action="store_true", help="no simulation: rigid rotation at synchronous speed"
    )
    _add_set(rd, "override a scenario value (as for run)")
    rd.add_argument("--t-end", type=float, metavar="SECONDS", help="simulated time when simulating first")
    rd.add_argument(
        "--frames", type=int, metavar="N", help="number of frames (default 24; --interactive: 400)"
    )
    rd.add_argument(
        "--start",
        type=float,
        metavar="SECONDS",
        help="time of the first frame (default: one input-shaft revolution before --end)",
    )
    rd.add_argument(
        "--end", type=float, metavar="SECONDS", help="time of the last frame (default: end of result)"
    )
    rd.add_argument("--out", type=Path, metavar="DIR", help="output folder (default: runs/SCENE/render)")
    rd.add_argument(
        "--format", choices=("gif", "mp4", "none"), default="gif", help="movie format (default gif)"
    )
    rd.add_argument("--fps", type=float, default=20.0, help="movie frames per second (default 20)")
    rd.add_argument("--width", type=int, default=800, help="image width in pixels (default 800)")
    rd.add_argument("--height", type=int, default=600, help="image height in pixels (default 600)")
    rd.add_argument("--view", default="iso", help="camera preset: iso, front, back, side, top (default iso)")
    rd.add_argument(
        "--azimuth", type=float, metavar="DEG", help="camera azimuth about the vertical, overrides --view"
    )
    rd.add_argument("--elevation", type=float, metavar="DEG", help="camera elevation, overrides --view")
    rd.add_argument("--zoom", type=float, default=1.0, help="magnification (1 = whole drive or all gears)")
    rd.add_argument(
        "--frame",
        choices=("drive", "gears"),
        default="drive",
        help="what the camera fits: the whole drive or the gears (hides motor and machine)",
    )
    rd.add_argument(
        "--housing",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="draw the transparent housing (default: the scenario's visual.housing)",
    )
    rd.add_argument(
        "--lateral-scale",
        type=float,
        metavar="X",
        help="magnification of lateral gear motion (default: the scenario's visual.lateral_scale)",
    )
    rd.add_argument(
        "--lateral-static",
        action="store_true",
        help="magnify the whole lateral displacement, static deflection included "
        "(default: the motion about its mean over the frames)",
    )
    rd.add_argument("--background", default="1,1,1", metavar="R,G,B", help="background colour, 0-1 each")
    rd.add_argument("--interactive", action="store_true", help="replay in Exudyn's viewer (needs a display)")
    rd.add_argument("--quiet", action="store_true", help="no progress display")
    return p


def _load(scene: str, overrides: list[str]):
    from .model import load_scenario

    return load_scenario(scene, overrides)


def cmd_list(_args) -> int:
    from .model import load_scenario
    from .scenes import list_scenes

    for name in list_scenes():
        print(f"{name}\t{load_scenario(name).meta.title}")
    return 0


def cmd_run(args) -> int:
    from .engine import simulate
    from .model import dump_scenario
    from .plotting.run import write_plots
    from .reports.summary import summarize

    overrides = _overrides(args)
    scenario = _load(args.scene, overrides)
    out = args.out or Path("runs") / (Path(args.scene).stem if args.scene.endswith(".toml") else args.scene)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    result = simulate(scenario, progress=not args.quiet)
    result.save_npz(out / "result.npz")
    dump_scenario(scenario, out / "scenario.toml")
    summary = summarize(result)
    summary["wall_time_s"] = time.perf_counter() - t0
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    plots = [] if args.no_plots else write_plots(result, out)
    if args.report:
        from .reports.html import write_report

        write_report(result, out / "report.html")
    if not args.quiet:
        print(f"{scenario.meta.title}")
        for key in (
            "kd_max",
            "kd_max_final",
            "kd_mean_final",
            "separation_fraction",
            "mesh_frequency_hz",
            "mean_speed_rad_s",
            "simulated_time_s",
            "wall_time_s",
        ):
            v = summary[key]
            print(f"  {key:22s} {v:.4g}" if isinstance(v, float) else f"  {key:22s} {v}")
        print(
            f"wrote {out}/result.npz, scenario.toml, summary.json"
            + (f", {len(plots)} plots" if plots else "")
            + (", report.html" if args.report else "")
        )
    return 0


def cmd_modes(args) -> int:
    from .analysis.modal import resonance_speeds_rad_s
    from .engine import scene_modes

    scenario = _load(args.scene, args.overrides)
    modes = scene_modes(scenario)
    z1 = scenario.stages[0].pinion.teeth
    k = ", ".join(f"{x:.4g}" for x in modes.mean_mesh_stiffness_N_per_m)
    print(f"{scenario.meta.title}")
    print(f"linearised at mean mesh stiffness {k} N/m; DOFs: {', '.join(modes.dof_names)}")
    speeds = resonance_speeds_rad_s(modes, z1, args.harmonics)
    head = "".join(f"{f'w({h}f_z) rad/s':>18}" for h in range(1, args.harmonics + 1))
    width = max(len(modes.label(m)) for m in range(len(modes.frequencies_hz))) + 2
    print(f"{'mode':>4} {'f_n Hz':>12}  {'dominant motion (share of kinetic energy)':<{width}}{head}")
    for m, f in enumerate(modes.frequencies_hz):
        cols = "".join(f"{'-' if math.isnan(s) else f'{s:.2f}':>18}" for s in speeds[:, m])
        print(f"{m + 1:>4} {f:12.3f}  {modes.label(m):<{width}}{cols}")
    print(f"(w(k f_z) = pinion speed at which the k-th mesh harmonic z1 w k / 2 pi meets f_n; z1 = {z1})")
    return 0


def cmd_mesh(args) -> int:
    from .plotting.mesh import plot_stage
    from .reports.mesh import damage_windows, static_transmission_error, stiffness_cycle, summary_text

    scenario = _load(args.scene, args.overrides)
    count = len(scenario.stages)
    if args.stage is not None and not 1 <= args.stage <= count:
        print(
            f"gearbody mesh: --stage = {args.stage}: {args.scene} has {count} stage(s); give 1..{count}",
            file=sys.stderr,
        )
        return 2
    if not (math.isfinite(args.load) and args.load >= 0):
        print(
            f"gearbody mesh: --load = {args.load!r}: give a fraction >= 0 of the rated force", file=sys.stderr
        )
        return 2
    name = Path(args.scene).stem if args.scene.endswith(".toml") else args.scene
    out = args.out or Path("runs") / name / "mesh"
    stages = range(count) if args.stage is None else [args.stage - 1]
    print(f"{scenario.meta.title}")
    written = []
    for k in stages:
        cycle, windows = stiffness_cycle(scenario, k), damage_windows(scenario, k)
        te = static_transmission_error(scenario, k, args.load)
        print(summary_text(scenario, k, args.load, cycle=cycle, windows=windows, te=te))
        if not args.no_plots:
            written.append(plot_stage(scenario, k, out / f"mesh_stage{k + 1}.png", cycle, windows, te))
    if written:
        print(f"wrote {', '.join(str(p) for p in written)}")
    return 0


def cmd_validate(args) -> int:
    from .validation.compare import run_validation

    ok = run_validation(args.scenes or None, short=args.short, tolerance_percent=args.tolerance)
    return 0 if ok else 1


def cmd_sweep(args) -> int:
    from .studies import SweepSpecError, run_study

    overrides = _overrides(args)
    try:
        study = run_study(
            args.scene,
            out_dir=args.out,
            vary=args.vary,
            random=args.random,
            samples=args.samples,
            study_seed=args.study_seed,
            seeds=args.seeds,
            base_overrides=overrides,
            workers=args.workers,
            scheduler=args.scheduler,
            progress=not args.quiet,
            save_results=not args.no_results,
            retry_failed=args.retry_failed,
            plot_value=args.plot_value,
            plot_key=args.plot_key,
        )
    except (SweepSpecError, ImportError) as exc:
        print(f"gearbody sweep: {exc}", file=sys.stderr)
        return 2
    if not args.quiet:
        print(study.table())
    return 0 if study.all_ok else 1


def cmd_render(args) -> int:
    from .render import RenderError, RenderOptions, render, view
    from .result import Result

    overrides = _overrides(args)
    scenario = _load(args.scene, overrides)
    try:
        background = tuple(float(v) for v in args.background.split(","))
        if len(background) != 3:
            raise ValueError
    except ValueError:
        print(f"gearbody render: --background = {args.background!r}: give R,G,B in [0, 1]", file=sys.stderr)
        return 2
    options = RenderOptions(
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
    try:
        options.check()
        if args.t_end is not None and (args.result is not None or args.kinematic):
            raise RenderError(
                "--t-end applies only when SCENE is simulated first (not with --result or --kinematic)"
            )
        if args.result is not None:
            path = args.result / "result.npz" if args.result.is_dir() else args.result
            if not path.is_file():
                raise RenderError(
                    f"--result = {args.result}: no result.npz there (write one with 'gearbody run')"
                )
            result = Result.load_npz(path)
        elif args.kinematic:
            result = None
        else:
            from .engine import simulate

            if not args.quiet:
                print(f"simulating {args.scene} ({scenario.operation.t_end_s:g} s) ...")
            result = simulate(scenario, progress=not args.quiet)
        name = Path(args.scene).stem if args.scene.endswith(".toml") else args.scene
        out_dir = args.out or Path("runs") / name / "render"
        if args.result is None and not args.kinematic and not args.interactive:
            from .model import dump_scenario

            out_dir.mkdir(parents=True, exist_ok=True)  # keep what was simulated: re-render with --result
            result.save_npz(out_dir / "result.npz")
            dump_scenario(scenario, out_dir / "scenario.toml")
        if args.interactive:
            view(
                scenario,
                result,
                frames=400 if args.frames is None else max(args.frames, 2),
                start_s=args.start,
                end_s=args.end,
                options=options,
                lateral_scale=args.lateral_scale,
                lateral_about_mean=not args.lateral_static,
                fps=args.fps,
            )
            return 0
        t0 = time.perf_counter()
        out = render(
            scenario,
            result,
            out_dir=out_dir,
            frames=24 if args.frames is None else args.frames,
            start_s=args.start,
            end_s=args.end,
            options=options,
            lateral_scale=args.lateral_scale,
            lateral_about_mean=not args.lateral_static,
            movie=args.format,
            fps=args.fps,
            progress=not args.quiet,
        )
    except RenderError as exc:
        print(f"gearbody render: {exc}", file=sys.stderr)
        return 2
    if not args.quiet:
        per = out.render_s / max(len(out.frames), 1)
        print(
            f"wrote {len(out.frames)} frames ({args.width}x{args.height}) to {out_dir}"
            + (f" and {out.movie.name}" if out.movie else "")
            + f" in {time.perf_counter() - t0:.1f} s ({per:.2f} s per frame, scene build {out.build_s:.1f} s)"
        )
    return 0


def main(argv: list[str] | None = None) -> int:
    from .engine.simulate import SimulationError
    from .model import ScenarioError

    args = _parser().parse_args(argv)
    handlers = {
        "list": cmd_list,
        "run": cmd_run,
        "modes": cmd_modes,
        "mesh": cmd_mesh,
        "validate": cmd_validate,
        "sweep": cmd_sweep,
        "render": cmd_render,
    }
    try:
        return handlers[args.command](args)
    except ScenarioError as exc:
        print(f"gearbody: invalid scenario: {exc}", file=sys.stderr)
        return 2
    except SimulationError as exc:
        print(f"gearbody: simulation failed: {exc}", file=sys.stderr)
        return 3


if __name__ == "__main__":
    sys.exit(main())
