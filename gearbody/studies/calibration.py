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
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gearbody.errors import InputError
from gearbody.folders import output_error, write_text

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

OPTIMIZER = "TwoPointsDE"
"""nevergrad optimiser of the global search."""

FAILED_RESIDUAL = 1e3
"""Residual given to every target of a failed evaluation (cost 5e5 per target: worse than any fit)."""

IDENTIFIED_MIN_SINGULAR_VALUE = 1.0
"""A direction of the normalised parameters whose Jacobian singular value is below this has a 1-sigma
wider than the search box (1 in normalised coordinates): the targets do not identify it within the
bounds. A parameter whose 1-sigma is wider than its own box is unidentified for the same reason."""

NUMERICAL_RCOND = 1e-10
"""Singular values below this fraction of the largest are zero (an exact combination of parameters that
no target sees); every parameter with a component above :data:`NULL_COMPONENT` in such a direction is
unidentified."""

NULL_COMPONENT = 1e-6
"""Largest component of a parameter in an exactly unidentified direction that is rounding, not a share."""

UNCERTAINTY_STEP = 1e-2
"""Forward-difference step (normalised coordinates: 1 % of the search box) of the Jacobian the
uncertainty is computed from. Simulated features jitter under tiny parameter changes (a mesh line
amplitude of one-stage by up to 9e-4 relative for a 1e-4 change of the mesh damping): divided by a
step of 1e-3 that jitter outweighed the weakest parameter's true sensitivity and its sigma changed 30x
between two fits at the same point; at 1e-2 it agrees with central differences of 1e-2 and 3e-2."""

AT_BOUND_TOLERANCE = 1e-2
"""A fitted parameter closer than this fraction of its search box (normalised coordinates) to a bound
ends on it: flagged in the result and warned about."""


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


@dataclass(frozen=True)
class Uncertainty:
    """The linearised uncertainty of a fit, in normalised coordinates (1 = the width of the search box).

    ``sigma_unit[j]``: 1-sigma of parameter j (``inf``: unidentified); ``correlation``: in [-1, 1], NaN in
    the rows of unidentified parameters; ``singular_values`` (descending, one per parameter: zeros where
    there are fewer targets) and ``directions`` (their unit vectors as columns) of the Jacobian."""

    sigma_unit: np.ndarray
    correlation: np.ndarray
    singular_values: np.ndarray
    directions: np.ndarray

    @property
    def identified(self) -> np.ndarray:
        """Per parameter: is its 1-sigma finite and within its search box."""
        return np.isfinite(self.sigma_unit) & (self.sigma_unit <= 1.0 / IDENTIFIED_MIN_SINGULAR_VALUE)

    @property
    def unidentified_directions(self) -> list[tuple[float, np.ndarray]]:
        """(singular value, unit direction) of every direction whose 1-sigma is wider than the box; each
        direction signed so that its first component above 1e-3 is positive."""
        out = []
        for s, v in zip(self.singular_values, self.directions.T, strict=True):
            if s < IDENTIFIED_MIN_SINGULAR_VALUE:
                out.append((float(s), v * np.sign(v[np.flatnonzero(np.abs(v) > 1e-3)[0]])))
        return out


def uncertainty(jacobian_unit: np.ndarray) -> Uncertainty:
    """The uncertainty from the Jacobian ``d residual / d u`` (targets x parameters) in normalised
    coordinates, by its SVD: ``cov = V diag(1 / s^2) V^T`` over the directions with a non-zero singular
    value; a parameter touching a zero one, or whose 1-sigma exceeds its box, is unidentified."""
    J = np.atleast_2d(np.asarray(jacobian_unit, float))
    n = J.shape[1]
    if not np.all(np.isfinite(J)):
        nan = np.full((n, n), math.nan)
        return Uncertainty(np.full(n, math.inf), nan, np.zeros(n), np.eye(n))
    _, s, vt = np.linalg.svd(J, full_matrices=True)
    singular = np.zeros(n)
    singular[: s.size] = s
    V = vt.T
    zero = singular <= NUMERICAL_RCOND * singular[0] if singular[0] > 0 else np.ones(n, bool)
    inverse_square = np.zeros(n)
    inverse_square[~zero] = 1.0 / singular[~zero] ** 2
    cov = (V * inverse_square) @ V.T
    variance = np.clip(np.diag(cov), 0.0, None)
    touches_zero = np.any(np.abs(V[:, zero]) > NULL_COMPONENT, axis=1)
    sd = np.where(touches_zero, math.inf, np.sqrt(variance))
    ok = np.isfinite(sd) & (sd <= 1.0 / IDENTIFIED_MIN_SINGULAR_VALUE)
    sd = np.where(ok, sd, math.inf)
    corr = np.full((n, n), math.nan)
    idx = np.flatnonzero(ok)
    if idx.size:
        block = cov[np.ix_(idx, idx)]
        scale = np.sqrt(np.diag(block))
        with np.errstate(invalid="ignore", divide="ignore"):
            c = np.clip(block / np.outer(scale, scale), -1.0, 1.0)
        np.fill_diagonal(c, 1.0)
        corr[np.ix_(idx, idx)] = c
    return Uncertainty(sd, corr, singular, V)


@dataclass
class CalibrationResult:
    """The fit: best parameters, residuals, uncertainties and the history of every evaluation."""

    parameters: dict[str, float]
    sigma: dict[str, float]  # 1-sigma in the parameter's unit (Jacobian at the optimum); inf: unidentified
    correlation: np.ndarray  # in [-1, 1]; NaN in the rows and columns of unidentified parameters
    features: dict[str, float]
    residuals: dict[str, float]  # (feature - target) / sigma per target
    cost: float  # sum of squared residuals / 2
    history: list[tuple[int, str, float]] = field(default_factory=list)  # (evaluation, stage, cost)
    evaluations: int = 0
    replayed: int = 0
    targets: tuple[Target, ...] = ()
    at_bound: dict[str, str] = field(default_factory=dict)  # parameter -> "lower" / "upper" it ends on
    singular_values: tuple[float, ...] = ()  # of the Jacobian in normalised coordinates, descending
    unidentified: tuple[dict[str, float], ...] = ()  # directions wider than the box: {parameter: component}
    unidentified_singular_values: tuple[float, ...] = ()  # one per direction of ``unidentified``
    bounds: dict[str, tuple[float, float]] = field(default_factory=dict)

    @property
    def identified(self) -> dict[str, bool]:
        """Per parameter: is its 1-sigma finite (within its search box)."""
        return {k: math.isfinite(v) for k, v in self.sigma.items()}

    def warnings(self) -> list[str]:
        """One line per parameter that ends on a bound or is unidentified, and per unidentified direction
        of two or more parameters."""
        lines = []
        for k, side in self.at_bound.items():
            lo, hi = self.bounds.get(k, (math.nan, math.nan))
            lines.append(
                f"{k} = {self.parameters[k]:.6g} ends on its {side} bound (range [{lo:g}, {hi:g}]): the best "
                "fit may lie beyond it, or the search stopped there in a local minimum; widen the range, "
                "check the targets or add some"
            )
        for k, ok in self.identified.items():
            if not ok:
                lines.append(f"{k} is not identified by the targets: its 1-sigma is wider than its range")
        for s, d in zip(self.unidentified_singular_values, self.unidentified, strict=True):
            if sum(abs(v) > 1e-3 for v in d.values()) < 2:  # one key alone: said above
                continue
            lines.append(
                f"unidentified direction {_direction(d)} (normalised coordinates, singular value {s:.3g} < "
                f"{IDENTIFIED_MIN_SINGULAR_VALUE:g}: its 1-sigma is wider than the range)"
            )
        return lines

    def uncertainty_record(self) -> dict:
        """The uncertainty and the flags as JSON-safe values (None: an unidentified sigma, correlation)."""
        return {
            "sigma": {k: (v if math.isfinite(v) else None) for k, v in self.sigma.items()},
            "identified": self.identified,
            "correlation": [
                [float(x) if math.isfinite(x) else None for x in row] for row in self.correlation
            ],
            "singular_values_unit": list(self.singular_values),
            "identified_min_singular_value": IDENTIFIED_MIN_SINGULAR_VALUE,
            "unidentified_directions": [
                {"singular_value": s, "direction": d}
                for s, d in zip(self.unidentified_singular_values, self.unidentified, strict=True)
            ],
            "at_bound": self.at_bound,
            "at_bound_tolerance": AT_BOUND_TOLERANCE,
            "warnings": self.warnings(),
        }

    def table(self) -> str:
        """Parameters with their uncertainties and flags, then each target's fit, as plain text (the
        sentences of :meth:`warnings` apart)."""
        w = max([len("parameter"), *map(len, self.parameters), *(len(t.label) for t in self.targets)])
        lines = [f"{'parameter':{w}s} {'value':>14s} {'1-sigma':>12s}"]
        for k, v in self.parameters.items():
            sd = f"{self.sigma[k]:12.3g}" if math.isfinite(self.sigma[k]) else f"{'unidentified':>12s}"
            flag = f"  on its {self.at_bound[k]} bound" if k in self.at_bound else ""
            lines.append(f"{k:{w}s} {v:14.6g} {sd}{flag}")
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


def _direction(components: Mapping[str, float]) -> str:
    """``0.707 a - 0.707 b``: the components above 1e-3, in the parameters' order."""
    terms = [(v, k) for k, v in components.items() if abs(v) > 1e-3]
    text = " ".join(f"{'-' if v < 0 else '+'} {abs(v):.3g} {k}" for v, k in terms)
    return text[2:] if text.startswith("+ ") else text


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
    # the Jacobian at the optimum, one batch, in normalised coordinates (columns of comparable size)
    r0 = run([u_best], "jacobian")[0]
    steps = [u_best + _step(u_best, j, uncertainty_step) for j in range(len(parameters))]
    rs = run(steps, "jacobian")
    values = point(u_best)
    J = np.empty((len(targets), len(parameters)))
    per_unit = np.empty(len(parameters))  # d parameter / d u at the optimum (secant of the step)
    for j, (p, u, r) in enumerate(zip(parameters, steps, rs, strict=True)):
        J[:, j] = (r - r0) / (u[j] - u_best[j])
        per_unit[j] = (p.from_unit(u[j]) - values[p.key]) / (u[j] - u_best[j])
    unc = uncertainty(J)
    sd = unc.sigma_unit * np.abs(per_unit)
    features = cache.evaluate(evaluate, [values])[0] or {}
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
        history=history,
        evaluations=len(history),
        replayed=cache.replayed,
        targets=tuple(targets),
        at_bound=at_bound,
        singular_values=tuple(map(float, unc.singular_values)),
        unidentified=tuple({k: float(x) for k, x in zip(names, v, strict=True)} for _, v in directions),
        unidentified_singular_values=tuple(s for s, _ in directions),
        bounds={p.key: (p.lower, p.upper) for p in parameters},
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
