"""Parsing of a parameter study's varied keys: ``--vary KEY=start:stop:count | KEY=v1,v2,...`` (grid
axes), ``--random KEY=uniform(a,b) | normal(mu,sigma) | choice(v1,v2,...)`` (Monte-Carlo keys), and
:class:`SweepSpecError`, whose messages name the argument at fault."""

from __future__ import annotations

import re
import zlib
from dataclasses import dataclass
from typing import Any

import numpy as np

from gearbody.model import parse_override

from ..errors import StudySpecError

__all__ = [
    "MAX_CASES",
    "MOST_CASES",
    "Axis",
    "Distribution",
    "RandomAxis",
    "SweepSpecError",
    "check_key",
    "parse_distribution",
    "parse_random",
    "parse_vary",
    "toml_literal",
    "toml_value",
]

_KEY = re.compile(r"^[A-Za-z_][\w-]*(\.([A-Za-z_][\w-]*|[1-9][0-9]*))*$")  # list items by number from 1
_DIST = re.compile(r"^\s*(\w+)\s*\((.*)\)\s*$", re.DOTALL)
_NUMBER = r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?"


MAX_CASES = 10_000
"""Most cases a study may have unless raised explicitly (``--max-cases``, ``max_cases=``): each case is
a whole simulation (seconds of wall time), and a larger grid is far more likely a typing slip (an extra
zero in a count) than a plan. Checked, like a range's count, before any value list is made."""

MOST_CASES = 100_000
"""Most cases (simulations) a study may have at all, whatever ``--max-cases`` or ``--force`` allow: its
case list or sample matrix is made in memory before anything runs (100,000 cases: ~0.1 GB; a count of
2**40 ran out of memory), and 100,000 simulations take hours even at 0.1 s each."""

SweepSpecError = StudySpecError
"""Invalid study input (syntax, conflicting options, a spec that differs from the one on disk); the
message names the argument. The study layer's name for :class:`gearbody.errors.StudySpecError`."""


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


def toml_value(text: str, label: str | None = None) -> Any:
    """A TOML literal's value, read as ``--set`` reads it (not valid TOML: the plain string); errors name
    ``label`` (the option as typed)."""
    return parse_override(f"v={text}", label)[1]


def toml_literal(value: Any) -> str:
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


def check_key(key: str, label: str) -> None:
    if not _KEY.match(key):
        raise SweepSpecError(
            f"{label}: {key!r} is not a dotted scenario key (e.g. production.error_mode.e_um, or "
            "design.stages.2.mesh.backlash_um for stage 2 of a train)"
        )


def _split_key(text: str, label: str, example: str) -> tuple[str, str]:
    if "=" not in text:
        raise SweepSpecError(f"{label}: expected KEY=SPEC, e.g. {example}")
    key, spec = (s.strip() for s in text.split("=", 1))
    check_key(key, label)
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


def _range_texts(key: str, spec: str, label: str, max_count: int) -> list[str]:
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
    if count > max_count:
        raise SweepSpecError(
            f"{label}: count {count} is more than the {max_count} cases a study may have; "
            f"give --max-cases {count} (or more) to run it anyway"
        )
    if count == 1 and start != stop:
        raise SweepSpecError(f"{label}: count 1 needs start == stop, got {spec!r}")
    values = np.linspace(start, stop, count)
    whole = all(re.fullmatch(r"[+-]?\d+", p) for p in parts[:2]) and np.all(values == np.round(values))
    if whole:
        return [str(int(round(v))) for v in values]
    return [repr(float(f"{v:.15g}")) for v in values]  # 0.30000000000000004 -> 0.3


def parse_vary(text: str, *, label: str | None = None, max_count: int = MAX_CASES) -> Axis:
    """``KEY=start:stop:count`` (inclusive linspace) or ``KEY=v1,v2,...`` (TOML literals) -> Axis; a
    range of more than ``max_count`` values is refused before it is made."""
    label = label or f"--vary {text}"
    key, spec = _split_key(text, label, "production.error_mode.e_um=0:20:5 or ...=5,10,15")
    commas, colons = _split_top(spec, ","), _split_top(spec, ":")
    if len(commas) > 1 and len(colons) > 1:
        raise SweepSpecError(f"{label}: give either a range start:stop:count or a list v1,v2,..., not both")
    texts = _range_texts(key, spec, label, max_count) if len(colons) > 1 else commas
    if any(not t for t in texts):
        raise SweepSpecError(f"{label}: empty value in the list {spec!r}")
    if len(set(texts)) != len(texts):
        raise SweepSpecError(f"{label}: repeated value in {spec!r}")
    return Axis(key, tuple(texts), tuple(toml_value(t, label) for t in texts), label)


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
        return Axis(self.key, texts, tuple(toml_value(t, self.label) for t in texts), self.label)


def parse_random(text: str, *, label: str | None = None) -> RandomAxis:
    """``KEY=uniform(a,b)`` | ``KEY=normal(mu,sigma)`` | ``KEY=choice(v1,v2,...)`` -> RandomAxis."""
    label = label or f"--random {text}"
    key, spec = _split_key(text, label, "production.error_mode.e_um=uniform(5,15)")
    return RandomAxis(key, parse_distribution(spec, label), label)
