"""``gearbody run SCENE``: simulate and write result.npz, scenario.toml, summary.json, the PNG plots and
optionally report.html."""

from __future__ import annotations

import argparse
import json
import time

from .common import (
    EXIT_OK,
    add_out,
    add_set,
    add_wall_limit,
    check_out,
    check_wall_time,
    default_out,
    load,
    number,
    scenario_labels,
    scenario_overrides,
    warn_if_backwards,
)


def register(sub) -> argparse.ArgumentParser:
    """Add the command's parser to ``sub`` (the subparsers of ``gearbody``)."""
    run = sub.add_parser(
        "run",
        help="simulate a scene or scenario file and write results and plots",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=(
            "Simulate SCENE and write DIR/result.npz (named arrays: time, mesh_force_N, kd, "
            "angles, speeds, accelerations, ...), DIR/scenario.toml (fully resolved, re-runnable "
            "with 'gearbody run DIR/scenario.toml'), DIR/summary.json and PNG plots: per parallel "
            "stage K_d over time and folded over the mesh period (stage k > 1: kd_time_stage_k.png, "
            "...), the spectrum of the pinion acceleration (lateral: housing acceleration) when the "
            "first stage is parallel, per planetary stage the planets' K_d, the load sharing and the "
            "ring-sensor spectrum."
        ),
    )
    run.add_argument(
        "scene", metavar="SCENE", help="scene name (see 'gearbody list') or path to a .toml scenario"
    )
    add_set(
        run,
        "override a scenario value by its dotted key, e.g. production.error_mode.e_um=15 "
        '(repeatable; values are TOML: numbers, true/false, [arrays], "strings")',
    )
    run.add_argument(
        "--t-end", type=number(gt=0), metavar="SECONDS", help="simulated time (sets operation.t_end_s)"
    )
    add_out(run, "output folder (default: runs/SCENE)")
    run.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    run.add_argument(
        "--report",
        action="store_true",
        help="also write DIR/report.html: summary, labelled spectrum, folded K_d, TSA and indicators",
    )
    run.add_argument("--quiet", action="store_true", help="no progress display and no summary on screen")
    add_wall_limit(run, "a run")
    run.set_defaults(handler=execute)
    return run


PLANETARY_SHOWN = (
    "kd_max",
    "kd_mean_final",
    "load_sharing_factor",
    "separation_fraction",
    "mesh_frequency_hz",
)


def execute(args) -> int:
    out = check_out(args.out or default_out(args.scene))  # before anything is imported or run
    from gearbody.engine import simulate
    from gearbody.model import dump_scenario

    scenario = load(args.scene, scenario_overrides(args), scenario_labels(args))
    check_wall_time(scenario, args)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    result = simulate(scenario, progress=not args.quiet)
    result.save_npz(out / "result.npz")
    dump_scenario(scenario, out / "scenario.toml")
    summary = result.summary()
    summary["wall_time_s"] = time.perf_counter() - t0
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    warn_if_backwards(result)
    plots = [] if args.no_plots else result.plot(out)
    if args.report:
        from gearbody.reports.html import write_report

        write_report(result, out / "report.html")
    if not args.quiet:
        print(f"{scenario.meta.title}")
        keys = (
            "kd_max",
            "kd_max_final",
            "kd_mean_final",
            "separation_fraction",
            "mesh_frequency_hz",
            "mean_speed_rad_s",
            "simulated_time_s",
            "wall_time_s",
        )
        if result.planetary_stages:  # per mesh type: K_d, sharing, separation
            keys = tuple(k for k in summary if k.endswith(PLANETARY_SHOWN) or k in keys)
        for key in keys:
            v = summary[key]
            width = max(22, *(len(k) for k in keys))
            print(f"  {key:{width}s} {v:.4g}" if isinstance(v, float) else f"  {key:{width}s} {v}")
        if result.planetary_stages:  # a ring-sensor spectrum too short for the carrier sidebands
            from gearbody.plotting.planetary import ring_sensor_notes

            for note in ring_sensor_notes(result):
                print(f"note: {note}")
        print(
            f"wrote {out}/result.npz, scenario.toml, summary.json"
            + (f", {len(plots)} plots" if plots else "")
            + (", report.html" if args.report else "")
        )
    return EXIT_OK
