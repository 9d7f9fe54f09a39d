"""Tacho pulses, the shaft angle and speed they imply, and the tacholess angle from a mesh harmonic, on
synthetic signals with known answers."""

import numpy as np
import pytest

from gearbody.analysis.tacho import pulse_times, shaft_angle_from_pulses, shaft_speed_from_pulses
from gearbody.analysis.tacholess import TacholessSpeed, tacholess_angle
from gearbody.errors import InputError

FS_HZ = 20_000.0
PPR = 4
T_S = np.arange(0.0, 4.0, 1.0 / FS_HZ)
SPEED_HZ = 5.0 + 5.0 * T_S  # run-up 5 -> 25 rev/s
ANGLE_RAD = 2 * np.pi * (5.0 * T_S + 2.5 * T_S**2) + 0.4


def _ttl(steepness: float) -> np.ndarray:
    """0 .. 5 V pulse train, PPR rising edges per revolution (where sin(PPR angle) rises through 0); the
    edge is a ramp over |sin| < 1 / steepness (an ideal square for a huge steepness)."""
    return 2.5 + 2.5 * np.clip(steepness * np.sin(PPR * ANGLE_RAD), -1.0, 1.0)


def _true_angle_from_first_pulse() -> np.ndarray:
    first = np.ceil(PPR * ANGLE_RAD[0] / (2 * np.pi))
    return ANGLE_RAD - 2 * np.pi * first / PPR


@pytest.mark.parametrize(
    "steepness, bound_rad",
    [
        # ideal square: a pulse instant is off by up to half a sample, angle error <= w_max / (2 fs) at
        # the pulses; the spline through them stays within 1.6 x that (measured 1.05 x)
        (1e12, 1.6 * 2 * np.pi * 25.0 * 0.5 / FS_HZ),
        # an edge over a few samples: the interpolated crossing is exact to ~1e-7 rad (measured 1.6e-7)
        (3.0, 1e-6),
    ],
)
def test_pulses_of_a_chirped_square_wave_give_the_exact_angle(steepness, bound_rad):
    pulses = pulse_times(_ttl(steepness), FS_HZ)
    true = _true_angle_from_first_pulse()
    revs = (ANGLE_RAD[-1] - ANGLE_RAD[0]) / (2 * np.pi)
    assert pulses.size == pytest.approx(PPR * revs, abs=1)
    angle = shaft_angle_from_pulses(pulses, PPR, T_S)
    inside = (T_S >= pulses[0]) & (T_S <= pulses[-1])
    assert np.abs(angle - true)[inside].max() < bound_rad
    speed = shaft_speed_from_pulses(pulses, PPR, T_S)
    tolerance = 0.02 if steepness > 1e6 else 1e-5  # measured 0.015 and 4.6e-7
    np.testing.assert_allclose(speed[inside], 2 * np.pi * SPEED_HZ[inside], rtol=tolerance)


def test_pchip_is_monotone_and_close_and_the_ends_extrapolate_with_the_end_speed():
    pulses = pulse_times(_ttl(3.0), FS_HZ)
    true = _true_angle_from_first_pulse()
    inside = (T_S >= pulses[0]) & (T_S <= pulses[-1])
    pchip = shaft_angle_from_pulses(pulses, PPR, T_S, method="pchip")
    assert np.all(np.diff(pchip) > 0)
    assert np.abs(pchip - true)[inside].max() < 1e-3  # measured 1.8e-4 (the spline: 1.6e-7)
    after = np.array([pulses[-1] + 0.01, pulses[-1] + 0.02])
    end = shaft_angle_from_pulses(pulses, PPR, [pulses[-1]])[0]
    end_speed = shaft_speed_from_pulses(pulses, PPR, [pulses[-1]])[0]
    np.testing.assert_allclose(
        shaft_angle_from_pulses(pulses, PPR, after), end + end_speed * (after - pulses[-1])
    )
    np.testing.assert_allclose(shaft_speed_from_pulses(pulses, PPR, after), end_speed)


def test_constant_speed_angle_is_exact_and_t0_and_the_falling_edge_shift_the_instants():
    t = np.arange(0.0, 1.0, 1.0 / FS_HZ)
    square = np.where(np.sin(2 * np.pi * 10.0 * t + 0.1) >= 0, 1.0, 0.0)
    rising = pulse_times(square, FS_HZ)
    falling = pulse_times(square, FS_HZ, edge="falling")
    assert np.abs(np.diff(rising) - 0.1).max() <= 1.0 / FS_HZ
    after = np.searchsorted(falling, rising)
    has = after < falling.size
    assert np.abs(falling[after[has]] - rising[has] - 0.05).max() <= 1.0 / FS_HZ  # half a period later
    np.testing.assert_allclose(pulse_times(square, FS_HZ, t0_s=2.5), rising + 2.5)
    angle = shaft_angle_from_pulses(rising, 1, t)
    np.testing.assert_allclose(np.gradient(angle, t), 2 * np.pi * 10.0, rtol=2e-3)


def test_hysteresis_ignores_chatter_at_the_edges():
    rng = np.random.default_rng(7)
    t = np.arange(0.0, 1.0, 1.0 / FS_HZ)
    clean = np.where(np.sin(2 * np.pi * 20.0 * t) >= 0, 5.0, 0.0)
    edges = np.flatnonzero(np.diff(clean) != 0)
    chattering = clean.copy()
    for e in edges:  # the level bounces across 2.5 V (inside the hysteresis) for 6 samples after an edge
        chattering[e + 1 : e + 7] = np.where(np.arange(6) % 2 == 0, 2.35, 2.65)
    chattering += rng.normal(0.0, 0.02, t.size)
    reference = pulse_times(clean, FS_HZ)
    assert pulse_times(chattering, FS_HZ, hysteresis=0.0).size > reference.size  # the chatter counts
    found = pulse_times(chattering, FS_HZ)  # default hysteresis: 10 % of 5 V, thresholds 2.25 / 2.75 V
    assert found.size == reference.size == 19
    assert np.abs(found - reference).max() < 8.0 / FS_HZ


def test_tacholess_speed_from_the_mesh_harmonic_of_a_run_up():
    fs, duration = 5000.0, 10.0
    t = np.arange(0.0, duration, 1.0 / fs)
    speed = 10.0 + 2.0 * t  # 10 -> 30 rev/s, mesh order 20: 200 -> 600 Hz
    angle = 2 * np.pi * np.cumsum(speed) / fs
    rng = np.random.default_rng(3)
    x = (
        np.cos(20 * angle + 0.3)
        + 0.5 * np.cos(40 * angle)
        + 0.3 * np.cos(angle)
        + 0.2 * (np.cos(19 * angle) + np.cos(21 * angle))  # sidebands one shaft order away
        + 0.5 * rng.normal(size=t.size)
    )
    interior = (t > 0.5) & (t < duration - 0.5)
    for kwargs in ({"band_hz": (150.0, 700.0)}, {"speed_guess_hz": 1.05 * speed}):
        est = tacholess_angle(x, fs, 20, **kwargs)
        assert isinstance(est, TacholessSpeed)
        # measured: speed within 0.08 %, angle within 0.0045 rad (0.026 deg) in the interior
        assert np.abs(est.speed_hz[interior] / speed[interior] - 1).max() < 0.01
        error = est.angle_rad - (angle - angle[0])
        error -= error[interior].mean()
        assert np.abs(error[interior]).max() < 0.02
        np.testing.assert_allclose(est.harmonic_amplitude[interior].mean(), 1.0, rtol=0.05)


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: pulse_times(np.ones(100), FS_HZ), "tacho_signal"),
        (lambda: pulse_times([0.0, 1.0, 0.0, 1.0], -1.0), "sample_rate_hz"),
        (lambda: pulse_times([0.0, 1.0, 0.0, 1.0], FS_HZ, hysteresis=-1.0), "hysteresis"),
        (lambda: pulse_times([0.0, 1.0, 0.0, 1.0], FS_HZ, edge="up"), "edge"),
        (lambda: pulse_times([0.0, np.nan, 0.0, 1.0], FS_HZ), "tacho_signal"),
        (lambda: shaft_angle_from_pulses([0.0, 0.1], 1, [0.05]), "pulse_times_s"),
        (lambda: shaft_angle_from_pulses([0.0, 0.2, 0.1], 1, [0.05]), "pulse_times_s"),
        (lambda: shaft_angle_from_pulses([0.0, 0.1, 0.2], 0, [0.05]), "pulses_per_rev"),
        (lambda: shaft_angle_from_pulses([0.0, 0.1, 0.2], 1, [0.05], method="linear"), "method"),
        (lambda: tacholess_angle(np.ones(1000), 1000.0, 20), "speed_guess_hz"),
        (lambda: tacholess_angle(np.ones(1000), 1000.0, 20, band_hz=(300.0, 200.0)), "band_hz"),
        (lambda: tacholess_angle(np.ones(1000), 1000.0, -2, band_hz=(100.0, 200.0)), "order"),
        (lambda: tacholess_angle(np.ones(1000), 1000.0, 20, speed_guess_hz=-5.0), "speed_guess_hz"),
    ],
)
def test_bad_inputs_name_the_parameter(call, name):
    with pytest.raises(InputError, match=name):
        call()
