"""Scenarios from TOML files, dicts and ``KEY=VALUE`` overrides; the resolved scenario back to TOML."""

from __future__ import annotations

import copy
import os
import shlex
import stat
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import tomli_w

from .params import ScenarioError, display_path, from_dict, to_dict
from .scenario import Scenario
from .scenes import scene_path
from .shorthand import canonical_form, legacy_topology, translate_key

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


MAX_SCENARIO_BYTES = 1 << 20
"""Largest scenario file read [bytes], 1 MiB. The shipped scenes are 1.4-4.2 kB and ``gearbody new`` writes
10-22 kB; 1 MiB still holds a measured speed or load profile of 25,000 points (two arrays of ~20
characters a value: 0.99 MB), while a device (``/dev/zero``), a huge file or a file that grows is
refused before it fills memory."""

MAX_NESTING = 32
"""Deepest nesting of tables and arrays in a scenario (a file, or a ``--set`` key and value). The deepest
scenario key, ``design.stages.N.sun.bearing.parameters.K``, nests 7 levels (the file's top table
counted); 32 leaves room while every recursive reader (the TOML parser, copies, validation) stays far
below Python's recursion limit (1000 frames: a TOML array nested ~500 deep or a 900-part table header
exhausted it)."""

_SPECIAL_FILES = (
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def _not_regular(path: Path, mode: int, what: str) -> ScenarioError:
    if stat.S_ISDIR(mode):
        return ScenarioError(f"{path}: is a folder, not a scenario file ({what})")
    kind = next((name for test, name in _SPECIAL_FILES if test(mode)), "not a regular file")
    return ScenarioError(f"{path}: {kind}, not a scenario file ({what}; only regular files are read)")


def names_a_file(path: str | Path) -> bool:
    """Whether ``path`` is to be read as a file rather than taken as a scene name: something is there (a
    broken or looping symbolic link included), or its name cannot even be looked up (too long): the
    reader then refuses it in one line naming the reason, where ``Path.exists`` would raise."""
    path = Path(path)
    try:
        return path.exists() or path.is_symlink()
    except OSError:
        return True


def read_scenario_bytes(path: str | Path) -> bytes:
    """The bytes of a scenario file: a regular file of at most MAX_SCENARIO_BYTES, else a one-line
    ScenarioError naming the file (missing, unreadable, a folder, a FIFO or device, too large).

    The file is checked before it is opened (``os.stat``) and again once open (``os.fstat``); it is
    opened non-blocking, so a FIFO put in its place in between cannot block, and at most one byte more
    than the limit is ever read."""
    path = Path(path)
    what = "a scenario is a UTF-8 TOML text file"
    try:
        mode = os.stat(path).st_mode
        if not stat.S_ISREG(mode):
            raise _not_regular(path, mode, what)
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise ScenarioError(f"{path}: no such scenario file") from None
    except OSError as exc:
        raise ScenarioError(f"{path}: cannot read the scenario file: {exc.strerror or exc}") from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise _not_regular(path, info.st_mode, what)
        chunks, size = [], 0
        while size <= MAX_SCENARIO_BYTES:
            chunk = os.read(fd, MAX_SCENARIO_BYTES + 1 - size)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    except OSError as exc:
        raise ScenarioError(f"{path}: cannot read the scenario file: {exc.strerror or exc}") from None
    finally:
        os.close(fd)
    if size > MAX_SCENARIO_BYTES:
        shown = f"{info.st_size} bytes" if info.st_size > MAX_SCENARIO_BYTES else "it grew while read"
        raise ScenarioError(
            f"{path}: too large for a scenario file ({shown}); allowed: at most {MAX_SCENARIO_BYTES} bytes "
            "(1 MiB)"
        )
    return b"".join(chunks)


def nesting_depth(value: Any) -> int:
    """Levels of tables and arrays in ``value`` (0 for a plain value), counted without recursion."""
    deepest, stack = 0, [(value, 1)]
    while stack:
        node, depth = stack.pop()
        if isinstance(node, dict):
            children = node.values()
        elif isinstance(node, (list, tuple)):
            children = node
        else:
            continue
        deepest = max(deepest, depth)
        if depth <= MAX_NESTING:  # deeper is refused anyway: stop counting there
            stack.extend((child, depth + 1) for child in children)
    return deepest


def _too_deep(where: str) -> ScenarioError:
    return ScenarioError(
        f"{where}: tables and arrays nested more than {MAX_NESTING} levels deep; allowed: at most "
        f"{MAX_NESTING} (a scenario needs 7)"
    )


def _parse_toml(text: str, where: str) -> dict[str, Any]:
    """``tomllib.loads`` with its failures as one-line ScenarioErrors naming ``where``; nesting deeper
    than MAX_NESTING is refused."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{where}: not valid TOML: {exc}") from None
    except RecursionError:  # the parser recurses per level: only hundreds of levels get here
        raise _too_deep(where) from None
    except ValueError:  # Python reads integers of at most 4300 digits
        raise ScenarioError(f"{where}: unreadable value: an integer of more than 4300 digits") from None
    if nesting_depth(data) > MAX_NESTING:
        raise _too_deep(where)
    return data


def read_toml(path: str | Path) -> dict[str, Any]:
    """Read a TOML file; a missing, unreadable, binary or non-UTF-8 file, one that is not a regular file
    (a folder, FIFO, device), one larger than MAX_SCENARIO_BYTES, nested deeper than MAX_NESTING or with a
    syntax error is a one-line ScenarioError naming the file."""
    return parse_scenario_bytes(read_scenario_bytes(path), path)


def parse_scenario_bytes(data: bytes, path: str | Path) -> dict[str, Any]:
    """The TOML data of a scenario file's bytes (:func:`read_scenario_bytes`); errors name ``path``."""
    path = Path(path)
    what = "a scenario is a UTF-8 TOML text file"
    if path.suffix == ".npz" or data.startswith(b"PK\x03\x04"):
        raise ScenarioError(f"{path}: a zip/npz archive (a result?), not a scenario file ({what})")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ScenarioError(
            f"{path}: not UTF-8 text (byte {data[exc.start]:#04x} at offset {exc.start}); {what}"
        ) from None
    if "\x00" in text:
        raise ScenarioError(f"{path}: a binary file (contains NUL bytes), not a scenario file ({what})")
    return _parse_toml(text.removeprefix("\ufeff"), str(path))  # a byte-order mark (Windows editors)


def override_label(text: str, limit: int = 200) -> str:
    """``--set KEY=VALUE`` as a user types it in a shell (quoted where the shell needs it; a text of
    more than ``limit`` characters is shortened)."""
    if len(text) > limit:
        text = text[: limit - 3] + "..."
    return f"--set {shlex.quote(text)}"


def parse_override(text: str, label: str | None = None) -> tuple[str, Any]:
    """``'production.error_mode.e_um=15'`` -> ``('production.error_mode.e_um', 15)``.

    The value is read as a TOML value (numbers, booleans, arrays, quoted strings); anything that is
    not valid TOML is taken as a plain string. Errors name ``label`` (default: the ``--set`` as typed).
    """
    label = label or override_label(text)
    if "=" not in text:
        raise ScenarioError(f"{label}: expected KEY=VALUE, e.g. production.error_mode.e_um=15")
    key, raw = (s.strip() for s in text.split("=", 1))
    if not key:
        raise ScenarioError(f"{label}: empty key")
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    except RecursionError:  # the parser recurses per level: only hundreds of levels get here
        raise _too_deep(label) from None
    except ValueError:  # Python reads integers of at most 4300 digits
        raise ScenarioError(f"{label}: unreadable value: an integer of more than 4300 digits") from None
    _check_override_depth(key, value, label)
    return key, value


def _check_override_depth(key: str, value: Any, label: str) -> None:
    """The levels a ``KEY=VALUE`` adds to a scenario (key parts, then the value's tables and arrays)
    stay within MAX_NESTING."""
    if key.count(".") + 1 + nesting_depth(value) > MAX_NESTING:
        raise ScenarioError(
            f"{label}: nests more than {MAX_NESTING} levels deep (the key's parts, then the value's tables "
            f"and arrays); allowed: at most {MAX_NESTING} (a scenario needs 7)"
        )


def apply_overrides(
    data: dict[str, Any],
    overrides: dict[str, Any] | list[str] | None,
    labels: Sequence[str] | None = None,
) -> tuple[dict[str, Any], dict[str, str], dict[str, str]]:
    """(copy of the canonical ``data`` with dotted-key overrides set, aliases for messages, origins:
    canonical key -> the override that set it, as typed).

    Tables are created as needed; a list item is addressed by its number counted from 1
    (``design.stages.2.mesh.backlash_um``); a single-stage shorthand key (``production.error_mode.e_um``)
    means stage 1 of a one-stage drive and is refused on a longer train, naming the key to write.
    ``labels`` (one per override) name them in messages; default ``--set KEY=VALUE`` as typed.
    """
    out = copy.deepcopy(data)
    aliases: dict[str, str] = {}
    origins: dict[str, str] = {}
    if not overrides:
        return out, aliases, origins
    if isinstance(overrides, list):
        labels = list(labels) if labels is not None else [override_label(o) for o in overrides]
        items = [(lab, *parse_override(o, lab)) for o, lab in zip(overrides, labels, strict=True)]
    else:
        for k, v in overrides.items():  # before repr() of a value (it recurses)
            _check_override_depth(k, v, f"override {k}")
        items = [(f"override {k}={v!r}", k, v) for k, v in overrides.items()]
    for label, key, value in items:
        if key == "meta.scene":  # the older name of meta.topology
            key, value = "meta.topology", legacy_topology(value, label)
        try:
            parts, alias = translate_key(key.split("."), out)
        except ScenarioError as exc:
            raise ScenarioError(f"{label}: {exc}") from None
        aliases.update(alias)
        _set_key(out, parts, value, label, alias)
        origins[".".join(parts)] = label
    return out, aliases, origins


def _set_key(data: dict[str, Any], parts: list[str], value: Any, label: str, aliases: dict[str, str]) -> None:
    node: Any = data

    def key(depth: int) -> str:  # the first ``depth`` parts, as the user typed them
        return display_path(".".join(parts[:depth]), aliases)

    for depth, part in enumerate(parts):
        last = depth == len(parts) - 1
        if isinstance(node, list):
            if not node:
                raise ScenarioError(
                    f"{label}: {key(depth)} is an empty list; give the whole list, e.g. {key(depth)}=[...]"
                )
            if not (part.isascii() and part.isdigit()):
                raise ScenarioError(
                    f"{label}: {key(depth)} is a list; address an item by its number, "
                    f"1..{len(node)} (e.g. {key(depth)}.1)"
                )
            index = int(part)
            if not 1 <= index <= len(node):
                raise ScenarioError(
                    f"{label}: {key(depth + 1)}: no item {index}; {key(depth)} has {len(node)} "
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
            nxt = parts[depth + 1]
            if part not in node and nxt.isascii() and nxt.isdigit():
                raise ScenarioError(
                    f"{label}: {key(depth + 1)} has no item {nxt} (it is not given); give the whole "
                    f"list, e.g. {key(depth + 1)}=[...]"
                )
            node = node.setdefault(part, {})
        else:
            raise ScenarioError(f"{label}: {key(depth)!r} is a value, not a table")
        if not isinstance(node, (dict, list)):
            raise ScenarioError(f"{label}: {key(depth + 1)!r} is a value, not a table")


def load_scenario(
    source: str | Path | dict[str, Any],
    overrides: dict[str, Any] | list[str] | None = None,
    labels: Sequence[str] | None = None,
) -> Scenario:
    """Build a validated :class:`Scenario` from a TOML path, a scene name, or a nested dict (either the
    canonical shape or the single-stage shorthand), with optional ``KEY=VALUE`` overrides; errors
    caused by an override quote it as typed (``labels``: one per override, default ``--set KEY=VALUE``)."""
    if isinstance(source, dict):
        data, name, stem, folder = source, "<dict>", "", None
        if nesting_depth(data) > MAX_NESTING:
            raise _too_deep(name)
    else:
        path = Path(source)
        if not path.suffix and not names_a_file(path):
            path = scene_path(str(source))
        # a file name that is not UTF-8 (bytes kept as surrogates) names the scenario with U+FFFD in
        # their place: meta.name is written into scenario.toml and summary.json, which are UTF-8
        stem = path.stem.encode("utf-8", "surrogateescape").decode("utf-8", "replace")
        data, name, folder = read_toml(path), str(path), path.parent
    data, aliases = canonical_form(data, name)
    anchor_files(data, folder)
    data, more, origins = apply_overrides(data, overrides, labels)
    anchor_files(data, None)  # what an override names, from where it was typed
    meta = data.setdefault("meta", {})
    if isinstance(meta, dict) and not meta.get("name") and stem:
        meta["name"] = stem
    return from_dict(Scenario, data, source=name, aliases={**aliases, **more}, origins=origins)


def anchor_files(data: dict[str, Any], folder: Path | None) -> None:
    """Make every relative ``instruments.accelerometers.N.frf_file`` of ``data`` absolute against
    ``folder`` (a scene file's folder; None: the working folder, for a dict and for overrides), in place, so a
    resolved scenario (a run's scenario.toml) names the same file wherever it is read. Anything not of the
    table's shape is left for validation to name."""
    instruments = data.get("instruments")
    items = instruments.get("accelerometers") if isinstance(instruments, dict) else None
    for item in items if isinstance(items, list) else []:
        text = item.get("frf_file") if isinstance(item, dict) else None
        if isinstance(text, str) and text.strip() and not os.path.isabs(text):
            base = os.getcwd() if folder is None else os.path.abspath(folder)
            item["frf_file"] = os.path.normpath(os.path.join(base, text))


def scenario_to_dict(scenario: Scenario) -> dict[str, Any]:
    """The resolved scenario as a nested dict in the canonical shape (every default filled in)."""
    return to_dict(scenario)


def dump_scenario(scenario: Scenario, path: str | Path) -> Path:
    """Write the resolved scenario as TOML; loading that file gives an equal scenario."""
    path = Path(path)
    text = tomli_w.dumps(scenario_to_dict(scenario))
    # a path quoted in it that is not UTF-8 (bytes kept as surrogates) gets U+FFFD: the file is UTF-8
    path.write_text(text.encode("utf-8", "surrogateescape").decode("utf-8", "replace"))
    return path
