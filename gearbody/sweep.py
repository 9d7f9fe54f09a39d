"""Parameter studies: many runs of one scene with some scenario keys varied, in parallel, resumable.

A :class:`Study` is a scene (name or TOML path), fixed ``KEY=VALUE`` overrides and the varied keys:

- ``vary``: a grid (cartesian product) of value lists per key, each given as ``start:stop:count``
  (``numpy.linspace``, both ends included) or ``v1,v2,...`` (TOML literals);
- ``random``: Monte-Carlo keys drawn from ``uniform(a,b)``, ``normal(mu,sigma)`` or
  ``choice(v1,v2,...)``, ``samples`` draws per key, reproducible from ``study_seed`` (each key has its
  own stream, so adding a key does not change the draws of the others);
- ``seeds``: ``meta.seed`` (the random per-tooth error factors) over 1..N.

The cases are the product grid x samples x seeds, in that order (the first ``vary`` key outermost);
each has a stable id (``case-0000``, ...) and a deterministic list of overrides. Every case is
validated (its scenario loaded) before anything runs.

:func:`run_study` runs the cases serially in-process, on a local process pool, or on a Dask
distributed cluster. Exudyn systems cannot be pickled: every worker rebuilds its model from the
scene's TOML data and the case's override strings. Each finished case is written at once and
atomically to ``OUT/cases/<id>/`` (``result.npz``, ``scenario.toml``, ``summary.json``, or
``error.json`` for a failed case); ``OUT/study.json`` holds the spec, so rerunning the same study on
the same folder resumes it. At the end ``OUT/summary.csv`` and ``OUT/<value>_vs_<key>.png`` are
written. See docs/sweep.md.
"""

from __future__ import annotations

import csv
import hashlib
import io
import itertools
import json
import math
import os
import re
import sys
import time
import traceback
import uuid
import zlib
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from . import __version__
from .model import Scenario, ScenarioError, dump_scenario, parse_override
from .model.io import apply_overrides, read_toml
from .model.params import from_dict
from .plotting.study import plot_study

__all__ = [
    "Axis",
    "Case",
    "Distribution",
    "RandomAxis",
    "Study",
    "StudyResult",
    "SweepSpecError",
    "parse_random",
    "parse_vary",
    "run_case",
    "run_study",
]

STUDY_FORMAT = "gearbody-sweep/1"
SEED_KEY = "meta.seed"
DEFAULT_PLOT_VALUE = "kd_max_final"
# Scalar summary values, in the order of summary.csv's columns (summarize() + the case wall time).
SUMMARY_COLUMNS = (
    "kd_max",
    "kd_min",
    "kd_max_final",
    "kd_mean_final",
    "kd_above_2",
    "separation_fraction",
    "contact_losses",
    "mesh_frequency_hz",
    "mean_speed_rad_s",
    "rated_mesh_force_N",
    "simulated_time_s",
    "solver_steps",
    "solver_rejected_steps",
    "wall_s_per_simulated_s",
    "wall_time_s",
)
_LATERAL_VALUE = re.compile(r"^\w+_(bearing_force_[xy]_max_N|housing_accel_[xy]_rms_final_m_s2)$")
_KEY = re.compile(r"^[A-Za-z_][\w-]*(\.[A-Za-z_][\w-]*)*$")
_DIST = re.compile(r"^\s*(\w+)\s*\((.*)\)\s*$", re.DOTALL)
_NUMBER = r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?"


class SweepSpecError(ValueError):
    """Invalid study input (syntax, conflicting options, a spec that differs from the one on disk);
    the message names the argument."""


# ---------------------------------------------------------------------------------------------------
# Spec parsing


def _split_top(text: str, sep: str) -> list[str]:
    """Split at ``sep`` outside quotes, [brackets] and {braces} (TOML arrays and inline tables)."""
    parts, depth, quote, start = [], 0, "", 0
    for i, ch in enumerate(text):
        if quote:
            if ch == quote and text[i - 1] != "\\":
                quote = ""
        elif ch in "\"'":
            quote = ch
        elif ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
        elif ch == sep and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    parts.append(text[start:])
    return [p.strip() for p in parts]


def _toml_value(text: str) -> Any:
    """A TOML literal's value, read as ``--set`` reads it (not valid TOML: the plain string)."""
    return parse_override(f"v={text}")[1]


def _toml_literal(value: Any) -> str:
    """A Python value as a TOML literal (for values given as Python objects to the API)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    import tomli_w

    return tomli_w.dumps({"v": value}).split("=", 1)[1].strip()


def _number(text: str, label: str, what: str) -> float:
    if not re.fullmatch(_NUMBER, text.strip()):
        raise SweepSpecError(f"{label}: {what} must be a number, got {text!r}")
    return float(text)


def _check_key(key: str, label: str) -> None:
    if not _KEY.match(key):
        raise SweepSpecError(
            f"{label}: {key!r} is not a dotted scenario key (e.g. production.error_mode.e_um)"
        )


def _split_key(text: str, label: str, example: str) -> tuple[str, str]:
    if "=" not in text:
        raise SweepSpecError(f"{label}: expected KEY=SPEC, e.g. {example}")
    key, spec = (s.strip() for s in text.split("=", 1))
    _check_key(key, label)
    if not spec:
        raise SweepSpecError(f"{label}: no values after '=' (e.g. {example})")
    return key, spec


@dataclass(frozen=True)
class Axis:
    """A varied key with its values: ``texts`` are the TOML literals put in the overrides, ``values``
    the parsed values (for tables and plots)."""

    key: str
    texts: tuple[str, ...]
    values: tuple[Any, ...]
    label: str = ""
    """The argument it came from, for error messages (e.g. ``--vary production.error_mode.e_um=0:20:5``)."""


def _range_texts(key: str, spec: str, label: str) -> list[str]:
    parts = _split_top(spec, ":")
    if len(parts) != 3:
        raise SweepSpecError(
            f"{label}: a range is start:stop:count (e.g. {key}=0:20:5), got {spec!r}; "
            "for a list of values use v1,v2,..."
        )
    start, stop = (_number(p, label, w) for p, w in zip(parts[:2], ("start", "stop"), strict=True))
    if not re.fullmatch(r"\d+", parts[2]) or int(parts[2]) < 1:
        raise SweepSpecError(f"{label}: count must be a whole number >= 1, got {parts[2]!r}")
    count = int(parts[2])
    if count == 1 and start != stop:
        raise SweepSpecError(f"{label}: count 1 needs start == stop, got {spec!r}")
    values = np.linspace(start, stop, count)
    whole = all(re.fullmatch(r"[+-]?\d+", p) for p in parts[:2]) and np.all(values == np.round(values))
    if whole:
        return [str(int(round(v))) for v in values]
    return [repr(float(f"{v:.15g}")) for v in values]  # 0.30000000000000004 -> 0.3


def parse_vary(text: str, *, label: str | None = None) -> Axis:
    """``KEY=start:stop:count`` (inclusive linspace) or ``KEY=v1,v2,...`` (TOML literals) -> Axis."""
    label = label or f"--vary {text}"
    key, spec = _split_key(text, label, "production.error_mode.e_um=0:20:5 or ...=5,10,15")
    commas, colons = _split_top(spec, ","), _split_top(spec, ":")
    if len(commas) > 1 and len(colons) > 1:
        raise SweepSpecError(f"{label}: give either a range start:stop:count or a list v1,v2,..., not both")
    texts = _range_texts(key, spec, label) if len(colons) > 1 else commas
    if any(not t for t in texts):
        raise SweepSpecError(f"{label}: empty value in the list {spec!r}")
    if len(set(texts)) != len(texts):
        raise SweepSpecError(f"{label}: repeated value in {spec!r}")
    return Axis(key, tuple(texts), tuple(_toml_value(t) for t in texts), label)


@dataclass(frozen=True)
class Distribution:
    """``uniform(a,b)``, ``normal(mu,sigma)`` or ``choice(v1,v2,...)``."""

    kind: str
    params: tuple[float, ...] = ()
    choices: tuple[str, ...] = ()
    """TOML literals of ``choice``."""

    def __str__(self) -> str:
        args = self.choices if self.kind == "choice" else [repr(p) for p in self.params]
        return f"{self.kind}({','.join(args)})"

    def draw_texts(self, rng: np.random.Generator, n: int) -> list[str]:
        """``n`` draws as TOML literals."""
        if self.kind == "uniform":
            return [repr(float(v)) for v in rng.uniform(*self.params, size=n)]
        if self.kind == "normal":
            return [repr(float(v)) for v in rng.normal(*self.params, size=n)]
        return [self.choices[i] for i in rng.integers(0, len(self.choices), size=n)]


def parse_distribution(spec: str, label: str) -> Distribution:
    """Parse ``uniform(a,b)`` / ``normal(mu,sigma)`` / ``choice(v1,...)``; errors name ``label``."""
    m = _DIST.match(spec)
    kinds = "uniform(a,b), normal(mu,sigma) or choice(v1,v2,...)"
    if not m or m.group(1) not in ("uniform", "normal", "choice"):
        raise SweepSpecError(f"{label}: unknown distribution {spec!r}; expected {kinds}")
    kind, args = m.group(1), _split_top(m.group(2), ",")
    if kind == "choice":
        if not all(args):
            raise SweepSpecError(f"{label}: choice needs one or more values, e.g. choice(5,10,15)")
        return Distribution(kind, choices=tuple(args))
    names = ("a", "b") if kind == "uniform" else ("mu", "sigma")
    if len(args) != 2:
        raise SweepSpecError(f"{label}: {kind} takes two numbers {kind}({','.join(names)}), got {spec!r}")
    p = tuple(_number(a, label, n) for a, n in zip(args, names, strict=True))
    if kind == "uniform" and not p[0] < p[1]:
        raise SweepSpecError(f"{label}: uniform(a,b) needs a < b, got {spec!r}")
    if kind == "normal" and not p[1] > 0:
        raise SweepSpecError(f"{label}: normal(mu,sigma) needs sigma > 0, got {spec!r}")
    return Distribution(kind, params=p)


@dataclass(frozen=True)
class RandomAxis:
    """A Monte-Carlo key: its distribution."""

    key: str
    distribution: Distribution
    label: str = ""

    def axis(self, samples: int, study_seed: int) -> Axis:
        """The ``samples`` draws of this key (own stream: seeded by study seed and key)."""
        rng = np.random.default_rng([study_seed, zlib.crc32(self.key.encode())])
        texts = tuple(self.distribution.draw_texts(rng, samples))
        return Axis(self.key, texts, tuple(_toml_value(t) for t in texts), self.label)


def parse_random(text: str, *, label: str | None = None) -> RandomAxis:
    """``KEY=uniform(a,b)`` | ``KEY=normal(mu,sigma)`` | ``KEY=choice(v1,v2,...)`` -> RandomAxis."""
    label = label or f"--random {text}"
    key, spec = _split_key(text, label, "production.error_mode.e_um=uniform(5,15)")
    return RandomAxis(key, parse_distribution(spec, label), label)


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
    from .scenes import scene_path

    path = Path(scene)
    if not path.suffix and not path.exists():
        return str(scene), scene_path(str(scene))
    if not path.is_file():
        raise ScenarioError(f"{path}: no such scenario file")
    return str(path.resolve()), path


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
        Raises:
            SweepSpecError: bad syntax or conflicting options (the message names the argument).
            ScenarioError: unknown scene or bad scenario file.
        """
        axes = _vary_axes(vary)
        rand = _random_axes(random)
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
        seen: dict[str, str] = {}
        for a in (*axes, *rand):
            if a.key in seen:
                raise SweepSpecError(f"{a.label}: {a.key} is already varied by {seen[a.key]}")
            seen[a.key] = a.label
        if seeds and SEED_KEY in seen:
            raise SweepSpecError(f"{seen[SEED_KEY]}: {SEED_KEY} is already varied by --seeds")
        base_overrides = tuple(base_overrides)
        for o in base_overrides:
            key = parse_override(o)[0]  # ScenarioError naming --set on bad syntax
            if key in seen or (seeds and key == SEED_KEY):
                by = seen.get(key, "--seeds")
                raise SweepSpecError(f"--set {o}: {key} is also varied by {by}; give it in one place")
        label, path = _resolve_scene(scene)
        return cls(
            scene=label,
            base=read_toml(path),
            scene_sha256=hashlib.sha256(path.read_bytes()).hexdigest(),
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
        """The case's validated scenario; a ScenarioError names the case and the argument."""
        try:
            return from_dict(Scenario, apply_overrides(self.base, list(case.overrides)), source=self.scene)
        except ScenarioError as exc:
            msg = str(exc)
            culprits = [a.label for a in self.axes() if a.key in msg] or [
                f"--set {o}" for o in self.base_overrides if parse_override(o)[0] in msg
            ]
            where = f"{culprits[0]}: " if culprits else ""
            values = ", ".join(f"{k}={t}" for k, t in case.texts.items())
            raise ScenarioError(f"{where}{case.id} ({values}): {msg}") from None


def _vary_axes(vary: Mapping[str, Sequence[Any] | str] | Sequence[str] | None) -> tuple[Axis, ...]:
    if not vary:
        return ()
    if isinstance(vary, str):
        vary = [vary]
    if not isinstance(vary, Mapping):
        return tuple(parse_vary(t) for t in vary)
    axes = []
    for key, spec in vary.items():
        label = f"vary[{key!r}]"
        if isinstance(spec, str):
            axes.append(parse_vary(f"{key}={spec}", label=label))
            continue
        _check_key(key, label)
        values = list(spec)
        if not values:
            raise SweepSpecError(f"{label}: no values")
        texts = tuple(_toml_literal(v) for v in values)
        if len(set(texts)) != len(texts):
            raise SweepSpecError(f"{label}: repeated value in {values!r}")
        axes.append(Axis(key, texts, tuple(_toml_value(t) for t in texts), label))
    return tuple(axes)


def _random_axes(random: Mapping[str, str] | Sequence[str] | None) -> tuple[RandomAxis, ...]:
    if not random:
        return ()
    if isinstance(random, str):
        random = [random]
    if isinstance(random, Mapping):
        return tuple(parse_random(f"{k}={v}", label=f"random[{k!r}]") for k, v in random.items())
    return tuple(parse_random(t) for t in random)


# ---------------------------------------------------------------------------------------------------
# One case (runs in a worker)


def run_case(base: Mapping[str, Any], overrides: Sequence[str], keep_result: bool = True) -> dict[str, Any]:
    """Rebuild the scenario from TOML data + overrides, simulate and summarise; never raises.

    Returns ``{"ok": True, "summary": {...}, "result": Result | None, "wall_time_s": s}`` or
    ``{"ok": False, "error_type", "message", "traceback", "wall_time_s"}``. Picklable both ways, so it
    runs in a process pool or on a Dask worker.
    """
    t0 = time.perf_counter()
    try:
        from .engine import simulate
        from .model import load_scenario
        from .reports.summary import summarize

        result = simulate(load_scenario(dict(base), list(overrides)))
        summary = summarize(result)
        wall = time.perf_counter() - t0
        summary["wall_time_s"] = wall
        return {
            "ok": True,
            "summary": summary,
            "result": result if keep_result else None,
            "wall_time_s": wall,
        }
    except Exception as exc:  # any failure is recorded for this case; the study goes on
        return _failure(exc, time.perf_counter() - t0)


def _failure(exc: BaseException, wall_s: float = math.nan) -> dict[str, Any]:
    return {
        "ok": False,
        "error_type": type(exc).__name__,
        "message": str(exc) or repr(exc),
        "traceback": "".join(traceback.format_exception(type(exc), exc, exc.__traceback__)),
        "wall_time_s": wall_s,
    }


# ---------------------------------------------------------------------------------------------------
# Executors: each yields (case id, outcome) as cases finish

Job = tuple[str, tuple]


def _run_serial(jobs: list[Job]) -> Iterator[tuple[str, dict]]:
    for cid, args in jobs:
        yield cid, run_case(*args)


def _run_pool(jobs: list[Job], workers: int) -> Iterator[tuple[str, dict]]:
    pool = ProcessPoolExecutor(max_workers=workers)
    futures = {}
    try:
        futures = {pool.submit(run_case, *args): cid for cid, args in jobs}
        for fut in as_completed(futures):
            try:
                outcome = fut.result()
            except Exception as exc:  # the worker died (BrokenProcessPool) or could not unpickle
                outcome = _failure(exc)
            yield futures[fut], outcome
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _dask():
    try:
        from dask import distributed
    except ImportError as exc:
        raise ImportError(
            "running a study on a Dask cluster needs dask.distributed: pip install gearbody[sweep]"
        ) from exc
    return distributed


def _run_dask(jobs: list[Job], scheduler: Any) -> Iterator[tuple[str, dict]]:
    distributed = _dask()
    own = isinstance(scheduler, str)
    if own:
        try:
            client = distributed.Client(scheduler, timeout="20s")
        except (OSError, TimeoutError) as exc:
            raise SweepSpecError(f"--scheduler {scheduler}: cannot connect: {exc}") from None
    else:
        client = scheduler  # an existing dask.distributed.Client
    token = uuid.uuid4().hex[:8]
    futures: dict = {}
    try:
        for cid, args in jobs:
            fut = client.submit(run_case, *args, key=f"gearbody-sweep-{token}-{cid}", pure=False)
            futures[fut] = cid
        for fut in distributed.as_completed(list(futures)):
            try:
                outcome = fut.result()
            except Exception as exc:  # KilledWorker, lost connection, ...
                outcome = _failure(exc)
            yield futures[fut], outcome
            fut.release()
    finally:
        if futures:
            client.cancel(list(futures))
        if own:
            client.close()


# ---------------------------------------------------------------------------------------------------
# Files


def _atomic_write(path: Path, write: Callable[[Path], Any]) -> Path:
    """Write via a temporary file in the same folder and ``os.replace``: readers never see a part."""
    tmp = path.with_name(f".{path.stem}.{os.getpid()}.{uuid.uuid4().hex[:8]}.tmp{path.suffix}")
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path


def _write_text(path: Path, text: str) -> Path:
    return _atomic_write(path, lambda p: p.write_text(text))


def _write_json(path: Path, data: Any) -> Path:
    return _write_text(path, json.dumps(data, indent=2, default=_jsonable) + "\n")


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, (np.ndarray, tuple)):
        return list(obj)
    return str(obj)


def _read_json(path: Path) -> dict | None:
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def _write_case(case_dir: Path, case: Case, scenario: Scenario, outcome: dict, save_results: bool) -> None:
    """A finished case's files; ``summary.json`` (or ``error.json``) last: it marks the case done."""
    case_dir.mkdir(parents=True, exist_ok=True)
    for stale in case_dir.glob(".*.tmp*"):  # left by an interrupted run
        stale.unlink(missing_ok=True)
    head = {"case": case.id, "values": case.texts, "overrides": list(case.overrides)}
    if outcome["ok"]:
        if save_results and outcome.get("result") is not None:
            _atomic_write(case_dir / "result.npz", outcome["result"].save_npz)
        _atomic_write(case_dir / "scenario.toml", lambda p: dump_scenario(scenario, p))
        _write_json(case_dir / "summary.json", {**outcome["summary"], **head, "status": "ok"})
        (case_dir / "error.json").unlink(missing_ok=True)
    else:
        error = {k: outcome[k] for k in ("error_type", "message", "wall_time_s", "traceback")}
        _write_json(case_dir / "error.json", {**head, "status": "failed", **error})


def _case_state(case_dir: Path) -> tuple[str, dict | None]:
    """("ok", summary) | ("failed", error) | ("pending", None) from a case folder."""
    summary = _read_json(case_dir / "summary.json")
    if summary is not None:
        return "ok", summary
    error = _read_json(case_dir / "error.json")
    if error is not None:
        return "failed", error
    return "pending", None


def _prepare_out(out: Path, study: Study, cases: list[Case]) -> None:
    """Create OUT/study.json, or check that the one there describes this study."""
    path = out / "study.json"
    spec = study.spec()
    listing = [{"id": c.id, "overrides": list(c.overrides)} for c in cases]
    if path.exists():
        old = _read_json(path)
        if old is None or old.get("format") != STUDY_FORMAT:
            raise SweepSpecError(f"--out {out}: {path} is not a gearbody study file; choose another --out")
        diff = [k for k in spec if old.get("spec", {}).get(k) != spec[k]]
        if diff:
            shown = "; ".join(f"{k}: {old.get('spec', {}).get(k)!r} there, {spec[k]!r} now" for k in diff)
            raise SweepSpecError(
                f"--out {out} holds a different study ({shown}); rerun with the same arguments to resume, "
                "or choose another --out"
            )
        if old.get("cases") != listing:
            raise SweepSpecError(
                f"--out {out}: same arguments but different cases (random draws changed with this numpy?); "
                "choose another --out"
            )
        return
    if (out / "cases").exists():
        raise SweepSpecError(f"--out {out} has a cases/ folder but no study.json; choose another --out")
    out.mkdir(parents=True, exist_ok=True)
    _write_json(
        path,
        {
            "format": STUDY_FORMAT,
            "gearbody_version": __version__,
            "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "keys": study.keys,
            "spec": spec,
            "cases": listing,
        },
    )


# ---------------------------------------------------------------------------------------------------
# Results


@dataclass
class StudyResult:
    """What a study produced (everything is also on disk in ``out_dir``)."""

    out_dir: Path
    keys: list[str]
    """Varied keys, in column order."""
    rows: list[dict[str, Any]]
    """One per case, as in summary.csv: id, each key's value, status, summary values, error."""
    ran: int
    """Cases run by this call."""
    skipped: int
    """Cases found done on disk (resume)."""
    csv_path: Path
    plot_path: Path | None
    plot_value: str = DEFAULT_PLOT_VALUE

    @property
    def n_ok(self) -> int:
        return sum(r["status"] == "ok" for r in self.rows)

    @property
    def n_failed(self) -> int:
        return sum(r["status"] == "failed" for r in self.rows)

    @property
    def all_ok(self) -> bool:
        return self.n_ok == len(self.rows)

    def table(self, max_rows: int = 30) -> str:
        """A short text table: id, varied values, status and the plotted value."""
        cols = ["id", *self.keys, "status", self.plot_value]
        cells = [[_cell(r.get(c)) for c in cols] for r in self.rows[:max_rows]]
        widths = [max(len(c), *(len(row[i]) for row in cells)) for i, c in enumerate(cols)]
        lines = ["  ".join(c.ljust(w) for c, w in zip(cols, widths, strict=True))]
        lines += ["  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)) for row in cells]
        if len(self.rows) > max_rows:
            lines.append(f"... {len(self.rows) - max_rows} more cases in {self.csv_path}")
        lines.append(
            f"{self.n_ok} ok, {self.n_failed} failed of {len(self.rows)} cases "
            f"({self.ran} run now, {self.skipped} done before); {self.csv_path}"
            + (f", {self.plot_path}" if self.plot_path else "")
        )
        return "\n".join(lines)


def _cell(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def _csv_value(v: Any, text: str) -> Any:
    return v if isinstance(v, (bool, int, float, str)) else text


def _rows(out: Path, cases: list[Case], keys: list[str]) -> tuple[list[dict], list[str]]:
    rows, extra = [], []
    for case in cases:
        status, data = _case_state(out / "cases" / case.id)
        row: dict[str, Any] = {"id": case.id}
        row.update({k: _csv_value(case.values[k], case.texts[k]) for k in keys})
        row["status"] = status if status != "pending" else "not run"
        if status == "ok":
            for k, v in data.items():
                if k in SUMMARY_COLUMNS or (_LATERAL_VALUE.match(k) and isinstance(v, (int, float))):
                    row[k] = v
                    if k not in SUMMARY_COLUMNS and k not in extra:
                        extra.append(k)
        elif status == "failed":
            row["error"] = f"{data.get('error_type')}: {data.get('message', '')}".splitlines()[0]
        rows.append(row)
    return rows, [*SUMMARY_COLUMNS, *sorted(extra)]


def _write_csv(path: Path, rows: list[dict], columns: list[str]) -> Path:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=columns, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in row.items()})
    return _write_text(path, buf.getvalue())


def _check_plot_value(value: str) -> None:
    if value not in SUMMARY_COLUMNS and not _LATERAL_VALUE.match(value):
        raise SweepSpecError(
            f"--plot-value {value}: not a summary value; one of {', '.join(SUMMARY_COLUMNS)} "
            "(lateral scenes also <gear>_bearing_force_<x|y>_max_N, ...)"
        )


# ---------------------------------------------------------------------------------------------------
# Driver


def run_study(
    scene: str | Path | Study,
    *,
    out_dir: str | Path,
    vary: Mapping[str, Sequence[Any] | str] | Sequence[str] | None = None,
    random: Mapping[str, str] | Sequence[str] | None = None,
    samples: int | None = None,
    study_seed: int = 0,
    seeds: int | None = None,
    base_overrides: Sequence[str] = (),
    workers: int | None = None,
    scheduler: str | Any | None = None,
    progress: bool = True,
    save_results: bool = True,
    retry_failed: bool = False,
    plot_value: str = DEFAULT_PLOT_VALUE,
    plot_key: str | None = None,
) -> StudyResult:
    """Run a parameter study, resuming whatever ``out_dir`` already holds of it.

    Args:
        scene: scene name, TOML path, or a prepared :class:`Study` (then leave the spec arguments out).
        out_dir: output folder (``study.json``, ``cases/<id>/``, ``summary.csv``, the plot).
        vary, random, samples, study_seed, seeds, base_overrides: the study, see :meth:`Study.build`.
        workers: local processes (default ``os.cpu_count()``); 1 runs the cases in this process.
        scheduler: a Dask scheduler address (``tcp://host:8786``) or a ``dask.distributed.Client``;
            the cases then run on that cluster (``workers`` must be left out).
        progress: show a progress bar (done, failed, time left) on stderr.
        save_results: write each case's ``result.npz`` (off for big studies: summaries only).
        retry_failed: rerun cases that have an ``error.json``.
        plot_value: summary value to plot (default ``kd_max_final``).
        plot_key: varied key on the x axis (default: the first one).
    Raises:
        SweepSpecError, ScenarioError: bad input, before anything runs.
        ImportError: ``scheduler`` given but dask.distributed is not installed.
    """
    if isinstance(scene, Study):
        if vary or random or samples is not None or seeds is not None or base_overrides or study_seed:
            raise SweepSpecError("give either a Study or the spec arguments (vary, random, ...), not both")
        study = scene
    else:
        study = Study.build(
            scene,
            vary=vary,
            random=random,
            samples=samples,
            study_seed=study_seed,
            seeds=seeds,
            base_overrides=base_overrides,
        )
    keys = study.keys
    plot_key = plot_key or keys[0]
    if plot_key not in keys:
        raise SweepSpecError(f"--plot-key {plot_key}: not a varied key; one of {', '.join(keys)}")
    _check_plot_value(plot_value)
    if scheduler is not None and workers is not None:
        raise SweepSpecError("--workers and --scheduler exclude each other (the cluster has its workers)")
    if workers is not None and (isinstance(workers, bool) or int(workers) != workers or workers < 1):
        raise SweepSpecError(f"--workers must be a whole number >= 1, got {workers!r}")
    if scheduler is not None:
        _dask()  # clear ImportError before anything runs

    cases = study.cases()
    scenarios = {c.id: study.load_case(c) for c in cases}  # every case valid before anything runs
    out = Path(out_dir)
    _prepare_out(out, study, cases)

    pending = []
    for case in cases:
        state, _ = _case_state(out / "cases" / case.id)
        if state == "pending" or (state == "failed" and retry_failed):
            pending.append(case)
    skipped = len(cases) - len(pending)
    if progress and skipped:
        print(f"resuming {out}: {skipped} of {len(cases)} cases already done", file=sys.stderr)

    by_id = {c.id: c for c in pending}
    jobs = [(c.id, (study.base, c.overrides, save_results)) for c in pending]
    n_workers = min(workers or os.cpu_count() or 1, max(len(jobs), 1))
    if not jobs:
        runner: Iterator[tuple[str, dict]] = iter(())
    elif scheduler is not None:
        runner = _run_dask(jobs, scheduler)
    elif n_workers == 1:
        runner = _run_serial(jobs)
    else:
        runner = _run_pool(jobs, n_workers)

    from tqdm import tqdm

    failed = 0
    bar = None
    try:
        for cid, outcome in runner:
            if bar is None:  # created after the pool has started its processes
                bar = tqdm(
                    total=len(jobs),
                    desc="sweep",
                    unit="case",
                    disable=not progress,
                    file=sys.stderr,
                    bar_format="{desc}: {n_fmt}/{total_fmt} cases done{postfix} |{bar}| "
                    "[{elapsed}<{remaining}]",
                )
                bar.set_postfix_str("0 failed", refresh=False)
            _write_case(out / "cases" / cid, by_id[cid], scenarios[cid], outcome, save_results)
            failed += not outcome["ok"]
            bar.set_postfix_str(f"{failed} failed", refresh=False)
            bar.update(1)
    finally:
        if bar is not None:
            bar.close()
        close = getattr(runner, "close", None)
        if close:
            close()

    rows, summary_cols = _rows(out, cases, keys)
    columns = ["id", *keys, "status", *summary_cols, "error"]
    csv_path = _write_csv(out / "summary.csv", rows, columns)
    plot_path = plot_study(
        rows,
        keys,
        plot_value,
        plot_key,
        out / f"{plot_value}_vs_{plot_key}.png",
        title=f"{study.scene if len(study.scene) < 40 else Path(study.scene).name}: {plot_value} "
        f"against {plot_key}",
    )
    return StudyResult(out, keys, rows, len(jobs), skipped, csv_path, plot_path, plot_value)
