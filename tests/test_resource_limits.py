"""Resources bounded (issue 17): keys that set a grid, a step, a horizon or a count are refused before
anything runs when the run would not fit its memory budget, a mode far above what a run resolves is
refused relative to the model, a run stops cleanly at its wall-time or memory budget, and a numerical
failure reads as gearbody's own message (no Exudyn banner, no Python repr)."""

import math
import re
import time

import pytest

from gearbody.cli import main
from gearbody.engine import simulate
from gearbody.errors import InputError, SimulationError
from gearbody.model import ScenarioError, budget, load_scenario
from gearbody.model.scenes import list_scenes


def refused(scene: str, *overrides: str) -> str:
    t0 = time.perf_counter()
    with pytest.raises(ScenarioError) as info:
        load_scenario(scene, list(overrides))
    assert time.perf_counter() - t0 < 2.0  # refused on load, not after allocating
    return str(info.value)


# -- estimated before anything runs --------------------------------------------------------------


@pytest.mark.parametrize("width", ["1e-5", "1e-12", "1e-300"])
def test_a_tiny_transition_width_is_refused_on_load_by_its_fine_grid(width):
    """On main 1e-5 ran the whole simulation, then died allocating 564 MiB (1e-12: 46 TiB)."""
    msg = refused("one-stage", f"design.mesh.transition_width={width}")
    assert f"design.mesh.transition_width = {float(width):g}" in msg
    assert "solver.memory_limit_MiB = 2048 (default)" in msg and "fine points per output sample" in msg
    assert len(msg) < 600  # no 300-digit oversampling factor


def test_the_transition_width_is_named_per_stage():
    msg = refused("two-stage", "design.stages.2.mesh.transition_width=1e-6")
    assert "design.stages.2.mesh.transition_width = 1e-06" in msg


def test_an_output_rate_beyond_the_budget_is_refused_with_its_estimate():
    """On main solver.output_rate_hz=1e10 was killed by the system at 24 GB with no message."""
    msg = refused("one-stage", "solver.output_rate_hz=1e10")
    assert "solver.output_rate_hz = 1e+10 with operation.t_end_s = 2" in msg
    assert "2e+10 output samples x 24 signals" in msg and "2048" in msg


def test_a_huge_end_time_is_refused_on_the_command_line_with_exit_2(tmp_path, capsys):
    """On main --t-end 1e9 ended in 'state diverged at t = -93.1279 s (speed of self.watch_node=0 ...)'."""
    assert main(["run", "one-stage", "--t-end", "1e9", "--quiet", "--no-plots", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "operation.t_end_s = 1e+09" in err and "memory budget" in err
    assert "self." not in err and "diverged" not in err


def test_a_tiny_largest_step_is_refused_by_its_stored_steps():
    """solver.max_step_s = 1e-300 stalled on main with a hint at the tolerances."""
    msg = refused("one-stage", "solver.max_step_s=1e-300")
    assert msg.count("solver.max_step_s = 1e-300") == 1 and "solver steps" in msg
    assert "tolerance" not in msg


def test_the_memory_budget_is_configurable_both_ways():
    assert load_scenario("one-stage", ["solver.memory_limit_MiB=64"]).solver.memory_limit_MiB == 64
    msg = refused("one-stage", "solver.memory_limit_MiB=0.5")
    assert "solver.memory_limit_MiB = 0.5" in msg and "(default)" not in msg
    short = ["operation.t_end_s=0.01", "design.mesh.transition_width=1e-5"]
    sc = load_scenario("one-stage", short)  # 0.01 s at width 1e-5: ~0.4 GB, inside the default budget
    assert budget.estimate(sc).total_bytes < 2**31
    assert "memory budget" in refused("one-stage", *short, "solver.memory_limit_MiB=100")
    assert "must be > 0" in refused("one-stage", "solver.memory_limit_MiB=0")


def test_every_scene_fits_the_default_budget_with_a_margin():
    for name in list_scenes():
        est = budget.estimate(load_scenario(name))
        assert est.total_bytes < 0.25 * budget.DEFAULT_MEMORY_LIMIT_MIB * 2**20, name


@pytest.mark.parametrize("scene", ["one-stage", "lateral-6dof", "two-wheel", "muller"])
def test_the_signal_estimate_counts_what_a_run_writes(scene):
    sc = load_scenario(scene, ["operation.t_end_s=0.005"])
    r = simulate(sc)
    assert budget.signal_count(sc) == len(r.signals)
    assert budget.estimate(sc).samples == r.time_s.size


def test_the_oversampling_rule_is_the_one_collect_uses():
    """The estimate and the run share one rule: 3 fine points per transition at the mesh frequency."""
    assert budget.oversampling(500.0, 0.0, 20000.0) == budget.OVERSAMPLING
    assert budget.oversampling(500.0, 1e-3, 20000.0) == math.ceil(3.0 * 500.0 / (1e-3 * 20000.0))


def test_a_run_faster_than_estimated_is_stopped_before_its_fine_grid(monkeypatch, steady_scenario):
    """The pre-run estimate takes the expected speeds; collect checks the measured ones."""
    monkeypatch.setattr(budget, "_pinion_speeds_rad_s", lambda scenario: [1e-3] * len(scenario.stages))
    overrides = ["design.mesh.transition_width=1e-4", "solver.memory_limit_MiB=20"]
    sc = steady_scenario("one-stage", *overrides, t_end=0.01)  # accepted: the estimate expects no speed
    with pytest.raises(SimulationError, match=r"design.stages.1.mesh.transition_width.*memory_limit_MiB"):
        simulate(sc)


# -- relative to the model -----------------------------------------------------------------------


def test_a_tiny_inertia_is_refused_relative_to_the_model_before_building():
    """On main design.machine.inertia_kg_m2=1e-12 had not finished 0.01 s simulated after 90 s."""
    sc = load_scenario("one-stage", ["design.machine.inertia_kg_m2=1e-12", "operation.t_end_s=0.01"])
    t0 = time.perf_counter()
    with pytest.raises(InputError) as info:
        simulate(sc)
    assert time.perf_counter() - t0 < 2.0
    msg = str(info.value)
    assert "design.machine.inertia_kg_m2 = 1e-12 kg m^2" in msg and "natural frequency" in msg
    assert "max(solver.output_rate_hz, 1 / solver.max_step_s)" in msg
    assert "other coordinates reach 2.7e+03 Hz" in msg  # relative to the rest of the model


def test_a_light_motor_on_a_steep_slip_characteristic_is_refused_by_its_damping_rate():
    """The simulation fuzzer's slow case: 1.3e-5 kg m^2 of motor at w_s = 1 rad/s has a slip slope of
    2 M_b / (s_b w_s) = 4.87e4 N m s/rad, a real root near -3.7e9 1/s; on main the run took 243 s to stop
    at its memory budget after 6.6 ms simulated."""
    from gearbody.physics import viscous_equivalent_Nms

    overrides = [
        "operation.t_end_s=0.01",
        "design.mesh.stiffness_single_N_per_m=1e5",
        "design.motor.inertia_kg_m2=1.3080523287051801e-05",
        "design.motor.synchronous_speed_rad_s=1.0",
    ]
    sc = load_scenario("lateral-8dof", overrides)
    t0 = time.perf_counter()
    with pytest.raises(InputError) as info:
        simulate(sc)
    assert time.perf_counter() - t0 < 2.0
    msg = str(info.value)
    slope = viscous_equivalent_Nms(1750.0, 0.0719, 1.0)
    rate_hz = slope / (2 * 1.3080523287051801e-05) / (2 * math.pi)
    assert (
        f"design.motor.inertia_kg_m2 = 1.30805e-05 kg m^2: against its damping ({slope:.3g} N m s/rad" in msg
    )
    assert (
        "motor's slip characteristic" in msg
        and f"damping rate C / (2 M) / 2 pi of at least {rate_hz:.3g} Hz" in msg
    )


def test_a_stiff_coupling_damper_on_a_light_pinion_names_its_damping_key():
    from gearbody.assembly import check_resolved_modes

    sc = load_scenario("one-stage", ["design.coupling.damping_Nms_per_rad=1e6"])
    with pytest.raises(
        InputError,
        match=r"design.stages.1.pinion.inertia_kg_m2 = .*mostly from "
        r"design.shafts.1.damping_Nms_per_rad\) this gives a damping rate",
    ):
        check_resolved_modes(sc)


def test_a_tiny_gear_mass_of_a_lateral_model_is_named():
    from gearbody.assembly import check_resolved_modes

    sc = load_scenario("lateral-8dof", ["design.stages.1.pinion.mass_kg=1e-9"])
    with pytest.raises(InputError, match=r"design.stages.1.pinion.mass_kg = 1e-09 kg"):
        check_resolved_modes(sc)


def test_every_scene_passes_the_mode_check_and_its_bound_is_below_the_modes():
    """sqrt(K_ii / M_ii) is a lower bound of the highest natural frequency (Rayleigh quotient)."""
    from gearbody.assembly import check_resolved_modes, coordinate_frequencies
    from gearbody.engine.modes import scene_modes

    for name in list_scenes():
        sc = load_scenario(name)
        check_resolved_modes(sc)
        bound = max(c.frequency_hz for c in coordinate_frequencies(sc))
        assert bound <= scene_modes(sc).frequencies_hz.max() * (1 + 1e-9), name


# -- budgets while running -----------------------------------------------------------------------


def test_a_run_stops_cleanly_at_its_wall_time_limit():
    sc = load_scenario("one-stage", ["operation.t_end_s=1.0", "solver.wall_time_limit_s=0.05"])
    t0 = time.perf_counter()
    with pytest.raises(SimulationError, match=r"stopped at t = .* of 1 s: the wall-time limit solver"):
        simulate(sc)
    assert time.perf_counter() - t0 < 5.0


def test_the_watchdog_stops_a_run_that_outgrows_its_memory_budget():
    from gearbody.engine.user_functions import STALL_CALLS, StallError, StallWatchdog

    dog = StallWatchdog()
    dog.watch(1.0, 1e3, False, "motor speed", "rad/s", memory_limit_bytes=2**20, memory_limit_default=False)
    dog.memory0_bytes = 0  # as if the whole process had grown while solving
    with pytest.raises(StallError, match=r"grew by .* MiB while solving.*solver.memory_limit_MiB = 1\."):
        for k in range(2 * STALL_CALLS):
            dog(1e-6 * k, 100.0)
    assert dog.calls == STALL_CALLS


def test_a_stall_from_a_tiny_largest_step_names_max_step_s():
    from gearbody.engine.user_functions import STALL_CALLS, StallError, StallWatchdog

    for max_step, hint in ((1e-300, "solver.max_step_s = 1e-300 s caps every step"), (1e-4, "tolerance")):
        dog = StallWatchdog()
        dog.watch(1.0, 1e3, False, "motor speed", "rad/s", max_step_s=max_step)
        with pytest.raises(StallError, match=hint):
            for _ in range(2 * STALL_CALLS):
                dog(0.25, 100.0)


# -- failure messages ----------------------------------------------------------------------------


@pytest.mark.parametrize("raised", ["stall", "bug"])
def test_a_numerical_failure_shows_neither_exudyns_text_nor_a_python_repr(raised, monkeypatch, capfd):
    from gearbody.engine import user_functions

    def check(self, t, speed):
        if raised == "stall":
            self.failure = f"state diverged at t = {t:.6g} s (motor speed nan rad/s). Hint: ..."
            raise user_functions.StallError(self.failure)
        raise ZeroDivisionError("float division by zero (self.watch_node=0)")

    monkeypatch.setattr(user_functions.StallWatchdog, "_check", check)
    sc = load_scenario("one-stage", ["operation.t_end_s=0.01"])
    with pytest.raises(SimulationError) as info:
        simulate(sc)
    out, err = capfd.readouterr()
    msg = str(info.value)
    for text in (out + err, msg):
        assert "DYNAMIC SOLVER FAILED" not in text and "check your Python" not in text
        assert "self." not in text and "USER FUNCTION" not in text and "Traceback" not in text
    assert re.match(r"(state diverged|the solver stopped) at t = \d", msg)
    if raised == "bug":
        assert "ZeroDivisionError" in msg and "solver.absolute_tolerance" in msg
    import exudyn as exu

    assert exu.config.printToConsole  # restored after the run


# -- render frames -------------------------------------------------------------------------------


def test_render_frames_are_bounded_before_anything_is_simulated(tmp_path, capsys):
    from gearbody.render import MAX_FRAMES, RenderError, check_frames

    t0 = time.perf_counter()
    assert main(["render", "one-stage", "--frames", "100000", "--quiet", "--out", str(tmp_path)]) == 2
    assert time.perf_counter() - t0 < 5.0 and not any(tmp_path.iterdir())
    assert f"--frames = 100000: must be a whole number >= 1 and <= {MAX_FRAMES}" in capsys.readouterr().err
    from gearbody.cli import render as render_command

    assert render_command.MAX_FRAMES == MAX_FRAMES  # the command line states the renderer's bound
    with pytest.raises(RenderError, match="animated GIF holds every frame in memory"):
        check_frames(1000, 800, 600, "gif")
    check_frames(1000, 800, 600, "none")
    with pytest.raises(RenderError, match=r"frames = 0"):
        check_frames(0, 800, 600)


def test_a_soft_mesh_that_runs_out_of_range_is_blamed_on_its_stiffness(steady_scenario):
    """Found by tests/test_fuzz_simulate.py: the hint spoke of a tooth stiffness factor of 0."""
    sc = steady_scenario(
        "one-stage",
        "design.mesh.stiffness_single_N_per_m=1e5",
        "design.mesh.stiffness_double_N_per_m=1e5",
        t_end=0.002,
    )
    with pytest.raises(SimulationError) as info:
        simulate(sc)
    msg = str(info.value)
    assert "softest mesh stiffness 1e+05 N/m deflects 103 mm" in msg
    assert "raise design.stages.1.mesh.stiffness_single_N_per_m" in msg and "factor of 0" not in msg


@pytest.mark.parametrize(
    ("scene", "overrides", "expected"),
    [
        (  # found by the fuzzer: the stall hint spoke of a tooth factor 0 and the tolerances
            "muller",
            ["design.mesh.stiffness_double_N_per_m=1e6"],
            r"stalled at t = .*Hint: the mesh stiffness jumps by more than 10x .*"
            r"design.stages.1.mesh.stiffness_single_N_per_m / stiffness_double_N_per_m \(1.2e\+09 / 1e\+06",
        ),
        (
            "muller",
            ["design.mesh.stiffness_double_N_per_m=1e6", "design.mesh.transition_width=0.02"],
            r"state diverged at t = .*Hint: the softest mesh stiffness 1e\+06 N/m deflects 10.3 mm",
        ),
        (
            "two-wheel",
            ["design.mesh.backlash_um=1474"],
            r"outside its range .*Hint: design.stages.1.mesh.backlash_um = 1474 alone spans",
        ),
    ],
)
def test_numerical_failure_hints_name_the_responsible_key(scene, overrides, expected):
    sc = load_scenario(scene, ["operation.t_end_s=0.01", *overrides])
    with pytest.raises(SimulationError, match=expected) as info:
        simulate(sc)
    assert "tolerance" not in str(info.value) and "factor of 0" not in str(info.value)
