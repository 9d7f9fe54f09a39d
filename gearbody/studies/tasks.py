"""The tasks the executors run, one per case (module-level and picklable both ways, so they run in a
process pool or on a Dask worker; they never raise): :func:`run_case` simulates and summarises a case
of a parameter study, :func:`speed_case` simulates one speed of a K_d-against-speed sweep and returns
its K_d statistics. Both rebuild the scenario from TOML data + override strings."""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .executors import failure

__all__ = ["run_case", "speed_case"]


def run_case(base: Mapping[str, Any], overrides: Sequence[str], keep_result: bool = True) -> dict[str, Any]:
    """Rebuild the scenario from TOML data + overrides, simulate and summarise; never raises.

    Returns ``{"ok": True, "summary": {...}, "result": Result | None, "wall_time_s": s}`` or
    ``{"ok": False, "error_type", "message", "traceback", "wall_time_s"}``. Picklable both ways, so it
    runs in a process pool or on a Dask worker.
    """
    t0 = time.perf_counter()
    try:
        from gearbody.engine import simulate
        from gearbody.model import load_scenario

        result = simulate(load_scenario(dict(base), list(overrides)))
        summary = result.summary()
        wall = time.perf_counter() - t0
        summary["wall_time_s"] = wall
        return {
            "ok": True,
            "summary": summary,
            "result": result if keep_result else None,
            "wall_time_s": wall,
        }
    except Exception as exc:  # any failure is recorded for this case; the study goes on
        raise_if_interrupted(exc)
        return failure(exc, time.perf_counter() - t0)


def raise_if_interrupted(exc: BaseException) -> None:
    """Raise KeyboardInterrupt when ``exc`` is a Ctrl-C in disguise: one that landed inside a compiled
    (numba) call surfaces as a SystemError whose context is the KeyboardInterrupt. A case interrupted so
    is not a failed case: the study stops and resumes it."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            raise KeyboardInterrupt from None
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__


SPEED_VALUES = (
    "pinion_speed_rad_s",
    "mesh_frequency_hz",
    "kd_max",
    "kd_min",
    "kd_rms_dynamic",
    "separation_fraction",
)


def speed_case(base: Mapping[str, Any], overrides: Sequence[str], settle_s: float) -> dict[str, Any]:
    """Simulate one steady run and take K_d statistics after ``settle_s``; never raises.

    Returns ``{"ok": True, "values": {name: float for name in SPEED_VALUES}, "wall_time_s": s}`` or a
    :func:`~gearbody.studies.executors.failure`.
    """
    t0 = time.perf_counter()
    try:
        from gearbody.analysis.dynamic_factor import separation_stats
        from gearbody.engine import simulate
        from gearbody.model import load_scenario

        res = simulate(load_scenario(dict(base), list(overrides)))
        window = res.time_s >= settle_s
        kd = res.kd[window]
        sep = separation_stats(res.mesh_force[window], res.time_s[window], kd=kd)
        values = (
            float(np.mean(res["pinion_speed_rad_s"][window])),
            float(np.mean(res["mesh_frequency_hz"][window])),
            float(kd.max()),
            float(kd.min()),
            float(np.std(kd)),
            float(sep.separated_fraction),
        )
        return {
            "ok": True,
            "values": dict(zip(SPEED_VALUES, values, strict=True)),
            "wall_time_s": time.perf_counter() - t0,
        }
    except Exception as exc:  # a failed speed is reported, the sweep goes on
        raise_if_interrupted(exc)
        return failure(exc, time.perf_counter() - t0)
