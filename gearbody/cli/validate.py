"""``gearbody validate``: compare gearbody with the independent ODE reference (exit 1 above tolerance)."""

from __future__ import annotations

import argparse

from .common import EXIT_FAILED, EXIT_OK, MAX_WORKERS, load, number


def register(sub) -> argparse.ArgumentParser:
    """Add the command's parser to ``sub`` (the subparsers of ``gearbody``)."""
    about = "compare gearbody with the independent ODE reference (exit 1 above tolerance)"
    val = sub.add_parser(
        "validate",
        help=about,
        description=f"{about[0].upper()}{about[1:]}: each scene is simulated by gearbody and by the"
        " reference integrator and the mesh forces are compared, relative to the rated mesh force.",
    )
    val.add_argument("scenes", metavar="SCENE", nargs="*", help="scenes to validate (default: all)")
    val.add_argument("--short", action="store_true", help="short runs (as in the test suite)")
    val.add_argument(
        "--tolerance", type=number(gt=0), default=0.5, help="max |dF|/F_rated in %% (default 0.5)"
    )
    val.add_argument(
        "--workers",
        type=number(whole=True, ge=1, le=MAX_WORKERS),
        default=None,
        help="cases run at once on this many local processes (default: one per CPU; 1: one after the other)",
    )
    val.add_argument(
        "--no-cache",
        action="store_true",
        help="run the reference on every case (default: take its output from the cache where the "
        "reference's code, its inputs and numpy/scipy are unchanged; $GEARBODY_REFERENCE_CACHE, "
        "default ~/.cache/gearbody/reference)",
    )
    val.set_defaults(handler=execute)
    return val


def execute(args) -> int:
    from gearbody_validation.compare import run_validation

    for scene in args.scenes:  # a misspelled scene fails before the table header
        load(scene, [])
    ok = run_validation(
        args.scenes or None,
        short=args.short,
        tolerance_percent=args.tolerance,
        workers=args.workers,
        use_cache=not args.no_cache,
    )
    return EXIT_OK if ok else EXIT_FAILED
