"""``gearbody analyze RECORDING --scene S``: the report a simulated run gets, for a recording (a data
logger's file, or a run's result.npz / run folder): labelled spectra in Hz and in orders, synchronous
averages of every gear's shaft with their indicators, fault bands, kurtogram and envelope spectrum."""

from __future__ import annotations

import argparse
from pathlib import Path

from .common import EXIT_OK, add_out, add_overwrite, add_set, check_out, number
from .run import INSTRUMENTS_FILE

__all__ = ["add_recording_options", "open_recording", "register"]


def add_recording_options(parser: argparse.ArgumentParser) -> None:
    """The options that say how to read a recording (shared with ``gearbody compare``)."""
    parser.add_argument(
        "--channel",
        action="append",
        metavar="NAME",
        help="channel to analyse (repeatable; default: a run's vibration signal, a file's vibration "
        "channels, at most 4)",
    )
    parser.add_argument(
        "--tacho",
        metavar="CHANNEL",
        help="the tacho's channel: a pulse train, or an encoder "
        "angle (unit rad/deg/rev); default: the file's own tacho",
    )
    parser.add_argument(
        "--pulses-per-rev",
        type=number(whole=True, ge=0, le=100000),
        metavar="N",
        help="tacho pulses per revolution of its shaft (default 1)",
    )
    parser.add_argument(
        "--tacho-shaft",
        metavar="SHAFT",
        help="the shaft the tacho measures: input (default), output, or a body of the scene "
        "(pinion, wheel, wheel_2, motor, ...)",
    )
    parser.add_argument(
        "--unit",
        action="append",
        default=[],
        metavar="NAME=UNIT",
        help="unit of a channel of a file that does not say it (g, m/s^2, mm/s, um, V, ...); repeatable",
    )
    parser.add_argument(
        "--calibration",
        metavar="FACTOR[,FACTOR...]",
        help="WAV: the physical value of a full-scale sample (integer WAV) or of a file unit (float WAV), "
        "one for every channel or one per channel of the file (comma-separated; channels ch1, ch2, ...)",
    )
    parser.add_argument(
        "--sample-rate", type=number(gt=0), metavar="HZ", help="sample rate of a file that does not say it"
    )
    parser.add_argument(
        "--input-speed",
        type=number(gt=0),
        metavar="HZ",
        help="without a tacho: the input shaft's approximate speed [rev/s] for the tacholess "
        "estimate from the mesh harmonic (default: the scene's nominal speed)",
    )
    parser.add_argument("--start", type=number(ge=0), metavar="SECONDS", help="analyse from this time")
    parser.add_argument("--end", type=number(gt=0), metavar="SECONDS", help="analyse up to this time")


def register(sub) -> argparse.ArgumentParser:
    p = sub.add_parser(
        "analyze",
        help="analyse a recording (data-logger file or a run) against a scene: report, plots, features",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=(
            "Read RECORDING (.csv, .parquet, .wav, .mat, .h5/.hdf5, .uff/.unv, .tdms, or a run's "
            "result.npz or folder) and write DIR/report.html, DIR/features.json and PNG figures per "
            "channel: the spectrum in Hz and in orders of the input shaft labelled with the scene's shaft "
            "orders, mesh harmonics, sidebands and bearing lines; synchronous averages of every gear's "
            "shaft with FM0, FM4, NA4, M6A, M8A and the energy ratio; fault-band metrics; the kurtogram "
            "and the squared-envelope spectrum in its band. Every shaft's angle comes from one tacho "
            "through the scene's ratios (or, without a tacho, from the first mesh harmonic near "
            "--input-speed, default the scene's nominal speed). A run folder that holds instruments.mat "
            "(a scenario with an [instruments] table) is analysed through its virtual instruments, like a "
            "logger's file: the accelerometers and the tacho the scenario describes, over the run's last "
            "quarter; --run-signals analyses the run's own signals instead."
        ),
    )
    p.add_argument("recording", metavar="RECORDING", help="recording file, or a run's result.npz or folder")
    p.add_argument(
        "--scene",
        metavar="SCENE",
        help="scene name or .toml scenario of the drive recorded "
        "(default: the scenario a simulated recording carries)",
    )
    add_set(p, "override a value of --scene's scenario by its dotted key (repeatable)")
    add_recording_options(p)
    p.add_argument(
        "--run-signals",
        action="store_true",
        help="a run folder: analyse the run's own signals (result.npz), not its virtual instruments "
        "(instruments.mat, analysed by default when the folder holds it)",
    )
    p.add_argument("--no-envelope", action="store_true", help="skip the kurtogram and the envelope spectrum")
    p.add_argument(
        "--prewhiten",
        action="store_true",
        help="kurtogram and envelope spectrum of the cepstrum-prewhitened channel (the gears' lines "
        "removed, so a bearing's impacts stand out; amplitudes relative)",
    )
    add_out(p, "output folder (default: runs/analyze-<recording file stem>)")
    add_overwrite(p, "analysis")
    p.set_defaults(handler=execute)
    return p


def open_recording(args, path: str | None = None, need_scenario: bool = True):
    """The recording named on the command line (``path``, default ``args.recording``) and its scenario
    (``--scene`` with ``--set``, else the scenario a simulated recording carries; None when there is none
    and ``need_scenario`` is false)."""
    from gearbody.errors import InputError
    from gearbody.model import load_scenario

    text = str(args.recording if path is None else path)
    label = "RECORDING" if path is None else "RUN"
    source = Path(text)
    if getattr(args, "scene", None) is not None and not args.scene.strip():
        raise InputError("--scene '': give a scene name or a .toml scenario")
    if not text.strip():
        raise InputError(f"{label} '': give a file, or a run's folder or result.npz")
    try:
        found, folder = source.exists(), source.is_dir()
    except OSError as exc:  # a name the system cannot even look up (too long)
        raise InputError(f"{label} {source}: cannot be used: {exc.strerror or exc}") from None
    if not found:
        raise InputError(f"{label} {source}: no such file or folder")
    run_signals = getattr(args, "run_signals", False)
    if folder and not run_signals and (source / INSTRUMENTS_FILE).is_file():
        rec = _instruments_recording(source / INSTRUMENTS_FILE, args)
    elif folder or source.suffix == ".npz":
        rec = _run_recording(source, args)
    elif run_signals:
        raise InputError(f"--run-signals: {label} {source} is a file; it applies to a run's folder")
    else:
        from gearbody.recording.files import read_recording

        options = {"sample_rate_hz": args.sample_rate, "start_s": args.start, "end_s": args.end}
        options.update(_units_and_calibration(args))
        if args.tacho:
            options.update(
                tacho_channel=args.tacho,
                pulses_per_rev=1 if args.pulses_per_rev is None else args.pulses_per_rev,
                tacho_shaft=args.tacho_shaft or "input",
            )
        else:
            given = [
                o
                for o, v in (("--pulses-per-rev", args.pulses_per_rev), ("--tacho-shaft", args.tacho_shaft))
                if v is not None
            ]
            if given:
                raise InputError(
                    f"{', '.join(given)}: describe the tacho of --tacho CHANNEL (a file's own "
                    "tacho names its shaft and pulses)"
                )
        rec = read_recording(source, **{k: v for k, v in options.items() if v is not None})
    if args.input_speed:
        rec.meta["input_speed_hz"] = float(args.input_speed)
    if getattr(args, "scene", None):
        from .common import load, scenario_labels, scenario_overrides

        scenario = load(args.scene, scenario_overrides(args), scenario_labels(args))
    elif isinstance(rec.meta.get("scenario"), dict):
        scenario = load_scenario(rec.meta["scenario"])
    elif not need_scenario:
        scenario = None
    else:
        raise InputError(
            f"{label} {source}: a measured recording needs --scene (the drive it was recorded on)"
        )
    return rec, scenario


def _units_and_calibration(args) -> dict:
    """read_recording's ``units`` and ``calibration`` from --unit NAME=UNIT and --calibration."""
    from gearbody.errors import InputError

    out: dict = {}
    units = {}
    for text in args.unit:
        name, eq, unit = text.partition("=")
        if not eq or not name:
            raise InputError(f"--unit {text}: expected NAME=UNIT, e.g. acc1=g")
        units[name] = unit
    if units:
        out["units"] = units
    if args.calibration:
        try:
            values = [float(v) for v in args.calibration.split(",")]
        except ValueError:
            raise InputError(
                f"--calibration {args.calibration}: expected a number, or one per channel separated by commas"
            ) from None
        out["calibration"] = values[0] if len(values) == 1 else values
    return out


def _instruments_recording(path: Path, args):
    """The virtual recording a run wrote (``gearbody run`` of a scenario with [instruments]): read as a
    logger's file, over the run's last quarter unless --start/--end say otherwise."""
    from gearbody.errors import InputError
    from gearbody.recording.files import read_recording
    from gearbody.result import FINAL_FRACTION

    given = [
        o
        for o, v in (
            ("--unit", args.unit),
            ("--calibration", args.calibration),
            ("--sample-rate", args.sample_rate),
            ("--tacho", args.tacho),
            ("--pulses-per-rev", args.pulses_per_rev),
            ("--tacho-shaft", args.tacho_shaft),
        )
        if v is not None and v != []
    ]
    if given:
        raise InputError(
            f"{', '.join(given)}: the run's virtual instruments ({path}) carry their units, rate and "
            "tacho ([instruments] of its scenario); --run-signals analyses the run's own signals, where "
            "--tacho-shaft and --pulses-per-rev choose the virtual tacho"
        )
    rec = read_recording(path)
    if args.start is not None or args.end is not None:
        return rec.window(args.start, args.end)
    t = rec.time_s
    rec = rec.window(float(t[-1] - FINAL_FRACTION * (t[-1] - t[0])), None)
    rec.meta["window_note"] = f"the last {FINAL_FRACTION:.0%} of the run"
    return rec


def _run_recording(source: Path, args):
    from gearbody.errors import InputError
    from gearbody.result import Result

    given = [
        o
        for o, v in (
            ("--unit", args.unit),
            ("--calibration", args.calibration),
            ("--sample-rate", args.sample_rate),
            ("--tacho", args.tacho),
        )
        if v
    ]
    if given:
        raise InputError(
            f"{', '.join(given)}: a run's recording carries its units, sample rate and tacho (its exact "
            "shaft angles); these options apply to files only (--tacho-shaft and --pulses-per-rev choose "
            "the run's virtual tacho)"
        )
    npz = source / "result.npz" if source.is_dir() else source
    if not npz.is_file():
        raise InputError(f"{source}: a folder must hold a run's result.npz")
    result = Result.load_npz(npz)
    shaft = args.tacho_shaft if args.tacho_shaft not in (None, "input", "output") else None
    if shaft is None:
        shaft = "pinion" if "pinion_angle_rad" in result else "sun" if "sun_angle_rad" in result else "motor"
    ppr = 1 if args.pulses_per_rev is None else args.pulses_per_rev
    rec = result.to_recording(tacho_shaft=shaft, pulses_per_rev=ppr)
    if args.start is not None or args.end is not None:
        rec = rec.window(args.start, args.end)
    elif result.meta.get("scenario"):  # a run: its steady end, as the run's own report reads it
        rec = rec.window(float(result.time_s[result.final_window()][0]), None)
        rec.meta["window_note"] = f"the last {result.FINAL_FRACTION:.0%} of the run"
    return rec


def execute(args) -> int:
    from gearbody.errors import InputError

    stem = Path(args.recording).stem if Path(args.recording).suffix else Path(args.recording).name
    out = check_out(args.out or Path("runs", f"analyze-{stem}"))
    if args.start is not None and args.end is not None and args.end <= args.start:
        raise InputError(f"--end {args.end:g} must be after --start {args.start:g}")
    from gearbody.diagnosis import DriveKinematics, analyze_recording
    from gearbody.folders import claim
    from gearbody.reports.recording import write_diagnosis

    rec, scenario = open_recording(args)
    drive = DriveKinematics.from_scenario(scenario)
    keys = (
        "scene",
        "overrides",
        "channel",
        "tacho",
        "pulses_per_rev",
        "tacho_shaft",
        "sample_rate",
        "input_speed",
        "start",
        "end",
        "no_envelope",
        "prewhiten",
        "run_signals",
        "unit",
        "calibration",
    )
    identity = {"recording": str(Path(args.recording).resolve()), **{k: getattr(args, k, None) for k in keys}}
    with claim(out, "analyze", identity, overwrite=args.overwrite) as folder:
        diag = analyze_recording(
            rec, drive, args.channel, envelope=not args.no_envelope, prewhiten=args.prewhiten
        )
        folder.begin()
        paths = write_diagnosis(diag, out, title=f"{Path(args.recording).name} on {drive.scene}")
        folder.finish()
    if rec.meta.get("source") == "virtual instruments":
        print(f"the run's virtual instruments ({INSTRUMENTS_FILE}; --run-signals: the run's own signals)")
    print(
        f"analysed {', '.join(diag.channels)} of {args.recording}: input shaft "
        f"{diag.mean_input_hz:.4f} rev/s "
        f"({diag.angles.source})"
    )
    for name, ch in diag.channels.items():
        for body, values in ch.indicators.items():
            print(
                f"  {name} / {body}: FM0 {values['fm0']:.3g}  FM4 {values['fm4']:.3g}  "
                f"NA4 {values['na4']:.3g}  "
                f"ER {values['energy_ratio']:.3g}"
            )
    print(f"wrote {out}/report.html, features.json and {len(paths) - 2} figures")
    return EXIT_OK
