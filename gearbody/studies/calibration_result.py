"""The outcome of a calibration (:mod:`gearbody.studies.calibration`): the linearised uncertainty of the fit
from the Jacobian at the optimum (:func:`uncertainty`, in the search's normalised coordinates) and the
:class:`CalibrationResult` with its warnings, JSON record and table."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .calibration import Target

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

AT_BOUND_TOLERANCE = 1e-2
"""A fitted parameter closer than this fraction of its search box (normalised coordinates) to a bound
ends on it: flagged in the result and warned about."""


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
