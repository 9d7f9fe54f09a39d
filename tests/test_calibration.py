"""Calibration on models whose answer is known by hand: the machinery (global search, polish, Jacobian
uncertainty, the evaluation record and resume) before it meets a gearbox."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("nevergrad")

from gearbody.studies.calibration import (  # noqa: E402
    CalibrationError,
    EvaluationCache,
    Parameter,
    Target,
    calibrate,
)

A = np.array([[1.0, 0.0], [1.0, 1.0], [1.0, 2.0], [1.0, 3.0]])  # a straight line y = p0 + p1 x at x = 0..3
TRUE = np.array([2.0, 0.5])
SIGMA = 0.1


class Line:
    """Features y_i = p0 + p1 x_i; counts its evaluations."""

    def __init__(self) -> None:
        self.calls = 0

    def __call__(self, points):
        self.calls += len(points)
        return [{f"y{i}": float(v) for i, v in enumerate(A @ [p["p0"], p["p1"]])} for p in points]


PARAMETERS = [Parameter("p0", -5.0, 5.0, start=-4.0), Parameter("p1", 0.01, 10.0, start=8.0, log=True)]
TARGETS = [Target(f"y{i}", float(v), SIGMA) for i, v in enumerate(A @ TRUE)]


def test_a_line_is_recovered_with_the_textbook_uncertainty():
    """Exact targets: the fit lands on the truth, and the uncertainty is that of weighted linear least
    squares, sqrt(diag((A^T A)^-1)) sigma, which no optimiser choice may change."""
    fit = calibrate(Line(), PARAMETERS, TARGETS, budget=40, batch=2, seed=3)
    assert fit.parameters["p0"] == pytest.approx(2.0, abs=1e-6)
    assert fit.parameters["p1"] == pytest.approx(0.5, rel=1e-6)
    expected = np.sqrt(np.diag(np.linalg.inv(A.T @ A))) * SIGMA
    assert [fit.sigma["p0"], fit.sigma["p1"]] == pytest.approx(expected, rel=1e-3)
    assert fit.cost < 1e-10 and max(abs(r) for r in fit.residuals.values()) < 1e-5
    assert fit.history[0][1] == "global" and fit.history[-1][1] in ("polish", "jacobian")
    assert "p1" in fit.table() and "residual/sigma" in fit.table()


def test_noisy_targets_leave_the_residuals_the_fit_cannot_explain():
    noise = np.array([0.05, -0.08, 0.02, 0.06])
    targets = [Target(t.feature, t.value + n, SIGMA) for t, n in zip(TARGETS, noise, strict=True)]
    fit = calibrate(Line(), PARAMETERS, targets, budget=40, seed=1)
    best = np.linalg.lstsq(A, A @ TRUE + noise, rcond=None)[0]
    assert [fit.parameters["p0"], fit.parameters["p1"]] == pytest.approx(best, abs=1e-5)


def test_an_interrupted_calibration_resumes_from_its_record(tmp_path):
    path = tmp_path / "evaluations.jsonl"
    first = Line()
    fit = calibrate(first, PARAMETERS, TARGETS, budget=20, seed=5, cache=EvaluationCache(path, "line"))
    lines = path.read_text().splitlines()
    path.write_text("\n".join(lines[: len(lines) // 2]) + '\n{"point": ')  # stopped mid-write
    again = Line()
    refit = calibrate(again, PARAMETERS, TARGETS, budget=20, seed=5, cache=EvaluationCache(path, "line"))
    assert refit.parameters == fit.parameters and refit.sigma == fit.sigma
    assert 0 < again.calls < first.calls  # only what was lost is evaluated again
    third = Line()
    calibrate(third, PARAMETERS, TARGETS, budget=20, seed=5, cache=EvaluationCache(path, "line"))
    assert third.calls == 0
    with pytest.raises(CalibrationError, match="records another calibration"):
        EvaluationCache(path, "another")


def test_failed_evaluations_score_a_penalty_not_a_crash():
    def sometimes(points):
        out = Line()(points)
        return [None if p["p0"] > 4.0 else f for p, f in zip(points, out, strict=True)]

    fit = calibrate(sometimes, PARAMETERS, TARGETS, budget=30, seed=2)
    assert fit.parameters["p0"] == pytest.approx(2.0, abs=1e-5)


def test_bad_setups_are_refused_naming_the_parameter():
    with pytest.raises(CalibrationError, match=r"k: bounds \[2, 1\]"):
        Parameter("k", 2.0, 1.0)
    with pytest.raises(CalibrationError, match="log scaling needs a positive lower bound"):
        Parameter("k", 0.0, 1.0, log=True)
    with pytest.raises(CalibrationError, match="start 3 outside"):
        Parameter("k", 0.0, 1.0, start=3.0)
    with pytest.raises(CalibrationError, match="sigma"):
        Target("kd_max", 1.0, 0.0)
    with pytest.raises(CalibrationError, match="no targets"):
        calibrate(Line(), PARAMETERS, [])
    assert math.isclose(Parameter("k", 1.0, 100.0, log=True).from_unit(0.5), 10.0)
