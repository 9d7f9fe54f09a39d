"""The compiled path (gearbody.engine.compiled_path): Exudyn calls the force laws' kernels from C++ with
no Python call per evaluation, the results are bit-identical to the Python path on every shipped scene,
and where it cannot work gearbody says so once and runs on the Python path."""

from __future__ import annotations

import os
import signal
import threading
import time
import warnings

import numpy as np
import pytest

from gearbody.engine import compiled_path
from gearbody.engine.build import build
from gearbody.engine.simulate import build_scenario, simulate
from gearbody.errors import InputError, SimulationError
from gearbody.model import load_scenario
from gearbody.model.scenes import list_scenes

WORKS, WHY = compiled_path.compiled_path_status()
needs_compiled = pytest.mark.skipif(not WORKS, reason=f"no compiled path here: {WHY}")

# Short runs: enough steps through start-up transients, tooth changes and contacts for any difference in
# a force to show in the states; the planetary scenes are the slow ones on the Python path.
T_END_S = {"planetary": 0.01, "planetary-conveyor": 0.01}


def _pair(scene: str):
    t_end = T_END_S.get(scene, 0.03)
    runs = {}
    for path in ("python", "compiled"):
        sc = load_scenario(scene, [f"operation.t_end_s={t_end}", f'solver.force_path="{path}"'])
        runs[path] = simulate(sc)
    return runs["python"], runs["compiled"]


@needs_compiled
@pytest.mark.slow
@pytest.mark.parametrize("scene", list_scenes())
def test_every_shipped_scene_is_bit_identical_on_both_paths(scene):
    python, compiled = _pair(scene)
    assert python.meta["solver_statistics"]["force_path"] == "python"
    assert compiled.meta["solver_statistics"]["force_path"] == "compiled"
    assert list(python.signals) == list(compiled.signals)
    assert np.array_equal(python.time_s, compiled.time_s)
    for name in python.signals:
        assert np.array_equal(python[name], compiled[name], equal_nan=True), name
    assert python.meta["solver_statistics"]["steps"] == compiled.meta["solver_statistics"]["steps"]


@needs_compiled
def test_the_one_stage_drive_is_bit_identical_on_both_paths():
    python, compiled = _pair("one-stage")
    for name in python.signals:
        assert np.array_equal(python[name], compiled[name], equal_nan=True), name


@needs_compiled
def test_exudyn_calls_the_entries_from_cpp_and_never_through_python():
    native = compiled_path._native()[0]
    sc = load_scenario("lateral-8dof-ball", ["operation.t_end_s=0.002"])
    built, _, _ = build_scenario(sc)
    items = [f for f in built.user_functions if isinstance(f, compiled_path.CompiledItem)]
    assert len(items) == len(built.user_functions) == 1  # mesh, motor, load, two bearing laws: one item
    assert len(items[0].kernels) == 5
    before = native.python_calls()
    import exudyn as exu

    from gearbody.engine.simulate import solver_settings

    exu.SolveDynamic(built.mbs, solver_settings(sc), solverType=exu.DynamicSolverType.DOPRI5)
    assert all(item.calls() > 100 for item in items)
    assert native.python_calls() == before


def test_force_path_python_builds_python_functions_only():
    sc = load_scenario("one-stage", ['solver.force_path="python"'])
    built, _, _ = build_scenario(sc)
    assert built.force_path == "python"
    assert all(callable(f) for f in built.user_functions)


def test_force_path_is_checked_on_load():
    with pytest.raises(InputError, match=r"solver.force_path.*'fast'.*auto.*compiled.*python"):
        load_scenario("one-stage", ['solver.force_path="fast"'])


@pytest.fixture
def no_extension(monkeypatch):
    """As if the extension could not be built (no compiler at install)."""
    monkeypatch.setattr(compiled_path, "_native", lambda: (None, "the extension is not built (test)"))
    monkeypatch.setattr(compiled_path, "_SAID", set())
    compiled_path.compiled_path_status.cache_clear()
    yield
    compiled_path.compiled_path_status.cache_clear()


def test_without_the_extension_auto_runs_on_python_and_says_so_once(no_extension):
    sc = load_scenario("one-stage", ["operation.t_end_s=0.01"])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r1 = simulate(sc)
        r2 = simulate(sc)
    said = [w for w in caught if issubclass(w.category, compiled_path.PerformanceWarning)]
    assert len(said) == 1 and "through Python" in str(said[0].message) and "not built" in str(said[0].message)
    assert (
        r1.meta["solver_statistics"]["force_path"] == r2.meta["solver_statistics"]["force_path"] == "python"
    )


def test_without_the_extension_compiled_is_refused_with_the_reason(no_extension):
    sc = load_scenario("one-stage", ['solver.force_path="compiled"'])
    with pytest.raises(InputError, match=r"force_path = 'compiled' is not available here: .*not built"):
        simulate(sc)


def test_gearbody_info_names_the_active_path(capsys):
    from gearbody.cli import main

    assert main(["info"]) == 0
    out = capsys.readouterr().out
    assert "exudyn" in out and "numba" in out
    assert ("force path compiled" in out) == WORKS
    if not WORKS:
        assert WHY in out


@needs_compiled
def test_an_item_without_a_kernel_runs_through_python_beside_compiled_ones(monkeypatch):
    """A bearing law without a compiled form (a user's pure-Python law) keeps the Python path for its
    item; the rest of the drive stays compiled (said once). The forces are added in another order than
    on the Python path (the compiled item first, then the Python one): equal within round-off."""
    from gearbody.physics.bearings import HertzianBearing

    monkeypatch.setattr(compiled_path, "_SAID", set())
    monkeypatch.delattr(HertzianBearing, "law_row")
    sc = load_scenario("lateral-8dof-ball", ["operation.t_end_s=0.005"])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mixed = simulate(sc)
    assert mixed.meta["solver_statistics"]["force_path"] == "mixed"
    assert any("HertzianBearing has no law_row()" in str(w.message) for w in caught)
    monkeypatch.undo()
    python = simulate(
        load_scenario("lateral-8dof-ball", ["operation.t_end_s=0.005", 'solver.force_path="python"'])
    )
    F = load_scenario("lateral-8dof-ball").rated_mesh_force_N
    assert np.max(np.abs(python["mesh_force_N"] - mixed["mesh_force_N"])) < 1e-6 * F
    assert np.array_equal(python.time_s, mixed.time_s)


@needs_compiled
def test_the_wall_time_limit_stops_a_compiled_run():
    sc = load_scenario("one-stage", ["operation.t_end_s=2.0", "solver.wall_time_limit_s=0.2"])
    t0 = time.perf_counter()
    with pytest.raises(SimulationError, match=r"stopped at t = .* of 2 s: the wall-time limit"):
        simulate(sc)
    assert time.perf_counter() - t0 < 5.0


@needs_compiled
@pytest.mark.skipif(threading.current_thread() is not threading.main_thread(), reason="signals: main thread")
def test_ctrl_c_stops_a_compiled_run_within_a_second():
    sc = load_scenario("one-stage", ["operation.t_end_s=5.0"])
    built, _, _ = build_scenario(sc)  # compile and build first: the timer measures the solve only
    assert built.force_path == "compiled"
    sent = []

    def interrupt():
        sent.append(time.perf_counter())
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(1.5, interrupt)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            simulate(sc)
        stopped = time.perf_counter()
    finally:
        timer.cancel()
    assert sent and stopped - sent[0] < 1.0


@needs_compiled
def test_a_diverging_compiled_run_names_the_time_and_a_hint():
    sc = load_scenario("one-stage", ["operation.t_end_s=0.05"])
    from gearbody.engine import user_functions

    def check(self, t, speed):  # as if the motor speed had run away at the first check
        self.failure = f"state diverged at t = {t:.6g} s (motor speed nan rad/s). Hint: check stiffness"
        raise user_functions.StallError(self.failure)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(user_functions.StallWatchdog, "_check", check)
        with pytest.raises(SimulationError, match=r"^state diverged at t = \d.*Hint"):
            simulate(sc)


@needs_compiled
def test_a_slot_is_released_with_its_system():
    native = compiled_path._native()[0]
    sc = load_scenario("one-stage")
    used = native.used()
    built, _, _ = build_scenario(sc)
    assert native.used() == used + 1
    del built
    import gc

    gc.collect()
    assert native.used() == used
    layout_sc = load_scenario("two-wheel")
    from gearbody.assembly.layouts import drive_system

    layout, q0, v0 = drive_system(layout_sc)
    assert build(layout, q0, v0, force_path="compiled").force_path == "compiled"


def test_the_command_line_says_it_once_in_one_line(no_extension, tmp_path, capsys):
    from gearbody.cli import main

    out = tmp_path / "run"
    assert main(["run", "two-wheel", "--t-end", "0.01", "--out", str(out), "--quiet", "--no-plots"]) == 0
    err = capsys.readouterr().err
    notes = [line for line in err.splitlines() if "through Python" in line]
    assert len(notes) == 1 and notes[0].startswith("gearbody: note: ") and "build.py" not in err


@needs_compiled
def test_a_checkout_first_on_the_path_uses_the_installed_extension(tmp_path):
    """The tests' command-line subprocesses put the checkout first on PYTHONPATH: with a plain install its
    gearbody has no built extension, and loads the installed one (with an editable install it is there)."""
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    code = "from gearbody.engine.compiled_path import compiled_path_status as s; print(s())"
    env = {**os.environ, "PYTHONPATH": str(root)}
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True)
    assert out.stdout.strip() == "(True, '')", out.stdout + out.stderr
