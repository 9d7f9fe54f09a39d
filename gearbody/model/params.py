"""Typed, range-checked parameters and the conversion of nested dicts (TOML) into dataclass trees.

A model dataclass declares each field with :func:`param`, giving its unit-carrying name, range and
meaning. :func:`from_dict` turns a nested dict into that dataclass tree and refuses bad input with a
:class:`ScenarioError` that names the source, the key, the value and the allowed range, before
anything runs. Unknown keys get the nearest valid key as a suggestion.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import re
import types
import typing
from typing import Any, get_args, get_origin, get_type_hints

from ..errors import ScenarioError
from .kinds import stage_kinds


def param(
    default: Any = dataclasses.MISSING,
    *,
    doc: str = "",
    gt: float | None = None,
    ge: float | None = None,
    lt: float | None = None,
    le: float | None = None,
    choices: tuple[Any, ...] | None = None,
    default_factory: Any = dataclasses.MISSING,
) -> Any:
    """A dataclass field with a documented meaning, unit (in its name) and allowed range."""
    meta = {"doc": doc, "gt": gt, "ge": ge, "lt": lt, "le": le, "choices": choices}
    if default_factory is not dataclasses.MISSING:
        return dataclasses.field(default_factory=default_factory, metadata=meta)
    return dataclasses.field(default=default, metadata=meta)


def stage_key(stage: int, key: str = "") -> str:
    """Dotted key of stage ``stage`` (0-based in Python, numbered from 1 in keys): design.stages.2.mesh."""
    return f"design.stages.{stage + 1}." + key


class Node:
    """Base of the scenario dataclasses: ``replace(**changes)`` gives a validated copy."""

    def replace(self, **changes: Any):
        """A copy with ``changes`` (field = new value): each value is checked against its field's type and
        range as a value read from a file would be, then the copy is validated like a fresh one."""
        fields = {f.name: f for f in dataclasses.fields(self)}
        hints = get_type_hints(type(self))
        checked = {}
        for name, value in changes.items():
            if name not in fields:
                near = difflib.get_close_matches(name, list(fields), n=1)
                hint = f"; did you mean {near[0]!r}?" if near else f"; fields: {', '.join(fields)}"
                raise ScenarioError(f"{type(self).__name__}.replace: no field {name!r}{hint}")
            if dataclasses.is_dataclass(value) or (
                isinstance(value, tuple) and value and all(dataclasses.is_dataclass(v) for v in value)
            ):
                checked[name] = value  # built (and checked) on its own
            else:
                ctx = _Ctx(f"{type(self).__name__}.replace", name)
                checked[name] = _convert(value, hints[name], ctx, fields[name].metadata)
        return dataclasses.replace(self, **checked)


def check_ranges(node: Any) -> None:
    """Check a node's number fields against their types and ranges, as :func:`from_dict` checks a value
    read from a file: for a node built in Python (``RollingGeometry(balls=2, ...)``), whose
    ``__post_init__`` calls this. A ScenarioError names the node, the field, its value and the range."""
    hints = get_type_hints(type(node))
    for f in dataclasses.fields(node):
        value = getattr(node, f.name)
        if hints[f.name] in (int, float) or isinstance(value, (int, float)):
            _convert(value, hints[f.name], _Ctx(type(node).__name__, f.name), f.metadata)


def describe_range(meta: typing.Mapping[str, Any]) -> str:
    """Human text for a field's allowed range, e.g. '> 0', '[0, 1]'."""
    if meta.get("choices"):
        return "one of " + ", ".join(repr(c) for c in meta["choices"])
    lo = (
        f"> {meta['gt']:g}"
        if meta.get("gt") is not None
        else (f">= {meta['ge']:g}" if meta.get("ge") is not None else "")
    )
    hi = (
        f"< {meta['lt']:g}"
        if meta.get("lt") is not None
        else (f"<= {meta['le']:g}" if meta.get("le") is not None else "")
    )
    if lo and hi:
        return f"{lo} and {hi}"
    return lo or hi or "any value"


def _in_range(value: float, meta: typing.Mapping[str, Any]) -> bool:
    if meta.get("gt") is not None and not value > meta["gt"]:
        return False
    if meta.get("ge") is not None and not value >= meta["ge"]:
        return False
    if meta.get("lt") is not None and not value < meta["lt"]:
        return False
    return not (meta.get("le") is not None and not value <= meta["le"])


class _Ctx:
    """Where a value came from: file name and dotted key path, for error messages.

    ``aliases`` maps canonical key prefixes to the keys the user wrote (the single-stage shorthand:
    ``design.stages.1.pinion`` was written ``design.pinion``), so that messages name the user's key.
    ``origins`` maps the canonical keys set by overrides to the override as typed
    (``--set production.error_mode.e_um=abc``), so that messages blame the override, not the file.
    """

    def __init__(
        self,
        source: str,
        path: str = "",
        aliases: typing.Mapping[str, str] | None = None,
        origins: typing.Mapping[str, str] | None = None,
    ):
        self.source, self.path = source, path
        self.aliases, self.origins = dict(aliases or {}), dict(origins or {})

    def child(self, key: str) -> _Ctx:
        return _Ctx(self.source, f"{self.path}.{key}" if self.path else key, self.aliases, self.origins)

    def shown(self, path: str | None = None) -> str:
        """``path`` (default: this one) as the user wrote it."""
        return display_path(self.path if path is None else path, self.aliases)

    def where(self, path: str | None = None) -> str:
        """The source of the value at ``path`` (default: this one): the override that set it or a key
        above or below it, else the file."""
        path = self.path if path is None else path
        hits = [k for k in self.origins if _related(k, path)] if path else []
        return self._blame(hits)

    def _blame(self, hits: list[str]) -> str:
        if not hits:
            return self.source
        on = "" if self.source == "<dict>" else f" (on {self.source})"
        return f"{self.origins[max(hits, key=len)]}{on}"

    def where_text(self, text: str) -> str:
        """The source of a cross-check message naming canonical keys in ``text``: the override of the
        longest such key, else the file with every override applied to it."""
        keys = re.findall(r"[A-Za-z_]\w*(?:\.\w+)+", text)
        hits = [k for k in self.origins if any(_related(k, t) for t in keys)]
        if hits:
            return self._blame(hits)
        if self.origins:
            return f"{self.source} with {', '.join(dict.fromkeys(self.origins.values()))}"
        return self.source

    def fail(self, value: Any, message: str) -> typing.NoReturn:
        shown = f"{value:.6g}" if isinstance(value, float) else _short_repr(value)
        raise ScenarioError(f"{self.where()}: {self.shown()} = {shown}: {message}")


def _related(key: str, path: str) -> bool:
    """True when dotted ``key`` is ``path``, above it or below it."""
    return key == path or path.startswith(key + ".") or key.startswith(path + ".")


def _short_repr(value: Any, limit: int = 120) -> str:
    text = repr(value)
    return text if len(text) <= limit else f"{text[: limit - 3]}..."


def _range_note(meta: typing.Mapping[str, Any]) -> str:
    """`` (range)`` of a field with a range, nothing for one without."""
    text = describe_range(meta)
    return "" if text == "any value" else f" ({text})"


def display_path(path: str, aliases: typing.Mapping[str, str]) -> str:
    """A canonical dotted key as the user wrote it (longest aliased prefix replaced)."""
    for canonical in sorted(aliases, key=len, reverse=True):
        if path == canonical or path.startswith(canonical + "."):
            return aliases[canonical] + path[len(canonical) :]
    return path


def display_text(text: str, aliases: typing.Mapping[str, str]) -> str:
    """Every aliased canonical key inside a message, as the user wrote it."""
    for canonical in sorted(aliases, key=len, reverse=True):
        text = re.sub(re.escape(canonical) + r"(?=[.\s:;,)']|$)", aliases[canonical], text)
    return text


def _type_name(tp: Any) -> str:
    return getattr(tp, "__name__", str(tp))


def _convert(value: Any, tp: Any, ctx: _Ctx, meta: typing.Mapping[str, Any]) -> Any:
    origin = get_origin(tp)
    if origin in (typing.Union, types.UnionType):
        args = [a for a in get_args(tp) if a is not type(None)]
        if value is None:
            return None
        if len(args) > 1 and all(dataclasses.is_dataclass(a) for a in args):
            return _convert_variant(value, args, ctx)
        return _convert(value, args[0], ctx, meta)
    if tp is dict or origin is dict:
        if not isinstance(value, dict):
            ctx.fail(value, "must be a table of name = number")
        out = {}
        for key, v in value.items():
            out[key] = _convert(v, float, ctx.child(key), {})
        return out
    if dataclasses.is_dataclass(tp):
        if not isinstance(value, dict):
            ctx.fail(value, f"must be a table of {_type_name(tp)} keys")
        return _from_dict(tp, value, ctx)
    if origin in (tuple, list):
        if not isinstance(value, (list, tuple)):
            ctx.fail(value, "must be a list")
        (item_tp, *_rest) = get_args(tp)
        # list items are numbered from 1 in keys (design.stages.2.mesh), as in --set and the signal names
        return tuple(_convert(v, item_tp, ctx.child(str(i + 1)), {}) for i, v in enumerate(value))
    if tp is bool:
        if not isinstance(value, bool):
            ctx.fail(value, "must be true or false")
        return value
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            ctx.fail(value, f"must be a whole number{_range_note(meta)}")
    elif tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            ctx.fail(value, f"must be a number{_range_note(meta)}")
        try:
            value = float(value)
        except OverflowError:  # an int of hundreds of digits
            ctx.fail(value, f"too large for a floating-point number{_range_note(meta)}")
        if not math.isfinite(value):
            ctx.fail(value, "must be finite")
    elif tp is str:
        if not isinstance(value, str):
            ctx.fail(value, "must be a string")
    if meta.get("choices") and value not in meta["choices"]:
        near = difflib.get_close_matches(str(value), [str(c) for c in meta["choices"]], n=1)
        hint = f"; did you mean {near[0]!r}?" if near else ""
        ctx.fail(value, f"must be {describe_range(meta)}{hint}")
    if tp in (int, float) and not _in_range(value, meta):
        ctx.fail(value, f"must be {describe_range(meta)}")
    return value


def _convert_variant(value: Any, kinds: list[type], ctx: _Ctx) -> Any:
    """A table that is one of several node types, told apart by its ``type`` key (each type's ``KIND``;
    the first type's tables may leave it out: a design.stages item is parallel unless it says
    ``type = "planetary"``). A type without a ``type`` field takes the key only as a label."""
    if not isinstance(value, dict):
        ctx.fail(value, f"must be a table of {_type_name(kinds[0])} keys")
    by_kind = {getattr(k, "KIND", _type_name(k)): k for k in kinds}
    if any(kind.model in kinds for kind in stage_kinds()):  # design.stages: every registered stage kind
        by_kind.update({kind.name: kind.model for kind in stage_kinds()})
    kind = value.get("type", getattr(kinds[0], "KIND", None))
    if not isinstance(kind, str) or kind not in by_kind:  # (an array or a table is no kind: unhashable)
        meta = {"choices": tuple(by_kind)}
        _convert(kind, str, ctx.child("type"), meta)  # names the key, the value and the choices
    cls = by_kind[kind]
    if "type" in value and "type" not in {f.name for f in dataclasses.fields(cls)}:
        value = {k: v for k, v in value.items() if k != "type"}
    return _from_dict(cls, value, ctx)


def _from_dict(cls: type, data: typing.Mapping[str, Any], ctx: _Ctx) -> Any:
    hints = get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls)}
    for key in data:
        if key not in fields:
            near = difflib.get_close_matches(key, list(fields), n=1, cutoff=0.5)
            hint = (
                f"; did you mean {ctx.child(near[0]).shown()!r}?"
                if near
                else f"; valid keys here: {', '.join(fields)}"
            )
            raise ScenarioError(f"{ctx.child(key).where()}: unknown key {ctx.child(key).shown()!r}{hint}")
    kwargs = {}
    for name, f in fields.items():
        sub = ctx.child(name)
        if name not in data:
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                doc = f.metadata.get("doc", "")
                raise ScenarioError(
                    f"{ctx.source}: missing required key {sub.shown()!r}"
                    + (f" ({doc}; {describe_range(f.metadata)})" if doc else "")
                )
            continue
        kwargs[name] = _convert(data[name], hints[name], sub, f.metadata)
    try:
        prepare = getattr(cls, "prepare_fields", None)  # e.g. Scenario: resolve gear geometry first
        return cls(**(prepare(kwargs) if prepare else kwargs))
    except ScenarioError as exc:
        text = str(exc)
        if not ctx.path:
            raise ScenarioError(f"{ctx.where_text(text)}: {display_text(text, ctx.aliases)}") from None
        raise ScenarioError(f"{ctx.where()}: {_under(ctx.shown(), text, fields)}") from None


def _under(shown: str, text: str, fields: typing.Mapping[str, Any]) -> str:
    """A node's own check message as the user's dotted key: ``spall_end_diameter_mm = 0: ...`` of
    ``condition.damaged_teeth.1`` -> ``condition.damaged_teeth.1.spall_end_diameter_mm = 0: ...``."""
    last = shown.rsplit(".", 1)[-1]
    if text.startswith(last + "."):  # 'bearing.kind = ...' said by the bearing itself
        text = text[len(last) + 1 :]
    head = re.match(r"[A-Za-z_]\w*", text)
    if head and head.group(0) in fields:
        return f"{shown}.{text}"
    return f"{shown}: {text}"


def from_dict(
    cls: type,
    data: typing.Mapping[str, Any],
    source: str = "<scenario>",
    aliases: typing.Mapping[str, str] | None = None,
    origins: typing.Mapping[str, str] | None = None,
) -> Any:
    """Build dataclass ``cls`` from a nested dict, checking keys, types and ranges; ``aliases`` name
    canonical keys as the user wrote them and ``origins`` the overrides that set keys, in messages
    (see :class:`_Ctx`)."""
    if not isinstance(data, dict):
        raise ScenarioError(f"{source}: the scenario must be a table of sections, got {type(data).__name__}")
    return _from_dict(cls, data, _Ctx(source, aliases=aliases, origins=origins))


def to_dict(obj: Any) -> Any:
    """Dataclass tree -> nested dict of TOML-writable values (None fields are left out)."""
    if dataclasses.is_dataclass(obj):
        out = {}
        for f in dataclasses.fields(obj):
            v = getattr(obj, f.name)
            if v is not None:
                out[f.name] = to_dict(v)
        return out
    if isinstance(obj, (list, tuple)):
        return [to_dict(v) for v in obj]
    if isinstance(obj, dict):
        return {k: to_dict(v) for k, v in obj.items()}
    return obj
