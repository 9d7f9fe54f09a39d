"""The single-stage shorthand of a scenario and its conversion to the canonical shape.

A one-stage drive may be written as in the paper's Figs. 1-3: ``design.pinion``, ``design.wheel``,
``design.mesh``, ``design.coupling``, ``design.output_shaft``, ``production.error_mode``,
``production.eccentricity``, ``condition.damaged_teeth`` and ``condition.pitted_teeth``. Inside gearbody
every drive is a chain of stages and shafts (:mod:`gearbody.model.scenario`), so these keys are moved
into stage 1 (and shafts 1 and 2) once, when the scenario is loaded. They apply only to a drive of one
stage; on a longer train they are refused, naming the key to write instead. Error messages keep naming
the key the user wrote (the returned aliases). Files of earlier gearbody versions state
``meta.scene`` ('one-stage', 'train', 'two-wheel', 'muller'): read as ``meta.topology``.
"""

from __future__ import annotations

import copy
import difflib
from typing import Any

from .faults import ErrorMode
from .mesh import Mesh
from .params import ScenarioError, stage_key, to_dict

# shorthand (table, key) -> key in stage 1
STAGE_KEYS = {
    ("design", "pinion"): "pinion",
    ("design", "wheel"): "wheel",
    ("design", "mesh"): "mesh",
    ("production", "error_mode"): "error_mode",
    ("production", "eccentricity"): "eccentricity",
    ("condition", "damaged_teeth"): "damaged_teeth",
    ("condition", "pitted_teeth"): "pitted_teeth",
}
# shorthand (table, key) -> shaft index (0-based) of a one-stage train
SHAFT_KEYS = {("design", "coupling"): 0, ("design", "output_shaft"): 1}
LEGACY_SCENES = {"one-stage": "train", "train": "train", "two-wheel": "two-wheel", "muller": "muller"}
CANONICAL_KEYS = {
    "design": ("motor", "machine", "stages", "shafts"),
    "condition": ("friction_coefficient", "friction_transition_speed_m_s"),
    "production": (),
}


def legacy_topology(scene: Any, source: str) -> str:
    """meta.topology of an older file's ``meta.scene``."""
    if scene not in LEGACY_SCENES:
        near = difflib.get_close_matches(str(scene), list(LEGACY_SCENES), n=1)
        hint = f"; did you mean {near[0]!r}?" if near else ""
        raise ScenarioError(
            f"{source}: meta.scene = {scene!r}: must be one of "
            f"{', '.join(repr(s) for s in LEGACY_SCENES)}{hint} (meta.scene is the older name of "
            "meta.topology: 'train', 'two-wheel' or 'muller')"
        )
    return LEGACY_SCENES[scene]


def shorthand_aliases() -> dict[str, str]:
    """Canonical key prefix -> shorthand key, for messages about a one-stage drive."""
    out = {stage_key(0, key): f"{table}.{name}" for (table, name), key in STAGE_KEYS.items()}
    out.update({f"design.shafts.{i + 1}": f"{table}.{name}" for (table, name), i in SHAFT_KEYS.items()})
    return out


def _where(key: tuple[str, str]) -> str:
    return ".".join(key)


def canonical_form(data: dict[str, Any], source: str) -> tuple[dict[str, Any], dict[str, str]]:
    """(canonical dict, aliases) of a scenario dict in either shape; the input is not changed."""
    data = copy.deepcopy(data)
    if not isinstance(data, dict):
        raise ScenarioError(f"{source}: the scenario must be a table of sections, got {type(data).__name__}")
    meta = data.get("meta")
    legacy = isinstance(meta, dict) and "scene" in meta
    if legacy:
        scene = meta.pop("scene")
        if "topology" in meta:
            raise ScenarioError(f"{source}: meta.scene and meta.topology both given; keep meta.topology")
        meta["topology"] = legacy_topology(scene, source)
    topology = meta.get("topology") if isinstance(meta, dict) else None
    tables = {t: data.get(t) for t in ("design", "production", "condition")}
    for t, table in tables.items():
        if table is not None and not isinstance(table, dict):
            raise ScenarioError(f"{source}: {t} = {table!r}: must be a table")
    _drop_empty(tables, trains_dump=legacy and "stages" in (tables["design"] or {}))
    given = [k for k in (*STAGE_KEYS, *SHAFT_KEYS) if k[1] in (tables[k[0]] or {})]
    _refuse_unknown(tables, source)
    if not given:
        if not data.get("production"):
            data.pop("production", None)
        return data, {}
    design = data.setdefault("design", {})
    stages = design.get("stages")
    if stages is not None and (not isinstance(stages, list) or len(stages) != 1):
        n = len(stages) if isinstance(stages, list) else "?"
        key = given[0]
        raise ScenarioError(
            f"{source}: {_where(key)} does not apply to a drive of {n} stages stated by [[design.stages]]; "
            f"write {_canonical_hint(key, n)}"
        )
    stage = stages[0] if stages else {}
    for key in STAGE_KEYS:
        if key in given:
            name = STAGE_KEYS[key]
            if name in stage:
                raise ScenarioError(
                    f"{source}: {_where(key)} and {stage_key(0, name)[:-1]} both given; keep one"
                )
            stage[name] = data[key[0]].pop(key[1])
    design["stages"] = [stage]
    shaft_keys = [k for k in SHAFT_KEYS if k in given]
    if topology == "train" or topology is None:
        if shaft_keys and "shafts" in design:
            raise ScenarioError(f"{source}: {_where(shaft_keys[0])} and design.shafts both given; keep one")
        if "shafts" not in design:
            for key in SHAFT_KEYS:
                if key not in given:
                    raise ScenarioError(
                        f"{source}: {_where(key)} is required for a one-stage drive (topology 'train'): "
                        + ("the motor-pinion coupling" if key[1] == "coupling" else "the wheel-machine shaft")
                    )
            design["shafts"] = [design.pop(k[1]) for k in SHAFT_KEYS]
    elif shaft_keys:
        raise ScenarioError(
            f"{source}: {_where(shaft_keys[0])} does not apply to topology {topology!r} (motor and machine "
            "sit rigidly on the gears); remove it, or use topology 'train' for a drive with shafts"
        )
    if not data.get("production"):
        data.pop("production", None)
    return data, shorthand_aliases()


def _drop_empty(tables: dict[str, Any], trains_dump: bool) -> None:
    """Drop shorthand keys that say nothing: empty lists, and in a train dumped by gearbody < 0.2 (which
    wrote every section) the default design.mesh and production.error_mode tables it never used."""
    defaults = {("design", "mesh"): to_dict(Mesh()), ("production", "error_mode"): to_dict(ErrorMode())}
    for t, key in (*STAGE_KEYS, *SHAFT_KEYS):
        table = tables[t]
        if not table or key not in table:
            continue
        if table[key] == [] or (trains_dump and table[key] == defaults.get((t, key))):
            del table[key]


def _canonical_hint(key: tuple[str, str], n_stages: Any, rest: str = "") -> str:
    """``design.stages.N.error_mode.e_um with N = 1..2``: what to write instead of a shorthand key."""
    if key in STAGE_KEYS:
        return f"design.stages.N.{STAGE_KEYS[key]}{rest} with N = 1..{n_stages}"
    return f"design.shafts.N{rest} with N = 1..{n_stages + 1 if isinstance(n_stages, int) else '?'}"


def _refuse_unknown(tables: dict[str, Any], source: str) -> None:
    """Keys of design/production/condition that are neither canonical nor shorthand, with a suggestion."""
    for t, table in tables.items():
        if not table:
            continue
        valid = [*CANONICAL_KEYS[t], *(k[1] for k in (*STAGE_KEYS, *SHAFT_KEYS) if k[0] == t)]
        for key in table:
            if key not in valid:
                near = difflib.get_close_matches(key, valid, n=1, cutoff=0.5)
                hint = (
                    f"; did you mean '{t}.{near[0]}'?" if near else f"; valid keys here: {', '.join(valid)}"
                )
                raise ScenarioError(f"{source}: unknown key '{t}.{key}'{hint}")


def translate_key(path: list[str], data: dict[str, Any]) -> tuple[list[str], dict[str, str]]:
    """A dotted override key on a canonical dict: a shorthand key becomes its stage-1 (or shaft) key
    when the drive has one stage; (new path, alias for messages). Refused on longer trains."""
    if len(path) >= 2 and path[0] in CANONICAL_KEYS:
        tables = {t: ({path[1]: None} if t == path[0] else None) for t in CANONICAL_KEYS}
        _refuse_unknown(tables, ".".join(path))
    if len(path) < 2 or (path[0], path[1]) not in (*STAGE_KEYS, *SHAFT_KEYS):
        return path, {}
    key = (path[0], path[1])
    design, meta = data.get("design", {}), data.get("meta")
    if not isinstance(design, dict):
        raise ScenarioError(f"{'.'.join(path)}: design = {design!r}: must be a table")
    stages = design.get("stages") or []
    if not isinstance(stages, list):
        raise ScenarioError(f"{'.'.join(path)}: design.stages = {stages!r}: must be a list of stages")
    n = len(stages)
    topology = meta.get("topology") if isinstance(meta, dict) else None
    dotted = ".".join(path)
    if key in SHAFT_KEYS and topology != "train":
        raise ScenarioError(
            f"{dotted}: {_where(key)} does not apply to topology {topology!r} (motor and machine sit "
            "rigidly on the gears)"
        )
    if n != 1:
        rest = "".join(f".{p}" for p in path[2:])
        raise ScenarioError(
            f"{dotted}: {_where(key)} does not apply to a drive of {n} stages; write "
            f"{_canonical_hint(key, n, rest)}"
        )
    if key in STAGE_KEYS:
        canonical = ["design", "stages", "1", STAGE_KEYS[key]]
    else:
        canonical = ["design", "shafts", str(SHAFT_KEYS[key] + 1)]
    return canonical + path[2:], {".".join(canonical): _where(key)}
