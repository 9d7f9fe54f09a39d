"""Scenarios from TOML files, dicts and ``KEY=VALUE`` overrides; the resolved scenario back to TOML."""

from __future__ import annotations

import copy
import sys
from pathlib import Path
from typing import Any

import tomli_w

from .params import ScenarioError, from_dict, to_dict
from .scenario import Scenario

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def read_toml(path: str | Path) -> dict[str, Any]:
    """Read a TOML file, turning syntax errors into a ScenarioError naming the file."""
    path = Path(path)
    try:
        with path.open("rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError:
        raise ScenarioError(f"{path}: no such scenario file") from None
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{path}: not valid TOML: {exc}") from None


def parse_override(text: str) -> tuple[str, Any]:
    """``'production.error_mode.e_um=15'`` -> ``('production.error_mode.e_um', 15)``.

    The value is read as a TOML value (numbers, booleans, arrays, quoted strings); anything that is
    not valid TOML is taken as a plain string.
    """
    if "=" not in text:
        raise ScenarioError(f"--set {text!r}: expected KEY=VALUE, e.g. production.error_mode.e_um=15")
    key, raw = (s.strip() for s in text.split("=", 1))
    if not key:
        raise ScenarioError(f"--set {text!r}: empty key")
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    return key, value


def apply_overrides(data: dict[str, Any], overrides: dict[str, Any] | list[str] | None) -> dict[str, Any]:
    """Return a copy of ``data`` with dotted-key overrides set (tables are created as needed)."""
    out = copy.deepcopy(data)
    if not overrides:
        return out
    items = [parse_override(o) for o in overrides] if isinstance(overrides, list) else overrides.items()
    for key, value in items:
        node = out
        parts = key.split(".")
        for part in parts[:-1]:
            node = node.setdefault(part, {})
            if not isinstance(node, dict):
                raise ScenarioError(f"--set {key}: {part!r} is a value, not a table")
        node[parts[-1]] = value
    return out


def load_scenario(
    source: str | Path | dict[str, Any], overrides: dict[str, Any] | list[str] | None = None
) -> Scenario:
    """Build a validated :class:`Scenario` from a TOML path, a scene name, or a nested dict."""
    if isinstance(source, dict):
        data, name = source, "<dict>"
    else:
        from ..scenes import scene_path  # local import: scenes is only a data locator

        path = Path(source)
        if not path.suffix and not path.exists():
            path = scene_path(str(source))
        data, name = read_toml(path), str(path)
    return from_dict(Scenario, apply_overrides(data, overrides), source=name)


def scenario_to_dict(scenario: Scenario) -> dict[str, Any]:
    """The resolved scenario as a nested dict (every default filled in)."""
    data = to_dict(scenario)
    for key in ("stages", "shafts"):  # train-only lists: leave them out of single-stage scenes
        if not data["design"].get(key):
            data["design"].pop(key, None)
    return data


def dump_scenario(scenario: Scenario, path: str | Path) -> Path:
    """Write the resolved scenario as TOML; loading that file gives an equal scenario."""
    path = Path(path)
    path.write_text(tomli_w.dumps(scenario_to_dict(scenario)))
    return path
