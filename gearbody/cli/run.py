"""``gearbody run SCENE``: simulate and write result.npz, scenario.toml, summary.json, the PNG plots and
optionally report.html."""

from __future__ import annotations

import argparse
import json
import sys
import time

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
            "ring-sensor spectrum. A scenario with an [instruments] table also gets DIR/instruments.mat: "
            "its virtual accelerometers and tacho as a recording ('gearbody analyze DIR' analyses it; "
            "docs/recordings.md). DIR must be empty, hold a run of the same resolved scenario (it is "
            "written again) or be replaced with --overwrite; DIR/.gearbody.json records the run."
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
    add_overwrite(run, "run (the same resolved scenario: scene, --set and --t-end)")
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


INSTRUMENTS_FILE = "instruments.mat"
"""The run's virtual recording (MATLAB v5: scipy writes it, every tool reads it; bit-exact for gearbody)."""

PLANETARY_SHOWN = (
    "kd_max",
    "kd_mean_final",
    "load_sharing_factor",
    "separation_fraction",
    "mesh_frequency_hz",
)


def check_plottable(scenario, args) -> None:
    """InputError (exit 2, before anything runs) when the run gives too few output samples for the plots
    and the report it is asked to write (gearbody.plotting.run.MIN_PLOT_SAMPLES), naming the simulated
    time that does and --no-plots."""
    from gearbody.errors import InputError
    from gearbody.model.budget import output_samples
    from gearbody.plotting.run import MIN_PLOT_SAMPLES

    samples = output_samples(scenario)
    if samples >= MIN_PLOT_SAMPLES:
        return
    rate = scenario.solver.output_rate_hz
    t_end = scenario.operation.t_end_s
    option = "--t-end" if args.t_end is not None else "operation.t_end_s"
    wanted = "the plots and the report analyse" if args.report else "the plots analyse"
    raise InputError(
        f"{option} = {t_end:g}: {samples} output samples at solver.output_rate_hz = {rate:g} Hz; {wanted} "
        f"the last 25 % of the run and need at least {MIN_PLOT_SAMPLES}; allowed: {option} >= "
        f"{(MIN_PLOT_SAMPLES - 1) / rate:g}, or --no-plots{' without --report' if args.report else ''} to "
        "write result.npz, scenario.toml and summary.json only"
    )


def bearing_marks(result) -> list:
    """The bearing defect frequencies (BPFO, BPFI, 2 BSF, FTF of every bearing with geometry) at the run's
    mean input speed over its final window, for its spectrum plot (none when the run has no scenario)."""
    from gearbody.reports.bearings import run_bearing_section

    section, input_hz = run_bearing_section(result)
    return section.marks(input_hz, float("inf"))


def execute(args) -> int:
    out = check_out(args.out or default_out(args.scene))  # before anything is imported or run
    from gearbody.engine import simulate
    from gearbody.folders import atomic_write, claim, write_text
    from gearbody.model import dump_scenario, scenario_to_dict

    scenario = load(args.scene, scenario_overrides(args), scenario_labels(args))
    if not args.no_plots or args.report:
        check_plottable(scenario, args)
    if scenario.instruments is not None:  # force signals, tacho shaft, FRF files: before the run
        from gearbody.diagnosis.virtual import check_instruments

        check_instruments(scenario)
    check_wall_time(scenario, args)
    identity = {"scenario": scenario_to_dict(scenario)}  # what makes a run the same run
    with claim(out, "run", identity, overwrite=args.overwrite) as folder:  # locked while it writes
        t0 = time.perf_counter()
        result = simulate(scenario, progress=not args.quiet)
        folder.begin()  # the old outputs go; the run is recorded incomplete until every file is written
        atomic_write(out / "result.npz", result.save_npz)
        atomic_write(out / "scenario.toml", lambda p: dump_scenario(scenario, p))
        summary = result.summary()
        summary["wall_time_s"] = time.perf_counter() - t0
        write_text(out / "summary.json", json.dumps(summary, indent=2) + "\n")
        warn_if_backwards(result)
        plots = [] if args.no_plots else result.plot(out, marks=bearing_marks(result))
        if args.report:
            from gearbody.reports.html import write_report

            write_report(result, out / "report.html")
        if scenario.instruments is not None:
            from gearbody.diagnosis.virtual import virtual_recording
            from gearbody.recording.files import write_recording

            recording = virtual_recording(result, scenario)
            write_recording(recording, out / INSTRUMENTS_FILE)
            if recording.tacho is None:
                print(f"gearbody: note: {recording.meta['tacho_note']}", file=sys.stderr)
        folder.finish()
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
            from gearbody.analysis.ring_sensor import ring_sensor_notes

            for note in ring_sensor_notes(result):
                print(f"note: {note}")
        print(
            f"wrote {out}/result.npz, scenario.toml, summary.json"
            + (f", {len(plots)} plots" if plots else "")
            + (", report.html" if args.report else "")
            + (f", {INSTRUMENTS_FILE}" if scenario.instruments is not None else "")
        )
    return EXIT_OK
