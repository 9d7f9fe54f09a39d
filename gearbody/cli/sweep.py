"""``gearbody sweep SCENE``: a parameter study (:mod:`gearbody.studies`), resumable; exit 0 all cases
ran, 1 some failed, 2 bad input, 130 interrupted (rerun to resume)."""

from __future__ import annotations

import argparse
import sys

from .common import (
    EXIT_FAILED,
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

MAX_CASES = 10_000  # gearbody.studies.MAX_CASES (not imported here: heavy imports wait for execute)


def register(sub) -> argparse.ArgumentParser:
    """Add the command's parser to ``sub`` (the subparsers of ``gearbody``)."""
    # size: a flat list of add_argument calls, one per option, read top to bottom like --help
    sw = sub.add_parser(
        "sweep",
        help="parameter study: many runs with scenario keys varied (grid, Monte-Carlo, seeds), resumable",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=(
            "Run SCENE once per case of a study: the grid of the --vary lists, times --samples random "
            "draws of the --random keys, times meta.seed = 1..N of --seeds. Writes DIR/study.json, "
            "DIR/cases/<id>/ (result.npz, scenario.toml, summary.json, or error.json), DIR/summary.csv "
            "and DIR/<value>_vs_<key>.png. Rerunning the same command on DIR resumes the study (after "
            "Ctrl-C, or a killed run); DIR holding anything else is refused unless --overwrite, and so is "
            "a second study on DIR while one runs. A study has at most 10000 cases unless --max-cases "
            "allows more. Exit code 0: all cases ran; 1: some failed, or a file could not be written (a "
            "full disk: the cases recorded stay, rerun to resume); 2: bad input; 130: interrupted. See "
            "docs/sweep.md."
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
    sw.add_argument(
        "--samples", type=number(whole=True, ge=1), metavar="N", help="random draws of the --random keys"
    )
    sw.add_argument(
        "--max-cases",
        type=number(whole=True, ge=1),
        default=MAX_CASES,
        metavar="N",
        help=f"refuse a study of more than N cases before anything runs (default {MAX_CASES})",
    )
    sw.add_argument(
        "--study-seed",
        type=number(whole=True, ge=0),
        default=0,
        metavar="S",
        help="seed of the random draws (default 0)",
    )
    sw.add_argument(
        "--seeds",
        type=number(whole=True, ge=1),
        metavar="N",
        help="vary meta.seed (random tooth errors) over 1..N",
    )
    add_set(sw, "fixed override of every case (as for run)")
    sw.add_argument("--t-end", type=number(gt=0), metavar="SECONDS", help="simulated time of every case")
    add_executor(sw)
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
    add_wall_limit(sw, "a study whose runs still to do are")
    add_out(sw, "output folder of the study", required=True)
    add_overwrite(sw, "study (its study.json: scene, --set, --vary, --random, --samples, seeds): resumed")
    sw.set_defaults(handler=execute)
    return sw


def execute(args) -> int:
    check_out(args.out)
    from gearbody.studies import SweepSpecError, run_study

    overrides = scenario_overrides(args)
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
            max_cases=args.max_cases,
            overwrite=args.overwrite,
            max_wall_minutes=args.max_wall_minutes,
        )
    except (SweepSpecError, ImportError) as exc:
        return usage_error("sweep", str(exc))
    if not args.quiet:
        print(study.table())
    if not study.all_ok:  # one line, --quiet or not: exit 1 never goes unexplained
        failed = [r for r in study.rows if r["status"] == "failed"]
        first = f" ({failed[0]['id']}: {str(failed[0].get('error') or '').strip()[:200]})" if failed else ""
        print(
            f"gearbody sweep: {len(failed)} of {len(study.rows)} cases failed{first}; each is recorded in "
            f"{study.csv_path}; rerun with --retry-failed to run them again",
            file=sys.stderr,
        )
    return EXIT_OK if study.all_ok else EXIT_FAILED
