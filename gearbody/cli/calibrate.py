"""``gearbody calibrate SCENE``: fit scenario keys within bounds to target features of the scene's
cases (:mod:`gearbody.studies.scene_calibration`), resumable; exit 0 fit written, 1 every evaluation
failed, 2 bad input."""

from __future__ import annotations

import argparse
import sys

from .common import (
    EXIT_OK,
    add_executor,
    add_out,
    add_overwrite,
    add_set,
    add_wall_limit,
    check_out,
    number,
    scenario_overrides,
    usage_error,
)


def register(sub) -> argparse.ArgumentParser:
    """Add the command's parser to ``sub`` (the subparsers of ``gearbody``)."""
    # size: a flat list of add_argument calls, one per option, read top to bottom like --help
    ca = sub.add_parser(
        "calibrate",
        help="fit scenario keys within bounds to target features (model updating), resumable",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=(
            "Identify the --param keys of SCENE within their bounds from --target features (measured or "
            "published values with their uncertainty): a global gradient-free search (nevergrad "
            "differential evolution, --budget evaluations in rounds of --batch run in parallel), then a "
            "least-squares polish (scipy), then 1-sigma uncertainties from the Jacobian at the optimum. A "
            "target may be read from a named --case (extra overrides, e.g. another error mode): every "
            "evaluation simulates each case its targets name. Writes DIR/evaluations.jsonl (every "
            "evaluation; rerunning the same command on DIR resumes it), DIR/calibration.json, "
            "calibration.md, convergence.png and calibrated.toml (the scene with the fitted values: "
            "gearbody run DIR/calibrated.toml). DIR holding anything else is refused unless --overwrite, "
            "and so is a second calibration on DIR while one runs. Exit code 0: fit written; 1: every "
            "evaluation failed, or a file could not be written (a full disk: rerun to resume); 2: bad "
            "input. See docs/calibration.md."
        ),
        epilog="example (recovers the mesh stiffness of one-stage, 1.2e9 N/m, from its 3rd natural "
        "frequency):\n"
        "  gearbody calibrate one-stage --t-end 0.2 --set 'operation.initial_state=\"steady\"' \\\n"
        "      --set 'operation.speed_profile={time_s=[0.0],fraction=[1.0]}' \\\n"
        "      --set 'operation.load_profile={time_s=[0.0],fraction=[1.0]}' \\\n"
        "      --param design.mesh.stiffness_single_N_per_m=0.6e9:2.4e9:log \\\n"
        "      --target natural_frequency_hz:mode=3 2843.9 28.4 \\\n"
        "      --budget 12 --out runs/cal\n",
    )
    ca.add_argument("scene", metavar="SCENE", help="scene name or .toml path")
    ca.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="KEY=LOW:HIGH[:log]",
        help="a fitted scenario key and its bounds (':log': searched on a log scale); repeatable",
    )
    ca.add_argument(
        "--start",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="the first point tried for a --param key (default: the middle of its range)",
    )
    ca.add_argument(
        "--target",
        action="append",
        nargs=3,
        default=[],
        metavar=("FEATURE[@CASE]", "VALUE", "SIGMA"),
        help="a feature spec (docs/features.md), optionally of a --case, its target value and 1-sigma "
        "uncertainty in the feature's unit; repeatable",
    )
    ca.add_argument(
        "--target-from",
        action="append",
        nargs=3,
        default=[],
        metavar=("FEATURES", "KEY", "SIGMA"),
        help="a target from a recording: feature KEY ('<channel>/<feature>' or '<feature>') of the "
        "features.json 'gearbody analyze' wrote (FEATURES: the file or its folder), computed on each run "
        "by the same analysis of --target-signal; repeatable",
    )
    ca.add_argument(
        "--target-signal",
        metavar="SIGNAL",
        help="the run's signal the --target-from features are computed on (default: its vibration signal)",
    )
    ca.add_argument(
        "--case",
        action="append",
        nargs=2,
        default=[],
        metavar=("NAME", "KEY=VALUE"),
        help="an override of the named case (repeat the name for more overrides of it)",
    )
    add_set(ca, "fixed override of every run and of the calibrated scene")
    ca.add_argument("--t-end", type=number(gt=0), metavar="SECONDS", help="simulated time of every run")
    ca.add_argument(
        "--budget",
        type=number(whole=True, ge=1),
        default=60,
        metavar="N",
        help="evaluations of the global search (default 60)",
    )
    ca.add_argument(
        "--batch",
        type=number(whole=True, ge=1),
        metavar="B",
        help="points per round of the global search, run in parallel (default: --workers, or 2)",
    )
    ca.add_argument(
        "--polish-evaluations",
        type=number(whole=True, ge=0),
        default=40,
        metavar="N",
        help="at most N evaluations of the least-squares polish (default 40; 0: none)",
    )
    ca.add_argument(
        "--seed", type=number(whole=True, ge=0), default=0, metavar="S", help="optimiser seed (default 0)"
    )
    add_executor(ca)
    ca.add_argument("--force", action="store_true", help="allow more evaluations than the limit (2000)")
    ca.add_argument("--quiet", action="store_true", help="no progress and no table")
    add_wall_limit(ca, "a calibration whose runs still to do are")
    add_out(ca, "output folder of the calibration", required=True)
    add_overwrite(
        ca, "calibration (the fingerprint in its evaluations.jsonl: scene, --set, --case, features, --param)"
    )
    ca.set_defaults(handler=execute)
    return ca


def _starts(texts: list[str]) -> dict[str, float]:
    from gearbody.studies import SweepSpecError

    starts = {}
    for text in texts:
        key, _, value = text.partition("=")
        try:
            starts[key.strip()] = float(value)
        except ValueError:  # no "=" leaves value empty
            raise SweepSpecError(f"--start {text}: expected KEY=VALUE with a number") from None
    return starts


def _recording_target(path: str, key: str, sigma: str, signal: str | None):
    """--target-from FEATURES KEY SIGMA: the 'recording' feature of KEY with the value the file holds."""
    from gearbody.diagnosis.features import target_from_features
    from gearbody.studies.scene_calibration import parse_target

    feature, value = target_from_features(path, key)
    spec = f"recording:feature={feature}" + (f",signal={signal}" if signal else "")
    return parse_target(spec, repr(value), sigma)


def execute(args) -> int:
    from gearbody.studies import SweepSpecError
    from gearbody.studies.scene_calibration import calibrate_scene, parse_parameter, parse_target

    check_out(args.out)
    try:
        starts = _starts(args.start)
        params = []
        for text in args.param:
            key = text.partition("=")[0].strip()
            params.append(parse_parameter(text, starts.pop(key, None)))
        if starts:
            raise SweepSpecError(f"--start {next(iter(starts))}: not a --param key")
        targets = [parse_target(*t) for t in args.target]
        targets += [_recording_target(*t, args.target_signal) for t in args.target_from]
        cases: dict[str, list[str]] = {}
        for name, override in args.case:
            cases.setdefault(name, []).append(override)
        res = calibrate_scene(
            args.scene,
            params,
            targets,
            out=args.out,
            cases=cases,
            overrides=scenario_overrides(args),
            workers=args.workers,
            scheduler=args.scheduler,
            budget=args.budget,
            batch=args.batch,
            polish=args.polish_evaluations > 0,
            polish_evaluations=args.polish_evaluations,
            seed=args.seed,
            force=args.force,
            progress=not args.quiet,
            overwrite=args.overwrite,
            max_wall_minutes=args.max_wall_minutes,
        )
    except (SweepSpecError, ImportError) as exc:
        return usage_error("calibrate", str(exc))
    for line in res.fit.warnings():  # on a bound, unidentified: the fit is written, but the user is told
        print(f"gearbody calibrate: warning: {line}", file=sys.stderr)
    if not args.quiet:
        print(res.table())
        print(
            f"({res.simulations} simulations now, {res.fit.replayed} evaluations replayed from the record, "
            f"{res.wall_time_s:.1f} s; files in {res.out}; rerun: gearbody run {res.scenario_file})"
        )
    return EXIT_OK
