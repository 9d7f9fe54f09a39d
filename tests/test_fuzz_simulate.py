"""Extreme-but-valid scenarios simulated (issues 17, 26): hypothesis draws in-range values of the
stiffness, inertia, damping, error, friction, backlash, speed and load keys of four scenes, and (issue 26)
of the planetary stages (planet counts meeting the assembly condition, tooth counts up to the bound,
pin errors up to a tenth of the module, member bearings, linear or Hertzian, planet bearing defects)
and of the lateral scenes' bearings (stiffness, damping, clearance, exponent, housing mass); each is
simulated for 0.01 s in a worker process capped at WORKER_MEMORY_BYTES of address space. Every example
must end within CASE_TIMEOUT_S in a result or a documented error (InputError, exit 2, or
SimulationError, exit 3) whose message is gearbody's own: no Exudyn banner, no traceback, no Python
repr. The outcome counts are printed at the end of the run; a failure names the ``gearbody run``
command line that reproduces it. Examples: EXAMPLES and PLANETARY_EXAMPLES times GEARBODY_FUZZ_SCALE
(tests/fuzzing.py: derandomized, no database, no local constants)."""

from __future__ import annotations

import collections
import json
import os
import re
import resource
import select
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

hypothesis = pytest.importorskip("hypothesis")
from fuzzing import Report, fuzz_settings  # noqa: E402
from hypothesis import given  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

pytestmark = pytest.mark.slow

EXAMPLES = 300
PLANETARY_EXAMPLES = 12
CASE_TIMEOUT_S = 60.0
WORKER_MEMORY_BYTES = 3 * 2**30
T_END_S = 0.01
FOREIGN_TEXT = ("DYNAMIC SOLVER FAILED", "check your Python", "USER FUNCTION", "Traceback")
PYTHON_REPR = re.compile(r"\bself\.\w+|\w+=\d")  # 'self.watch_node=0', an f-string's {x=}

WORKER = r"""
import json, os, sys, time
out = os.fdopen(os.dup(1), "w")
os.dup2(2, 1)  # anything printed by the run (C++ included) goes to stderr, checked separately
from gearbody.engine import simulate
from gearbody.errors import InputError, SimulationError
from gearbody.model import load_scenario
out.write("ready\n"); out.flush()
for line in sys.stdin:
    case = json.loads(line)
    t0 = time.perf_counter()
    try:
        r = simulate(load_scenario(case["scene"], case["overrides"]))
        answer = {"outcome": "result", "samples": int(r.time_s.size)}
    except InputError as exc:
        answer = {"outcome": "InputError", "message": str(exc)}
    except SimulationError as exc:
        answer = {"outcome": "SimulationError", "message": str(exc)}
    except BaseException as exc:  # noqa: BLE001 - anything else is a finding
        import traceback
        answer = {"outcome": "crash", "message": traceback.format_exc()}
    answer["wall_s"] = time.perf_counter() - t0
    out.write(json.dumps(answer) + "\n"); out.flush()
"""


def _cap_memory() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (WORKER_MEMORY_BYTES, WORKER_MEMORY_BYTES))


class Worker:
    """One memory-capped Python process that simulates cases sent to it (restarted after a kill)."""

    def __init__(self, stderr_path: Path) -> None:
        self.stderr_path = stderr_path
        self.proc: subprocess.Popen | None = None

    def _start(self) -> None:
        env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
        self.proc = subprocess.Popen(
            [sys.executable, "-c", WORKER],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=open(self.stderr_path, "a"),  # noqa: SIM115 - lives as long as the worker
            text=True,
            env=env,
            preexec_fn=_cap_memory,
        )
        assert self._read(120.0) == "ready"

    def _read(self, timeout_s: float) -> str | None:
        ready, _, _ = select.select([self.proc.stdout], [], [], timeout_s)
        return self.proc.stdout.readline().strip() if ready else None

    def run(self, scene: str, overrides: list[str]) -> dict:
        if self.proc is None or self.proc.poll() is not None:
            self._start()
        self.proc.stdin.write(json.dumps({"scene": scene, "overrides": overrides}) + "\n")
        self.proc.stdin.flush()
        line = self._read(CASE_TIMEOUT_S)
        if not line:  # no answer in time, or the process died (killed at its memory cap, crashed)
            self.stop()
            return {"outcome": "timeout or died", "message": f"no answer within {CASE_TIMEOUT_S} s"}
        return json.loads(line)

    def stop(self) -> None:
        if self.proc is not None:
            self.proc.kill()
            self.proc.wait()
            self.proc = None


SCENES = ("one-stage", "lateral-8dof", "two-wheel", "muller")
TRAIN_SCENES = ("one-stage", "lateral-8dof")


def _log_uniform(lo: float, hi: float):
    return st.floats(min_value=lo, max_value=hi).map(lambda e: 10.0**e)


@st.composite
def cases(draw) -> tuple[str, list[str]]:
    """A scene and 1-6 in-range overrides of its physical keys, run for T_END_S."""
    scene = draw(st.sampled_from(SCENES))
    factor = _log_uniform(-6, 6)  # on the scene's value: 1e-6 .. 1e6 times
    keys = {
        "design.mesh.stiffness_single_N_per_m": _log_uniform(5, 12),
        "design.mesh.stiffness_double_N_per_m": _log_uniform(5, 12),
        "design.mesh.damping_Ns_per_m": st.one_of(st.just(0.0), _log_uniform(0, 7)),
        "design.mesh.backlash_um": st.one_of(st.just(0.0), st.floats(0, 2000)),
        "design.mesh.transition_width": st.one_of(st.just(0.0), _log_uniform(-6, -1)),
        "production.error_mode.e_um": st.floats(-1000, 1000),
        "production.error_mode.r": st.floats(0, 1),
        "condition.friction_coefficient": st.floats(0, 0.99),
        "design.motor.synchronous_speed_rad_s": _log_uniform(-1, 3.5),
        "design.machine.rated_torque_Nm": _log_uniform(-2, 6),
        "design.pinion.inertia_kg_m2": factor,
        "design.wheel.inertia_kg_m2": factor,
        "design.motor.inertia_kg_m2": factor,
        "design.machine.inertia_kg_m2": factor,
        "operation.speed_profile": st.floats(0, 3),
        "operation.load_profile": st.floats(0, 5),
        "operation.initial_state": st.sampled_from(["rest", "steady"]),
    }
    if scene in TRAIN_SCENES:
        keys["design.coupling.stiffness_Nm_per_rad"] = _log_uniform(2, 9)
        keys["design.output_shaft.stiffness_Nm_per_rad"] = _log_uniform(2, 10)
    if scene == "lateral-8dof":
        keys["design.pinion.mass_kg"] = _log_uniform(-3, 4)
        keys["design.wheel.mass_kg"] = _log_uniform(-3, 4)
    chosen = draw(st.lists(st.sampled_from(sorted(keys)), min_size=1, max_size=6, unique=True))
    from gearbody.model import load_scenario

    base = load_scenario(scene)
    overrides = [f"operation.t_end_s={T_END_S}"]
    for key in chosen:
        value = draw(keys[key])
        if key.endswith("_profile"):
            overrides.append(f"{key}={{time_s = [0.0], fraction = [{value!r}]}}")
        elif key == "operation.initial_state":
            overrides.append(f'{key}="{value}"')
        elif key.endswith("inertia_kg_m2"):
            where = {"design.pinion": base.stages[0].pinion, "design.wheel": base.stages[0].wheel}
            holder = where.get(key.rsplit(".", 1)[0]) or getattr(base.design, key.split(".")[1])
            overrides.append(f"{key}={holder.inertia_kg_m2 * value!r}")
        else:
            overrides.append(f"{key}={value!r}")
    return scene, overrides


@pytest.fixture(scope="module")
def worker(request):
    with tempfile.TemporaryDirectory() as tmp:
        w = Worker(Path(tmp) / "worker-stderr.txt")
        w.outcomes = collections.Counter()
        w.errors = []
        w.walls = []
        w.report = Report("simulate")
        yield w
        w.stop()
        w.report.write()
        printed = w.stderr_path.read_text() if w.stderr_path.exists() else ""
        reporter = request.config.pluginmanager.get_plugin("terminalreporter")
        capture = request.config.pluginmanager.get_plugin("capturemanager")
        if reporter is not None and capture is not None:
            walls = sorted(w.walls) or [0.0]
            with capture.global_and_fixture_disabled():
                reporter.write_line(
                    f"\nfuzz (simulate {T_END_S} s): {dict(w.outcomes)}; wall per case: median "
                    f"{walls[len(walls) // 2]:.2f} s, max {walls[-1]:.2f} s"
                )
                if request.config.get_verbosity() > 0:  # -v: every error message, for reading
                    for line in sorted(w.errors):
                        reporter.write_line(f"  {line[:400]}")
        for text in FOREIGN_TEXT[:3]:
            assert text not in printed, f"a run printed {text!r}"


def reproduce(scene: str, overrides: list[str]) -> str:
    """The command line that runs the case as the fuzzer did (``--no-plots``: 0.01 s has too few samples
    for the plots)."""
    sets = " ".join(f"--set {shlex.quote(o)}" for o in overrides)
    return f"gearbody run {scene} {sets} --no-plots"


def check_case(worker, scene: str, overrides: list[str], kind: str) -> None:
    answer = worker.run(scene, overrides)
    worker.outcomes[answer["outcome"]] += 1
    worker.report.add(kind, answer["outcome"])
    worker.walls.append(answer.get("wall_s", CASE_TIMEOUT_S))
    where = reproduce(scene, overrides)
    if answer["outcome"] != "result":
        worker.errors.append(f"{answer['outcome']}: {answer.get('message', '')[:150]} <- {where}")
    assert answer["outcome"] in ("result", "InputError", "SimulationError"), f"{where}: {answer}"
    if answer["outcome"] == "result":
        assert answer["samples"] == round(T_END_S * 20000) + 1, where
    else:
        message = answer["message"]
        assert message and "\n" not in message.strip(), f"{where}: {message}"
        assert not any(text in message for text in FOREIGN_TEXT), f"{where}: {message}"
        typed = re.sub(r"--(set|vary|random) \S+", "", message)  # the override quoted as the user typed it
        assert not PYTHON_REPR.search(typed), f"{where}: {message}"
    assert answer["wall_s"] < CASE_TIMEOUT_S, where


# No shrinking: each shrink step is a simulation, and hypothesis shrinks for up to 5 min; the first
# failing case is reported as drawn (the command line that reproduces it is in the assertion message).
@fuzz_settings(EXAMPLES, shrink=False)
@given(case=cases())
def test_extreme_valid_scenarios_end_in_a_result_or_a_documented_error(worker, case):
    scene, overrides = case
    check_case(worker, scene, overrides, "parallel")


# -- planetary stages and bearings: every draw within the documented ranges -----------------------------

PLANETARY_SCENES = ("planetary", "planetary-conveyor")
BEARING_SCENES = ("lateral-8dof", "lateral-6dof", "lateral-8dof-ball")


def _planetary_stage(scene: str) -> tuple[str, float]:
    """(key prefix, module in mm) of the scene's planetary stage."""
    from gearbody.model import load_scenario

    for k, stage in enumerate(load_scenario(scene).stages, start=1):
        if getattr(stage, "type", "") == "planetary":
            return f"design.stages.{k}", stage.module_mm
    raise AssertionError(scene)


def _hertzian(draw) -> str:
    k = draw(_log_uniform(8, 12))
    c = draw(st.one_of(st.just(0.0), _log_uniform(-7, -4)))
    n = draw(st.sampled_from([1.0, 10 / 9, 1.5, 2.0]) | st.floats(1.0, 2.0))
    d = draw(st.one_of(st.just(0.0), _log_uniform(0, 5)))
    return (
        f"{{kind='hertzian',parameters={{contact_stiffness_N_per_m_n={k!r},radial_clearance_m={c!r},"
        f"exponent={n!r},damping_Ns_per_m={d!r}}}}}"
    )


@st.composite
def planetary_cases(draw) -> tuple[str, list[str]]:
    """A planetary scene with in-range extremes: N planets meeting the assembly condition (z_s + z_r)/N
    whole with z_r = z_s + 2 z_p <= 2000, pin errors up to a tenth of the module, member bearings
    (linear, or a Hertzian law), planet bearing defects, meshes, friction."""
    scene = draw(st.sampled_from(PLANETARY_SCENES))
    stage, module_mm = _planetary_stage(scene)
    overrides = [f"operation.t_end_s={T_END_S}"]
    choices = ("teeth", "pins", "bearings", "laws", "defects", "meshes", "friction")
    chosen = draw(st.lists(st.sampled_from(choices), min_size=1, max_size=4, unique=True))
    planets = 3
    if "teeth" in chosen:
        planets = draw(st.integers(1, 12))
        z_p = draw(st.one_of(st.integers(6, 60), st.integers(6, 660)))
        z_s = draw(st.one_of(st.integers(6, 80), st.integers(6, 2000 - 2 * z_p - planets)))
        while (2 * z_s + 2 * z_p) % planets:  # the assembly condition: (z_s + z_r) / N whole
            z_s += 1
        z_r = z_s + 2 * z_p
        overrides += [f"{stage}.planets={planets}", f"{stage}.sun.teeth={z_s}", f"{stage}.planet.teeth={z_p}"]
        overrides.append(f"{stage}.ring.teeth={z_r}")
    if "pins" in chosen:
        bound = 100.0 * module_mm  # a tenth of the module, in um
        error = st.sampled_from([bound, -bound, 0.0]) | st.floats(-bound, bound)
        errors = draw(st.lists(error, min_size=planets, max_size=planets))
        overrides.append(f"{stage}.planet_position_errors_um=[{', '.join(repr(e) for e in errors)}]")
    members = ("sun", "planet", "ring", "carrier")
    if "bearings" in chosen:
        for member in draw(st.lists(st.sampled_from(members), min_size=1, max_size=4, unique=True)):
            overrides.append(f"{stage}.{member}.bearing_stiffness_N_per_m={draw(_log_uniform(5, 11))!r}")
            damping = draw(st.one_of(st.just(0.0), _log_uniform(0, 5)))
            overrides.append(f"{stage}.{member}.bearing_damping_Ns_per_m={damping!r}")
    if "laws" in chosen:  # a law replaces the member's linear bearing
        for member in draw(st.lists(st.sampled_from(members), min_size=1, max_size=2, unique=True)):
            overrides.append(f"{stage}.{member}.bearing_stiffness_N_per_m=0.0")
            overrides.append(f"{stage}.{member}.bearing={_hertzian(draw)}")
    if "defects" in chosen:
        which = draw(st.lists(st.integers(1, planets), min_size=1, max_size=planets, unique=True))
        factors = [draw(st.sampled_from([1e-6, 0.5, 1.0]) | st.floats(1e-6, 1.0)) for _ in which]
        entries = ", ".join(
            f"{{planet={p}, stiffness_factor={f!r}}}" for p, f in zip(which, factors, strict=True)
        )
        overrides.append(f"{stage}.planet_bearing_defects=[{entries}]")
    if "meshes" in chosen:
        for mesh in draw(
            st.lists(st.sampled_from(["sun_mesh", "ring_mesh"]), min_size=1, max_size=2, unique=True)
        ):
            overrides.append(
                f"{stage}.{mesh}.damping_Ns_per_m={draw(st.one_of(st.just(0.0), _log_uniform(0, 6)))!r}"
            )
            overrides.append(f"{stage}.{mesh}.backlash_um={draw(st.floats(0, 500))!r}")
    if "friction" in chosen:
        overrides.append(f"condition.friction_coefficient={draw(st.floats(0, 0.3))!r}")
    overrides.append(f'operation.initial_state="{draw(st.sampled_from(["steady", "steady", "rest"]))}"')
    return scene, overrides


@st.composite
def bearing_cases(draw) -> tuple[str, list[str]]:
    """A lateral scene with in-range bearing extremes: linear stiffness and damping per direction, or a
    Hertzian law (stiffness, clearance, exponent in [1, 2], damping), and the housing mass."""
    scene = draw(st.sampled_from(BEARING_SCENES))
    overrides = [f"operation.t_end_s={T_END_S}"]
    for gear in draw(st.lists(st.sampled_from(["pinion", "wheel"]), min_size=1, max_size=2, unique=True)):
        key = f"design.{gear}.bearing"
        if draw(st.booleans()):
            overrides.append(f"{key}={_hertzian(draw)}")
        else:
            kx, ky = draw(_log_uniform(5, 12)), draw(_log_uniform(5, 12))
            cx, cy = (draw(st.one_of(st.just(0.0), _log_uniform(0, 6))) for _ in range(2))
            overrides.append(
                f"{key}={{kind='linear',parameters={{stiffness_x_N_per_m={kx!r},stiffness_y_N_per_m={ky!r},"
                f"damping_x_Ns_per_m={cx!r},damping_y_Ns_per_m={cy!r}}}}}"
            )
        if draw(st.booleans()):
            overrides.append(f"{key}.housing_mass_kg={draw(_log_uniform(-3, 4))!r}")
    overrides.append(f'operation.initial_state="{draw(st.sampled_from(["steady", "rest"]))}"')
    return scene, overrides


@fuzz_settings(PLANETARY_EXAMPLES, shrink=False)
@given(case=st.one_of(planetary_cases(), bearing_cases()))
def test_in_range_planetary_and_bearing_extremes_end_in_a_result_or_a_documented_error(worker, case):
    scene, overrides = case
    check_case(worker, scene, overrides, "planetary" if scene in PLANETARY_SCENES else "bearings")
