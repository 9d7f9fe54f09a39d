"""Where the shipped scenes are: ``scenes/`` beside the package in a checkout (so a checkout works in
place, whatever is installed), otherwise the installed data package ``gearbody_scenes``."""

from __future__ import annotations

import difflib
import importlib.util
from functools import cache
from pathlib import Path

from .params import ScenarioError


@cache
def scene_dir() -> Path:
    """The folder of the shipped scene files."""
    checkout = Path(__file__).resolve().parents[2]
    if (checkout / "pyproject.toml").is_file() and any((checkout / "scenes").glob("*.toml")):
        return checkout / "scenes"
    spec = importlib.util.find_spec("gearbody_scenes")
    if spec is None or not spec.submodule_search_locations:
        raise ScenarioError(
            "the shipped scenes are not installed (package gearbody_scenes); reinstall gearbody"
        )
    return Path(next(iter(spec.submodule_search_locations)))


def list_scenes() -> list[str]:
    """Names of the shipped scenes (file names without .toml), sorted."""
    return sorted(p.stem for p in scene_dir().glob("*.toml"))


def scene_path(name: str) -> Path:
    """Path of a shipped scene; raises ScenarioError naming the valid scenes."""
    path = scene_dir() / f"{name}.toml"
    if not path.exists():
        near = difflib.get_close_matches(name, list_scenes(), n=1)
        hint = f"; did you mean {near[0]!r}?" if near else ""
        raise ScenarioError(
            f"unknown scene {name!r}{hint} (scenes: {', '.join(list_scenes())}; "
            "or give a path to a .toml file)"
        )
    return path
