"""Scenarios from TOML files, dicts and ``KEY=VALUE`` overrides; the resolved scenario back to TOML."""

from __future__ import annotations

import copy
import sys
from pathlib import Path
from typing import Any

import tomli_w

from .params import ScenarioError, from_dict, to_dict
from .scenario import Scenario
from .scenes import scene_path
from .shorthand import canonical_form, legacy_topology, translate_key

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


def apply_overrides(
    data: dict[str, Any], overrides: dict[str, Any] | list[str] | None
) -> tuple[dict[str, Any], dict[str, str]]:
    """(copy of the canonical ``data`` with dotted-key overrides set, aliases for messages).

    Tables are created as needed; a list item is addressed by its number counted from 1
    (``design.stages.2.mesh.backlash_um``); a single-stage shorthand key (``production.error_mode.e_um``)
    means stage 1 of a one-stage drive and is refused on a longer train, naming the key to write.
    """
    out = copy.deepcopy(data)
    aliases: dict[str, str] = {}
    if not overrides:
        return out, aliases
    items = [parse_override(o) for o in overrides] if isinstance(overrides, list) else overrides.items()
    for key, value in items:
        if key == "meta.scene":  # the older name of meta.topology
            key, value = "meta.topology", legacy_topology(value, "--set")
        try:
            parts, alias = translate_key(key.split("."), out)
        except ScenarioError as exc:
            raise ScenarioError(f"--set {exc}") from None
        aliases.update(alias)
        _set_key(out, parts, value, key)
    return out, aliases


def _set_key(data: dict[str, Any], parts: list[str], value: Any, key: str) -> None:
    node: Any = data
    for depth, part in enumerate(parts):
        last = depth == len(parts) - 1
        where = ".".join(parts[: depth + 1])
        if isinstance(node, list):
            if not part.isdigit():
                raise ScenarioError(
                    f"--set {key}: {'.'.join(parts[:depth])} is a list; address an item by its number, "
                    f"1..{len(node)} (e.g. {'.'.join(parts[:depth])}.1)"
                )
            index = int(part)
            if not 1 <= index <= len(node):
                raise ScenarioError(
                    f"--set {key}: {where}: no item {index}; {'.'.join(parts[:depth])} has {len(node)} "
                    f"(valid: 1..{len(node)})"
                )
            if last:
                node[index - 1] = value
                return
            node = node[index - 1]
        elif isinstance(node, dict):
            if last:
                node[part] = value
                return
            node = node.setdefault(part, {})
        else:
            raise ScenarioError(f"--set {key}: {'.'.join(parts[:depth])!r} is a value, not a table")
        if not isinstance(node, (dict, list)):
            raise ScenarioError(f"--set {key}: {where!r} is a value, not a table")


def load_scenario(
    source: str | Path | dict[str, Any], overrides: dict[str, Any] | list[str] | None = None
) -> Scenario:
    """Build a validated :class:`Scenario` from a TOML path, a scene name, or a nested dict (either the
    canonical shape or the single-stage shorthand), with optional ``KEY=VALUE`` overrides."""
    if isinstance(source, dict):
        data, name, stem = source, "<dict>", ""
    else:
        path = Path(source)
        if not path.suffix and not path.exists():
            path = scene_path(str(source))
        data, name, stem = read_toml(path), str(path), path.stem
    data, aliases = canonical_form(data, name)
    data, more = apply_overrides(data, overrides)
    meta = data.setdefault("meta", {})
    if isinstance(meta, dict) and not meta.get("name") and stem:
        meta["name"] = stem
    return from_dict(Scenario, data, source=name, aliases={**aliases, **more})


def scenario_to_dict(scenario: Scenario) -> dict[str, Any]:
    """The resolved scenario as a nested dict in the canonical shape (every default filled in)."""
    return to_dict(scenario)


def dump_scenario(scenario: Scenario, path: str | Path) -> Path:
    """Write the resolved scenario as TOML; loading that file gives an equal scenario."""
    path = Path(path)
    path.write_text(tomli_w.dumps(scenario_to_dict(scenario)))
    return path
