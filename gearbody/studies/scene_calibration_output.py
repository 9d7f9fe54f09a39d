"""The files of a finished scene calibration (:mod:`gearbody.studies.scene_calibration`) in its ``OUT``:
``calibrated.toml`` (the scene with the fitted values), ``calibration.json``, ``calibration.md`` and
``convergence.png``."""

from __future__ import annotations

from pathlib import Path

from gearbody.folders import atomic_write
from gearbody.version import __version__

from .calibration import CalibrationResult
from .store import write_json, write_text


def write_outputs(
    out: Path, fit: CalibrationResult, label: str, base, overrides, cases, stats, wall: float
) -> Path:
    """Write the calibration's files into ``out``; returns the path of ``calibrated.toml``."""
    from gearbody.model import dump_scenario, load_scenario
    from gearbody.plotting.calibration import plot_convergence

    values = [f"{k}={v!r}" for k, v in fit.parameters.items()]
    sc = load_scenario(dict(base), [*overrides, *values])
    sources = (
        *sc.meta.sources,
        f"calibrated by gearbody {__version__} from {label}: {', '.join(values)} fitted to "
        + "; ".join(f"{t.label} = {t.value:g} +- {t.sigma:g}" for t in fit.targets)
        + f" (files in {out})",
    )
    sc = sc.replace(meta=sc.meta.replace(name=f"{sc.meta.name}-calibrated", sources=sources))
    scenario_file = atomic_write(out / "calibrated.toml", lambda p: dump_scenario(sc, p))
    write_json(
        out / "calibration.json",
        {
            "format": "gearbody-calibration/1",
            "gearbody": __version__,
            "scene": label,
            "overrides": list(overrides),
            "cases": {c: list(v) for c, v in cases.items()},
            "parameters": fit.parameters,
            **fit.uncertainty_record(),  # sigma (null: unidentified), correlation, flags, warnings
            "targets": [
                {"feature": t.feature, "case": t.case, "value": t.value, "sigma": t.sigma}
                for t in fit.targets
            ],
            "features": fit.features,
            "residuals": fit.residuals,
            "cost": fit.cost,
            "evaluations": fit.evaluations,
            "replayed": fit.replayed,
            "simulations": stats["simulations"],
            "failed_evaluations": stats["failed"],
            "wall_time_s": wall,
            "history": fit.history,
        },
    )
    warnings = "".join(f"- warning: {w}\n" for w in fit.warnings())
    text = (
        f"# Calibration of {label}\n\n```\n{fit.table()}\n```\n\n"
        + (f"{warnings}\n" if warnings else "")
        + f"{stats['simulations']} simulations in this run, {wall:.1f} s wall; "
        f"cases: {', '.join(repr(c) for c in cases if c) or 'the scene only'}. "
        f"Rerun the fitted scene: `gearbody run {out / 'calibrated.toml'}`.\n"
    )
    write_text(out / "calibration.md", text)
    plot_convergence(fit.history, out / "convergence.png", title=f"{Path(label).name}: calibration")
    return scenario_file
