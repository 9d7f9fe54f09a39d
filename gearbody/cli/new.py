"""``gearbody new SCENE [--out FILE]``: a starting scenario for one's own drive, written from a scene.

The file is the scene's fully resolved scenario (every key, in the canonical shape) with a comment on
each key: meaning, unit, allowed range, default, and whether the scene set it, gearbody filled in its
default or computed it (:mod:`gearbody.model.template`). ``gearbody run FILE`` takes it unchanged.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from .common import EXIT_OK, add_set

__all__ = ["register", "execute"]


def register(sub) -> argparse.ArgumentParser:
    """Add the command's parser to ``sub`` (the subparsers of ``gearbody``)."""
    about = "write a commented starting scenario for your own drive from a scene"
    parser = sub.add_parser(
        "new",
        help=about,
        description=f"{about[0].upper()}{about[1:]}: the scene's fully resolved scenario as TOML, every"
        " key with a comment giving its meaning, unit, allowed range, default and where its value"
        " comes from (the scene, --set, gearbody's default, or resolved by gearbody). Edit it, then"
        " 'gearbody run FILE'.",
        epilog="example: gearbody new one-stage --out my-drive.toml && gearbody run my-drive.toml",
    )
    parser.add_argument("scene", metavar="SCENE", help="scene name (see 'gearbody list') or .toml path")
    add_set(parser, "override a value before writing (as for run); the file says which keys were set")
    parser.add_argument(
        "--out",
        type=Path,
        metavar="FILE",
        help="the file to write (default: SCENE.toml in the current folder; '-': print it)",
    )
    parser.add_argument(
        "--overwrite",
        "--force",
        dest="overwrite",
        action="store_true",
        help="replace an existing FILE (--force: the same, its earlier name)",
    )
    parser.set_defaults(handler=execute)
    return parser


def _scene_file(scene: str) -> Path:
    from gearbody.model.io import names_a_file
    from gearbody.model.scenes import scene_path

    path = Path(scene)
    return path if path.suffix or names_a_file(path) else scene_path(scene)


def execute(args) -> int:
    from gearbody.errors import InputError
    from gearbody.folders import write_text
    from gearbody.model import load_scenario
    from gearbody.model.io import apply_overrides, parse_scenario_bytes, read_scenario_bytes
    from gearbody.model.shorthand import canonical_form
    from gearbody.model.template import commented_toml, header_comment
    from gearbody.version import __version__

    scenario = load_scenario(args.scene, args.overrides)  # refuses a bad scene or override (exit 2)
    source = _scene_file(args.scene)
    data = read_scenario_bytes(source)  # a regular file within the size limit (checked by load_scenario too)
    text = data.decode("utf-8")
    given, _ = canonical_form(parse_scenario_bytes(data, source), str(source))
    _, _, origins = apply_overrides(given, args.overrides)
    out = args.out if args.out is not None else Path(f"{scenario.meta.name or source.stem}.toml")
    command = "gearbody new " + " ".join([args.scene, *(f"--set {o}" for o in args.overrides)])
    shown = "this file" if str(out) == "-" else out.name
    intro = [
        scenario.meta.title or scenario.meta.name,
        "",
        f"A starting scenario written by `{command}` (gearbody {__version__}) from {source.name}:",
        "the fully resolved scenario, every key with a comment above it: meaning [unit]; allowed range;",
        "default; and where the value comes from: set by the scene, set by --set, gearbody's default, or",
        "resolved by gearbody (left as a comment, so that it follows your edits of the keys it comes",
        "from). Keys that are not set are listed as comments too.",
        f"Edit the values of your drive, then: gearbody run {shown}",
        "Every key and equation: docs/scenario.md; sources of the published figures: docs/references.md.",
    ]
    document = commented_toml(
        scenario, given=given, overridden=list(origins), intro=intro, scene_notes=header_comment(text)
    )
    # file names that are not UTF-8 (their bytes kept as surrogates) are quoted with U+FFFD: the file is UTF-8
    document = document.encode("utf-8", "surrogateescape").decode("utf-8", "replace")
    if str(out) == "-":
        sys.stdout.write(document)
        return EXIT_OK
    name_max = _name_max(out.parent)
    for part in out.parts:
        if len(os.fsencode(part)) > name_max:
            raise InputError(
                f"--out {out}: a name in it has {len(os.fsencode(part))} bytes, more than the "
                f"{name_max} this file system allows; give a shorter name"
            )
    if out.is_dir():
        raise InputError(f"--out {out}: is a folder, not a file")
    if out.exists() and not args.overwrite:
        raise InputError(f"--out {out}: exists already; give --overwrite to replace it, or another name")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"--out {out}: cannot write it: {exc.strerror or exc}") from None
    write_text(out, document)  # atomic: a full disk leaves FILE as it was (OutputError naming it)
    print(f"wrote {out}: {scenario.meta.name} with every key commented; run it with: gearbody run {out}")
    return EXIT_OK


def _name_max(folder: Path) -> int:
    """The longest file name, in bytes, that ``folder``'s file system (or that of its nearest existing
    parent) takes; 255 where it cannot say."""
    try:
        while not folder.exists() and folder.parent != folder:
            folder = folder.parent
        return int(os.pathconf(folder, "PC_NAME_MAX"))
    except (OSError, ValueError, AttributeError):
        return 255
