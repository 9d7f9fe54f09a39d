"""Band-limited sampling of signals with jumps (gearbody.analysis.antialias) and its use in simulate().

Hand cases: a square wave's Fourier series is known (4 / (pi k) at odd k), its aliases are not in it,
and the filtered value at any instant is a convolution integral that quad computes piecewise.
"""

import numpy as np
import pytest
from scipy.integrate import quad

from gearbody.analysis import amplitude_spectrum, peak_near
from gearbody.analysis.antialias import _kaiser_beta, _kernel, band_limited_samples, level_crossings

FS, M = 20000.0, 4


def _square(t, f0, phase):
    return np.where(np.mod(t * f0 + phase, 1.0) < 0.5, 1.0, -1.0)


def _square_jumps(f0, phase, t_end):
    n = np.arange(-1, t_end * f0 + 2)
    return np.concatenate([(n - phase) / f0, (n + 0.5 - phase) / f0])


def test_square_wave_harmonics_are_exact_and_aliases_gone():
    """500 Hz square wave at 20 kHz, 1 s: point samples put every folded harmonic (k > 20) onto the
    odd harmonics below Nyquist and bias them; band-limited samples give 4 / (pi k) to 1e-4."""
    f0, phase = 500.0, 0.123  # jumps between samples
    t = np.arange(int(FS * M) + 1) / (FS * M)
    x = _square(t, f0, phase)
    y = band_limited_samples(t, x, M, _square_jumps(f0, phase, 1.0))[:-1]
    point = x[::M][:-1]
    for k in (1, 3, 5, 7, 15):  # below the pass-band edge 0.4 fs = 8 kHz
        exact = 4 / (np.pi * k)
        sp_y = amplitude_spectrum(y, FS, window="boxcar")
        sp_x = amplitude_spectrum(point, FS, window="boxcar")
        assert peak_near(sp_y, k * f0, 1.0).amplitude == pytest.approx(exact, rel=1e-4)
        assert abs(peak_near(sp_x, k * f0, 1.0).amplitude / exact - 1) > 1e-3  # aliasing biases these


def test_alias_of_a_mesh_harmonic_is_suppressed():
    """494 Hz square wave: its 41st harmonic folds to 41 f0 - fs = 248.3 Hz in point samples."""
    f0, phase = 493.86, 0.31
    t = np.arange(int(2 * FS * M) + 1) / (FS * M)
    x = _square(t, f0, phase)
    y = band_limited_samples(t, x, M, _square_jumps(f0, phase, 2.0))
    alias = 41 * f0 - FS
    sp_x = amplitude_spectrum(x[::M], FS, window=("kaiser", 14))
    sp_y = amplitude_spectrum(y, FS, window=("kaiser", 14))
    assert peak_near(sp_x, alias, 1.0).amplitude > 0.02  # ~4 / (41 pi) = 0.031
    assert peak_near(sp_y, alias, 1.0).amplitude < 1e-5


def test_each_sample_is_the_convolution_integral():
    """y(t_k) = integral h(t_k - s) x(s) ds with the continuous kernel, by quad between the jumps,
    near jumps and at the record's ends (odd reflection of the continuous part)."""
    f0, phase = 731.0, 0.2
    t_end = 0.02
    t = np.arange(int(t_end * FS * M) + 1) / (FS * M)
    smooth = lambda s: 0.3 * np.sin(2 * np.pi * 900 * s)  # noqa: E731
    x = _square(t, f0, phase) + smooth(t)
    jumps = _square_jumps(f0, phase, t_end)
    y = band_limited_samples(t, x, M, jumps)
    half_w = 32 / FS
    beta = _kaiser_beta(100.0)
    norm = quad(lambda s: _kernel(np.array(s), FS, half_w, beta), -half_w, half_w, limit=400)[0]
    for k in (100, 137, 200, 253):  # away from the ends by more than the kernel's half width
        tk = k / FS

        def integrand(s, tk=tk):
            return _kernel(np.array(tk - s), FS, half_w, beta) * (_square(s, f0, phase) + smooth(s))

        pts = [j for j in jumps if abs(j - tk) < half_w]
        val = quad(integrand, tk - half_w, tk + half_w, points=pts, limit=800)[0] / norm
        # jump sizes are extrapolated from the samples: error ~ dt^3 x''' of the smooth part, ~1e-5 here
        assert y[k] == pytest.approx(float(val), abs=2e-5)


def test_level_crossings_of_a_line():
    t = np.linspace(0, 1, 11)
    np.testing.assert_allclose(level_crossings(t, 3 * t - 1.05), [0.35])
    np.testing.assert_allclose(level_crossings(t, 1.05 - 3 * t, 0.0), [0.35])


def test_records_shorter_than_the_kernel():
    """A constant stays constant and a step keeps its size, also when the record is short."""
    t = np.arange(37) / (FS * M)
    y = band_limited_samples(t, np.full(t.size, 3.0), M, np.array([]))
    np.testing.assert_allclose(y, 3.0, rtol=1e-12)
    y = band_limited_samples(t, np.where(t < 2.1e-4, 0.0, 1.0), M, np.array([2.1e-4]))
    assert y.shape == (10,) and abs(y[0]) < 0.1 and abs(y[-1] - 1) < 0.1


def test_bad_oversampling_is_refused():
    t = np.linspace(0, 1, 11)
    with pytest.raises(ValueError, match="oversampling"):
        band_limited_samples(t, t, 1, np.array([]))


@pytest.fixture(scope="module")
def one_stage_pair():
    """one-stage, steady rated, E(0.5, 10, 0), no friction, 1 s analysed: filter on and off."""
    from gearbody.engine import simulate
    from gearbody.model import load_scenario

    base = [
        'operation.initial_state="steady"',
        "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
        "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
        "operation.t_end_s=1.2",
        "solver.relative_tolerance=1e-10",
        "solver.absolute_tolerance=1e-10",
        "condition.friction_coefficient=0.0",
        "production.error_mode.r=0.0",
    ]
    on = simulate(load_scenario("one-stage", base))
    off = simulate(load_scenario("one-stage", [*base, "solver.anti_aliasing=false"]))
    return on, off


@pytest.mark.slow
def test_simulated_mesh_force_loses_its_aliases_but_keeps_its_harmonics(one_stage_pair):
    on, off = one_stage_pair
    window = on.time_s >= on.time_s[-1] - 1.0
    f_z = float(np.mean(on["mesh_frequency_hz"][window]))
    fs = on.sample_rate_hz
    point = amplitude_spectrum(on["mesh_force_N"][window], fs, window="hann")
    band = amplitude_spectrum(on["mesh_force_bandlimited_N"][window], fs, window="hann")
    for alias in (41 * f_z - fs, fs - 40 * f_z):  # 248.3 and 245.6 Hz
        aliased, clean = peak_near(point, alias, 1.0).amplitude, peak_near(band, alias, 1.0).amplitude
        assert aliased > 0.3  # N; measured ~0.9 and ~8 N
        assert clean < 0.01 and 20 * np.log10(aliased / clean) > 30
    for k in (1, 2, 3, 6):
        a, b = peak_near(point, k * f_z, 1.0).amplitude, peak_near(band, k * f_z, 1.0).amplitude
        assert b == pytest.approx(a, rel=0.02)
    # states and the instantaneous force are the same samples with or without the filter
    np.testing.assert_allclose(on.time_s, off.time_s, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(on["mesh_force_N"], off["mesh_force_N"])
    assert "mesh_force_bandlimited_N" not in off
    # accelerations are band-limited: their mean (rigid-body acceleration) is kept
    assert np.mean(on["pinion_accel_rad_s2"][window]) == pytest.approx(
        np.mean(off["pinion_accel_rad_s2"][window]), abs=0.01 * np.std(off["pinion_accel_rad_s2"])
    )
