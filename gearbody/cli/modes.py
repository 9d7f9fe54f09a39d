"""``gearbody modes SCENE``: natural frequencies at mean mesh stiffness, their dominant motion, and the
first stage's input speeds where its mesh harmonics meet them (:mod:`gearbody.analysis.modal`): the
pinion's speed, or a planetary first stage's input member's."""

from __future__ import annotations

import argparse
import math

from .common import EXIT_OK, add_set, load, number


def register(sub) -> argparse.ArgumentParser:
    """Add the command's parser to ``sub`` (the subparsers of ``gearbody``)."""
    about = "natural frequencies (Hz) at mean mesh stiffness, and resonance speeds"
    modes = sub.add_parser(
        "modes",
        help=about,
        description=f"{about[0].upper()}{about[1:]}: the linearised model's modes with their dominant"
        " motion, and the speeds of the first stage's input (the pinion; a planetary stage's input member,"
        " e.g. the sun) at which that stage's first mesh harmonics meet them.",
    )
    modes.add_argument("scene", metavar="SCENE", help="scene name or .toml path")
    add_set(modes, "override a scenario value (as for run)")
    modes.add_argument(
        "--harmonics",
        type=number(whole=True, ge=1, le=100),
        default=3,
        help="mesh harmonics to list resonance speeds for (default 3)",
    )
    modes.set_defaults(handler=execute)
    return modes


def execute(args) -> int:
    from gearbody.analysis.modal import resonance_speeds_rad_s
    from gearbody.engine import scene_modes

    scenario = load(args.scene, args.overrides)
    modes = scene_modes(scenario)
    z1, footnote = _first_stage_input(scenario.stages[0])
    k = ", ".join(f"{x:.4g}" for x in modes.mean_mesh_stiffness_N_per_m)
    print(f"{scenario.meta.title}")
    print(f"linearised at mean mesh stiffness {k} N/m; DOFs: {', '.join(modes.dof_names)}")
    speeds = resonance_speeds_rad_s(modes, z1, args.harmonics)
    head = "".join(f"{f'w({h}f_z) rad/s':>18}" for h in range(1, args.harmonics + 1))
    motion = "dominant motion (share of kinetic energy)"
    # the column is as wide as its longest entry, header included, so that the values stay under theirs
    width = max(len(motion), *(len(modes.label(m)) for m in range(len(modes.frequencies_hz)))) + 2
    print(f"{'mode':>4} {'f_n Hz':>12}  {motion:<{width}}{head}")
    for m, f in enumerate(modes.frequencies_hz):
        cols = "".join(f"{'-' if math.isnan(s) else f'{s:.2f}':>18}" for s in speeds[:, m])
        print(f"{m + 1:>4} {f:12.3f}  {modes.label(m):<{width}}{cols}")
    print(footnote)
    return EXIT_OK


def _first_stage_input(stage) -> tuple[float, str]:
    """(mesh periods per revolution of the first stage's input, the table's footnote), from the stage's
    model (:meth:`mesh_periods_per_revolution`: a parallel stage's z1, a planetary one's f_m / f_in)."""
    return stage.mesh_periods_per_revolution()
