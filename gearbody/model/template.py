"""A scenario as a commented TOML file: the starting point of a user's own drive (``gearbody new``).

:func:`commented_toml` writes the fully resolved scenario, every key in the canonical shape, each with a
comment above it: its meaning, unit, allowed range and default (from the field's :func:`param`), and
where its value comes from: the scene file, an override, gearbody's default, or gearbody's resolution
(a base radius computed from the gear geometry, a tolerance from ``solver.accuracy``). Resolved values
and keys left unset are listed as comments, so that a resolved value follows edits of its inputs.
The scene's own header comment (its parameter choices and their sources) is kept at the top. Loading
the file gives the resolved scenario it was written from (its ``meta.name`` then defaults to the
file's name).
"""

from __future__ import annotations

import dataclasses
import math
import textwrap
import typing
from collections.abc import Mapping, Sequence
from typing import Any

import tomli_w

from .params import describe_range, to_dict

__all__ = ["UNSET", "commented_toml", "header_comment", "unit_of"]

UNITS = (
    ("_Nms_per_rad", "N m s/rad"),
    ("_Nm_per_rad", "N m/rad"),
    ("_Ns_per_m", "N s/m"),
    ("_N_per_m", "N/m"),
    ("_kg_m2", "kg m^2"),
    ("_Nm", "N m"),
    ("_rad_s", "rad/s"),
    ("_MiB", "MiB"),
    ("_GPa", "GPa"),
    ("_hz", "Hz"),
    ("_deg", "deg"),
    ("_um", "um"),
    ("_mm", "mm"),
    ("_kg", "kg"),
    ("_s", "s"),
    ("_m", "m"),
)
"""Unit of a key from the end of its name (gearbody's names carry their units)."""

ARRAYS_OF_TABLES = ("stages", "shafts", "accelerometers")
"""List keys written as ``[[...]]`` tables (the chain); other lists of tables are written inline."""

UNSET = "not set"
WIDTH = 100
"""Comment lines are wrapped at this width."""

SCENE = "set by the scene"
OVERRIDE = "set by --set"
DEFAULT = "gearbody's default"
COMPUTED = "resolved by gearbody (a default, or computed from other keys)"


def unit_of(name: str) -> str:
    """The unit a key's name carries (``inertia_kg_m2`` -> ``kg m^2``), '' for none."""
    for suffix, unit in UNITS:
        if name.endswith(suffix):
            return unit
    return ""


def _float(x: float) -> str:
    """The shortest text that reads back as ``x`` exactly: 1.2e+09 rather than 1200000000.0."""
    if x != 0 and math.isfinite(x) and not 1e-4 <= abs(x) < 1e6:
        for digits in range(17):
            text = f"{x:.{digits}e}"
            if float(text) == x:
                return text
    return tomli_w.dumps({"v": x}).split("=", 1)[1].strip()


def _value(v: Any) -> str:
    """A TOML value, written inline."""
    if isinstance(v, float):
        return _float(v)
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_value(x)}" for k, x in v.items()) + " }" if v else "{}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    return tomli_w.dumps({"v": v}).split("=", 1)[1].strip()


def _default_of(f: dataclasses.Field) -> Any:
    if f.default is not dataclasses.MISSING:
        return f.default
    if f.default_factory is not dataclasses.MISSING:
        return f.default_factory()
    return dataclasses.MISSING


def _describe(f: dataclasses.Field, value_for_unit: str = "") -> str:
    """``meaning [unit]; range; default``."""
    meta = f.metadata
    parts = [meta.get("doc", "") or f.name.replace("_", " ")]
    unit = unit_of(f.name) or value_for_unit
    if unit:
        parts[0] += f" [{unit}]"
    allowed = describe_range(meta)
    if allowed != "any value":
        parts.append(allowed)
    default = _default_of(f)
    if default is dataclasses.MISSING:
        parts.append("required")
    elif default is not None and not dataclasses.is_dataclass(default):
        shown = to_dict(default)
        if shown not in ((), [], {}, ""):
            parts.append(f"default {_value(shown)}")
    return "; ".join(parts)


def _item_fields(hint: Any) -> list[type]:
    """The dataclasses of a ``tuple[Item, ...]`` (or of a union of items) type hint."""
    items = []
    for arg in typing.get_args(hint):
        if arg is Ellipsis:
            continue
        if dataclasses.is_dataclass(arg):
            items.append(arg)
        else:
            items.extend(a for a in typing.get_args(arg) if dataclasses.is_dataclass(a))
    return items


def _lookup(data: Any, path: Sequence[str]) -> tuple[bool, Any]:
    node = data
    for part in path:
        if isinstance(node, Mapping) and part in node:
            node = node[part]
        elif isinstance(node, list) and part.isdigit() and 1 <= int(part) <= len(node):
            node = node[int(part) - 1]
        else:
            return False, None
    return True, node


class _Writer:
    def __init__(self, given: Mapping[str, Any], overridden: set[str]):
        self.given, self.overridden = given, overridden
        self.lines: list[str] = []

    def provenance(self, path: Sequence[str], value: Any, f: dataclasses.Field) -> str:
        key = ".".join(path)
        if any(key == o or key.startswith(o + ".") for o in self.overridden):
            return OVERRIDE
        found, _ = _lookup(self.given, path)
        if found:
            return SCENE
        default = _default_of(f)  # a required key not in the scene: its table is a default as a whole
        same = default is dataclasses.MISSING or to_dict(value) == to_dict(default)
        return DEFAULT if same else COMPUTED

    def comment(self, text: str) -> None:
        """``# text``, wrapped at WIDTH; continuation lines indented."""
        lines = textwrap.wrap(text, WIDTH - 2, subsequent_indent="  ", break_on_hyphens=False) or [""]
        self.lines.extend(f"# {line}".rstrip() for line in lines)

    def table(
        self, obj: Any, path: list[str], header: str | None, doc: str = "", array: bool = False
    ) -> None:
        """``obj``'s fields under ``[header]`` (``[[header]]`` with ``array``), ``doc`` above it; ``path``
        is the canonical key (list items numbered from 1), ``header`` the TOML table name."""
        hints = typing.get_type_hints(type(obj))
        scalars, tables, arrays = [], [], []
        for f in dataclasses.fields(obj):
            v = getattr(obj, f.name)
            if dataclasses.is_dataclass(v):
                tables.append(f)
            elif f.name in ARRAYS_OF_TABLES and isinstance(v, tuple) and v and dataclasses.is_dataclass(v[0]):
                arrays.append(f)
            else:
                scalars.append(f)
        if header is not None and (scalars or array):
            self.lines.append("")
            if doc:
                self.comment(doc)
            self.lines.append(f"[[{header}]]" if array else f"[{header}]")
        for f in scalars:
            self.scalar(obj, f, path, hints[f.name])
        prefix = f"{header}." if header else ""
        for f in tables:
            doc = _describe(f) if f.metadata.get("doc") else ""
            self.table(getattr(obj, f.name), [*path, f.name], prefix + f.name, doc)
        for f in arrays:
            for i, item in enumerate(getattr(obj, f.name)):
                doc = (
                    f"{prefix}{f.name} item {i + 1}: {_describe(f)}"
                    if i == 0
                    else f"{prefix}{f.name} item {i + 1}"
                )
                self.table(item, [*path, f.name, str(i + 1)], prefix + f.name, doc, array=True)

    def scalar(self, obj: Any, f: dataclasses.Field, path: list[str], hint: Any) -> None:
        v = getattr(obj, f.name)
        key = [*path, f.name]
        if v is None:
            self.comment(f"{f.name}: {UNSET}; {_describe(f)}")
            return
        text = _describe(f)
        if isinstance(v, dict) and v:
            text += "; names carry their units"
        origin = self.provenance(key, v, f)
        if origin == COMPUTED:  # left for gearbody to compute again, so it follows edits of its inputs
            self.comment(f"{text}; {origin}; uncomment to fix it")
            self.lines.append(f"# {f.name} = {_value(to_dict(v))}")
            return
        self.comment(f"{text}; {origin}")
        items = _item_fields(hint) if isinstance(v, tuple) else []
        for item in items:
            keys = ", ".join(
                f"{g.name} ({describe_range(g.metadata)})"
                if describe_range(g.metadata) != "any value"
                else g.name
                for g in dataclasses.fields(item)
            )
            self.comment(f"  an item ({item.__name__}): {{ {keys} }}")
        shown = to_dict(v)
        if isinstance(shown, list) and len(_value(shown)) + len(f.name) > 100:
            self.lines.append(f"{f.name} = [")
            self.lines.extend(f"  {_value(x)}," for x in shown)
            self.lines.append("]")
        else:
            self.lines.append(f"{f.name} = {_value(shown)}")


def header_comment(text: str) -> list[str]:
    """The leading comment lines of a TOML text (a scene's own notes), without their ``#``."""
    out = []
    for line in text.splitlines():
        if line.startswith("#"):
            out.append(line[1:].removeprefix(" "))
        elif line.strip():
            break
        elif out:
            out.append("")
    while out and not out[-1]:
        out.pop()
    return out


def commented_toml(
    scenario: Any,
    *,
    given: Mapping[str, Any] | None = None,
    overridden: Sequence[str] = (),
    intro: Sequence[str] = (),
    scene_notes: Sequence[str] = (),
) -> str:
    """The resolved ``scenario`` as TOML with a comment on every key (see the module docstring).

    ``given``: the scene's own data in the canonical shape (which keys it sets); ``overridden``: the
    canonical keys set by overrides; ``intro``: comment lines at the top; ``scene_notes``: the scene's
    header comment, kept below them."""
    w = _Writer(given or {}, set(overridden))
    for line in intro:
        w.comment(line)
    if scene_notes:
        w.lines.append("#")
        w.lines.append("# The scene's own notes on its values:")
        w.lines.extend(f"#   {line}".rstrip() for line in scene_notes)
    meta = scenario.meta
    w.lines.append("")
    w.lines.append("[meta]")
    for f in dataclasses.fields(meta):
        if f.name == "name":  # left out: a file's scenario is named after the file
            w.comment(
                f"{_describe(f)}; {UNSET} here, so the scenario takes the file's name; uncomment to fix it"
            )
            w.lines.append(f"# name = {_value(meta.name)}")
            continue
        w.scalar(meta, f, ["meta"], typing.get_type_hints(type(meta))[f.name])
    for f in dataclasses.fields(scenario):
        if f.name == "meta":
            continue
        if getattr(scenario, f.name) is None:  # an optional section the scenario leaves out
            w.lines.append("")
            w.comment(f"[{f.name}]: {UNSET}; {_describe(f)}")
            continue
        w.table(getattr(scenario, f.name), [f.name], f.name)
    lines = [ln if ln.strip() != "#" else "#" for ln in w.lines]
    return "\n".join(lines).lstrip("\n") + "\n"
