"""Calibration on models whose answer is known by hand: the machinery (global search, polish, Jacobian
uncertainty, the evaluation record and resume) before it meets a gearbox."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

pytest.importorskip("nevergrad")

from gearbody.studies.calibration import (  # noqa: E402
    AT_BOUND_TOLERANCE,
    IDENTIFIED_MIN_SINGULAR_VALUE,
    CalibrationError,
    EvaluationCache,
    Parameter,
    Target,
    calibrate,
    uncertainty,
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
    assert fit.at_bound == {} and fit.unidentified == () and fit.warnings() == []


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


def _scaled(points, keys, scales, rows):
    """Features y_i = sum_j rows[i][j] * point[key_j] / scale_j: a linear model whose parameters have the
    given scales, the answer known by hand in the scaled parameters."""
    out = []
    for p in points:
        x = np.array([p[k] / s for k, s in zip(keys, scales, strict=True)])
        out.append({f"y{i}": float(v) for i, v in enumerate(np.asarray(rows) @ x)})
    return out


def test_parameters_of_scales_1e9_and_1e_minus_6_get_the_sigma_of_the_scaled_problem():
    """y0 = k / 1e9, y1 = k / 1e9 + x / 1e-6, sigma 0.1: in the scaled parameters (A^T A)^-1 =
    [[1, -1], [-1, 2]], so sigma_k = 0.1e9 N/m, sigma_x = 0.1 sqrt(2) 1e-6 m and their correlation is
    -1/sqrt(2). In the parameters' own units J^T J has a condition number of 1e30: an inverse of it (with
    any cut-off of small singular values) loses k altogether."""
    rows, scales, keys = [[1.0, 0.0], [1.0, 1.0]], (1e9, 1e-6), ("k", "x")
    truth = {"k": 1.1e9, "x": 2.5e-6}
    targets = [
        Target(f"y{i}", v, 0.1) for i, v in enumerate(_scaled([truth], keys, scales, rows)[0].values())
    ]
    params = [Parameter("k", 0.5e9, 2e9, start=1.9e9, log=True), Parameter("x", 1e-6, 5e-6, start=4e-6)]
    fit = calibrate(lambda pts: _scaled(pts, keys, scales, rows), params, targets, budget=30, seed=4)
    assert fit.parameters["k"] == pytest.approx(1.1e9, rel=1e-6)
    assert fit.parameters["x"] == pytest.approx(2.5e-6, rel=1e-6)
    assert fit.sigma["k"] == pytest.approx(0.1e9, rel=1e-6)
    assert fit.sigma["x"] == pytest.approx(0.1 * math.sqrt(2) * 1e-6, rel=1e-6)
    assert fit.correlation[0, 1] == pytest.approx(-1 / math.sqrt(2), rel=1e-6)
    assert np.all(np.abs(fit.correlation) <= 1.0) and np.all(np.diag(fit.correlation) == 1.0)
    assert fit.unidentified == () and fit.at_bound == {}
    J_units = np.array(rows) / np.array(scales) / 0.1  # the problem as the old inverse saw it
    assert np.linalg.cond(J_units.T @ J_units) > 1e25


def test_an_exactly_unidentifiable_combination_is_reported_not_given_a_small_sigma():
    """y_i = (a + b) x_i + c: a and b are seen only as their sum, so neither is identified (sigma inf) and
    the direction a - b (equal boxes: components +-1/sqrt(2)) is reported; c keeps the sigma of the
    straight line y = s x + c, sqrt((A^T A)^-1)[1, 1] sigma with A = [x, 1]."""
    x = np.arange(4.0)
    rows = np.column_stack([x, x, np.ones(4)])
    keys, scales = ("a", "b", "c"), (1.0, 1.0, 1.0)
    truth = {"a": 0.6, "b": 0.9, "c": 0.3}
    targets = [
        Target(f"y{i}", v, SIGMA) for i, v in enumerate(_scaled([truth], keys, scales, rows)[0].values())
    ]
    params = [Parameter("a", 0.0, 3.0), Parameter("b", 0.0, 3.0), Parameter("c", -1.0, 1.0)]
    fit = calibrate(lambda pts: _scaled(pts, keys, scales, rows), params, targets, budget=30, seed=2)
    assert fit.parameters["a"] + fit.parameters["b"] == pytest.approx(1.5, abs=1e-6)
    assert math.isinf(fit.sigma["a"]) and math.isinf(fit.sigma["b"])
    A = np.column_stack([x, np.ones(4)])
    assert fit.sigma["c"] == pytest.approx(math.sqrt(np.linalg.inv(A.T @ A)[1, 1]) * SIGMA, rel=1e-6)
    assert fit.identified == {"a": False, "b": False, "c": True}
    (direction,) = fit.unidentified
    assert direction["a"] == pytest.approx(1 / math.sqrt(2), abs=1e-6)
    assert direction["b"] == pytest.approx(-1 / math.sqrt(2), abs=1e-6)
    assert abs(direction["c"]) < 1e-6
    assert np.all(np.isnan(fit.correlation[:2])) and fit.correlation[2, 2] == 1.0
    warnings = "\n".join(fit.warnings())
    assert "a is not identified" in warnings and "b is not identified" in warnings
    assert "unidentified direction 0.707 a - 0.707 b" in warnings
    assert fit.table().count("unidentified") == 2
    record = fit.uncertainty_record()
    assert record["sigma"] == {"a": None, "b": None, "c": fit.sigma["c"]}
    assert json.loads(json.dumps(record, allow_nan=False))["unidentified_directions"][0]["direction"]


@pytest.mark.parametrize("seed", range(5))
def test_correlations_lie_in_minus_1_1_even_for_nearly_collinear_columns(seed):
    """Columns equal to 1e-9 relative, of scales 1e-6 to 1e6: the correlations come from one positive
    semi-definite covariance and are clipped, so they never leave [-1, 1]; the diagonal is exactly 1."""
    rng = np.random.default_rng(seed)
    base = rng.normal(size=6)
    J = np.column_stack([base, base * (1 + 1e-9 * rng.normal(size=6)), rng.normal(size=6)])
    J *= 10.0 ** rng.uniform(-6, 6, size=3)
    unc = uncertainty(J)
    c = unc.correlation[np.isfinite(unc.correlation)]
    assert np.all(np.abs(c) <= 1.0)
    finite = np.isfinite(unc.sigma_unit)
    assert np.all(np.diag(unc.correlation)[finite] == 1.0)


def test_a_parameter_that_moves_no_target_and_more_parameters_than_targets_are_unidentified():
    unc = uncertainty(np.array([[5.0, 0.0], [3.0, 0.0]]))
    assert np.isfinite(unc.sigma_unit[0]) and math.isinf(unc.sigma_unit[1])
    assert unc.sigma_unit[0] == pytest.approx(1 / math.sqrt(34))
    assert [s for s, _ in unc.unidentified_directions] == [0.0]
    unc = uncertainty(np.array([[4.0, 4.0]]))  # one target, two parameters: their difference is free
    assert np.all(np.isinf(unc.sigma_unit)) and len(unc.unidentified_directions) == 1
    weak = uncertainty(np.array([[0.5], [0.5]]))  # 1-sigma 1.41 of the box: wider than the range
    assert weak.singular_values[0] < IDENTIFIED_MIN_SINGULAR_VALUE and math.isinf(weak.sigma_unit[0])


def test_a_fit_that_ends_on_its_bounds_is_flagged_and_warned_about():
    """Targets y = 10 - 3 x: the intercept p0 in [-5, 5] ends on its upper bound, the slope p1 in
    [0.01, 10] on its lower one (with p1 = 0.01 the best p0 is 5.49, with p0 = 5 the best p1 is -0.86)."""
    targets = [Target(f"y{i}", 10.0 - 3.0 * i, SIGMA) for i in range(4)]
    fit = calibrate(Line(), PARAMETERS, targets, budget=40, seed=3)
    assert fit.at_bound == {"p0": "upper", "p1": "lower"}
    assert fit.parameters["p0"] >= 5.0 - 10.0 * AT_BOUND_TOLERANCE
    warnings = fit.warnings()
    assert any(w.startswith("p0 = ") and "ends on its upper bound (range [-5, 5])" in w for w in warnings)
    assert any(w.startswith("p1 = ") and "ends on its lower bound (range [0.01, 10])" in w for w in warnings)
    assert "on its upper bound" in fit.table()
    assert fit.uncertainty_record()["at_bound"] == {"p0": "upper", "p1": "lower"}


def _jittery(points):
    """The line's features plus a jitter of +-0.01 sigma that changes on parameter scales far below 1e-3
    of the box: what a simulated spectral line does under tiny parameter changes."""
    out = Line()(points)
    for p, features in zip(points, out, strict=True):
        for i, key in enumerate(features):
            features[key] += 0.01 * SIGMA * math.sin(1e5 * (p["p0"] + 3.0 * p["p1"]) + i)
    return out


def test_the_uncertainty_step_is_wide_enough_for_features_that_jitter():
    """Steps of 1 % of the box keep the textbook sigma to 5 % despite the jitter; steps of 0.1 % (the
    polish's) read the jitter as slope and miss it by more."""
    expected = np.sqrt(np.diag(np.linalg.inv(A.T @ A))) * SIGMA
    fit = calibrate(_jittery, PARAMETERS, TARGETS, budget=40, seed=3)
    assert [fit.sigma["p0"], fit.sigma["p1"]] == pytest.approx(expected, rel=0.05)
    narrow = calibrate(_jittery, PARAMETERS, TARGETS, budget=40, seed=3, uncertainty_step=1e-3)
    assert [narrow.sigma["p0"], narrow.sigma["p1"]] != pytest.approx(expected, rel=0.05)


def test_a_parameter_no_target_sees_is_warned_about_once():
    """p1 moves nothing: its direction is the p1 axis alone, said once as "p1 is not identified"."""

    def flat(points):
        return [{"y0": p["p0"], "y1": 2.0 * p["p0"]} for p in points]

    fit = calibrate(flat, PARAMETERS, [Target("y0", 1.0, 0.1), Target("y1", 2.0, 0.1)], budget=20, seed=1)
    assert fit.identified == {"p0": True, "p1": False} and len(fit.unidentified) == 1
    assert [w for w in fit.warnings() if "not identified" in w or "direction" in w] == [
        "p1 is not identified by the targets: its 1-sigma is wider than its range"
    ]
