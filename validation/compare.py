"""Compare gearbody (Exudyn) with the independent reference (scipy) on the validation cases.

This is the only validation module that imports gearbody: it builds a scenario with gearbody, runs
it, hands the *resolved* scenario dict to :mod:`validation.reference` (which shares no force-law or
assembly code with gearbody) and compares the mesh forces on the common output grid.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

VALIDATED_SCENES = (  # scene files
    "muller",
    "two-wheel",
    "one-stage",
    "two-stage",
    "three-stage",
    "lateral-6dof",
    "lateral-8dof",
    "lateral-8dof-ball",
    "industrial-two-stage",
    "one-stage-geometry",
    "two-stage-geometry",
    "planetary",
    "planetary-conveyor",
)
# Speed (fraction of the synchronous speed) at which the first mesh frequency meets the mesh mode:
# the separation case. Lateral scenes: the mesh mode rises from 2844 Hz to 3616 Hz (3670 Hz on the
# ball bearings) because the gear masses move with the mesh (gearbody modes).
SEPARATION_SPEED = {
    "two-wheel": 1.0,
    "lateral-6dof": 7.3,
    "lateral-8dof": 7.3,
    "lateral-8dof-ball": 7.3,
    "industrial-two-stage": 7.3,  # stage 1 mesh mode 3651 Hz (gearbody modes): 791 rad/s = 7.3 x
    # softer computed meshes (mean k_z 1.07e9 instead of 1.26e9 N/m): at 5.6 x they only touch K_d 2
    "one-stage-geometry": 5.2,
    "two-stage-geometry": 5.2,
    # the calibrated one-stage scenes (one-stage's model with fitted values, so not in VALIDATED_SCENES;
    # here so that their separation case separates): at 5.6 x far above their softer mesh modes, K_d < 2.
    # Scanned in steps of 0.1 x: K_d jumps to 3.8 (calibrated, 47 % separated) at 2.4 x and to 4.3
    # (rating, 56 %) at 2.0 x; taken a little above the jump, where gearbody and the reference agree
    # within 0.31 % / 0.014 % over the full 0.3 s (0.14 % / 0.011 % short)
    "one-stage-calibrated": 2.6,
    "one-stage-calibrated-rating": 2.2,
    # 2593 Hz below the ring's torsional mode (2660 Hz): K_d 2.49, 20 % separated (x4.8: K_d 2.26 but only
    # 1.2 % separated). At x2.0 (1122 Hz on the 1102 Hz translational pair) K_d reaches 3.4 with 10-15 %
    # separated and the impacts are chaotic: gearbody and the reference part after 0.027 s at the default
    # tolerance, after 0.031 s at 1e-10.
    "planetary": 4.6,
    # planetary-conveyor: spur mesh 2.95 kHz near its mesh mode, K_d 2.75, 32 % separated. At the default
    # x5.6 the planetary stage meshes at 720 Hz on its 714 Hz translational pair (K_d 2.4) and with
    # friction the impacts turn chaotic: gearbody and the reference part after 0.037 / 0.042 / 0.044 s at
    # gearbody's 1e-9 / 1e-10 / 1e-11 (without friction that case passed at 0.035 %)
    "planetary-conveyor": 5.9,
}
# Scenes without a run-up case: on bearings with clearance an unloaded gear rattles inside the
# clearance, as unloaded teeth do in the backlash (chaotic, not comparable pointwise). phm2009 (four
# gears on ball bearings with 5 um clearance): its run-up parts from the reference by 11 % of F_rated.
NO_RUN_UP = ("lateral-8dof-ball", "phm2009", "planetary", "planetary-conveyor")
"""Planetary scenes: steady and separation cases (issue 19); a run-up of the reference at ~250 s per
simulated second (2N segmented meshes) is left to validation/ scripts."""
BEARING_DEFECT = {
    # lateral-8dof-ball's bearings ball by ball ('rolling-elements', per-ball K from the lumped k_b by
    # Stribeck's Z K / 4.37; cage slip 1.5 %), a 20 um outer-race spall in the pinion bearing's load zone
    # and a ball defect, a 20 um inner-race spall on the wheel's (docs/scenario.md, "Bearing defects")
    "lateral-8dof-ball": tuple(
        f"design.stages.1.{gear}.bearing.{key}"
        for gear, k_ball, damping, defects in (
            (
                "pinion",
                5.5e10,
                2000.0,
                '[{race="outer",depth_m=20e-6,width_deg=6.0,angle_deg=90.0},'
                '{race="ball",depth_m=20e-6,width_deg=20.0,angle_deg=30.0,ball=3}]',
            ),
            ("wheel", 1.1e11, 4000.0, '[{race="inner",depth_m=20e-6,width_deg=8.0,angle_deg=45.0}]'),
        )
        for key in (
            'kind="rolling-elements"',
            f"parameters={{ball_stiffness_N_per_m_n={k_ball},radial_clearance_m=5e-6,damping_Ns_per_m={damping},"
            "cage_slip=0.015,slip_seed=7}",
            f"defects={defects}",
        )
    ),
}
"""Scenes with a bearing-defect case: overrides that make their bearings ball by ball with defects."""
SHORT_S = {"planetary": (0.04, 0.06), "planetary-conveyor": (0.04, 0.06), "phm2009": (0.02, 0.02)}
"""(steady, separation) short-run lengths where the default ones would make the suite slow, s (phm2009:
the reference took 59 s for the steady 0.1 s and 154 s for the separating 0.08 s, four Hertzian
bearings and two 6-7 kHz torsional modes; on its ball-by-ball bearings 5 s and 29 s for 0.02 s, where
the separation case reaches K_d 4.65)."""

STEADY = [
    'operation.initial_state="steady"',
    "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
]
ERROR_MODE = "error_mode={a=0.5,e_um=10.0,r=0.3}"  # E(0.5, 10, 0.3) on every stage


def error_mode_overrides(scene: str) -> list[str]:
    """E(0.5, 10, 0.3) on each stage of the scene (design.stages.N.error_mode; a planetary stage's
    sun_error_mode and ring_error_mode)."""
    from gearbody.model import load_scenario

    out = []
    for k, st in enumerate(load_scenario(scene).stages):
        keys = ("sun_", "ring_") if hasattr(st, "planets") else ("",)
        out += [f"design.stages.{k + 1}.{key}{ERROR_MODE}" for key in keys]
    return out


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
    ]


def cases(scene: str, short: bool = False) -> list[Case]:
    """Cases of a scene: steady rated E(0.5,10,0.3); tooth separation (K_d > 2); four-period run-up."""
    # Separation: the two-wheel scene's mesh mode (429 Hz) lies just under its rated mesh frequency
    # (494 Hz); the others are run at the speed where the mesh frequency meets their mesh mode.
    sep_speed = SEPARATION_SPEED.get(scene, 5.6)
    errors = error_mode_overrides(scene)
    steady = [*STEADY, *errors]
    separation = [
        *STEADY[:1],
        f"operation.speed_profile={{time_s=[0.0],fraction=[{sep_speed}]}}",
        *STEADY[2:],
        *errors,
    ]
    scale = 0.4 if short else 1.0
    run_up = [*_run_up(scale), *errors]
    run_up_text = "four periods: run-up, no load, load ramp, rated"
    if scene != "muller":
        # Unloaded (period 2), the torsional models rattle chaotically in the backlash: between
        # rtol 1e-10 and 1e-12 the reference disagrees with itself by 60 % (one-stage, from 0.40 s)
        # and 121 % (two-wheel, from 0.38 s) of F_rated, so no pointwise comparison is meaningful
        # there. Without backlash the same runs are well posed (<= 0.009 %). Backlash and impacts
        # are validated by the separation cases.
        run_up_text += "; no backlash (with it the unloaded rattle is chaotic)"
    short_steady, short_separation = SHORT_S.get(scene, (0.1, 0.08))
    out = [
        Case("steady", "steady rated running, E(0.5, 10, 0.3)", tuple(steady), 0.5, short_steady),
        Case(
            "separation",
            f"tooth separation, speed x{sep_speed}, E(0.5, 10, 0.3)",
            tuple(separation),
            0.3,
            short_separation,
            must_separate=True,
        ),
    ]
    if scene not in NO_RUN_UP:
        out.append(Case("run-up", run_up_text, tuple(run_up), 1.0, 0.4, no_backlash=scene != "muller"))
    if scene in BEARING_DEFECT:
        text = "steady rated, ball-by-ball bearings: outer-race and ball defects (pinion), inner-race (wheel)"
        out.append(Case("bearing-defect", text, (*steady, *BEARING_DEFECT[scene]), 0.5, 0.1))
    return out


@dataclass
class CaseResult:
    scene: str
    case: str
    max_error_percent: float
    rms_error_percent: float
    bearing_error_percent: float  # worst bearing force: max |dF_b| / max |F_b,ref|; NaN without bearings
    kd_max: float
    separated_fraction: float
    wall_gearbody_s: float
    wall_reference_s: float
    passed: bool
    note: str = ""
    reference_cached: bool = False  # the reference's output came from the cache (cached_reference)


def case_scenario(scene: str, case: Case, short: bool = False):
    """The gearbody Scenario of a validation case."""
    from gearbody.model import load_scenario, scenario_to_dict

    t_end = case.t_end_short_s if short else case.t_end_s
    # compare instantaneous samples: the anti-aliasing filter is post-processing, tested on its own
    overrides = [*case.overrides, f"operation.t_end_s={t_end}", "solver.anti_aliasing=false"]
    scenario = load_scenario(scene, overrides)
    if case.no_backlash:
        data = scenario_to_dict(scenario)
        for mesh in (st["mesh"] for st in data["design"]["stages"]):
            mesh["backlash_um"] = 0.0
            for key in ("thickness_allowance_pinion_um", "thickness_allowance_wheel_um"):
                mesh.get("geometry", {}).pop(key, None)
        scenario = load_scenario(data)
    return scenario


def reference_input(scenario) -> dict:
    """The resolved scenario dict handed to the reference, with each potential-energy mesh's pair
    stiffness table added as data (``mesh.pair_table``, docs/scenario.md "Pair stiffness table"): the
    stiffness computation is checked by its own tests; the reference implements the law that uses it."""
    from gearbody.model import scenario_to_dict
    from gearbody.physics.mesh_stiffness import stage_pair_table

    data = scenario_to_dict(scenario)
    for stage, st in zip(scenario.stages, data["design"]["stages"], strict=True):
        if "mesh" not in st:  # a planetary stage: its own meshes
            continue
        mesh = st["mesh"]
        if stage.mesh.stiffness_profile == "potential-energy":
            table = stage_pair_table(stage)
            mesh["pair_table"] = {
                "stiffness_N_per_m": table.stiffness_N_per_m.tolist(),
                "ratios": [
                    {"gear": gear, "tooth": tooth, "ratio": ratio.tolist()}
                    for (gear, tooth), ratio in sorted(table.ratios.items())
                ],
            }
    return data


def bearing_force_errors_percent(res, ref: dict) -> dict[str, float]:
    """Per bearing force signal (gear, direction): max |gearbody - reference| over the reference's peak."""
    out = {}
    for gear, forces in ref.get("bearing_force_N", {}).items():
        for d, axis in enumerate("xy"):
            peak = float(np.max(np.abs(forces[d])))
            if peak > 0:
                diff = np.abs(res[f"{gear}_bearing_force_{axis}_N"] - forces[d])
                out[f"{gear}_{axis}"] = float(diff.max() / peak * 100.0)
    return out


def compare_case(
    scene: str,
    case: Case,
    short: bool = False,
    tolerance_percent: float = 0.5,
    bearing_tolerance_percent: float = 1.0,
    use_cache: bool = False,
) -> CaseResult:
    """Run gearbody and the reference on one case; the error is the worst stage's max |dF|/F_rated,s,
    and in lateral scenes also the worst bearing force's max error over its peak."""
    from gearbody.engine import simulate

    from .reference import simulate_reference
    from .reference_lateral import simulate_reference_lateral

    scenario = case_scenario(scene, case, short)
    t0 = time.perf_counter()
    res = simulate(scenario)
    t1 = time.perf_counter()
    if scenario.has_planetary:
        from .reference.planetary_drive import simulate_reference_drive as reference
    else:
        reference = simulate_reference_lateral if scenario.is_lateral else simulate_reference
    ref, cached = cached_reference(reference, reference_input(scenario), res.time_s, use_cache)
    t2 = time.perf_counter()
    err = np.zeros_like(res.time_s)
    forces = []  # (gearbody, reference) mesh force signal names
    for k, st in enumerate(scenario.stages):
        prefix = "" if k == 0 else f"stage_{k + 1}_"
        if hasattr(st, "planets"):  # every planet's sun and ring mesh
            names = [
                f"{prefix}planet_{n + 1}_{m}_mesh_force_N" for n in range(st.planets) for m in ("sun", "ring")
            ]
        else:
            names = [prefix + "mesh_force_N"]
        for name in names:
            reference_force = ref[name] if scenario.has_planetary else ref["stage_mesh_force_N"][k]
            dF = np.abs(res[name] - reference_force)
            err = np.maximum(err, dF / scenario.stage_rated_force_N(k) * 100.0)
            forces.append(name)
    bearing = bearing_force_errors_percent(res, ref)
    bearing_err = max(bearing.values()) if bearing else float("nan")
    first = [n for n in forces if _stage_of(n) == 0]  # K_d and separation of the first stage's meshes
    kd_max = max(float(np.max(res[n] / scenario.stage_rated_force_N(0))) for n in first)
    sep = max(float(np.mean(res[n] <= 0.0)) for n in first)
    passed = bool(err.max() <= tolerance_percent) and not bearing_err > bearing_tolerance_percent
    note = ""
    if case.must_separate and kd_max <= 2.0:
        passed, note = False, "case did not separate (K_d <= 2)"
    return CaseResult(
        scene,
        case.name,
        float(err.max()),
        float(np.sqrt(np.mean(err**2))),
        bearing_err,
        kd_max,
        sep,
        t1 - t0,
        t2 - t1,
        passed,
        note,
        cached,
    )


def _stage_of(signal: str) -> int:
    """0-based stage of a mesh force signal name (stage_2_... is 1)."""
    return int(signal.split("_")[1]) - 1 if signal.startswith("stage_") else 0


def _case_job(scene: str, case_name: str, short: bool, tolerance_percent: float, use_cache: bool) -> dict:
    """One case as a job of gearbody's executors (a process pool): its CaseResult's fields."""
    case = next(c for c in cases(scene, short) if c.name == case_name)
    result = compare_case(scene, case, short, tolerance_percent, use_cache=use_cache)
    return {"ok": True, "result": result.__dict__}


def run_validation(
    scenes: list[str] | None = None,
    short: bool = False,
    tolerance_percent: float = 0.5,
    echo=print,
    workers: int | None = 1,
    use_cache: bool = False,
) -> bool:
    """Run every case of the given scenes, print a table (rows in case order), return True when all pass.
    ``workers``: cases run on that many local processes at once (None: one per CPU; 1: in this process,
    one after the other). Each case's wall times are its own process's. ``use_cache``: take the reference's
    output from :func:`cached_reference`'s cache where the reference and its inputs are unchanged."""
    from gearbody.studies.executors import run_jobs

    scenes = list(scenes or VALIDATED_SCENES)
    todo = [(scene, case) for scene in scenes for case in cases(scene, short)]  # a bad scene: before output
    echo(
        "gearbody vs independent reference (scipy solve_ivp): max |dF|/F_rated, "
        f"tolerance {tolerance_percent} %; bearing forces: max |dF_b| / peak |F_b|, tolerance 1 %"
        + (" [short runs]" if short else "")
        + (
            "; 'cached': the reference's output of an unchanged reference and case, from the cache"
            if use_cache
            else ""
        )
    )
    echo(
        f"{'scene':<22}{'case':<12}{'max dF %':>10}{'rms dF %':>10}{'bearing %':>11}{'K_d max':>9}{'sep.':>7}"
        f"{'gearbody s':>12}{'reference s':>13}  result"
    )
    results = []
    jobs = [
        (str(i), (scene, case.name, short, tolerance_percent, use_cache))
        for i, (scene, case) in enumerate(todo)
    ]
    done: dict[int, CaseResult] = {}
    for jid, outcome in run_jobs(_case_job, jobs, workers=workers, name="gearbody-validate"):
        if not outcome["ok"]:
            scene, case = todo[int(jid)]
            raise RuntimeError(f"validation case {scene} {case.name} failed: {outcome['message']}")
        done[int(jid)] = CaseResult(**outcome["result"])
        while len(results) in done:  # print the rows in case order as they become ready
            _echo_row(echo, done[len(results)])
            results.append(done[len(results)])
    ok = all(r.passed for r in results)
    echo("all cases pass" if ok else "SOME CASES FAIL")
    return ok


def _echo_row(echo, r: CaseResult) -> None:
    bearing = "-" if np.isnan(r.bearing_error_percent) else f"{r.bearing_error_percent:.4f}"
    echo(
        f"{r.scene:<22}{r.case:<12}{r.max_error_percent:>10.4f}{r.rms_error_percent:>10.4f}"
        f"{bearing:>11}{r.kd_max:>9.3f}"
        f"{r.separated_fraction:>7.2f}{r.wall_gearbody_s:>12.2f}"
        f"{'cached' if r.reference_cached else f'{r.wall_reference_s:.2f}':>13}  "
        f"{'PASS' if r.passed else 'FAIL'} {r.note}"
    )


CACHE_ENV = "GEARBODY_REFERENCE_CACHE"
"""Folder of the reference's cached outputs (default ~/.cache/gearbody/reference)."""


def cache_folder() -> Path:
    """Where :func:`cached_reference` keeps the reference's outputs."""
    default = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "gearbody" / "reference"
    return Path(os.environ.get(CACHE_ENV, default))


def reference_digest() -> str:
    """SHA-256 of the reference's own source (every module of validation/reference and
    validation/reference_lateral.py) and of the numpy, scipy and Python versions it runs on."""
    here = Path(__file__).resolve().parent
    h = hashlib.sha256()
    for path in sorted([*(here / "reference").glob("*.py"), here / "reference_lateral.py"]):
        h.update(path.name.encode())
        h.update(path.read_bytes())
    import scipy

    h.update(f"numpy {np.__version__} scipy {scipy.__version__} python {sys.version}".encode())
    return h.hexdigest()


def cached_reference(reference, data: dict, t_eval: np.ndarray, use_cache: bool = True) -> tuple[dict, bool]:
    """(``reference(data, t_eval=t_eval)``, whether it came from the cache). The output is kept in
    :func:`cache_folder` under a key of the reference's source and versions (:func:`reference_digest`),
    its function, ``data`` and ``t_eval``: a reference or an input that changed is run again; a cache
    that cannot be read or written is passed over."""
    if not use_cache:
        return reference(data, t_eval=t_eval), False
    h = hashlib.sha256(reference_digest().encode())
    h.update(f"{reference.__module__}.{reference.__qualname__}".encode())
    h.update(json.dumps(data, sort_keys=True, default=_jsonable).encode())
    h.update(np.ascontiguousarray(t_eval, dtype=np.float64).tobytes())
    path = cache_folder() / f"{h.hexdigest()}.npz"
    try:
        with np.load(path, allow_pickle=False) as stored:
            return {k: stored[k] for k in stored.files}, True
    except (OSError, ValueError, KeyError, EOFError):
        pass
    out = reference(data, t_eval=t_eval)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp.npz")
        np.savez(tmp, **{k: np.asarray(v) for k, v in out.items()})
        os.replace(tmp, path)
    except (OSError, ValueError, TypeError):
        pass
    return out, False


def _jsonable(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{type(value).__name__} in the reference's input")
