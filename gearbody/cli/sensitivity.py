"""``gearbody sensitivity SCENE``: Morris or Sobol sensitivity indices of features to scenario keys
(:mod:`gearbody.studies.sensitivity`), resumable; exit 0 indices written, 1 rows failed (all recorded,
no indices), 2 bad input."""

from __future__ import annotations

import argparse

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
    se = sub.add_parser(
        "sensitivity",
        help="Morris screening or Sobol indices of features to scenario keys over ranges, resumable",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=(
            "Run SCENE on a SALib sample of the --key ranges and compute, per --feature, Morris "
            "elementary-effect statistics (mu*, sigma) or Sobol indices (S1, ST, S2) with bootstrap "
            "confidence half-widths. Writes DIR/sensitivity.json, DIR/evaluations/<job>.json (one per "
            "run), DIR/indices.csv, indices.md, indices.json and indices.png. Rerunning the same command "
            "on DIR resumes it; DIR holding anything else is refused unless --overwrite, and so is a "
            "second analysis on DIR while one runs. At most 2000 runs unless --force. Runs: Morris "
            "samples x (keys + 1), Sobol samples x (2 keys + 2). Exit code 0: indices written; 1: runs "
            "failed (recorded; no indices), or a file could not be written (a full disk: rerun to "
            "resume); 2: bad input. See docs/features.md."
        ),
        epilog="examples:\n"
        "  gearbody sensitivity one-stage --key design.mesh.damping_Ns_per_m=3000:12000 \\\n"
        "      --key design.mesh.stiffness_single_N_per_m=1.0e9:1.25e9 --feature kd_max \\\n"
        "      --feature line_amplitude:signal=pinion_accel_rad_s2,mesh=1 --method morris --samples 8 \\\n"
        "      --seed 1 --t-end 0.05 --set 'operation.initial_state=\"steady\"' --out runs/sens\n",
    )
    se.add_argument("scene", metavar="SCENE", help="scene name or .toml path")
    se.add_argument(
        "--key",
        action="append",
        default=[],
        metavar="KEY=LOW:HIGH",
        help="a varied scenario key and its range (uniform); repeatable",
    )
    se.add_argument(
        "--feature",
        action="append",
        default=[],
        metavar="SPEC",
        help="a feature spec (docs/features.md), e.g. kd_max:period=4; repeatable",
    )
    se.add_argument(
        "--target-from",
        action="append",
        nargs=3,
        default=[],
        metavar=("FEATURES", "KEY", "SIGMA"),
        help="a recording's feature as target: the output is the run's misfit (value - target) / SIGMA of "
        "feature KEY of the features.json 'gearbody analyze' wrote (FEATURES: the file or its folder), "
        "computed on each run by the same analysis of its vibration signal; repeatable",
    )
    se.add_argument("--method", choices=("morris", "sobol"), default="morris", help="default morris")
    se.add_argument(
        "--samples",
        type=number(whole=True, ge=2),
        default=8,
        metavar="N",
        help="Morris: trajectories (default 8); Sobol: base sample, a power of 2",
    )
    se.add_argument(
        "--seed", type=number(whole=True, ge=0), default=0, metavar="S", help="seed of the sample (default 0)"
    )
    se.add_argument(
        "--levels",
        type=number(whole=True, ge=2),
        default=4,
        metavar="P",
        help="Morris grid levels, even (default 4)",
    )
    se.add_argument("--no-second-order", action="store_true", help="Sobol: no S2 (D + 2 runs per sample)")
    add_set(se, "fixed override of every run (as for run)")
    se.add_argument("--t-end", type=number(gt=0), metavar="SECONDS", help="simulated time of every run")
    add_executor(se)
    se.add_argument("--force", action="store_true", help="allow more runs than the limit (2000)")
    se.add_argument("--retry-failed", action="store_true", help="on resume, rerun the runs that failed")
    se.add_argument(
        "--exclude-failed",
        action="store_true",
        help="Morris only: compute the indices without the trajectories holding failed runs",
    )
    se.add_argument("--quiet", action="store_true", help="no progress bar and no table")
    add_wall_limit(se, "an analysis whose runs still to do are")
    add_out(se, "output folder of the analysis", required=True)
    add_overwrite(se, "analysis (its sensitivity.json: scene, --set, --key, --feature, method, sample)")
    se.set_defaults(handler=execute)
    return se


def execute(args) -> int:
    from gearbody.analysis.features import FeatureError
    from gearbody.studies import SweepSpecError
    from gearbody.studies.sensitivity import sensitivity

    check_out(args.out)
    try:
        features = list(args.feature)
        for path, key, sigma in args.target_from:
            from gearbody.diagnosis.features import target_from_features

            feature, value = target_from_features(path, key)
            features.append(f"recording:feature={feature},target={value!r},sigma={sigma}")
        res = sensitivity(
            args.scene,
            args.key,
            features,
            out=args.out,
            method=args.method,
            samples=args.samples,
            seed=args.seed,
            overrides=scenario_overrides(args),
            workers=args.workers,
            scheduler=args.scheduler,
            force=args.force,
            levels=args.levels,
            second_order=not args.no_second_order,
            retry_failed=args.retry_failed,
            exclude_failed=args.exclude_failed,
            progress=not args.quiet,
            overwrite=args.overwrite,
            max_wall_minutes=args.max_wall_minutes,
        )
    except (SweepSpecError, FeatureError, ImportError) as exc:
        return usage_error("sensitivity", str(exc))
    if not args.quiet:
        print(res.table())
        print(f"({res.ran} runs now, {res.skipped} recorded before; files in {res.out})")
    return EXIT_OK
