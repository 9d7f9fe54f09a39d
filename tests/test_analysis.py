"""Engine-free analysis on synthetic signals with known answers."""

import numpy as np
import pytest

from gearbody.analysis import (
    FoldedSignal,
    amplitude_spectrum,
    fold_over_mesh_period,
    mesh_harmonics,
    mesh_phase,
    peak_at,
    peak_near,
    periods_stats,
    separation_stats,
    unstable,
)

# --- spectrum -------------------------------------------------------------------------------------------

FS_HZ = 4096.0
N = 4096  # 1 Hz bins


def _sine(amplitude: float, f_hz: float, n: int = N, fs_hz: float = FS_HZ, phase_rad: float = 0.3):
    t = np.arange(n) / fs_hz
    return amplitude * np.sin(2 * np.pi * f_hz * t + phase_rad)


@pytest.mark.parametrize("window", ["hann", "boxcar", "hamming", ("kaiser", 8.0)])
def test_sine_on_bin_shows_its_amplitude(window):
    spec = amplitude_spectrum(_sine(3.7, 250.0), FS_HZ, window=window)
    assert spec.resolution_hz == pytest.approx(1.0)
    assert spec.frequency_hz[0] == 0.0 and spec.frequency_hz[-1] == pytest.approx(FS_HZ / 2)
    # exact for Hann/boxcar; other windows leak ~1e-7 from the negative-frequency image
    assert peak_at(spec, 250.0, 0.5) == pytest.approx(3.7, rel=1e-6)
    peak = peak_near(spec, 250.0, 5.0)
    assert peak.frequency_hz == pytest.approx(250.0)


def test_sine_off_bin_within_hann_scalloping():
    amplitude = 2.0
    for offset in (0.1, 0.25, 0.5):
        spec = amplitude_spectrum(_sine(amplitude, 250.0 + offset), FS_HZ)
        a = peak_at(spec, 250.0 + offset, 1.0)
        # Hann scalloping loss at most 1.42 dB (0.849 at half a bin)
        assert 0.845 * amplitude <= a <= amplitude * (1 + 1e-6)
    half_bin = peak_at(amplitude_spectrum(_sine(amplitude, 250.5), FS_HZ), 250.5, 1.0)
    assert half_bin == pytest.approx(0.8488 * amplitude, rel=2e-3)


def test_two_sines_odd_length_and_mean_handling():
    n = 3001
    fs = 3001.0  # 1 Hz bins, odd N: no Nyquist bin
    x = 5.0 + _sine(1.0, 100.0, n, fs) + _sine(0.25, 300.0, n, fs)
    spec = amplitude_spectrum(x, fs)
    assert peak_at(spec, 100.0, 0.5) == pytest.approx(1.0, rel=1e-9)
    assert peak_at(spec, 300.0, 0.5) == pytest.approx(0.25, rel=1e-9)
    assert spec.amplitude[0] < 1e-9  # mean removed
    raw = amplitude_spectrum(x, fs, window="boxcar", detrend=False)
    assert raw.amplitude[0] == pytest.approx(5.0)  # DC not doubled
    lin = amplitude_spectrum(x + 0.01 * np.arange(n), fs, detrend="linear")
    assert peak_at(lin, 100.0, 0.5) == pytest.approx(1.0, rel=2e-3)


def test_nyquist_bin_not_doubled():
    x = 1.5 * np.cos(np.pi * np.arange(64))  # +-1.5 at fs/2
    spec = amplitude_spectrum(x, 64.0, window="boxcar", detrend=False)
    assert spec.amplitude[-1] == pytest.approx(1.5)


def test_spectrum_input_validation():
    with pytest.raises(ValueError):
        amplitude_spectrum(np.ones((4, 4)), 10.0)
    with pytest.raises(ValueError):
        amplitude_spectrum([1.0, np.nan, 2.0], 10.0)
    with pytest.raises(ValueError):
        amplitude_spectrum([1.0, 2.0], -1.0)
    with pytest.raises(ValueError):
        amplitude_spectrum([1.0, 2.0, 3.0], 10.0, detrend="quadratic")
    spec = amplitude_spectrum(_sine(1.0, 10.0), FS_HZ)
    with pytest.raises(ValueError, match="no spectrum bin"):
        peak_at(spec, 10.3, 0.1)


def test_mesh_harmonics():
    np.testing.assert_allclose(mesh_harmonics(500.0, 1600.0), [500.0, 1000.0, 1500.0])
    np.testing.assert_allclose(mesh_harmonics(0.1, 0.3), [0.1, 0.2, 0.3])  # inclusive despite rounding
    assert mesh_harmonics(500.0, 400.0).size == 0
    with pytest.raises(ValueError):
        mesh_harmonics(0.0, 100.0)


# --- folding --------------------------------------------------------------------------------------------


def test_mesh_phase():
    z1 = 29
    angle = np.array(
        [0.0, np.pi / z1, 2 * np.pi / z1, -np.pi / z1, 10 * 2 * np.pi / z1 + 0.25 * 2 * np.pi / z1]
    )
    np.testing.assert_allclose(mesh_phase(angle, z1), [0.0, 0.5, 0.0, 0.5, 0.25], atol=1e-12)
    phase = mesh_phase(np.linspace(-50.0, 50.0, 10001), z1)
    assert np.all((phase >= 0.0) & (phase < 1.0))


def test_fold_recovers_function_of_mesh_phase():
    z1, bins = 29, 50
    rng = np.random.default_rng(1)
    t = np.linspace(0.0, 2.0, 200_001)
    # non-uniform rotation: the fold must use the given angle, not a nominal speed
    angle = 100.0 * t + 0.02 * np.sin(2 * np.pi * 7.0 * t) + 3.0
    p = mesh_phase(angle, z1)
    kd = 1.0 + 0.3 * np.sin(2 * np.pi * p) + 0.1 * (p > 0.6)

    folded = fold_over_mesh_period(kd, angle, z1, bins=bins)
    assert isinstance(folded, FoldedSignal) and folded.bins == bins
    np.testing.assert_allclose(folded.percent_of_period, (np.arange(bins) + 0.5) * 100.0 / bins)
    assert folded.count.sum() == t.size and np.all(folded.count > 0)
    centre_phase = folded.percent_of_period / 100.0
    expected = 1.0 + 0.3 * np.sin(2 * np.pi * centre_phase) + 0.1 * (centre_phase > 0.6)
    smooth = np.abs(centre_phase - 0.6) > 1.0 / bins  # skip the bin with the step
    # within-bin variation of the sine is at most 0.3 * 2 pi / bins / 2
    np.testing.assert_allclose(folded.mean[smooth], expected[smooth], atol=0.3 * np.pi / bins)
    assert np.all(folded.minimum <= folded.mean) and np.all(folded.mean <= folded.maximum)
    assert np.nanmax(folded.maximum) == pytest.approx(kd.max())

    # noise on top averages out; a piecewise-constant function of the phase is recovered exactly
    step = np.floor(p * 4) / 4.0
    folded_step = fold_over_mesh_period(step + rng.normal(0, 1e-3, t.size), angle, z1, bins=4)
    np.testing.assert_allclose(folded_step.mean, [0.0, 0.25, 0.5, 0.75], atol=1e-4)


def test_fold_empty_bins_nan_and_bad_input():
    z1 = 10
    angle = np.array([0.01, 0.02]) * 2 * np.pi / z1  # both in the first 10 % of the period
    folded = fold_over_mesh_period([1.0, 3.0], angle, z1, bins=10)
    assert folded.count.tolist() == [2] + [0] * 9
    assert folded.mean[0] == 2.0 and folded.minimum[0] == 1.0 and folded.maximum[0] == 3.0
    assert np.all(np.isnan(folded.mean[1:]))
    with pytest.raises(ValueError):
        fold_over_mesh_period([1.0, 2.0], [0.0], z1)
    with pytest.raises(ValueError):
        fold_over_mesh_period([1.0], [0.0], z1, bins=0)
    with pytest.raises(ValueError):
        fold_over_mesh_period([1.0], [0.0], 0)


# --- separation and stability ---------------------------------------------------------------------------


def test_separation_counts_hand_made_force():
    force = np.array([100, 50, 0, -5, 20, 80, 0, 30, 40, 0, 0], dtype=float)
    t = np.arange(force.size) * 0.1
    stats = separation_stats(force, t)
    assert stats.contact_losses == 3  # 50->0, 80->0, 40->0
    assert stats.impacts == 2  # -5->20, 0->30
    # separated samples 2,3,6,9,10: weights 0.1,0.1,0.1,0.1,0.05 of 1.0 s
    assert stats.separated_time_s == pytest.approx(0.45)
    assert stats.duration_s == pytest.approx(1.0)
    assert stats.separated_fraction == pytest.approx(0.45)
    assert stats.first_separation_s == pytest.approx(0.2)
    assert stats.max_kd is None and stats.kd_above_2 is None


def test_separation_start_separated_and_threshold_and_kd():
    force = np.array([0.0, 0.0, 10.0, 10.0, 3.0, 10.0])
    t = np.linspace(0.0, 0.5, force.size)
    stats = separation_stats(force, t, kd=force / 4.0)
    assert (stats.contact_losses, stats.impacts) == (0, 1)
    assert stats.max_kd == pytest.approx(2.5) and stats.kd_above_2 is True
    thr = separation_stats(force, t, threshold_N=5.0)
    assert (thr.contact_losses, thr.impacts) == (1, 2)
    never = separation_stats(np.ones(5), np.arange(5.0), kd=np.full(5, 1.9))
    assert never.contact_losses == never.impacts == 0
    assert never.separated_fraction == 0.0 and never.first_separation_s is None
    assert never.kd_above_2 is False


def test_unstable():
    assert unstable([1.0, 2.01])
    assert not unstable([1.0, 2.0])  # strictly greater than 2
    assert not unstable([])
    assert not unstable([np.nan, 1.5])
    assert unstable([1.0, 1.6], threshold=1.5)


# --- period statistics ----------------------------------------------------------------------------------


def test_periods_stats_on_ramp():
    t = np.linspace(0.0, 4.0, 4001)  # 1 ms steps
    kd = t.copy()  # ramp: K_d equals time
    rows = periods_stats(kd, t, [0.0, 1.0, 2.0, 4.0])
    assert [r["period"] for r in rows] == [1, 2, 3]
    assert [r["samples"] for r in rows] == [1000, 1000, 2001]  # half-open, last closed
    first, second, last = rows
    # samples 0.000..0.999: percentile q at 0.999 * q / 100
    assert first["p50"] == pytest.approx(0.4995)
    assert first["p95"] == pytest.approx(0.999 * 0.95)
    assert first["p99"] == pytest.approx(0.999 * 0.99)
    assert first["max"] == pytest.approx(0.999)
    assert second["p50"] == pytest.approx(1.4995)
    assert last["p50"] == pytest.approx(3.0) and last["p99"] == pytest.approx(2.0 + 2.0 * 0.99)
    assert last["max"] == pytest.approx(4.0)
    assert (last["start_s"], last["end_s"]) == (2.0, 4.0)


def test_periods_stats_empty_period_and_validation():
    rows = periods_stats([1.0, 2.0], [0.0, 0.1], [0.0, 0.5, 1.0])
    assert rows[0]["max"] == 2.0 and rows[1]["samples"] == 0 and np.isnan(rows[1]["p95"])
    with pytest.raises(ValueError):
        periods_stats([1.0], [0.0], [0.0])
    with pytest.raises(ValueError):
        periods_stats([1.0], [0.0], [1.0, 0.0])
