"""Issue 30, deliverable 3 (first part): the path from bearing forces to a housing accelerometer, the
sensor's noise, rate and anti-alias filter, and the tacho, as a Recording."""

from types import SimpleNamespace

import numpy as np
import pytest

import gearbody as gb
from gearbody.recording.instruments import (
    Accelerometer,
    HousingMode,
    housing_acceleration,
    virtual_instruments,
)

FS = 20_000.0


def _run(force, seconds=2.0, shaft_hz=17.0):
    t = np.arange(int(seconds * FS)) / FS
    angle = 2 * np.pi * shaft_hz * t
    signals = {"b_force_y_N": force(t), "pinion_angle_rad": angle,
               "pinion_speed_rad_s": np.full(t.size, 2 * np.pi * shaft_hz)}  # fmt: skip
    return SimpleNamespace(time_s=t, signals=signals, meta={"output_rate_hz": FS, "scene": "test"})


@pytest.mark.parametrize(("f_force", "gain"), [(1000.0, 1 / (2 * 0.02)), (5000.0, None)])
def test_a_mode_amplifies_its_own_frequency_by_one_over_two_zeta(f_force, gain):
    mode = HousingMode(1000.0, 0.02, {"b_force_y_N": 1e-3})
    run = _run(lambda t: np.sin(2 * np.pi * f_force * t))
    a = housing_acceleration(run.time_s, run.signals, [mode])
    r = f_force / mode.frequency_hz
    exact = 1e-3 * r**2 / abs(complex(1 - r**2, 2 * 0.02 * r))  # |phi s^2 / (s^2 + 2 zeta w s + w^2)|
    if gain is not None:
        assert exact == pytest.approx(1e-3 * gain)
    steady = a[int(1.5 * FS) :]  # the transient (time constant 1 / (zeta w) = 8 ms) long gone
    assert np.max(np.abs(steady)) == pytest.approx(exact, rel=0.01)


def test_noise_is_seeded_and_the_sensor_rate_filters_what_it_cannot_hold():
    mode = HousingMode(1000.0, 0.05, {"b_force_y_N": 1e-3})
    run = _run(lambda t: np.sin(2 * np.pi * 900 * t) + np.sin(2 * np.pi * 7000 * t))
    acc = Accelerometer("acc", [mode], noise_rms_m_s2=0.01, sample_rate_hz=10_000.0)
    a, b = virtual_instruments(run, [acc], seed=3), virtual_instruments(run, [acc], seed=3)
    c = virtual_instruments(run, [acc], seed=4)
    assert a.sample_rate_hz == 10_000.0 and np.array_equal(a["acc"], b["acc"])
    assert not np.array_equal(a["acc"], c["acc"])
    quiet = virtual_instruments(run, [Accelerometer("acc", [mode], sample_rate_hz=10_000.0)])
    from gearbody.analysis import amplitude_spectrum

    spec = amplitude_spectrum(quiet["acc"][10_000:], 10_000.0)
    at = lambda f: spec.amplitude[np.argmin(np.abs(spec.frequency_hz - f))]  # noqa: E731
    r = 0.9
    assert at(900) == pytest.approx(1e-3 * r**2 / abs(complex(1 - r**2, 0.1 * r)), rel=0.02)
    tone_7khz = 1e-3 * 49 / abs(complex(1 - 49, 0.1 * 7))  # what reaches the sensor's filter
    assert at(3000) < 1e-3 * tone_7khz  # 7 kHz would alias to 3 kHz: attenuated by more than 60 dB
    assert a.tacho.pulses_per_rev == 1 and a.tacho.pulse_times_s.size == 33  # 17 rev/s for 2 s
    assert np.allclose(np.diff(a.tacho.pulse_times_s), 1 / 17)


def test_bad_modes_and_sensors_are_refused_by_name():
    with pytest.raises(gb.InputError, match="damping_ratio"):
        HousingMode(1000.0, 1.5, {"x": 1.0})
    with pytest.raises(gb.InputError, match="frequency_hz"):
        HousingMode(-1.0, 0.1, {"x": 1.0})
    with pytest.raises(gb.InputError, match="noise_rms_m_s2"):
        Accelerometer("a", [HousingMode(1.0, 0.1, {"x": 1.0})], noise_rms_m_s2=-1)
    run = _run(np.sin)
    with pytest.raises(gb.SignalError, match="force signals: b_force_y_N"):
        virtual_instruments(run, [Accelerometer("a", [HousingMode(1.0, 0.1, {"nope_N": 1.0})])])
    with pytest.raises(gb.InputError, match="ratio p/q"):
        virtual_instruments(
            run,
            [
                Accelerometer(
                    "a", [HousingMode(1.0, 0.1, {"b_force_y_N": 1.0})], sample_rate_hz=float(np.pi * 1e4)
                )
            ],
        )


def test_a_simulated_accelerometer_is_a_recording_analyze_takes():
    result = gb.simulate(gb.load_scenario("lateral-8dof-ball", ["operation.t_end_s=0.5"]))
    mode = HousingMode(
        3000.0, 0.03, {"pinion_bearing_force_y_N": 1 / 30.0, "wheel_bearing_force_y_N": 1 / 60.0}
    )
    rec = virtual_instruments(
        result, [Accelerometer("housing", [mode], noise_rms_m_s2=0.05)], pulses_per_rev=60
    )
    drive = gb.DriveKinematics.from_scenario(gb.load_scenario("lateral-8dof-ball"))
    diag = gb.analyze_recording(rec.window(0.25), drive)
    assert diag.mean_input_hz == pytest.approx(result["pinion_speed_rad_s"][-1] / (2 * np.pi), rel=0.02)
    housing = diag.channels["housing"]
    assert housing.unit == "m/s^2" and housing.indicators["pinion"]["fm0"] > 0
    assert rec.meta["source"] == "virtual instruments" and rec.channel("housing").sensitivity == 0.0102
