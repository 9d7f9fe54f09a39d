"""Sensitivity methods (:mod:`gearbody.studies.sensitivity`): the problem (keys and their ranges), the
SALib sample matrix of Morris screening or Sobol (Saltelli) sampling, and the SALib analysis of the
evaluated rows into indices."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .parse import MOST_CASES, SweepSpecError, check_key

METHODS = ("morris", "sobol")
MAX_LEVELS = 1000
"""Most Morris grid levels (``--levels``; 4-10 are usual): SALib allocates per level, and 2**63 levels
raised numpy's 'array is too big'."""
INDEX_NAMES = {
    "morris": ("mu_star", "mu_star_conf", "sigma", "mu"),
    "sobol": ("S1", "S1_conf", "ST", "ST_conf"),
}
_NUMBER = re.compile(r"^\s*[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?\s*$")


def salib():
    """The SALib package, or an ImportError saying what to install."""
    try:
        import SALib  # noqa: F401
        import SALib.analyze.morris
        import SALib.analyze.sobol
        import SALib.sample.morris
        import SALib.sample.sobol
    except ImportError as exc:
        raise ImportError("sensitivity analysis needs SALib: pip install gearbody[calibrate]") from exc
    return SALib


def parse_key_range(text: str, label: str | None = None) -> tuple[str, float, float]:
    """``KEY=low:high`` -> (key, low, high); low < high, both finite."""
    label = label or f"--key {text}"
    if "=" not in text:
        raise SweepSpecError(f"{label}: expected KEY=low:high, e.g. design.mesh.damping_Ns_per_m=3000:12000")
    key, spec = (s.strip() for s in text.split("=", 1))
    check_key(key, label)
    parts = spec.split(":")
    if len(parts) != 2 or not all(_NUMBER.match(p) for p in parts):
        raise SweepSpecError(f"{label}: the range must be low:high (two numbers), got {spec!r}")
    return (key, *_check_bounds(key, float(parts[0]), float(parts[1]), label))


def _check_bounds(key: str, low: Any, high: Any, label: str) -> tuple[float, float]:
    try:
        lo, hi = float(low), float(high)
    except (TypeError, ValueError):
        raise SweepSpecError(
            f"{label}: the range of {key} must be two numbers, got {low!r}, {high!r}"
        ) from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise SweepSpecError(f"{label}: the range of {key} needs finite low < high, got {lo!r}:{hi!r}")
    return lo, hi


def make_problem(
    keys: Mapping[str, tuple[float, float]] | Sequence[str],
) -> dict[str, tuple[float, float]]:
    """Ordered ``{key: (low, high)}`` from a mapping or ``["KEY=low:high", ...]``."""
    if isinstance(keys, Mapping):
        items = []
        for k, bounds in keys.items():
            check_key(k, f"key {k}")
            if isinstance(bounds, str) or np.shape(bounds) != (2,):
                raise SweepSpecError(f"key {k}: give the range as (low, high), got {bounds!r}")
            items.append((k, *_check_bounds(k, bounds[0], bounds[1], f"key {k}")))
    else:
        items = [parse_key_range(str(t)) for t in keys]
    if not items:
        raise SweepSpecError("nothing to analyse: give at least one --key KEY=low:high")
    problem: dict[str, tuple[float, float]] = {}
    for k, lo, hi in items:
        if k in problem:
            raise SweepSpecError(f"--key {k}: given twice")
        problem[k] = (lo, hi)
    return problem


def whole_number(value: Any, name: str, minimum: int) -> int:
    """``value`` as an int, refused unless a whole number (not a bool) >= ``minimum``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise SweepSpecError(f"{name} must be a whole number >= {minimum}, got {value!r}")
    return int(value)


def run_count(method: str, samples: int, n_keys: int, second_order: bool = True) -> int:
    """Rows of the sample matrix (model evaluations) of a method."""
    if method == "morris":
        return samples * (n_keys + 1)
    return samples * (2 * n_keys + 2 if second_order else n_keys + 2)


def check_sampling(method: str, samples: Any, levels: Any, exclude_failed: bool) -> tuple[int, Any]:
    """``(samples, levels)`` checked for the method (one of :data:`METHODS`): Morris, at least 2
    trajectories of an even number of levels up to :data:`MAX_LEVELS`; Sobol, a base sample a power of
    2, and every row needed (no ``exclude_failed``)."""
    if method == "morris":
        samples = whole_number(samples, "--samples (Morris trajectories)", 2)
        levels = whole_number(levels, "--levels", 2)
        if levels % 2 or levels > MAX_LEVELS:
            raise SweepSpecError(
                f"--levels must be even (a grid jump of levels/(2 (levels-1))) and <= {MAX_LEVELS}, got "
                f"{levels}"
            )
    else:
        samples = whole_number(samples, "--samples (Sobol base sample)", 2)
        if samples & (samples - 1):
            raise SweepSpecError(f"--samples must be a power of 2 for Sobol (Sobol sequence), got {samples}")
        if exclude_failed:
            raise SweepSpecError("--exclude-failed is for Morris only: Sobol's estimators need every row")
    return samples, levels


def check_outputs(method: str, outputs: Sequence[str]) -> tuple[str, ...]:
    """The method one of :data:`METHODS`; the outputs, as text, one or more and distinct."""
    if method not in METHODS:
        raise SweepSpecError(f"--method {method!r}: valid are {', '.join(METHODS)}")
    outputs = tuple(str(o) for o in outputs)
    if not outputs or len(set(outputs)) != len(outputs):
        raise SweepSpecError(f"give one or more distinct features, got {list(outputs)}")
    return outputs


def check_seed_batch_conf(seed: Any, batch: Any, conf_level: float) -> tuple[int, int]:
    """``(seed, batch)`` as whole numbers (>= 0, >= 1), the confidence level in (0, 1)."""
    seed = whole_number(seed, "--seed", 0)
    batch = whole_number(batch, "batch", 1)
    if not 0 < conf_level < 1:
        raise SweepSpecError(f"conf_level must be in (0, 1), got {conf_level!r}")
    return seed, batch


def checked_run_count(
    method: str, samples: int, n_keys: int, second_order: bool, max_runs: int | None, force: bool
) -> int:
    """The rows of the sample; refused above what any analysis may have, and above ``max_runs`` unless
    ``force``."""
    n_rows = run_count(method, samples, n_keys, second_order)
    if n_rows > MOST_CASES:  # even with --force: the sample matrix is made in memory first
        raise SweepSpecError(
            f"{method} with --samples {samples} over {n_keys} keys is {n_rows} runs, above the most "
            f"any analysis may have ({MOST_CASES}, --force included); lower --samples"
        )
    if max_runs is not None and n_rows > max_runs and not force:
        raise SweepSpecError(
            f"{method} with --samples {samples} over {n_keys} keys is {n_rows} runs, above the limit "
            f"of {max_runs}; lower --samples or give --force"
        )
    return n_rows


def sample_matrix(problem: Mapping[str, tuple[float, float]], spec: Mapping[str, Any]) -> np.ndarray:
    """The SALib sample of the method: one row per model evaluation."""
    salib()
    from SALib.sample import morris, sobol

    sp = {"num_vars": len(problem), "names": list(problem), "bounds": [list(b) for b in problem.values()]}
    if spec["method"] == "morris":
        return morris.sample(sp, spec["samples"], num_levels=spec["levels"], seed=spec["seed"])
    return sobol.sample(sp, spec["samples"], calc_second_order=spec["second_order"], seed=spec["seed"])


def analyse_rows(
    spec: Mapping[str, Any], X: np.ndarray, Y: np.ndarray, keep: np.ndarray | None
) -> dict[str, np.ndarray]:
    """The indices of one output ``Y`` over the sample ``X`` (Morris: the rows ``keep`` only, if given)."""
    from SALib.analyze import morris, sobol

    problem = {"num_vars": len(spec["keys"]), "names": list(spec["keys"]), "bounds": spec["bounds"]}
    common = {"num_resamples": spec["num_resamples"], "conf_level": spec["conf_level"], "seed": spec["seed"]}
    if spec["method"] == "morris":
        x, y = (X, Y) if keep is None else (X[keep], Y[keep])
        res = morris.analyze(problem, x, y, num_levels=spec["levels"], **common)
        return {k: np.asarray(res[k], dtype=float) for k in ("mu", "mu_star", "mu_star_conf", "sigma")}
    res = sobol.analyze(problem, Y, calc_second_order=spec["second_order"], **common)
    names = ("S1", "S1_conf", "ST", "ST_conf") + (("S2", "S2_conf") if spec["second_order"] else ())
    return {k: np.asarray(res[k], dtype=float) for k in names}
