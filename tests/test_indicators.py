"""Condition indicators on synthetic signals whose values are known in closed form."""

import numpy as np
import pytest

from gearbody.analysis.indicators import (
    ConditionIndicators,
    condition_indicators,
    condition_indicators_from_average,
    crest_factor,
    energy_ratio,
    fm0,
    fm4,
    kurtosis,
    m6a,
    m8a,
    na4,
    na4_trend,
    peak_to_peak,
    rms,
    sideband_energy_ratio,
)
from gearbody.analysis.tsa import synchronous_average

POINTS = 4096  # one revolution


def _theta(n: int = POINTS):
    return np.arange(n) * 2 * np.pi / n


@pytest.fixture(scope="module")
def gaussian():
    return np.random.default_rng(20240607).standard_normal(1_000_000)


def test_gaussian_moments(gaussian):
    assert kurtosis(gaussian) == pytest.approx(3.0, abs=0.02)
    assert fm4(gaussian) == kurtosis(gaussian)
    assert m6a(gaussian) == pytest.approx(15.0, rel=0.03)
    assert m8a(gaussian) == pytest.approx(105.0, rel=0.05)
    # moments are about the mean and scale-free
    assert kurtosis(5.0 + 0.1 * gaussian) == pytest.approx(kurtosis(gaussian), rel=1e-9)


def test_sine_on_whole_periods():
    amplitude = 2.5
    x = amplitude * np.sin(7 * _theta())  # 4096 / 7 samples per period; sampled peaks are within 1e-6 of A
    assert kurtosis(x) == pytest.approx(1.5, abs=1e-9)
    assert m6a(x) == pytest.approx(2.5, abs=1e-9)  # (5/16) / (1/2)^3
    assert m8a(x) == pytest.approx(4.375, abs=1e-9)  # (35/128) / (1/2)^4
    assert rms(x) == pytest.approx(amplitude / np.sqrt(2), rel=1e-12)
    y = amplitude * np.sin(8 * _theta())  # a sample on each peak
    assert crest_factor(y) == pytest.approx(np.sqrt(2), rel=1e-12)
    assert peak_to_peak(y) == pytest.approx(2 * amplitude, rel=1e-12)


def test_square_wave():
    x = np.where(np.sin(4 * _theta() + 0.1) >= 0, 3.0, -3.0)
    assert np.mean(x) == 0.0
    assert kurtosis(x) == pytest.approx(1.0, abs=1e-12)
    assert crest_factor(x) == pytest.approx(1.0, abs=1e-12)
    assert m6a(x) == pytest.approx(1.0) and m8a(x) == pytest.approx(1.0)


def test_fm0_pure_mesh_tone_is_two():
    teeth = 20
    amplitude = 1.7
    x = 4.0 + amplitude * np.sin(teeth * _theta())  # 4096 = 20 * 204.8 -> peaks sampled to 1e-5
    assert fm0(x, teeth) == pytest.approx(2.0, rel=1e-4)
    exact = amplitude * np.sin(teeth * _theta(80 * teeth))  # a sample on each peak
    assert fm0(exact, teeth) == pytest.approx(2.0, rel=1e-12)
    # cos u + 0.5 cos 2u = c^2 + c - 0.5 with c = cos u: max 1.5 (c = 1), min -0.75 (c = -1/2)
    cosines = np.cos(teeth * _theta()) + 0.5 * np.cos(2 * teeth * _theta())
    assert fm0(cosines, teeth) == pytest.approx((1.5 + 0.75) / 1.5, rel=1e-5)
    # non-mesh content raises the peak-to-peak, not the denominator
    with_fault = exact + 0.5 * np.sin(3 * _theta(80 * teeth))
    assert fm0(with_fault, teeth) > 2.0


def test_energy_ratio_of_known_parts():
    theta = _theta()
    regular = 2.0 * np.sin(20 * theta) + 1.0 * np.cos(21 * theta)  # rms sqrt(5/2)
    difference = 0.3 * np.sin(37 * theta)  # rms 0.3 / sqrt 2
    assert energy_ratio(difference, regular) == pytest.approx(0.3 / np.sqrt(5.0), rel=1e-12)


def test_sideband_energy_ratio_of_a_synthetic_spectrum():
    f = np.arange(0.0, 2000.0, 0.5)
    a = np.full(f.size, 1e-3)
    mesh_hz, shaft_hz = 500.0, 12.5
    a[f == mesh_hz] = 2.0
    sidebands = {1: 0.4, 2: 0.2, 3: 0.1, 4: 0.05, 5: 0.02, 6: 0.01, 7: 5.0}  # 7th is outside n = 6
    for k, value in sidebands.items():
        a[f == mesh_hz + k * shaft_hz] = value
        a[f == mesh_hz - k * shaft_hz] = 0.5 * value
    expected = 1.5 * sum(sidebands[k] for k in range(1, 7)) / 2.0
    assert sideband_energy_ratio(f, a, mesh_hz, shaft_hz) == pytest.approx(expected, rel=1e-12)
    assert sideband_energy_ratio(f, a, mesh_hz, shaft_hz, n_sidebands=1) == pytest.approx(1.5 * 0.4 / 2.0)
    # off-grid request: nearest bin (500.2 -> 500.0, 12.6 spacing -> 512.6 -> 512.5, ...)
    assert sideband_energy_ratio(f, a, 500.2, 12.52, n_sidebands=1) == pytest.approx(1.5 * 0.4 / 2.0)


def test_na4_of_stationary_gaussian_records_is_about_three():
    rng = np.random.default_rng(7)
    records = rng.standard_normal((10, 65_536))
    assert na4(records) == pytest.approx(3.0, abs=0.1)
    trend = na4_trend(list(records))
    assert trend.shape == (10,)
    np.testing.assert_allclose(trend, 3.0, atol=0.1)
    # one record: its kurtosis
    assert na4([records[0]]) == pytest.approx(kurtosis(records[0]), rel=1e-12)


def test_na4_normalises_by_the_mean_variance_of_the_run_so_far():
    g = np.random.default_rng(3).standard_normal(4096)
    # nine healthy records, then one with twice the amplitude: fourth moment x16, mean variance (9 + 4) / 10
    records = [g] * 9 + [2.0 * g]
    assert na4(records) == pytest.approx(kurtosis(g) * 16 / (13 / 10) ** 2, rel=1e-12)
    # literal formula N sum (r - rbar)^4 / ((1/M) sum_j sum_i (r_ij - rbar_j)^2)^2
    n, m = g.size, len(records)
    centred = [r - r.mean() for r in records]
    literal = n * np.sum(centred[-1] ** 4) / (sum(np.sum(c**2) for c in centred) / m) ** 2
    assert na4(records) == pytest.approx(literal, rel=1e-12)
    # kurtosis does not see the growth, NA4 does
    assert kurtosis(records[-1]) == pytest.approx(kurtosis(g), rel=1e-12)


def test_condition_indicators_from_tsa():
    teeth = 20
    theta = np.linspace(0.0, 2 * np.pi * 8, 8 * 1000, endpoint=False)
    wrapped = np.mod(theta - 2.0 + np.pi, 2 * np.pi) - np.pi
    signal = np.sin(teeth * theta) + 0.2 * np.exp(-0.5 * (wrapped / 0.05) ** 2)
    sa = synchronous_average(signal, theta, teeth=teeth)
    result = condition_indicators_from_average(sa)
    assert isinstance(result, ConditionIndicators)
    direct = condition_indicators(sa.average, sa.difference(), sa.residual(), sa.regular(), teeth)
    assert result == direct
    values = result.as_dict()
    assert set(values) == {
        "rms",
        "peak_to_peak",
        "crest_factor",
        "kurtosis",
        "fm0",
        "fm4",
        "m6a",
        "m8a",
        "na4",
        "energy_ratio",
    }
    assert values["fm4"] > 3.0  # a local bump makes the difference signal peaky
    assert values["na4"] == pytest.approx(kurtosis(sa.residual()), rel=1e-12)
    assert values["energy_ratio"] == pytest.approx(rms(sa.difference()) / rms(sa.regular()), rel=1e-12)


def test_bad_inputs_raise_naming_the_parameter():
    with pytest.raises(ValueError, match="signal has zero variance"):
        kurtosis(np.ones(10))
    with pytest.raises(ValueError, match="difference has zero variance"):
        m6a(np.zeros(10))
    with pytest.raises(ValueError, match="difference must be 1-D"):
        fm4(np.ones((3, 3)))
    with pytest.raises(ValueError, match="signal must be finite, sample 2"):
        rms([1.0, 2.0, np.inf])
    with pytest.raises(ValueError, match="signal is all zero"):
        crest_factor(np.zeros(4))
    with pytest.raises(ValueError, match="teeth must be a positive integer, got 0"):
        fm0(np.sin(_theta()), 0)
    with pytest.raises(ValueError, match="tsa must have at least 2 \\* teeth = 40"):
        fm0(np.sin(_theta(30)), 20)
    with pytest.raises(ValueError, match="tsa has no content at the mesh orders"):
        fm0(np.sin(3 * _theta()), 20)
    with pytest.raises(ValueError, match="regular is all zero"):
        energy_ratio(np.ones(4), np.zeros(4))
    with pytest.raises(ValueError, match="residual_records must hold at least 1 record"):
        na4([])
    with pytest.raises(ValueError, match="residual_records must be a sequence of 1-D records"):
        na4(np.ones(8))
    with pytest.raises(ValueError, match=r"residual_records\[1\] has zero variance"):
        na4([np.arange(4.0), np.zeros(4)])
    f = np.arange(0.0, 100.0, 1.0)
    a = np.ones(f.size)
    with pytest.raises(ValueError, match="shaft_hz must be >= the spectrum resolution 1 Hz.*got 0.5"):
        sideband_energy_ratio(f, a, 50.0, 0.5)
    with pytest.raises(ValueError, match=r"mesh_hz \+- n_sidebands \* shaft_hz = -10 .. 110 Hz"):
        sideband_energy_ratio(f, a, 50.0, 10.0)
    with pytest.raises(ValueError, match="n_sidebands must be a positive integer, got 0"):
        sideband_energy_ratio(f, a, 50.0, 5.0, n_sidebands=0)
    with pytest.raises(ValueError, match="equal lengths"):
        sideband_energy_ratio(f, a[:-1], 50.0, 5.0)
    with pytest.raises(ValueError, match="spectrum_frequency_hz must be strictly increasing"):
        sideband_energy_ratio(f[::-1], a, 50.0, 5.0)
    zero_at_mesh = a.copy()
    zero_at_mesh[50] = 0.0
    with pytest.raises(ValueError, match="spectrum amplitude at mesh_hz=50.0 is 0.0"):
        sideband_energy_ratio(f, zero_at_mesh, 50.0, 5.0)
