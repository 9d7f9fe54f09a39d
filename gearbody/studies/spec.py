"""What a parameter study runs: :class:`Study` (a scene, fixed overrides, the varied keys) and its
:class:`Case` list, the product grid x random samples x seeds with stable ids and deterministic
overrides. Every case is validated (its scenario loaded) before anything runs."""

from __future__ import annotations

import hashlib
import itertools
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from gearbody.model import Scenario, ScenarioError, parse_override
from gearbody.model.io import (
    load_scenario,
    names_a_file,
    override_label,
    parse_scenario_bytes,
    read_scenario_bytes,
)

from .parse import (
    MAX_CASES,
    MOST_CASES,
    Axis,
    RandomAxis,
    SweepSpecError,
    check_key,
    parse_random,
    parse_vary,
    toml_literal,
    toml_value,
)

__all__ = ["MAX_CASES", "SEED_KEY", "Case", "Study"]

SEED_KEY = "meta.seed"


@dataclass(frozen=True)
class Case:
    """One run of a study."""

    id: str
    overrides: tuple[str, ...]
    """All overrides of this case: the study's fixed ones, then one per varied key."""
    texts: dict[str, str]
    """Varied key -> TOML literal of its value in this case."""
    values: dict[str, Any]
    """Varied key -> value."""


def _resolve_scene(scene: str | Path) -> tuple[str, Path]:
    """(label stored in the spec, TOML path), as :func:`gearbody.model.load_scenario` resolves it."""
    from gearbody.model.scenes import scene_path

    path = Path(scene)
    if not path.suffix and not names_a_file(path):
        return str(scene), scene_path(str(scene))
    if not names_a_file(path):  # a folder, binary, a link loop, a name too long: read_toml says so
        raise ScenarioError(f"{path}: no such scenario file")
    return os.path.realpath(path), path


@dataclass(frozen=True)
class Study:
    """What a parameter study runs; build it with :meth:`Study.build`."""

    scene: str
    """Scene name, or the absolute path of a TOML scenario."""
    base: dict[str, Any] = field(repr=False, compare=False)
    """The scene's TOML data, shipped to the workers (they need neither the file nor the scene)."""
    scene_sha256: str
    base_overrides: tuple[str, ...] = ()
    vary: tuple[Axis, ...] = ()
    random: tuple[RandomAxis, ...] = ()
    samples: int = 0
    study_seed: int = 0
    seeds: int = 0

    @classmethod
    def build(
        cls,
        scene: str | Path,
        *,
        vary: Mapping[str, Sequence[Any] | str] | Sequence[str] | None = None,
        random: Mapping[str, str] | Sequence[str] | None = None,
        samples: int | None = None,
        study_seed: int = 0,
        seeds: int | None = None,
        base_overrides: Sequence[str] = (),
        max_cases: int = MAX_CASES,
    ) -> Study:
        """Check and assemble a study.

        Args:
            scene: scene name or path of a TOML scenario.
            vary: grid keys: ``["KEY=0:20:5", "KEY2=a,b"]`` (command-line form) or a mapping
                ``{KEY: "0:20:5" | "a,b" | [python values]}``.
            random: Monte-Carlo keys: ``["KEY=uniform(a,b)"]`` or ``{KEY: "normal(mu,sigma)"}``.
            samples: number of random draws (required with ``random``).
            study_seed: seed of the random draws.
            seeds: vary ``meta.seed`` over 1..seeds.
            base_overrides: fixed ``KEY=VALUE`` overrides of every case (``--set``).
            max_cases: most cases allowed (default :data:`MAX_CASES`); checked before any is made.
        Raises:
            SweepSpecError: bad syntax, conflicting options, or more than ``max_cases`` cases (the
                message names the argument, the count and the limit).
            ScenarioError: unknown scene or bad scenario file.
        """
        max_cases = _check_max_cases(max_cases)
        axes = _vary_axes(vary, max_cases)
        rand = _random_axes(random)
        _check_draws(axes, rand, samples, seeds, study_seed)
        _check_size(axes, rand, int(samples or 0), int(seeds or 0), max_cases)
        base_overrides = tuple(base_overrides)
        _check_varied_once(axes, rand, seeds, base_overrides)
        label, path = _resolve_scene(scene)
        data = read_scenario_bytes(path)  # a regular file within the size limit, read once
        base = parse_scenario_bytes(data, path)
        if isinstance(base.get("meta"), dict):  # the cases of a study carry the scene's name
            base["meta"].setdefault("name", path.stem)
        return cls(
            scene=label,
            base=base,
            scene_sha256=hashlib.sha256(data).hexdigest(),
            base_overrides=base_overrides,
            vary=axes,
            random=rand,
            samples=int(samples or 0),
            study_seed=int(study_seed),
            seeds=int(seeds or 0),
        )

    def axes(self) -> list[Axis]:
        """Every varied key with its values: grid keys, random keys (drawn), then ``meta.seed``."""
        out = list(self.vary) + [r.axis(self.samples, self.study_seed) for r in self.random]
        if self.seeds:
            texts = tuple(str(s) for s in range(1, self.seeds + 1))
            out.append(Axis(SEED_KEY, texts, tuple(range(1, self.seeds + 1)), "--seeds"))
        return out

    @property
    def keys(self) -> list[str]:
        """The varied keys, in column order."""
        return [a.key for a in self.axes()]

    def cases(self) -> list[Case]:
        """All cases: grid (first key outermost) x random samples x seeds, with stable ids."""
        axes = self.axes()
        grid = list(self.vary)
        rand = axes[len(grid) : len(grid) + len(self.random)]
        seed_axes = axes[len(grid) + len(self.random) :]
        grid_idx = itertools.product(*(range(len(a.texts)) for a in grid))
        sample_idx = range(self.samples) if rand else [None]
        seed_idx = range(self.seeds) if seed_axes else [None]
        combos = list(itertools.product(grid_idx, sample_idx, seed_idx))
        width = max(4, len(str(len(combos) - 1)))
        cases = []
        for n, (g, s, k) in enumerate(combos):
            picks = [(a, i) for a, i in zip(grid, g, strict=True)]
            picks += [(a, s) for a in rand] + [(a, k) for a in seed_axes]
            texts = {a.key: a.texts[i] for a, i in picks}
            values = {a.key: a.values[i] for a, i in picks}
            overrides = self.base_overrides + tuple(f"{key}={t}" for key, t in texts.items())
            cases.append(Case(f"case-{n:0{width}d}", overrides, texts, values))
        return cases

    def spec(self) -> dict[str, Any]:
        """The defining part of the study (stored in study.json; a resume must match it)."""
        return {
            "scene": self.scene,
            "scene_sha256": self.scene_sha256,
            "base_overrides": list(self.base_overrides),
            "vary": {a.key: list(a.texts) for a in self.vary},
            "random": {r.key: str(r.distribution) for r in self.random},
            "samples": self.samples,
            "study_seed": self.study_seed,
            "seeds": self.seeds,
        }

    def load_case(self, case: Case) -> Scenario:
        """The case's validated scenario; a ScenarioError names the case and the argument at fault as
        typed (``--set ...``, ``--vary ...``, ``--random ...``; else the first whose override alone, on
        top of the fixed ones, is refused)."""
        labels = {a.key: a.label for a in self.axes()}
        typed = [override_label(o) for o in self.base_overrides]
        typed += [labels[key] or override_label(f"{key}={t}") for key, t in case.texts.items()]
        try:
            return load_scenario(self.base, list(case.overrides), typed)
        except ScenarioError as exc:
            values = ", ".join(f"{k}={t}" for k, t in case.texts.items())
            text = str(exc)
            blamed = next((lab for lab in typed if text.startswith(lab)), None)
            if blamed is not None:  # the message starts with the argument as typed
                rest = text[len(blamed) :].lstrip(": ")
                raise ScenarioError(f"{blamed}: {case.id} ({values}): {rest}") from None
            fixed = list(self.base_overrides)
            where = ""
            if not _loads(self.base, fixed):
                where = "--set: "
            else:
                for key, t in case.texts.items():
                    if not _loads(self.base, [*fixed, f"{key}={t}"]):
                        where = f"{labels[key]}: "
                        break
            raise ScenarioError(f"{where}{case.id} ({values}): {exc}") from None


def _check_size(
    axes: Sequence[Axis], rand: Sequence[RandomAxis], samples: int, seeds: int, max_cases: int
) -> None:
    """SweepSpecError if grid x samples x seeds exceeds ``max_cases`` (counted, nothing is made)."""
    factors = [(a.label, len(a.texts)) for a in axes]
    if rand:
        factors.append((f"--samples {samples}", samples))
    if seeds:
        factors.append((f"--seeds {seeds}", seeds))
    n_cases = math.prod(n for _, n in factors)
    if n_cases > max_cases:
        shown = " x ".join(f"{n} ({label})" for label, n in factors)
        raise SweepSpecError(
            f"the study has {n_cases} cases ({shown}), more than the limit of {max_cases}; "
            f"give --max-cases {n_cases} to run it anyway"
        )


def _loads(base: dict[str, Any], overrides: list[str]) -> bool:
    try:
        load_scenario(base, overrides)
    except ScenarioError:
        return False
    return True


def _vary_axes(
    vary: Mapping[str, Sequence[Any] | str] | Sequence[str] | None, max_cases: int = MAX_CASES
) -> tuple[Axis, ...]:
    if not vary:
        return ()
    if isinstance(vary, str):
        vary = [vary]
    if not isinstance(vary, Mapping):
        return tuple(parse_vary(t, max_count=max_cases) for t in vary)
    axes = []
    for key, spec in vary.items():
        label = f"vary[{key!r}]"
        if isinstance(spec, str):
            axes.append(parse_vary(f"{key}={spec}", label=label, max_count=max_cases))
            continue
        check_key(key, label)
        if hasattr(spec, "__len__") and len(spec) > max_cases:
            raise SweepSpecError(f"{label}: {len(spec)} values, more than the limit of {max_cases} cases")
        values = list(spec)
        if not values:
            raise SweepSpecError(f"{label}: no values")
        texts = tuple(toml_literal(v) for v in values)
        if len(set(texts)) != len(texts):
            raise SweepSpecError(f"{label}: repeated value in {values!r}")
        axes.append(Axis(key, texts, tuple(toml_value(t, label) for t in texts), label))
    return tuple(axes)


def _random_axes(random: Mapping[str, str] | Sequence[str] | None) -> tuple[RandomAxis, ...]:
    if not random:
        return ()
    if isinstance(random, str):
        random = [random]
    if isinstance(random, Mapping):
        return tuple(parse_random(f"{k}={v}", label=f"random[{k!r}]") for k, v in random.items())
    return tuple(parse_random(t) for t in random)


def _check_max_cases(max_cases: Any) -> int:
    """``--max-cases`` as an int: a whole number from 1 to MOST_CASES."""
    if isinstance(max_cases, bool) or int(max_cases) != max_cases or max_cases < 1:
        raise SweepSpecError(f"--max-cases must be a whole number >= 1, got {max_cases!r}")
    if max_cases > MOST_CASES:
        raise SweepSpecError(
            f"--max-cases = {max_cases}: at most {MOST_CASES} (a study's cases are listed in memory "
            "before any runs)"
        )
    return int(max_cases)


def _check_draws(
    axes: Sequence[Axis], rand: Sequence[RandomAxis], samples: Any, seeds: Any, study_seed: Any
) -> None:
    """``--samples`` given exactly when a key is random, ``--seeds`` and ``--study-seed`` whole numbers,
    and something varied."""
    if rand and samples is None:
        raise SweepSpecError(f"{rand[0].label}: give the number of draws with --samples N")
    if samples is not None and (isinstance(samples, bool) or int(samples) != samples or samples < 1):
        raise SweepSpecError(f"--samples must be a whole number >= 1, got {samples!r}")
    if samples is not None and not rand:
        raise SweepSpecError("--samples needs at least one --random KEY=DIST")
    if seeds is not None and (isinstance(seeds, bool) or int(seeds) != seeds or seeds < 1):
        raise SweepSpecError(f"--seeds must be a whole number >= 1, got {seeds!r}")
    if isinstance(study_seed, bool) or int(study_seed) != study_seed or study_seed < 0:
        raise SweepSpecError(f"--study-seed must be a whole number >= 0, got {study_seed!r}")
    if not axes and not rand and not seeds:
        raise SweepSpecError(
            "nothing to vary: give at least one of --vary, --random (with --samples), --seeds"
        )


def _check_varied_once(
    axes: Sequence[Axis], rand: Sequence[RandomAxis], seeds: Any, base_overrides: tuple[str, ...]
) -> None:
    """Every key varied in one place only: by one --vary or --random, by --seeds (``meta.seed``), and
    not also set by --set."""
    seen: dict[str, str] = {}
    for a in (*axes, *rand):
        if a.key in seen:
            raise SweepSpecError(f"{a.label}: {a.key} is already varied by {seen[a.key]}")
        seen[a.key] = a.label
    if seeds and SEED_KEY in seen:
        raise SweepSpecError(f"{seen[SEED_KEY]}: {SEED_KEY} is already varied by --seeds")
    for o in base_overrides:
        key = parse_override(o)[0]  # ScenarioError naming --set on bad syntax
        if key in seen or (seeds and key == SEED_KEY):
            by = seen.get(key, "--seeds")
            raise SweepSpecError(f"--set {o}: {key} is also varied by {by}; give it in one place")
