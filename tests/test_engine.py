"""The Exudyn engine: steady running, reproducibility, the Result and its file, failures reported."""

import numpy as np
import pytest

import gearbody as gb
from gearbody.engine import simulate
from gearbody.errors import InputError


@pytest.fixture
def steady(steady_scenario):
    return steady_scenario


@pytest.mark.parametrize("scene", ["muller", "two-wheel", "one-stage"])
def test_static_equilibrium_holds_without_excitation(scene, steady):
    """Constant stiffness, no error, no friction, steady start: the mesh force stays at F_rated."""
    sc = steady(
        scene,
        "design.mesh.stiffness_double_N_per_m=1.2e9",
        "production.error_mode.e_um=0",
        "condition.friction_coefficient=0",
    )
    r = simulate(sc)
    assert np.max(np.abs(r.kd - 1.0)) < 2e-3


def test_steady_running_transmits_rated_force_on_average(steady):
    sc = steady("one-stage", t_end=0.2)
    r = simulate(sc)
    f_mesh = np.mean(r["mesh_frequency_hz"])
    n_periods = int((r.time_s[-1] - 0.1) * f_mesh)
    w = r.time_s >= r.time_s[-1] - n_periods / f_mesh
    assert np.mean(r.kd[w]) == pytest.approx(1.0, abs=0.01)
    assert f_mesh == pytest.approx(29 * 107.0 / (2 * np.pi), rel=2e-3)  # the seed's rated speed


def test_result_has_fixed_output_grid_signals_and_metadata(tmp_path, steady):
    sc = steady("one-stage")
    r = gb.simulate(sc)
    rate = sc.solver.output_rate_hz
    assert np.allclose(np.diff(r.time_s), 1 / rate)
    assert r.time_s[-1] == pytest.approx(0.05)
    for name in (
        "mesh_force_N",
        "kd",
        "pinion_angle_rad",
        "pinion_speed_rad_s",
        "pinion_accel_rad_s2",
        "wheel_angle_rad",
        "motor_speed_rad_s",
        "machine_speed_rad_s",
        "friction_force_N",
    ):
        assert r[name].shape == r.time_s.shape and np.all(np.isfinite(r[name]))
    assert np.allclose(r.kd, r.mesh_force / sc.rated_mesh_force_N)
    for key in (
        "scenario",
        "seed",
        "gearbody_version",
        "exudyn_version",
        "solver_statistics",
        "output_rate_hz",
    ):
        assert key in r.meta
    assert r.meta["solver_statistics"]["steps"] > 0
    back = gb.Result.load_npz(r.save_npz(tmp_path / "result.npz"))
    assert np.array_equal(back.mesh_force, r.mesh_force) and back.meta["seed"] == sc.meta.seed
    with np.load(tmp_path / "result.npz") as z:
        assert {"time", "mesh_force_N"} <= set(z.files)


def test_same_seed_same_run_other_seed_other_teeth(steady):
    a = simulate(steady("two-wheel", "production.error_mode.r=0.8"))
    b = simulate(steady("two-wheel", "production.error_mode.r=0.8"))
    c = simulate(steady("two-wheel", "production.error_mode.r=0.8", "meta.seed=2"))
    assert np.array_equal(a.mesh_force, b.mesh_force)
    assert not np.allclose(a.mesh_force, c.mesh_force)


def test_muller_pitch_line_is_kinematic(steady):
    """Muller: the mesh phase follows the prescribed speed, whatever the mass does."""
    r = simulate(steady("muller"))
    assert np.allclose(r["pinion_angle_rad"], r.time_s * 108.63)


def test_motor_that_cannot_carry_the_load_is_reported_before_running(steady):
    with pytest.raises(InputError, match="breakdown torque"):  # an input error (exit 2), not numerical
        simulate(steady("one-stage", "design.machine.rated_torque_Nm=6000"))


def test_steady_start_on_a_broken_tooth_is_refused_with_a_hint(steady):
    with pytest.raises(InputError, match="carry no load"):
        broken = 'condition.damaged_teeth=[{gear="pinion",tooth=0,stiffness_factor=0.0}]'
        simulate(steady("one-stage", broken))


def test_steady_start_subtracts_the_error_in_mesh(steady):
    """a = 0 puts the full error at p = 0: the steady start must still be an equilibrium."""
    sc = steady(
        "one-stage",
        "production.error_mode={a=0.0,e_um=10.0,r=0.0}",
        "condition.friction_coefficient=0",
        "design.mesh.stiffness_double_N_per_m=1.2e9",
        t_end=0.0004,
    )
    r = simulate(sc)
    assert abs(r.kd[0] - 1.0) < 1e-9


def test_the_watchdog_reports_divergence_and_stalls_with_their_time():
    """No pre-step Python call per step attempt: the force function's watchdog checks every few thousand
    calls for a non-finite or runaway speed, and for time that stopped advancing."""
    from gearbody.engine.user_functions import CHECK_CALLS, STALL_CALLS, StallError, StallWatchdog

    dog = StallWatchdog()
    dog.watch(1.0, 1e3, False, "motor speed", "rad/s")
    for k in range(CHECK_CALLS - 1):
        dog(1e-3 * k, float("nan"))  # between checks: no cost, no verdict
    with pytest.raises(StallError, match=r"diverged at t = .*motor speed nan rad/s"):
        dog(0.5, float("nan"))
    assert "diverged" in dog.failure
    dog = StallWatchdog()
    dog.watch(1.0, 1e3, False, "motor speed", "rad/s")
    with pytest.raises(StallError, match=r"stalled at t = 0\.25"):
        for _ in range(2 * STALL_CALLS):
            dog(0.25, 100.0)
    assert dog.calls == 2 * STALL_CALLS  # the first check sets the mark, the second finds no progress


def test_the_watchdog_ticker_checks_like_a_call_per_evaluation():
    """The force functions use ``tick, check = watchdog.ticker()``: the same verdicts, counted the same."""
    from gearbody.engine.user_functions import CHECK_CALLS, STALL_CALLS, StallError, StallWatchdog

    dog = StallWatchdog()
    dog.watch(1.0, 1e3, False, "motor speed", "rad/s")
    tick, check = dog.ticker()
    assert [tick() for _ in range(CHECK_CALLS)].count(True) == 1
    dog = StallWatchdog()
    dog.watch(1.0, 1e3, False, "motor speed", "rad/s")
    tick, check = dog.ticker()
    with pytest.raises(StallError, match=r"diverged at t = 0\.5 s .*motor speed 2e\+03 rad/s"):
        for k in range(10 * CHECK_CALLS):
            if tick():
                check(0.5, 100.0 if k < 5 * CHECK_CALLS else 2e3)
    assert dog.calls == 6 * CHECK_CALLS
    dog = StallWatchdog()
    dog.watch(1.0, 1e3, False, "motor speed", "rad/s")
    tick, check = dog.ticker()
    with pytest.raises(StallError, match=r"stalled at t = 0\.25"):
        for _ in range(2 * STALL_CALLS):
            if tick():
                check(0.25, 100.0)
    assert dog.calls == 2 * STALL_CALLS


def test_cubic_hermite_is_scipys_spline_bit_for_bit():
    """collect() resamples with engine.sampling.CubicHermite instead of importing scipy.interpolate:
    the same values to the last bit, at, between and beyond the step times."""
    from scipy.interpolate import CubicHermiteSpline

    from gearbody.engine.sampling import CubicHermite

    rng = np.random.default_rng(7)
    for _ in range(50):
        n, m = int(rng.integers(2, 200)), int(rng.integers(1, 5))
        x = np.cumsum(rng.uniform(1e-7, 1e-3, n))
        y = rng.normal(size=(m, n)) * 10 ** rng.uniform(-6, 3)
        dydx = rng.normal(size=(m, n)) * 1e3
        times = np.concatenate([np.linspace(x[0] - 1e-4, x[-1] + 1e-4, 300), x, rng.uniform(x[0], x[-1], 50)])
        expected = CubicHermiteSpline(x, y, dydx, axis=1)(times)
        assert np.array_equal(CubicHermite(x, y, dydx)(times), expected)
