"""The scenes shipped with gearbody: one TOML scenario per system of the paper.

Installed as ``gearbody.scenes``."""

from __future__ import annotations

from pathlib import Path

SCENE_DIR = Path(__file__).resolve().parent


def list_scenes() -> list[str]:
    """Names of the shipped scenes (file names without .toml), sorted."""
    return sorted(p.stem for p in SCENE_DIR.glob("*.toml"))


def scene_path(name: str) -> Path:
    """Path of a shipped scene; raises ValueError naming the valid scenes."""
    path = SCENE_DIR / f"{name}.toml"
    if not path.exists():
        import difflib

        from gearbody.model.params import ScenarioError

        near = difflib.get_close_matches(name, list_scenes(), n=1)
        hint = f"; did you mean {near[0]!r}?" if near else ""
        raise ScenarioError(
            f"unknown scene {name!r}{hint} (scenes: {', '.join(list_scenes())}; "
            "or give a path to a .toml file)"
        )
    return path
