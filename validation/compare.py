"""Compare gearbody (Exudyn) with the independent reference (scipy) on the validation cases.

This is the only validation module that imports gearbody: it builds a scenario with gearbody, runs
it, hands the *resolved* scenario dict to :mod:`validation.reference` (which shares no force-law or
assembly code with gearbody) and compares the mesh forces on the common output grid.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

VALIDATED_SCENES = ("muller", "two-wheel", "one-stage", "two-stage", "three-stage")  # scene files

STEADY = [
    'operation.initial_state="steady"',
    "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
    "production.error_mode={a=0.5,e_um=10.0,r=0.3}",
]


@dataclass(frozen=True)
class Case:
    name: str
    description: str
    overrides: tuple[str, ...]
    t_end_s: float
    t_end_short_s: float
    must_separate: bool = False
    no_backlash: bool = False  # applied to every stage


def _run_up(scale: float) -> list[str]:
    """The four periods of Fig. 12 compressed: run-up, no load, load ramp, rated load."""
    return [
        'operation.initial_state="rest"',
        f"operation.speed_profile={{time_s=[0.0,{0.3 * scale}],fraction=[0.0,1.0]}}",
        f"operation.load_profile={{time_s=[0.0,{0.45 * scale},{0.7 * scale}],fraction=[0.0,0.0,1.0]}}",
        "production.error_mode={a=0.5,e_um=10.0,r=0.3}",
    ]


def cases(scene: str, short: bool = False) -> list[Case]:
    """Cases of a scene: steady rated E(0.5,10,0.3); tooth separation (K_d > 2); four-period run-up."""
    # Separation: the two-wheel scene's mesh mode (429 Hz) lies just under its rated mesh frequency
    # (494 Hz); the others are run at the speed where the mesh frequency meets their mesh mode.
    sep_speed = 1.0 if scene == "two-wheel" else 5.6
    separation = [
        *STEADY[:1],
        f"operation.speed_profile={{time_s=[0.0],fraction=[{sep_speed}]}}",
        *STEADY[2:],
    ]
    scale = 0.4 if short else 1.0
    run_up = _run_up(scale)
    run_up_text = "four periods: run-up, no load, load ramp, rated"
    if scene != "muller":
        # Unloaded (period 2), the torsional models rattle chaotically in the backlash: between
        # rtol 1e-10 and 1e-12 the reference disagrees with itself by 60 % (one-stage, from 0.40 s)
        # and 121 % (two-wheel, from 0.38 s) of F_rated, so no pointwise comparison is meaningful
        # there. Without backlash the same runs are well posed (<= 0.009 %). Backlash and impacts
        # are validated by the separation cases.
        run_up_text += "; no backlash (with it the unloaded rattle is chaotic)"
    return [
        Case("steady", "steady rated running, E(0.5, 10, 0.3)", tuple(STEADY), 0.5, 0.1),
        Case(
            "separation",
            f"tooth separation, speed x{sep_speed}, E(0.5, 10, 0.3)",
            tuple(separation),
            0.3,
            0.08,
            must_separate=True,
        ),
        Case("run-up", run_up_text, tuple(run_up), 1.0, 0.4, no_backlash=scene != "muller"),
    ]


@dataclass
class CaseResult:
    scene: str
    case: str
    max_error_percent: float
    rms_error_percent: float
    kd_max: float
    separated_fraction: float
    wall_gearbody_s: float
    wall_reference_s: float
    passed: bool
    note: str = ""


def case_scenario(scene: str, case: Case, short: bool = False):
    """The gearbody Scenario of a validation case."""
    from gearbody.model import load_scenario, scenario_to_dict

    t_end = case.t_end_short_s if short else case.t_end_s
    scenario = load_scenario(scene, [*case.overrides, f"operation.t_end_s={t_end}"])
    if case.no_backlash:
        data = scenario_to_dict(scenario)
        meshes = (
            [st["mesh"] for st in data["design"]["stages"]]
            if "stages" in data["design"]
            else [data["design"]["mesh"]]
        )
        for mesh in meshes:
            mesh["backlash_um"] = 0.0
        scenario = load_scenario(data)
    return scenario


def compare_case(scene: str, case: Case, short: bool = False, tolerance_percent: float = 0.5) -> CaseResult:
    """Run gearbody and the reference on one case; the error is the worst stage's max |dF|/F_rated,s."""
    from gearbody.engine import simulate
    from gearbody.model import scenario_to_dict

    from .reference import simulate_reference

    scenario = case_scenario(scene, case, short)
    t0 = time.perf_counter()
    res = simulate(scenario)
    t1 = time.perf_counter()
    ref = simulate_reference(scenario_to_dict(scenario), t_eval=res.time_s)
    t2 = time.perf_counter()
    err = np.zeros_like(res.time_s)
    for k in range(len(scenario.stages)):
        prefix = "" if k == 0 else f"stage_{k + 1}_"
        dF = np.abs(res[prefix + "mesh_force_N"] - ref["stage_mesh_force_N"][k])
        err = np.maximum(err, dF / scenario.stage_rated_force_N(k) * 100.0)
    kd_max = float(res.kd.max())
    sep = float(np.mean(res.mesh_force <= 0.0))
    passed = bool(err.max() <= tolerance_percent)
    note = ""
    if case.must_separate and kd_max <= 2.0:
        passed, note = False, "case did not separate (K_d <= 2)"
    return CaseResult(
        scene,
        case.name,
        float(err.max()),
        float(np.sqrt(np.mean(err**2))),
        kd_max,
        sep,
        t1 - t0,
        t2 - t1,
        passed,
        note,
    )


def run_validation(
    scenes: list[str] | None = None, short: bool = False, tolerance_percent: float = 0.5, echo=print
) -> bool:
    """Run every case of the given scenes, print a table, return True when all pass."""
    scenes = list(scenes or VALIDATED_SCENES)
    echo(
        "gearbody vs independent reference (scipy solve_ivp): max |dF|/F_rated, "
        f"tolerance {tolerance_percent} %" + (" [short runs]" if short else "")
    )
    echo(
        f"{'scene':<13}{'case':<12}{'max dF %':>10}{'rms dF %':>10}{'K_d max':>9}{'sep.':>7}"
        f"{'gearbody s':>12}{'reference s':>13}  result"
    )
    results = []
    for scene in scenes:
        for case in cases(scene, short):
            r = compare_case(scene, case, short, tolerance_percent)
            results.append(r)
            echo(
                f"{r.scene:<13}{r.case:<12}{r.max_error_percent:>10.4f}{r.rms_error_percent:>10.4f}{r.kd_max:>9.3f}"
                f"{r.separated_fraction:>7.2f}{r.wall_gearbody_s:>12.2f}{r.wall_reference_s:>13.2f}  "
                f"{'PASS' if r.passed else 'FAIL'} {r.note}"
            )
    ok = all(r.passed for r in results)
    echo("all cases pass" if ok else "SOME CASES FAIL")
    return ok
