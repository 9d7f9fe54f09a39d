"""The input of a scene calibration (:func:`gearbody.studies.scene_calibration.calibrate_scene`): its
``--param`` and ``--target`` specs parsed, and every check made before anything runs (settings, targets and
their cases, each case's scenario at every parameter bound, features and their signals, the wall time)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from .calibration import CalibrationError, Parameter, Target
from .executors import check_options
from .parse import MOST_CASES, SweepSpecError, check_key
from .sensitivity_scene import check_feature_signals, check_feature_windows
from .wall import check_study_wall_time, run_estimates_s

MAX_SEED = 2**32 - 1
"""Largest optimiser seed (``--seed``): the optimiser's random state takes 32 bits (2**64 raised numpy's
'Seed must be between 0 and 2**32 - 1')."""


def parse_parameter(text: str, start: float | None = None) -> Parameter:
    """``KEY=low:high`` or ``KEY=low:high:log`` -> :class:`Parameter` (``--param``)."""
    label = f"--param {text}"
    if "=" not in text:
        raise SweepSpecError(
            f"{label}: expected KEY=low:high[:log], e.g. design.mesh.damping_Ns_per_m=3000:12000:log"
        )
    key, spec = (s.strip() for s in text.split("=", 1))
    check_key(key, label)
    parts = spec.split(":")
    log = len(parts) == 3 and parts[2].strip() == "log"
    if len(parts) not in (2, 3) or (len(parts) == 3 and not log):
        raise SweepSpecError(f"{label}: the range must be low:high or low:high:log, got {spec!r}")
    try:
        lo, hi = float(parts[0]), float(parts[1])
    except ValueError:
        raise SweepSpecError(
            f"{label}: low and high must be numbers, got {parts[0]!r}, {parts[1]!r}"
        ) from None
    try:
        return Parameter(key, lo, hi, start, log)
    except CalibrationError as exc:
        raise SweepSpecError(f"{label}: {exc}") from None


def parse_target(feature: str, value: str, sigma: str) -> Target:
    """``FEATURE[@CASE] VALUE SIGMA`` -> :class:`Target` (``--target``)."""
    label = f"--target {feature} {value} {sigma}"
    spec, _, case = feature.partition("@")
    try:
        return Target(spec.strip(), float(value), float(sigma), case.strip())
    except ValueError as exc:
        raise SweepSpecError(f"{label}: {exc}") from None


def _recorded_evaluations(path: Path) -> int:
    """Evaluation lines of an evaluations.jsonl (0 when there is none or it cannot be read)."""
    try:
        with open(path, "rb") as f:
            return max(0, sum(1 for _ in f) - 1)  # the first line is the fingerprint
    except OSError:
        return 0


def _cases_used(targets: Sequence[Target], cases: Mapping[str, Sequence[str]]) -> dict[str, tuple[str, ...]]:
    """The cases the targets name, in first-use order, with their overrides ("" = no extra override)."""
    used: dict[str, tuple[str, ...]] = {}
    for t in targets:
        if t.case and t.case not in cases:
            known = ", ".join(sorted(cases)) or "none given"
            raise SweepSpecError(
                f"target {t.label}: no case {t.case!r} (cases: {known}; give --case {t.case} KEY=VALUE)"
            )
        used.setdefault(t.case, tuple(cases.get(t.case, ())))
    unused = [c for c in cases if c not in used]
    if unused:
        raise SweepSpecError(
            f"case {unused[0]!r} is read by no target (give --target FEATURE@{unused[0]} ...)"
        )
    return used


def check_settings(
    parameters: tuple[Parameter, ...],
    targets: tuple[Target, ...],
    fit_options: Mapping[str, Any],
    batch: Any,
    limits: tuple[int, bool],
    workers: int | None,
    scheduler: Any | None,
) -> tuple[int, int]:
    """``(batch, most evaluations)``: something to fit and to fit to, whole numbers where needed, the
    executor options, and no more evaluations than ``max_evaluations`` unless ``force`` (``limits``).
    ``fit_options``: budget, polish, polish_evaluations, seed."""
    budget, polish = fit_options["budget"], fit_options["polish"]
    polish_evaluations, seed = fit_options["polish_evaluations"], fit_options["seed"]
    max_evaluations, force = limits
    if not parameters:
        raise SweepSpecError("nothing to fit: give one or more --param KEY=low:high")
    if not targets:
        raise SweepSpecError("nothing to fit to: give one or more --target FEATURE VALUE SIGMA")
    for n, v in (("budget", budget), ("polish_evaluations", polish_evaluations), ("seed", seed)):
        if isinstance(v, bool) or not isinstance(v, int) or v < (1 if n == "budget" else 0):
            raise SweepSpecError(
                f"--{n.replace('_', '-')} must be a whole number >= {1 if n == 'budget' else 0}, got {v!r}"
            )
    if seed > MAX_SEED:
        raise SweepSpecError(f"--seed must be a whole number >= 0 and <= {MAX_SEED}, got {seed!r}")
    check_options(workers, scheduler)
    if batch is None:
        batch = 2 if workers is None else max(1, workers)
    if isinstance(batch, bool) or not isinstance(batch, int) or batch < 1:
        raise SweepSpecError(f"--batch must be a whole number >= 1, got {batch!r}")
    if batch > MOST_CASES:  # points asked of the optimiser at once, and listed for the wall-time estimate
        raise SweepSpecError(f"--batch = {batch}: at most {MOST_CASES} points per round")
    total = budget + (polish_evaluations if polish else 0) + len(parameters) + 2
    if total > max_evaluations and not force:
        raise SweepSpecError(
            f"--budget {budget} + --polish-evaluations {polish_evaluations if polish else 0} is up to "
            f"{total} evaluations, above the limit of {max_evaluations}; lower them or give --force"
        )
    return batch, total


def check_targets(
    parameters: tuple[Parameter, ...],
    targets: tuple[Target, ...],
    cases: Mapping[str, tuple[str, ...]],
    overrides: tuple[str, ...],
) -> tuple[dict[str, tuple[str, ...]], list[str]]:
    """``(the cases used with their overrides, the parameters' keys)``: targets distinct with features
    that parse, every case read by a target, parameters distinct and none also set by an override."""
    from gearbody.analysis.features import FeatureError, parse_feature
    from gearbody.model import parse_override
    from gearbody.model.io import override_label

    labels = [t.label for t in targets]
    if len(set(labels)) != len(labels):
        raise SweepSpecError(f"a target is given twice: {labels}")
    for t in targets:
        try:
            parse_feature(t.feature)
        except FeatureError as exc:
            raise SweepSpecError(f"--target {t.label}: {exc}") from None
    used = _cases_used(targets, cases)
    keys = [p.key for p in parameters]
    if len(set(keys)) != len(keys):
        raise SweepSpecError(f"a --param is given twice: {keys}")
    given = [(o, None) for o in overrides]
    given += [
        (o, f"--case {c} {override_label(o).removeprefix('--set ')}") for c, os in used.items() for o in os
    ]
    for o, typed in given:  # a case's override named as --case NAME KEY=VALUE
        key = parse_override(o, typed)[0]
        if key in keys:
            raise SweepSpecError(f"override {o}: {key} is also a --param; give it in one place")
    return used, keys


def check_cases(
    base: Mapping[str, Any],
    overrides: tuple[str, ...],
    used: Mapping[str, tuple[str, ...]],
    parameters: tuple[Parameter, ...],
    targets: tuple[Target, ...],
) -> list[float]:
    """Every case a valid scenario, at every parameter bound and start too, holding its targets' windows
    and recording their signals; returns the estimated wall time of a simulation of each case that runs
    one (s; the costlier end of each parameter's range)."""
    from gearbody.analysis.features import parse_feature
    from gearbody.model import ScenarioError, load_scenario

    case_s: list[float] = []  # estimated wall time of a simulation of each case, s
    for case, extra in used.items():
        where = f"case {case!r}" if case else "the fixed overrides"
        specs = [parse_feature(t.feature) for t in targets if t.case == case]
        try:
            scenario = load_scenario(dict(base), [*overrides, *extra])
            loaded = [scenario]
        except ScenarioError as exc:
            raise SweepSpecError(f"{where}: {exc}") from None
        check_feature_windows(scenario, specs, f" ({where})", "--target")
        for p in parameters:
            for v in (p.lower, p.upper, *(() if p.start is None else (p.start,))):
                try:
                    scenario = load_scenario(dict(base), [*overrides, *extra, f"{p.key}={v!r}"])
                    loaded.append(scenario)
                except ScenarioError as exc:
                    raise SweepSpecError(f"--param {p.key}: at {v!r} ({where}): {exc}") from None
                check_feature_windows(scenario, specs, f" (--param {p.key} at {v!r}, {where})", "--target")
        check_feature_signals(base, [*overrides, *extra], specs)
        if not all(spec.name == "natural_frequency_hz" for spec in specs):  # else the modes only
            case_s.append(max(run_estimates_s(loaded)))
    return case_s


def check_wall_time(
    out: Path,
    case_s: list[float],
    batch: int,
    total: int,
    workers: int | None,
    scheduler: Any | None,
    max_wall_minutes: float | None,
    progress: bool,
) -> None:
    """Refuse evaluations still to do (those not recorded in ``out``) estimated above
    ``max_wall_minutes`` of wall time (:mod:`gearbody.studies.wall`)."""
    recorded = _recorded_evaluations(Path(out) / "evaluations.jsonl")  # read only: replayed on resume
    check_study_wall_time(
        case_s * batch,
        workers=workers,
        scheduler=scheduler,
        max_wall_minutes=max_wall_minutes,
        progress=progress,
        what=f"the calibration (up to {max(0, total - recorded)} of {total} evaluations to do)",
        remedy="shorten operation.t_end_s (--t-end), lower --budget / --polish-evaluations or give more "
        "--workers",
        parallel=batch * len(case_s),
        repeat=math.ceil(max(0, total - recorded) / batch),
    )
