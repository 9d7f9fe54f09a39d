"""Scalar features (gearbody.analysis.features) against hand-computed values on synthetic records, and on
a run: the numbers calibration fits and sensitivity analysis ranks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearbody.analysis import synchronous_average
from gearbody.analysis.features import (
    FEATURES,
    FeatureError,
    Record,
    evaluate_feature,
    evaluate_features,
    kd_statistic,
    line_frequency_hz,
    natural_frequency_hz,
    parse_feature,
    resonance_speed,
)
from gearbody.analysis.indicators import condition_indicators_from_average
from gearbody.model import load_scenario, scenario_to_dict
from gearbody.result import Result

FS, F_PINION, Z1, Z2 = 10_000.0, 20.0, 25, 75  # f_z = 500 Hz, f_wheel = 6.667 Hz


@pytest.fixture
def record() -> Record:
    """1 s at 10 kHz: mesh line 3.0 at 500 Hz, lower sideband 0.5 at 480 Hz, second pinion order 0.2 at
    40 Hz (every line on a bin of the 1 Hz grid); K_d = 1 + 0.01 k/N; contact lost for the last 10 %."""
    t = np.arange(10_000) / FS
    w = 2 * np.pi * t
    accel = 3.0 * np.sin(w * 500.0) + 0.5 * np.sin(w * 480.0) + 0.2 * np.sin(w * 40.0)
    force = np.where(t < 0.9, 1.0, -0.0)
    return Record(
        time_s=t,
        signals={
            "pinion_angle_rad": w * F_PINION,
            "pinion_accel_rad_s2": accel,
            "kd": 1.0 + 0.01 * np.arange(t.size) / t.size,
            "mesh_force_N": force,
        },
        pinion_teeth=Z1,
        wheel_teeth=Z2,
        period_boundaries_s=(0.0, 0.5, t[-1]),
        natural_frequencies_hz=(0.0, 420.0, 1300.0),
    )


def test_spectral_lines_read_their_amplitudes_by_kind(record):
    full = "from_s=0"
    assert line_frequency_hz(F_PINION, Z1, Z2, mesh=1, order=-1) == pytest.approx(480.0)
    assert line_frequency_hz(F_PINION, Z1, Z2, mesh=0, order=3, shaft="wheel") == pytest.approx(20.0)
    values = evaluate_features(
        [
            f"line_amplitude:signal=pinion_accel_rad_s2,mesh=1,{full}",
            f"line_amplitude:signal=pinion_accel_rad_s2,mesh=1,order=-1,{full}",
            f"line_amplitude:signal=pinion_accel_rad_s2,mesh=0,order=2,{full}",
        ],
        record,
    )
    assert list(values.values()) == pytest.approx([3.0, 0.5, 0.2], rel=1e-9)
    rms = evaluate_feature(f"rms:signal=pinion_accel_rad_s2,{full}", record)
    assert rms == pytest.approx(math.sqrt((3.0**2 + 0.5**2 + 0.2**2) / 2), rel=1e-9)


def test_a_sideband_the_window_cannot_resolve_is_refused(record):
    """20 Hz between pinion orders; the final 0.25 s window resolves 4 Hz x 2 bins: fine; 0.05 s is not."""
    assert evaluate_feature("line_amplitude:signal=pinion_accel_rad_s2,mesh=1,order=-1", record) > 0.4
    with pytest.raises(
        FeatureError, match=r"window resolves lines to 40 Hz, not the 20 Hz .* longer than 0.2 s"
    ):
        evaluate_feature("line_amplitude:signal=pinion_accel_rad_s2,mesh=1,order=-1,fraction=0.05", record)


def test_kd_statistics_and_windows(record):
    kd = record.signals["kd"]
    assert evaluate_feature("kd_max:period=1", record) == kd[record.time_s < 0.5].max()
    assert evaluate_feature("kd_min:period=2", record) == kd[record.time_s >= 0.5].min()
    assert evaluate_feature("kd_mean", record) == pytest.approx(kd[record.time_s >= 0.75 * 0.9999].mean())
    assert evaluate_feature("kd_p95:from_s=0", record) == pytest.approx(np.percentile(kd, 95))
    assert kd_statistic(np.arange(101.0), "p95") == pytest.approx(95.0)
    with pytest.raises(FeatureError, match=r"period = 3: the record has periods 1..2"):
        evaluate_feature("kd_max:period=3", record)


def test_separation_fraction_counts_time_without_contact(record):
    assert evaluate_feature("separation_fraction:from_s=0", record) == pytest.approx(0.1, abs=2e-4)
    assert evaluate_feature("separation_fraction:period=1", record) == 0.0


def test_natural_frequencies_skip_rigid_body_modes(record):
    assert evaluate_feature("natural_frequency_hz:mode=1", record) == 420.0
    assert natural_frequency_hz([1300.0, 1e-9, 420.0], 2) == 1300.0
    with pytest.raises(FeatureError, match="mode = 3; the record has modes 1..2"):
        evaluate_feature("natural_frequency_hz:mode=3", record)


def test_indicator_features_are_the_synchronous_averages_indicators():
    t = np.arange(40_000) / FS
    angle = 2 * np.pi * F_PINION * t
    u = angle * Z1 / (2 * np.pi)
    x = np.sin(2 * np.pi * u) + 5.0 * ((np.floor(u) % Z1 == 7) & (u % 1 < 0.2))  # one damaged tooth
    rec = Record(time_s=t, signals={"pinion_angle_rad": angle, "a": x}, pinion_teeth=Z1, wheel_teeth=Z2)
    expected = condition_indicators_from_average(synchronous_average(x, angle, teeth=Z1)).as_dict()
    got = evaluate_features(["fm4:signal=a,from_s=0", "tsa_rms:signal=a,from_s=0"], rec)
    assert list(got.values()) == [expected["fm4"], expected["rms"]]
    assert expected["fm4"] > 5  # a once-per-revolution event: far from a Gaussian's 3


def test_resonance_speed_refines_the_peak_and_flags_an_edge():
    speeds = np.linspace(50.0, 150.0, 11)
    speed, inside = resonance_speed(speeds, 10.0 - (speeds - 93.0) ** 2)
    assert inside and speed == pytest.approx(93.0, rel=1e-9)
    speed, inside = resonance_speed(speeds, speeds)
    assert not inside and speed == 150.0


def test_specs_are_parsed_and_bad_ones_refused_with_the_valid_choices():
    spec = parse_feature("line_amplitude:signal=pinion_accel_rad_s2,mesh=2,order=-1")
    assert spec.options == {"signal": "pinion_accel_rad_s2", "mesh": 2, "order": -1}
    assert str(spec) == "line_amplitude:signal=pinion_accel_rad_s2,mesh=2,order=-1"
    with pytest.raises(FeatureError, match="no feature 'kd_maxx'; valid are kd_max"):
        parse_feature("kd_maxx")
    with pytest.raises(FeatureError, match="option 'mode=2' not understood; kd_max takes stage=...,"):
        parse_feature("kd_max:mode=2")
    with pytest.raises(FeatureError, match="period = '1.5' must be an integer"):
        parse_feature("kd_max:period=1.5")
    with pytest.raises(FeatureError, match="give the signal"):
        evaluate_feature("rms", Record(np.arange(3.0), {}, 10, 20))
    assert set(FEATURES) >= {"kd_max", "separation_fraction", "line_amplitude", "fm4", "natural_frequency_hz"}


def test_a_results_periods_come_from_its_speed_and_load_profiles():
    """The four-period run of the one-stage scene: run-up to 0.5 s, no load to 0.8 s, ramp to 1.2 s."""
    sc = load_scenario("one-stage")
    t = np.linspace(0.0, sc.operation.t_end_s, 2001)
    res = Result(
        time_s=t,
        signals={"kd": t.copy(), "mesh_force_N": np.ones_like(t)},
        meta={"scenario": scenario_to_dict(sc), "pinion_teeth": 29, "wheel_teeth": 88},
    )
    assert res.period_boundaries_s() == (0.0, 0.5, 0.8, 1.2, sc.operation.t_end_s)
    assert res.features(["kd_max:period=3"]) == {"kd_max:period=3": pytest.approx(1.199)}


def test_features_of_a_simulated_run(steady_scenario):
    """On a run: the mesh line's feature is the largest bin near the run's own mesh frequency."""
    from gearbody.analysis import amplitude_spectrum, peak_at
    from gearbody.engine import simulate

    res = simulate(steady_scenario("one-stage", t_end=0.2))
    win = res.final_window()
    spec = amplitude_spectrum(res["pinion_accel_rad_s2"][win], res.sample_rate_hz, window="hann")
    expected = peak_at(spec, res.mesh_frequency_hz(), 2 * spec.resolution_hz)
    got = res.features(["line_amplitude:signal=pinion_accel_rad_s2,mesh=1", "kd_max", "separation_fraction"])
    assert got["line_amplitude:signal=pinion_accel_rad_s2,mesh=1"] == pytest.approx(expected, rel=1e-12)
    assert got["kd_max"] == pytest.approx(float(np.max(res.kd[win])))
    assert got["separation_fraction"] == 0.0


def test_a_feature_registered_from_outside_gearbody_is_parsed_and_evaluated_everywhere():
    """A new analysis is one module: it registers its FeatureKind, and Result.features and the studies'
    parsing know it; unknown options are refused as for gearbody's own."""
    from gearbody import load_scenario, simulate
    from gearbody.analysis.features import (
        WINDOW_OPTIONS,
        FeatureKind,
        parse_feature,
        register_feature,
        unregister_feature,
    )

    def peak_to_peak(spec, record, names, mask):
        x = record.signal(names[0])[mask]
        return float(np.max(x) - np.min(x))

    kind = FeatureKind(
        ("signal", *WINDOW_OPTIONS), lambda spec, record: (str(spec.options["signal"]),), peak_to_peak
    )
    register_feature("test_peak_to_peak", kind)
    try:
        result = simulate(load_scenario("two-wheel", ["operation.t_end_s=0.05"]))
        text = "test_peak_to_peak:signal=mesh_force_N,fraction=0.5"
        value = result.features([text])[text]
        mask = result.record().window({"fraction": 0.5})
        assert 0 < np.count_nonzero(mask) < mask.size
        assert value == np.ptp(result["mesh_force_N"][mask]) > 0
        with pytest.raises(FeatureError, match="order"):
            parse_feature("test_peak_to_peak:order=2")
    finally:
        unregister_feature("test_peak_to_peak")
    with pytest.raises(FeatureError, match="no feature 'test_peak_to_peak'"):
        parse_feature("test_peak_to_peak:signal=mesh_force_N")
