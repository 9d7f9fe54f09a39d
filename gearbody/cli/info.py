"""``gearbody info``: versions of gearbody and what it runs on, and which force path runs use."""

from __future__ import annotations

import argparse
import platform
import sys

from .common import EXIT_OK


def register(sub) -> argparse.ArgumentParser:
    """Add the command's parser to ``sub`` (the subparsers of ``gearbody``)."""
    about = "print versions and the active force path (compiled or Python)"
    parser = sub.add_parser(
        "info",
        help=about,
        description=f"{about[0].upper()}{about[1:]}. The compiled path (Exudyn calls the force laws from "
        "C++, no Python per evaluation) is probed once; where it does not work the reason is printed and "
        "runs use the Python path. solver.force_path in a scenario chooses (auto, compiled, python).",
    )
    parser.set_defaults(handler=execute)
    return parser


def execute(_args) -> int:
    from importlib.metadata import PackageNotFoundError, version

    from gearbody.engine.compiled_path import compiled_path_status

    def v(name: str) -> str:
        try:
            return version(name)
        except PackageNotFoundError:
            return "not installed"

    print(f"gearbody   {v('gearbody')}")
    print(f"python     {platform.python_version()} ({sys.executable})")
    for name in ("exudyn", "numba", "numpy", "scipy", "matplotlib"):
        print(f"{name:<10} {v(name)}")
    works, why = compiled_path_status()
    if works:
        print("force path compiled (Exudyn calls the laws' kernels from C++; solver.force_path = 'auto')")
    else:
        print(f"force path python: {why}")
    return EXIT_OK
