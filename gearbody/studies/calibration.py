"""Calibration (model updating): fit chosen parameters within bounds to target features.

A global, gradient-free search (nevergrad's differential evolution ``TwoPointsDE``, asking ``batch``
points at a time so that they can be evaluated in parallel) is followed by a local least-squares polish
(scipy's trust-region reflective ``least_squares``, its forward-difference Jacobian evaluated as one
batch). Residuals are ``(feature - target) / sigma``: ``sigma`` is the target's uncertainty (or 1 / its
weight), so the cost is chi^2 / 2 and the parameter covariance at the optimum is ``(J^T J)^-1`` in the
parameters' units.

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
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = [
    "CalibrationError",
    "CalibrationResult",
    "EvaluationCache",
    "Parameter",
    "Target",
    "calibrate",
]

OPTIMIZER = "TwoPointsDE"
"""nevergrad optimiser of the global search."""

FAILED_RESIDUAL = 1e3
"""Residual given to every target of a failed evaluation (cost 5e5 per target: worse than any fit)."""


class CalibrationError(ValueError):
    """A calibration that cannot be set up: bad bounds, no targets, an unknown cache."""


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
    appended and flushed as it arrives: an interruption loses at most the evaluations in flight)."""

    def __init__(self, path: str | Path | None = None, fingerprint: str = "") -> None:
        self.path = Path(path) if path is not None else None
        self.fingerprint = fingerprint
        self.values: dict[str, dict[str, float] | None] = {}
        self.replayed = 0  # evaluations answered from the file read at the start
        self.recorded: set[str] = set()
        if self.path is not None and self.path.exists():
            lines = self.path.read_text().splitlines()
            head = json.loads(lines[0]) if lines else {}
            if head.get("fingerprint") != fingerprint:
                raise CalibrationError(
                    f"{self.path}: records another calibration (a different scene, parameters, targets or "
                    "settings); use another output folder or delete the file"
                )
            kept = lines[:1]
            for line in lines[1:]:
                try:
                    item = json.loads(line)
                except json.JSONDecodeError:  # a line cut by an interruption: evaluated again
                    continue
                self.values[item["point"]] = item["features"]
                kept.append(line)
            self.recorded = set(self.values)
            if len(kept) < len(lines) or not self.path.read_text().endswith("\n"):
                self.path.write_text("\n".join(kept) + "\n")  # new lines must not join a cut one
        elif self.path is not None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._append({"fingerprint": fingerprint})

    @staticmethod
    def key(point: Mapping[str, float]) -> str:
        return json.dumps({k: float(v) for k, v in point.items()}, sort_keys=True)

    def _append(self, item: dict) -> None:
        with open(self.path, "a") as f:
            f.write(json.dumps(item) + "\n")
            f.flush()
            os.fsync(f.fileno())

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


@dataclass
class CalibrationResult:
    """The fit: best parameters, residuals, uncertainties and the history of every evaluation."""

    parameters: dict[str, float]
    sigma: dict[str, float]  # 1-sigma uncertainty of each parameter from the Jacobian at the optimum
    correlation: np.ndarray
    features: dict[str, float]
    residuals: dict[str, float]  # (feature - target) / sigma per target
    cost: float  # sum of squared residuals / 2
    history: list[tuple[int, str, float]] = field(default_factory=list)  # (evaluation, stage, cost)
    evaluations: int = 0
    replayed: int = 0
    targets: tuple[Target, ...] = ()

    def table(self) -> str:
        """Parameters with their uncertainties, then each target's fit, as plain text."""
        w = max([len("parameter"), *map(len, self.parameters), *(len(t.label) for t in self.targets)])
        lines = [f"{'parameter':{w}s} {'value':>14s} {'1-sigma':>12s}"]
        for k, v in self.parameters.items():
            lines.append(f"{k:{w}s} {v:14.6g} {self.sigma[k]:12.3g}")
        lines.append("")
        lines.append(f"{'feature':{w}s} {'target':>14s} {'fitted':>12s} {'residual/sigma':>15s}")
        for t in self.targets:
            lines.append(
                f"{t.label:{w}s} {t.value:14.6g} {self.features[t.label]:12.6g} "
                f"{self.residuals[t.label]:15.3g}"
            )
        lines.append(
            f"cost (chi^2/2) {self.cost:.4g} after {self.evaluations} evaluations "
            f"({self.replayed} replayed from the record)"
        )
        return "\n".join(lines)


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
) -> CalibrationResult:
    """Fit ``parameters`` to ``targets``: ``budget`` global evaluations (nevergrad, ``batch`` per
    round), then at most ``polish_evaluations`` in scipy's ``least_squares`` from the best point; the
    uncertainty from the Jacobian (forward differences of ``jacobian_step`` in normalised coordinates).
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
    cache = cache or EvaluationCache()
    history: list[tuple[int, str, float]] = []
    best: dict = {"cost": math.inf, "u": None}

    def point(u) -> dict[str, float]:
        return {p.key: p.from_unit(x) for p, x in zip(parameters, u, strict=True)}

    def residuals_of(features) -> np.ndarray:
        if features is None or any(not math.isfinite(features.get(t.label, math.nan)) for t in targets):
            return np.full(len(targets), FAILED_RESIDUAL)
        return np.array([(features[t.label] - t.value) / t.sigma for t in targets])

    seen: set[str] = set()

    def run(us: list[np.ndarray], stage: str) -> list[np.ndarray]:
        points = [point(u) for u in us]
        res = [residuals_of(f) for f in cache.evaluate(evaluate, points)]
        for u, p, r in zip(us, points, res, strict=True):
            c = 0.5 * float(r @ r)
            key = cache.key(p)
            if key not in seen:  # each distinct point once in the history
                seen.add(key)
                history.append((len(history) + 1, stage, c))
            if c < best["cost"]:
                best.update(cost=c, u=np.array(u, float))
        return res

    u_start = np.array([0.5 if p.start is None else p.to_unit(p.start) for p in parameters])
    _global_search(run, u_start, budget, batch, seed)
    u_best = best["u"]
    if polish and polish_evaluations > 0:
        u_best = _polish(run, u_best, len(targets), polish_evaluations, jacobian_step)
        u_best = best["u"]
    # the Jacobian at the optimum, one batch: d residual / d parameter in the parameters' units
    r0 = run([u_best], "jacobian")[0]
    steps = [u_best + _step(u_best, j, jacobian_step) for j in range(len(parameters))]
    rs = run(steps, "jacobian")
    values = point(u_best)
    J = np.empty((len(targets), len(parameters)))
    for j, (p, u, r) in enumerate(zip(parameters, steps, rs, strict=True)):
        J[:, j] = (r - r0) / (p.from_unit(u[j]) - values[p.key])  # per unit of the parameter
    cov = np.linalg.pinv(J.T @ J)
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(sd, sd)
    features = cache.evaluate(evaluate, [values])[0] or {}
    return CalibrationResult(
        parameters=values,
        sigma=dict(zip(names, map(float, sd), strict=True)),
        correlation=corr,
        features={t.label: float(features.get(t.label, math.nan)) for t in targets},
        residuals={t.label: float(x) for t, x in zip(targets, r0, strict=True)},
        cost=0.5 * float(r0 @ r0),
        history=history,
        evaluations=len(history),
        replayed=cache.replayed,
        targets=tuple(targets),
    )


def _step(u: np.ndarray, j: int, h: float) -> np.ndarray:
    e = np.zeros_like(u)
    e[j] = h if u[j] + h <= 1.0 else -h  # stay inside the bounds
    return e


def _global_search(run, u_start: np.ndarray, budget: int, batch: int, seed: int) -> None:
    try:
        import nevergrad as ng
    except ImportError as exc:
        raise ImportError("calibration needs nevergrad: pip install gearbody[calibrate]") from exc
    param = ng.p.Array(init=u_start).set_mutation(sigma=0.25).set_bounds(0.0, 1.0)
    param.random_state.seed(seed)
    # NGOpt's automatic choice picks a metamodel that fails with numpy 2 in nevergrad 1.0.12 (TypeError in
    # metamodel.py): differential evolution, robust on small bounded problems and batch-parallel
    opt = ng.optimizers.registry[OPTIMIZER](parametrization=param, budget=budget, num_workers=batch)
    opt.suggest(u_start)  # the stated start is the first point asked
    done = 0
    while done < budget:
        n = min(batch, budget - done)
        cands = [opt.ask() for _ in range(n)]
        us = [np.clip(np.asarray(c.value, float), 0.0, 1.0) for c in cands]
        for c, r in zip(cands, run(us, "global"), strict=True):
            opt.tell(c, 0.5 * float(r @ r))
        done += n


def _polish(run, u0: np.ndarray, n_targets: int, max_evaluations: int, h: float) -> np.ndarray:
    from scipy.optimize import least_squares

    def fun(u):
        return run([np.asarray(u, float)], "polish")[0]

    def jac(u):
        u = np.asarray(u, float)
        r0 = fun(u)
        steps = [u + _step(u, j, h) for j in range(u.size)]
        rs = run(steps, "polish")
        return np.column_stack(
            [(r - r0) / (s[j] - u[j]) for j, (s, r) in enumerate(zip(steps, rs, strict=True))]
        )

    fit = least_squares(
        fun,
        u0,
        jac=jac,
        bounds=(0.0, 1.0),
        max_nfev=max(1, max_evaluations // (u0.size + 2)),
        x_scale=1.0,
        method="trf",
    )
    return np.asarray(fit.x, float)
