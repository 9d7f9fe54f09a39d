"""The scene side of a sensitivity analysis (:func:`gearbody.studies.sensitivity.sensitivity`): the scene
read, and every check made before anything runs: keys and their range ends, features and their windows,
the signals they read (a probe run of :data:`PROBE_S`), every sample row's scenario and the wall time of
the runs still to do."""

from __future__ import annotations

import hashlib
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .parse import SweepSpecError
from .sensitivity_record import pending_rows, recorded_rows
from .wall import check_study_wall_time, run_estimates_s

PROBE_S = 0.002
"""Simulated time of the probe run that finds the signals a scene records (a few hundredths of a second)."""


def read_scene(scene: str | Path) -> tuple[str, dict[str, Any], str]:
    """(label stored in the spec, TOML data, sha256 of the file) of a scene name or TOML path."""
    from gearbody.model import scene_path
    from gearbody.model.io import names_a_file, parse_scenario_bytes, read_scenario_bytes

    path = Path(scene)
    if not path.suffix and not names_a_file(path):
        label, path = str(scene), scene_path(str(scene))
    else:  # realpath: a symbolic-link loop is the reader's one-line refusal below, not a RuntimeError
        label = os.path.realpath(path)
    data = read_scenario_bytes(path)  # refuses a missing file, a folder, a FIFO, a device, a huge file
    base = parse_scenario_bytes(data, path)
    if isinstance(base.get("meta"), dict):
        base["meta"].setdefault("name", path.stem)
    return label, base, hashlib.sha256(data).hexdigest()


def check_scene_inputs(
    scene: str | Path,
    problem: Mapping[str, tuple[float, float]],
    features: Sequence[str],
    overrides: tuple[str, ...],
) -> tuple[list[str], list, str, dict[str, Any], str]:
    """``(feature specs as text, parsed, scene label, TOML data, sha256)`` of a scene analysis, refused
    before anything runs: a feature that does not parse, a ``--set`` key also a ``--key``, a feature
    window the fixed scenario cannot hold, a range end that is no valid scenario."""
    from gearbody.analysis.features import FeatureError, parse_feature
    from gearbody.model import ScenarioError, load_scenario, parse_override

    specs = []
    for f in features:
        try:
            specs.append(str(parse_feature(f)))
        except FeatureError as exc:
            raise SweepSpecError(f"--feature {f}: {exc}") from None
    if not specs:
        raise SweepSpecError("give one or more --feature specs, e.g. --feature kd_max")
    for o in overrides:
        if parse_override(o)[0] in problem:
            raise SweepSpecError(f"--set {o}: {parse_override(o)[0]} is also a --key; give it in one place")
    label, base, sha = read_scene(scene)
    parsed = [parse_feature(f) for f in specs]
    fixed = load_scenario(dict(base), list(overrides))  # the fixed overrides alone
    check_feature_windows(fixed, parsed)  # a window the run cannot hold, before the sample is drawn
    for k, (lo, hi) in problem.items():
        for v in (lo, hi):
            try:
                load_scenario(dict(base), [*overrides, f"{k}={v!r}"])
            except ScenarioError as exc:
                raise SweepSpecError(f"--key {k}={lo!r}:{hi!r}: at {k} = {v!r}: {exc}") from None
    return specs, parsed, label, base, sha


def check_sample(
    X: np.ndarray,
    problem: Mapping[str, tuple[float, float]],
    base: Mapping[str, Any],
    overrides: Sequence[str],
    parsed: Sequence,
    out: Path,
    options: Mapping[str, Any],
    workers: int | None,
    scheduler: Any | None,
    max_wall_minutes: float | None,
) -> None:
    """The sample matrix ``X`` checked after the options, before anything is written: every row's
    scenario, the signals the features read, and the wall time of the runs still to do in ``out``."""
    scenarios = _check_rows(problem, base, overrides, X, parsed)
    check_feature_signals(base, overrides, parsed)
    if all(spec.name == "natural_frequency_hz" for spec in parsed):
        return  # the modes only: no simulation
    recorded = recorded_rows(out)  # read only: a resume runs the rest
    pending = pending_rows(recorded, len(X), options.get("retry_failed", False))
    check_study_wall_time(
        run_estimates_s([scenarios[r] for r in pending]),
        workers=workers,
        scheduler=scheduler,
        max_wall_minutes=max_wall_minutes,
        progress=options.get("progress", True),
        what=f"the analysis ({len(pending)} of {len(X)} runs to do)",
        remedy="shorten operation.t_end_s (--t-end), lower --samples or give more --workers",
    )


def check_feature_windows(scenario, specs, where: str = "", option: str = "--feature") -> None:
    """Every feature's window exists in a run of ``scenario``: its operating ``period``, its
    ``from_s``..``to_s`` or ``fraction`` holding 2 samples or more of the run's output grid. Needs no run:
    SweepSpecError naming the feature (given by ``option``), the run's length and its operating periods
    (``where``: which scenario)."""
    from gearbody.analysis.features import WINDOW_OPTIONS, FeatureError, Record, operating_periods_s
    from gearbody.model.budget import output_samples

    op, rate = scenario.operation, scenario.solver.output_rate_hz
    t = np.arange(output_samples(scenario)) / rate
    edges = operating_periods_s(t[0], t[-1], [*op.speed_profile.time_s, *op.load_profile.time_s])
    grid = Record(time_s=t, signals={}, period_boundaries_s=edges)
    for spec in specs:
        try:
            grid.window({k: v for k, v in spec.options.items() if k in WINDOW_OPTIONS})
        except FeatureError as exc:
            bounds = ", ".join(f"{e:g}" for e in edges)
            raise SweepSpecError(
                f"{option} {spec}: {exc} in a run of operation.t_end_s = {op.t_end_s:g} s{where} ({t.size} "
                f"samples; operating periods 1..{len(edges) - 1}, boundaries {bounds} s); nothing was run"
            ) from None


def check_feature_signals(base: Mapping[str, Any], overrides: Sequence[str], specs) -> None:
    """Every signal the features read is one the scene records: a probe run of PROBE_S finds them."""
    from gearbody.analysis.features import FeatureError, feature_signals

    if all(spec.name == "natural_frequency_hz" for spec in specs):
        return
    from gearbody.engine import simulate
    from gearbody.errors import SimulationError
    from gearbody.model import load_scenario

    try:
        record = simulate(load_scenario(dict(base), [*overrides, f"operation.t_end_s={PROBE_S}"])).record()
    except SimulationError:
        return  # the runs will say why
    for spec in specs:
        try:
            names = feature_signals(spec, record)
        except FeatureError as exc:  # the feature does not apply to the stage it names
            raise SweepSpecError(f"--feature {spec}: {str(exc).removeprefix(f'feature {spec}: ')}") from None
        for name in names:
            if name not in record.signals:
                raise SweepSpecError(
                    f"--feature {spec}: the scene records no signal {name!r}; it records "
                    f"{', '.join(sorted(record.signals))}"
                )


def _check_rows(problem, base, overrides, X: np.ndarray, specs=()) -> list:
    """Every row's scenario, each valid (keys that are valid alone may be refused together) and holding
    every feature's window (:func:`check_feature_windows`)."""
    from gearbody.model import ScenarioError, load_scenario

    scenarios = []
    for r, x in enumerate(X):
        row = [f"{k}={float(v)!r}" for k, v in zip(problem, x, strict=True)]
        try:
            scenario = load_scenario(dict(base), [*overrides, *row])
            scenarios.append(scenario)
        except ScenarioError as exc:
            raise SweepSpecError(
                f"sample row {r} ({', '.join(row)}) is not a valid scenario: {exc}"
            ) from None
        check_feature_windows(scenario, specs, f" (sample row {r}: {', '.join(row)})")
    return scenarios
