"""The Recording container: channels in SI units, a tacho, a run's export with its exact shaft angles,
unit and quantity conversion."""

import numpy as np
import pytest

from gearbody.errors import InputError, SignalError
from gearbody.recording import Channel, Recording, Tacho
from gearbody.recording.from_run import hermite_crossings


def _rec(n=1000, fs=1000.0, **kw):
    t = np.arange(n) / fs
    return Recording(
        fs, [Channel("acc", np.sin(2 * np.pi * 10 * t), "m/s^2"), Channel("v", np.cos(t), "V")], **kw
    )


def test_units_convert_to_si_on_the_way_in_and_keep_the_sensitivity():
    ch = Channel("acc", np.array([1.0, 2.0]), "g", sensitivity=0.1)  # 100 mV/g
    assert ch.unit == "m/s^2" and ch.quantity == "acceleration"
    assert np.array_equal(ch.data, np.array([1.0, 2.0]) * 9.80665)
    assert ch.sensitivity == pytest.approx(0.1 / 9.80665)  # V per m/s^2
    assert Channel("x", np.zeros(2), "um").data.dtype == np.float64
    with pytest.raises(InputError, match="unit = 'furlong'"):
        Channel("x", np.zeros(2), "furlong")
    with pytest.raises(InputError, match="sensitivity"):
        Channel("x", np.zeros(2), "m", sensitivity=0.0)


def test_recording_checks_its_shape_and_names_what_is_wrong():
    with pytest.raises(InputError, match="same number of samples"):
        Recording(100.0, [Channel("a", np.zeros(5)), Channel("b", np.zeros(6))])
    with pytest.raises(InputError, match="sample_rate_hz"):
        Recording(-1.0, [Channel("a", np.zeros(5))])
    with pytest.raises(InputError, match="appears twice"):
        Recording(100.0, [Channel("a", np.zeros(5)), Channel("a", np.zeros(5))])
    with pytest.raises(InputError, match="tacho channel 'tt'"):
        Recording(100.0, [Channel("a", np.zeros(5))], tacho=Tacho("input", 1, channel="tt"))
    with pytest.raises(InputError, match="at least 3 pulse"):
        Tacho("input", 1, pulse_times_s=[0.1, 0.2])
    rec = _rec()
    with pytest.raises(SignalError, match="channels: acc, v"):
        rec["nope"]


def test_window_select_and_time_grid():
    rec = _rec(t0_s=2.0)
    assert rec.time_s[0] == 2.0 and rec.duration_s == pytest.approx(1.0)
    w = rec.window(2.25, 2.5)
    assert w.n_samples == 250 and w.t0_s == pytest.approx(2.25)
    assert np.array_equal(w["acc"], rec["acc"][250:500])
    assert rec.select(["v"]).names == ["v"]
    assert rec.vibration_channels == ["acc"]


def test_integration_recovers_velocity_and_displacement_of_a_tone():
    fs, f = 1000.0, 10.0
    t = np.arange(2000) / fs  # 20 whole periods: every line on a bin
    acc = -((2 * np.pi * f) ** 2) * np.sin(2 * np.pi * f * t)
    rec = Recording(fs, [Channel("a", acc, "m/s^2")])
    disp = rec.as_quantity("a", "displacement", f_low_hz=1.0)
    vel = rec.as_quantity("a", "velocity", f_low_hz=1.0)
    assert disp.unit == "m" and np.max(np.abs(disp.data - np.sin(2 * np.pi * f * t))) < 1e-9
    assert vel.unit == "m/s" and np.max(np.abs(vel.data - 2 * np.pi * f * np.cos(2 * np.pi * f * t))) < 1e-7
    back = Recording(fs, [disp]).as_quantity("a_displacement", "acceleration")
    assert np.max(np.abs(back.data - acc)) < 1e-6 * np.max(np.abs(acc))
    with pytest.raises(InputError, match="f_low_hz"):
        rec.as_quantity("a", "velocity")


def test_hermite_crossings_find_the_exact_instants_of_a_cubic_angle():
    t = np.linspace(0.0, 2.0, 201)
    angle = 3.0 * t + 0.5 * t**3  # a cubic: the Hermite interpolant is exact
    speed = 3.0 + 1.5 * t**2
    step = 2 * np.pi / 7
    found = hermite_crossings(t, angle, speed, step)
    k = np.arange(1, int(angle[-1] // step) + 1)
    from scipy.optimize import brentq

    exact = np.array([brentq(lambda x, a=a: 3 * x + 0.5 * x**3 - a, 0, 2.0) for a in k * step])
    assert found.size == exact.size and np.max(np.abs(found - exact)) < 1e-12
