"""Real cepstrum, cepstral peaks, comb liftering and cepstrum pre-whitening on synthetic gear and bearing
signals with lines on exact bins (N = 2^16 samples at 10 kHz, bin 0.153 Hz)."""

import numpy as np
import pytest
import scipy.fft as sfft

from gearbody.analysis.cepstrum import (
    CepstralPeak,
    Cepstrum,
    cepstral_peak,
    cepstrum_prewhiten,
    lifter_family,
    real_cepstrum,
)
from gearbody.analysis.indicators import kurtosis
from gearbody.errors import InputError

FS_HZ = 10_000.0
N = 2**16
DF_HZ = FS_HZ / N
SHAFT_HZ = 128 * DF_HZ  # 19.53 Hz: 1 / SHAFT_HZ = 512 samples
MESH_HZ = 40 * SHAFT_HZ  # 40 teeth: 781.25 Hz
OTHER_HZ = 15_000 * DF_HZ  # 2288.8 Hz, another stage's mesh tone, off the shaft-rate grid
T = np.arange(N) / FS_HZ
SIDEBANDS = (-2, -1, 1, 2)


def _modulated_mesh(seed: int = 0, noise_rms: float = 0.01, depth: float = 1.0) -> np.ndarray:
    """Mesh tone amplitude-modulated at the shaft rate: sidebands +-1 (0.15) and +-2 (0.075)."""
    shaft = 2 * np.pi * SHAFT_HZ * T
    modulation = 1 + depth * (0.3 * np.cos(shaft) + 0.15 * np.cos(2 * shaft + 0.5))
    noise = np.random.default_rng(seed).normal(0.0, noise_rms, N)
    return modulation * np.cos(2 * np.pi * MESH_HZ * T) + noise


def _line(x: np.ndarray, f_hz: float) -> float:
    return float(np.abs(sfft.rfft(x)[int(round(f_hz / DF_HZ))]) * 2 / x.size)


def _sideband_energy(x: np.ndarray) -> float:
    return sum(_line(x, MESH_HZ + k * SHAFT_HZ) ** 2 for k in SIDEBANDS)


def test_real_cepstrum_rebuilds_the_log_spectrum_and_has_its_quefrency_axis():
    x = _modulated_mesh()
    ceps = real_cepstrum(x, FS_HZ)
    assert isinstance(ceps, Cepstrum) and ceps.cepstrum.size == N // 2 + 1
    assert ceps.quefrency_s[512] == pytest.approx(1 / SHAFT_HZ, rel=1e-12)
    full = np.concatenate([ceps.cepstrum, ceps.cepstrum[-2:0:-1]])  # even: c(N - n) = c(n)
    np.testing.assert_allclose(sfft.rfft(full).real, np.log(np.abs(sfft.rfft(x))), atol=1e-9)


def test_shaft_rate_modulation_shows_a_cepstral_peak_at_one_over_the_shaft_rate():
    peak = cepstral_peak(_modulated_mesh(), FS_HZ, SHAFT_HZ)
    assert isinstance(peak, CepstralPeak) and peak.nperseg == 4096  # 8 fs / f_shaft = 4096
    assert peak.quefrency_s == pytest.approx(1 / SHAFT_HZ, abs=0.5 / FS_HZ)
    assert peak.prominence > 6.0
    plain = cepstral_peak(_modulated_mesh(depth=0.0), FS_HZ, SHAFT_HZ)
    assert plain.prominence < 3.0
    assert peak.amplitude > 2.5 * plain.amplitude


def test_liftering_the_shaft_rate_family_removes_its_sidebands_and_with_them_the_carrier():
    x = _modulated_mesh()
    edited = lifter_family(x, FS_HZ, SHAFT_HZ, width_s=5e-3)
    assert _sideband_energy(edited) < 1e-2 * _sideband_energy(x)
    # the carrier is the k = 0 member of its own sideband family: the lifter cannot tell it apart
    assert _line(edited, MESH_HZ) < 0.1 * _line(x, MESH_HZ)
    # the broadband noise floor is left (its median bin within 5 %)
    assert np.median(np.abs(sfft.rfft(edited))) == pytest.approx(np.median(np.abs(sfft.rfft(x))), rel=0.05)
    kept = np.abs(sfft.rfft(lifter_family(x, FS_HZ, SHAFT_HZ, width_s=5e-3, keep=True)))
    top = np.sort(np.argsort(kept)[-5:]) * DF_HZ  # the family alone: its five lines are the top bins
    np.testing.assert_allclose(top, MESH_HZ + np.arange(-2, 3) * SHAFT_HZ)


def test_a_narrow_lifter_removes_a_wideband_shaft_harmonic_family_and_leaves_another_tone():
    impacts = np.zeros(N)
    impacts[::512] = 1.0  # once per shaft revolution, ringing a short response: harmonics to ~3 kHz
    ring = np.exp(-np.arange(40) / 4.0) * np.sin(2 * np.pi * 0.3 * np.arange(40))
    family = sfft.irfft(sfft.rfft(impacts) * sfft.rfft(ring, N), N)
    x = family + 0.5 * np.cos(2 * np.pi * OTHER_HZ * T) + np.random.default_rng(0).normal(0.0, 0.01, N)
    edited = lifter_family(x, FS_HZ, SHAFT_HZ)  # 3-sample notches at every k / f_shaft
    harmonics = np.arange(128, N // 2, 128)
    before, after = np.abs(sfft.rfft(x)[harmonics]), np.abs(sfft.rfft(edited)[harmonics])
    assert np.sum(after**2) < 1e-3 * np.sum(before**2)
    # the other tone's bin moves by the lifter's share of the noise's log-spectrum scatter, ~4 % rms here
    assert _line(edited, OTHER_HZ) == pytest.approx(_line(x, OTHER_HZ), rel=0.05)
    alone = lifter_family(x, FS_HZ, SHAFT_HZ, rahmonics=5, keep=True)
    assert _line(alone, OTHER_HZ) < 0.5 * _line(x, OTHER_HZ)


def test_cepstrum_prewhitening_raises_the_kurtosis_of_impacts_under_a_strong_tone():
    rng = np.random.default_rng(2)
    impacts = np.zeros(N)
    impacts[::103] = 1.0  # ~97 Hz repetition
    resonance = np.exp(-np.arange(60) / 8.0) * np.sin(2 * np.pi * 0.35 * np.arange(60))
    bearing = sfft.irfft(sfft.rfft(impacts) * sfft.rfft(resonance, N), N)
    x = 20.0 * np.cos(2 * np.pi * MESH_HZ * T) + bearing + rng.normal(0.0, 0.05, N)
    whitened = cepstrum_prewhiten(x)
    assert kurtosis(x) < 2.0
    assert kurtosis(whitened) > 2 * kurtosis(x) and kurtosis(whitened) > 3.0  # above Gaussian
    assert np.allclose(np.abs(sfft.rfft(whitened)), 1.0)


@pytest.mark.parametrize(
    ("call", "word"),
    [
        (lambda x: lifter_family(x, FS_HZ, 0.0), "spacing_hz"),
        (lambda x: lifter_family(x, FS_HZ, 0.1), "spacing_hz"),
        (lambda x: lifter_family(x, FS_HZ, SHAFT_HZ, width_s=0.1), "width_s"),
        (lambda x: lifter_family(x, FS_HZ, SHAFT_HZ, rahmonics=0), "rahmonics"),
        (lambda x: cepstral_peak(x, FS_HZ, 0.1), "spacing_hz"),
        (lambda x: cepstral_peak(x, FS_HZ, SHAFT_HZ, nperseg=512), "nperseg"),
        (lambda x: cepstral_peak(x, FS_HZ, SHAFT_HZ, search_s=1.0), "search_s"),
        (lambda x: real_cepstrum(np.zeros(64), FS_HZ), "zeros"),
        (lambda x: real_cepstrum(x, float("inf")), "sample_rate_hz"),
    ],
)
def test_bad_arguments_are_input_errors_naming_them(call, word):
    with pytest.raises(InputError, match=word):
        call(_modulated_mesh())
