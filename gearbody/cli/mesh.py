"""``gearbody mesh SCENE``: the mesh report of each stage (:mod:`gearbody.reports.mesh`), printed, and
its figure (:mod:`gearbody.reports.mesh.figure`)."""

from __future__ import annotations

import argparse
import contextlib
import math

from .common import (
    EXIT_OK,
    add_out,
    add_overwrite,
    add_set,
    check_out,
    default_out,
    load,
    number,
    usage_error,
)

MAX_LOAD_FRACTION = 100.0
"""Largest --load: the static TE is linear in the load, and a hundred times the rated force already
deflects a mesh far beyond the lumped model's range (0.1 of the base pitch); 1e300 printed numbers
of 300 digits."""


def register(sub) -> argparse.ArgumentParser:
    """Add the command's parser to ``sub`` (the subparsers of ``gearbody``)."""
    me = sub.add_parser(
        "mesh",
        help="gear mesh report: geometry table, k_z over the mesh cycle (healthy, damaged teeth), static TE",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=(
            "Print each stage's gear geometry and stiffness table (teeth, module, pressure angles, radii, "
            "contact ratios, backlash, k_z single/double/mean, ISO 6336-1 method B, potential-energy mean) "
            "and write DIR/mesh_stage<N>.png: k_z over the mesh cycle, k_z around each damaged tooth next "
            "to the healthy curve, and the static transmission error F/k - E + l_u under load over a "
            "pinion turn. A planetary stage: its teeth, radii and both planet meshes' table, k_z of the "
            "sun-planet and ring-planet law over the mesh cycle, each damaged tooth in the meshes it "
            "enters, and planet 1's static TE in each mesh. Evaluated with the solver's own mesh law, no "
            "simulation. DIR must be empty, hold the plots of the same resolved scenario (drawn again) or "
            "be replaced with --overwrite. See docs/mesh.md."
        ),
    )
    me.add_argument("scene", metavar="SCENE", help="scene name or .toml path")
    add_set(me, "override a scenario value (as for run)")
    me.add_argument(
        "--stage",
        type=number(whole=True, ge=1),
        metavar="N",
        help="only stage N (1 = first in power-flow order; default: all)",
    )
    add_out(me, "output folder (default: runs/SCENE/mesh)")
    add_overwrite(me, "scenario (scene and --set)")
    me.add_argument(
        "--load",
        type=number(ge=0, le=MAX_LOAD_FRACTION),
        default=1.0,
        metavar="FRACTION",
        help=(
            f"static TE at this fraction of each stage's rated force (default 1, at most "
            f"{MAX_LOAD_FRACTION:g})"
        ),
    )
    me.add_argument("--no-plots", action="store_true", help="print the tables only, write no PNGs")
    me.set_defaults(handler=execute)
    return me


def execute(args) -> int:
    out = None if args.no_plots else check_out(args.out or default_out(args.scene, "mesh"))
    scenario = load(args.scene, args.overrides)
    count = len(scenario.stages)
    if args.stage is not None and not 1 <= args.stage <= count:
        return usage_error(
            "mesh", f"--stage = {args.stage}: {args.scene} has {count} stage(s); give 1..{count}"
        )
    if not (math.isfinite(args.load) and 0 <= args.load <= MAX_LOAD_FRACTION):
        return usage_error(
            "mesh", f"--load = {args.load!r}: give a fraction 0..{MAX_LOAD_FRACTION:g} of the rated force"
        )
    stages = range(count) if args.stage is None else [args.stage - 1]
    with contextlib.ExitStack() as stack:
        if out is not None:  # locked while it writes; the old plots go first
            from gearbody.folders import claim
            from gearbody.model import scenario_to_dict

            identity = {"scenario": scenario_to_dict(scenario)}
            folder = stack.enter_context(claim(out, "mesh", identity, overwrite=args.overwrite))
            folder.begin()
        written = _report(args, scenario, stages, out)
        if out is not None:
            folder.finish()
    if written:
        print(f"wrote {', '.join(str(p) for p in written)}")
    return EXIT_OK


def _report(args, scenario, stages, out) -> list:
    """Print each stage's report and write its plot in ``out`` (None: no plots); the plots written. Each
    stage's kind makes its own report (its ``mesh_report``); a kind without one is named and skipped."""
    import gearbody.reports.mesh.kinds  # noqa: F401  (the kinds' mesh reports register on import)
    from gearbody.model.kinds import stage_kind

    print(f"{scenario.meta.title}")
    written = []
    for k in stages:
        path = None if args.no_plots else out / f"mesh_stage{k + 1}.png"
        kind = stage_kind(scenario.stages[k])
        if kind.mesh_report is None:
            print(f"stage {k + 1} (type {kind.name!r}): its kind has no mesh report")
            continue
        text, plot = kind.mesh_report(scenario, k, args.load, path)
        print(text)
        if plot is not None:
            written.append(plot)
    return written
