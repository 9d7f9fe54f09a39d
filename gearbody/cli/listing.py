"""``gearbody list``: the shipped scenes, one per line (name, then its title)."""

from __future__ import annotations

import argparse

from .common import EXIT_OK


def register(sub) -> argparse.ArgumentParser:
    """Add the command's parser to ``sub`` (the subparsers of ``gearbody``)."""
    about = "list the shipped scenes, one per line (name first, then its title)"
    parser = sub.add_parser(
        "list",
        help=about,
        description=f"{about[0].upper()}{about[1:]}. A name is what run, modes, mesh, sweep and render take"
        " as SCENE; a .toml path works as well.",
    )
    parser.set_defaults(handler=execute)
    return parser


def execute(_args) -> int:
    from gearbody.model import load_scenario
    from gearbody.model.scenes import list_scenes

    for name in list_scenes():
        print(f"{name}\t{load_scenario(name).meta.title}")
    return EXIT_OK
