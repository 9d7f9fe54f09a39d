"""Calibration (model updating): fit chosen parameters within bounds to target features.

A global, gradient-free search (nevergrad's differential evolution ``TwoPointsDE``, asking ``batch``
points at a time so that they can be evaluated in parallel) is followed by a local least-squares polish
(scipy's trust-region reflective ``least_squares``, its forward-difference Jacobian evaluated as one
batch). Residuals are ``(feature - target) / sigma``: ``sigma`` is the target's uncertainty (or 1 / its
weight), so the cost is chi^2 / 2 and the parameter covariance at the optimum is ``(J^T J)^-1``.

The uncertainty is computed in the search's normalised coordinates u (each parameter's bounds mapped to
[0, 1]), where the Jacobian's columns are of comparable size whatever the parameters' units (1e9 N/m
next to 1e-6 m), by an SVD of that Jacobian: a direction whose 1-sigma is wider than the search box
(singular value below :data:`IDENTIFIED_MIN_SINGULAR_VALUE`) is reported as unidentified, and so is a
parameter whose own 1-sigma is wider than its box: its sigma is ``inf``, never a small number from a
dropped direction. The 1-sigma is then converted to the parameter's unit; the correlations are those
of one positive semi-definite covariance, clipped to [-1, 1]. A parameter that ends within
:data:`AT_BOUND_TOLERANCE` of a bound is flagged: the best fit may lie beyond it.

The search runs in normalised coordinates u in [0, 1] per parameter (logarithmic for parameters marked
``log``: stiffnesses, damping). ``evaluate(points) -> list[features | None]`` is any batch function
(None: that evaluation failed; it scores a fixed penalty). Every evaluation goes through an
:class:`EvaluationCache`: with a file, a rerun of the same calibration replays the evaluations already
made (the optimiser is seeded, so it asks the same points again) and an interrupted calibration
resumes where it stopped.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gearbody.errors import InputError
from gearbody.folders import output_error, write_text

from .calibration_result import (  # the constants: this module's names before the split
    AT_BOUND_TOLERANCE,
    IDENTIFIED_MIN_SINGULAR_VALUE,  # noqa: F401
    NULL_COMPONENT,  # noqa: F401
    NUMERICAL_RCOND,  # noqa: F401
    CalibrationResult,
    Uncertainty,
    uncertainty,
)

# OPTIMIZER: this module's name before the split
from .calibration_search import OPTIMIZER, global_search, least_squares_polish, step  # noqa: F401

__all__ = [
    "CalibrationError",
    "CalibrationResult",
    "EvaluationCache",
    "Parameter",
    "Target",
    "Uncertainty",
    "calibrate",
    "uncertainty",
]

FAILED_RESIDUAL = 1e3
"""Residual given to every target of a failed evaluation (cost 5e5 per target: worse than any fit)."""

UNCERTAINTY_STEP = 1e-2
"""Forward-difference step (normalised coordinates: 1 % of the search box) of the Jacobian the
uncertainty is computed from. Simulated features jitter under tiny parameter changes (a mesh line
amplitude of one-stage by up to 9e-4 relative for a 1e-4 change of the mesh damping): divided by a
step of 1e-3 that jitter outweighed the weakest parameter's true sensitivity and its sigma changed 30x
between two fits at the same point; at 1e-2 it agrees with central differences of 1e-2 and 3e-2."""


class CalibrationError(InputError):
    """A calibration that cannot be set up: bad bounds, no targets, an unknown cache (exit code 2; a
    ``ValueError``)."""


@dataclass(frozen=True)
class Parameter:
    """A parameter to fit: a scenario key (or any name), its bounds, an optional start, log scaling."""

    key: str
    lower: float
    upper: float
    start: float | None = None
    log: bool = False

    def __post_init__(self) -> None:
        if not (math.isfinite(self.lower) and math.isfinite(self.upper) and self.lower < self.upper):
            raise CalibrationError(
                f"{self.key}: bounds [{self.lower:g}, {self.upper:g}] must be finite, lower < upper"
            )
        if self.log and self.lower <= 0:
            raise CalibrationError(
                f"{self.key}: log scaling needs a positive lower bound, got {self.lower:g}"
            )
        if self.start is not None and not self.lower <= self.start <= self.upper:
            raise CalibrationError(
                f"{self.key}: start {self.start:g} outside the bounds [{self.lower:g}, {self.upper:g}]"
            )

    def to_unit(self, value: float) -> float:
        if self.log:
            return math.log(value / self.lower) / math.log(self.upper / self.lower)
        return (value - self.lower) / (self.upper - self.lower)

    def from_unit(self, u: float) -> float:
        u = min(max(float(u), 0.0), 1.0)
        if self.log:
            return self.lower * (self.upper / self.lower) ** u
        return self.lower + u * (self.upper - self.lower)


@dataclass(frozen=True)
class Target:
    """A feature to match: its name (a feature spec), the target value and its uncertainty (same unit),
    and optionally the case (a named set of extra overrides, :mod:`.scene_calibration`) it is read from."""

    feature: str
    value: float
    sigma: float
    case: str = ""

    @property
    def label(self) -> str:
        """``feature`` or ``feature@case``: the target's key in features and residuals."""
        return f"{self.feature}@{self.case}" if self.case else self.feature

    def __post_init__(self) -> None:
        if not math.isfinite(self.value):
            raise CalibrationError(f"target {self.label}: value {self.value!r} must be finite")
        if not (math.isfinite(self.sigma) and self.sigma > 0):
            raise CalibrationError(f"target {self.label}: sigma {self.sigma!r} must be finite and > 0")


class EvaluationCache:
    """Evaluations by parameter point, optionally persisted as JSON lines (one line per evaluation,
    appended and flushed as it arrives: an interruption loses at most the evaluations in flight).

    The first line holds the calibration's fingerprint: a file of another calibration, or one whose
    first line is no gearbody record, is refused (:class:`CalibrationError`). A later line that is no
    whole evaluation (cut by an interruption or a full disk, or damaged) is dropped, and that point is
    evaluated again. A record that cannot be written raises :class:`~gearbody.errors.OutputError`
    naming the file."""

    def __init__(self, path: str | Path | None = None, fingerprint: str = "") -> None:
        self.path = Path(path) if path is not None else None
        self.fingerprint = fingerprint
        self.values: dict[str, dict[str, float] | None] = {}
        self.replayed = 0  # evaluations answered from the file read at the start
        self.recorded: set[str] = set()
        text = self._read() if self.path is not None else ""
        head_start = '{"fingerprint": "'
        if not (head_start.startswith(text) or (text.startswith(head_start) and "\n" not in text)):
            lines = text.splitlines()
            head = _record(lines[0])
            if head is None or "fingerprint" not in head:
                raise CalibrationError(f"{self.path}: its first line is not a gearbody calibration record")
            if head.get("fingerprint") != fingerprint:
                raise CalibrationError(
                    f"{self.path}: records another calibration (a different scene, parameters, targets or "
                    "settings)"
                )
            kept = lines[:1]
            for line in lines[1:]:
                item = _record(line)
                point, features = (item or {}).get("point"), (item or {}).get("features", 0)
                if not isinstance(point, str) or not (features is None or isinstance(features, dict)):
                    continue  # a line cut by an interruption, or damaged: evaluated again
                self.values[point] = features
                kept.append(line)
            self.recorded = set(self.values)
            if len(kept) < len(lines) or not text.endswith("\n"):  # new lines must not join a cut one
                write_text(self.path, "\n".join(kept) + "\n")
        elif self.path is not None:  # new, or its first line cut (a full disk when it was made): no record
            try:
                self.path.parent.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                raise output_error(self.path.parent, exc) from None
            write_text(self.path, json.dumps({"fingerprint": fingerprint}) + "\n")

    def _read(self) -> str:
        """The record's text ('' if there is none)."""
        try:
            return self.path.read_text()
        except FileNotFoundError:
            return ""
        except (OSError, UnicodeDecodeError) as exc:
            reason = exc.strerror if isinstance(exc, OSError) else "not UTF-8 text"
            raise CalibrationError(f"{self.path}: cannot read it: {reason or exc}") from None

    @staticmethod
    def key(point: Mapping[str, float]) -> str:
        return json.dumps({k: float(v) for k, v in point.items()}, sort_keys=True)

    def _append(self, item: dict) -> None:
        try:
            with open(self.path, "a") as f:
                f.write(json.dumps(item) + "\n")
                f.flush()
                os.fsync(f.fileno())
        except OSError as exc:  # a part of the line may be there: it is dropped when the file is read
            raise output_error(self.path, exc) from None

    def evaluate(self, evaluate: Callable, points: list[dict[str, float]]) -> list[dict[str, float] | None]:
        """Features of every point: cached ones replayed, the others evaluated as one batch and recorded."""
        keys = [self.key(p) for p in points]
        todo = [i for i, k in enumerate(keys) if k not in self.values]
        self.replayed += sum(k in self.recorded for k in set(keys))
        self.recorded -= set(keys)  # each recorded evaluation counted once
        if todo:
            fresh = evaluate([points[i] for i in todo])
            for i, features in zip(todo, fresh, strict=True):
                self.values[keys[i]] = features
                if self.path is not None:
                    self._append({"point": keys[i], "features": features})
        return [self.values[k] for k in keys]


def _record(line: str) -> dict | None:
    """A JSON object of one line of the record, or None."""
    try:
        item = json.loads(line)
    except ValueError:
        return None
    return item if isinstance(item, dict) else None


def fingerprint(*parts) -> str:
    """A stable hash of a calibration's definition (what a resumed run must match)."""
    return hashlib.sha256(json.dumps(parts, sort_keys=True, default=repr).encode()).hexdigest()[:16]


def calibrate(
    evaluate: Callable[[list[dict[str, float]]], list[dict[str, float] | None]],
    parameters: Sequence[Parameter],
    targets: Sequence[Target],
    *,
    budget: int = 60,
    batch: int = 2,
    polish: bool = True,
    polish_evaluations: int = 40,
    seed: int = 0,
    cache: EvaluationCache | None = None,
    jacobian_step: float = 1e-3,
    uncertainty_step: float = UNCERTAINTY_STEP,
) -> CalibrationResult:
    """Fit ``parameters`` to ``targets``: ``budget`` global evaluations (nevergrad, ``batch`` per
    round), then at most ``polish_evaluations`` in scipy's ``least_squares`` from the best point; the
    uncertainty from the Jacobian at the optimum (forward differences of ``uncertainty_step`` in
    normalised coordinates; the polish steps by ``jacobian_step``).
    Starting values (``Parameter.start``) are the optimiser's first point."""
    if not parameters:
        raise CalibrationError("no parameters to fit")
    if not targets:
        raise CalibrationError("no targets to fit")
    if budget < 1 or batch < 1 or polish_evaluations < 0:
        raise CalibrationError(
            f"budget = {budget}, batch = {batch} must be >= 1; polish_evaluations = "
            f"{polish_evaluations} must be >= 0"
        )
    names = [p.key for p in parameters]
    if len(set(names)) != len(names):
        raise CalibrationError(f"a parameter is given twice: {names}")
    run = _Run(evaluate, parameters, targets, cache or EvaluationCache())
    u_start = np.array([0.5 if p.start is None else p.to_unit(p.start) for p in parameters])
    global_search(run, u_start, budget, batch, seed)
    u_best = run.best["u"]
    if polish and polish_evaluations > 0:
        u_best = least_squares_polish(run, u_best, len(targets), polish_evaluations, jacobian_step)
        u_best = run.best["u"]
    # the Jacobian at the optimum, one batch, in normalised coordinates (columns of comparable size)
    r0, J, per_unit = _jacobian(run, parameters, targets, u_best, uncertainty_step)
    return _result(run, parameters, targets, u_best, r0, uncertainty(J), per_unit)


class _Run:
    """``run(us, stage) -> residuals``: evaluates points of normalised coordinates through the cache,
    keeps the history (each distinct point once) and the best point."""

    def __init__(self, evaluate: Callable, parameters: Sequence[Parameter], targets: Sequence[Target], cache):
        self.evaluate, self.parameters, self.targets, self.cache = evaluate, parameters, targets, cache
        self.history: list[tuple[int, str, float]] = []
        self.best: dict = {"cost": math.inf, "u": None}
        self.seen: set[str] = set()

    def point(self, u) -> dict[str, float]:
        return {p.key: p.from_unit(x) for p, x in zip(self.parameters, u, strict=True)}

    def residuals_of(self, features) -> np.ndarray:
        targets = self.targets
        if features is None or any(not math.isfinite(features.get(t.label, math.nan)) for t in targets):
            return np.full(len(targets), FAILED_RESIDUAL)
        return np.array([(features[t.label] - t.value) / t.sigma for t in targets])

    def __call__(self, us: list[np.ndarray], stage: str) -> list[np.ndarray]:
        points = [self.point(u) for u in us]
        res = [self.residuals_of(f) for f in self.cache.evaluate(self.evaluate, points)]
        for u, p, r in zip(us, points, res, strict=True):
            c = 0.5 * float(r @ r)
            key = self.cache.key(p)
            if key not in self.seen:  # each distinct point once in the history
                self.seen.add(key)
                self.history.append((len(self.history) + 1, stage, c))
            if c < self.best["cost"]:
                self.best.update(cost=c, u=np.array(u, float))
        return res


def _jacobian(
    run: _Run, parameters: Sequence[Parameter], targets: Sequence[Target], u_best: np.ndarray, h: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(residuals at u_best, Jacobian d residual / d u, d parameter / d u)`` by forward differences of
    ``h`` (one batch)."""
    r0 = run([u_best], "jacobian")[0]
    steps = [u_best + step(u_best, j, h) for j in range(len(parameters))]
    rs = run(steps, "jacobian")
    values = run.point(u_best)
    J = np.empty((len(targets), len(parameters)))
    per_unit = np.empty(len(parameters))  # d parameter / d u at the optimum (secant of the step)
    for j, (p, u, r) in enumerate(zip(parameters, steps, rs, strict=True)):
        J[:, j] = (r - r0) / (u[j] - u_best[j])
        per_unit[j] = (p.from_unit(u[j]) - values[p.key]) / (u[j] - u_best[j])
    return r0, J, per_unit


def _result(
    run: _Run,
    parameters: Sequence[Parameter],
    targets: Sequence[Target],
    u_best: np.ndarray,
    r0: np.ndarray,
    unc: Uncertainty,
    per_unit: np.ndarray,
) -> CalibrationResult:
    """The fit at ``u_best``: its features (replayed), residuals ``r0``, uncertainty and flags."""
    names = [p.key for p in parameters]
    values = run.point(u_best)
    sd = unc.sigma_unit * np.abs(per_unit)
    features = run.cache.evaluate(run.evaluate, [values])[0] or {}
    at_bound = {}
    for p, u in zip(parameters, u_best, strict=True):
        if u <= AT_BOUND_TOLERANCE:
            at_bound[p.key] = "lower"
        elif u >= 1.0 - AT_BOUND_TOLERANCE:
            at_bound[p.key] = "upper"
    directions = unc.unidentified_directions
    return CalibrationResult(
        parameters=values,
        sigma=dict(zip(names, map(float, sd), strict=True)),
        correlation=unc.correlation,
        features={t.label: float(features.get(t.label, math.nan)) for t in targets},
        residuals={t.label: float(x) for t, x in zip(targets, r0, strict=True)},
        cost=0.5 * float(r0 @ r0),
        history=run.history,
        evaluations=len(run.history),
        replayed=run.cache.replayed,
        targets=tuple(targets),
        at_bound=at_bound,
        singular_values=tuple(map(float, unc.singular_values)),
        unidentified=tuple({k: float(x) for k, x in zip(names, v, strict=True)} for _, v in directions),
        unidentified_singular_values=tuple(s for s, _ in directions),
        bounds={p.key: (p.lower, p.upper) for p in parameters},
    )
