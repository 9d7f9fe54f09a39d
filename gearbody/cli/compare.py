"""``gearbody compare RUN RECORDING``: a simulated run beside a recording of the same drive: the same
analysis of both, their features with ratios, and their order spectra overlaid with the same labels."""

from __future__ import annotations

import argparse
from pathlib import Path

from .analyze import add_recording_options, open_recording
from .common import EXIT_OK, add_out, add_overwrite, add_set, check_out

__all__ = ["register"]

IDENTITY = ("scene", "overrides", "channel", "run_channel", "tacho", "pulses_per_rev", "tacho_shaft",
            "sample_rate", "input_speed", "start", "end", "unit", "calibration")  # fmt: skip
"""The options that make a comparison folder hold "the same comparison"."""


def register(sub) -> argparse.ArgumentParser:
    p = sub.add_parser(
        "compare",
        help="put a simulated run beside a recording: features with ratios, overlaid order spectra",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=(
            "Analyse RUN (a run folder or its result.npz: its steady last quarter) and RECORDING (a file "
            "'gearbody analyze' reads, or another run: a run folder holding instruments.mat, its virtual "
            "instruments) with the same drive and write DIR/comparison.html, "
            "comparison.json and comparison.csv (every feature of both with the ratio recording / run) and "
            "overlay_orders.png (both order spectra, labelled by the drive's lines). The drive is --scene, "
            "else the run's scenario."
        ),
    )
    p.add_argument("run", metavar="RUN", help="a run folder or result.npz")
    p.add_argument("recording", metavar="RECORDING", help="recording file (or a run)")
    p.add_argument("--scene", metavar="SCENE", help="scene of the drive (default: the run's scenario)")
    add_set(p, "override a value of --scene's scenario by its dotted key (repeatable)")
    add_recording_options(p)
    p.add_argument("--run-channel", metavar="NAME", help="the run's channel (default: its vibration signal)")
    add_out(p, "output folder (default: runs/compare-<run>-<recording>)")
    add_overwrite(p, "comparison")
    p.set_defaults(handler=execute)
    return p


def execute(args) -> int:
    from gearbody.errors import InputError

    names = [Path(x).stem if Path(x).suffix else Path(x).name for x in (args.run, args.recording)]
    out = check_out(args.out or Path("runs", f"compare-{names[0]}-{names[1]}"))
    from gearbody.diagnosis import DriveKinematics, analyze_recording
    from gearbody.diagnosis.compare import compare_diagnoses
    from gearbody.folders import claim
    from gearbody.reports.comparison import write_comparison

    run_args = argparse.Namespace(
        **{
            **vars(args),
            "tacho": None,
            "tacho_shaft": "input",
            "start": None,
            "end": None,
            "input_speed": None,
            "sample_rate": None,
            "unit": [],
            "calibration": None,
            "scene": None,
            "run_signals": True,  # RUN: the run's own signals (RECORDING may be a run's virtual instruments)
        }
    )
    run_rec, run_scenario = open_recording(run_args, args.run)
    if run_rec.meta.get("source") != "simulation":
        raise InputError(f"RUN {args.run}: not a simulated run (a run folder or its result.npz)")
    rec, scenario = open_recording(args, need_scenario=False)
    scenario = scenario if args.scene else run_scenario
    drive = DriveKinematics.from_scenario(scenario)
    run_channel = args.run_channel or run_rec.vibration_channels[0]
    rec_channel = (args.channel or rec.vibration_channels)[0]
    identity = {
        "run": str(Path(args.run).resolve()),
        "recording": str(Path(args.recording).resolve()),
        **{k: getattr(args, k, None) for k in IDENTITY},
    }
    with claim(out, "compare", identity, overwrite=args.overwrite) as folder:
        run_diag = analyze_recording(run_rec, drive, [run_channel], envelope=True)
        rec_diag = analyze_recording(rec, drive, [rec_channel], envelope=True)
        comparison = compare_diagnoses(run_diag, rec_diag, run_channel, rec_channel)
        folder.begin()
        pages = write_comparison(comparison, out, f"{Path(args.run).name} beside {Path(args.recording).name}")
        folder.finish()
    _show(comparison, drive.scene, out, pages)
    return EXIT_OK


def _show(comparison, scene: str, out: Path, pages: list[Path]) -> None:
    run_channel, rec_channel = comparison.run_channel, comparison.recording_channel
    print(
        f"run {run_channel} [{comparison.run_side.unit}] beside recording {rec_channel} "
        f"[{comparison.recording_side.unit}], drive {scene}: {len(comparison.rows)} features"
    )
    shown = [
        r
        for r in comparison.rows
        if r["feature"].split(":")[0] in ("input_speed_hz", "rms", "kurtosis", "fm4", "na4", "energy_ratio")
    ]
    for row in shown[:12]:
        print(
            f"  {row['feature']:32s} run {row['run']:<11.4g} recording {row['recording']:<11.4g} "
            f"ratio {row['ratio']:.3g}"
        )
    print(f"wrote {out}/{', '.join(p.name for p in pages)}")
