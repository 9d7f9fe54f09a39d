"""Spectral kurtosis and the fast kurtogram on a synthetic bearing-fault signal: a 97 Hz train of impacts
each ringing a 3.5 kHz resonance, in white Gaussian noise, under a strong 30 Hz sinusoid."""

import math

import numpy as np
import pytest

from gearbody.analysis.envelope import envelope_spectrum
from gearbody.analysis.kurtogram import Kurtogram, fast_kurtogram, spectral_kurtosis
from gearbody.errors import InputError

FS_HZ = 20_000.0
DURATION_S = 2.0
REPETITION_HZ, RESONANCE_HZ, DECAY_S = 97.0, 3500.0, 1e-3


def _fault_signal(seed: int, noise_rms: float = 0.3) -> np.ndarray:
    n = int(FS_HZ * DURATION_S)
    t = np.arange(n) / FS_HZ
    x = np.zeros(n)
    for k in range(int(DURATION_S * REPETITION_HZ) + 1):
        t0 = k / REPETITION_HZ
        i0 = int(math.ceil(t0 * FS_HZ))
        tt = t[i0 : i0 + 400] - t0
        x[i0 : i0 + 400] += np.exp(-tt / DECAY_S) * np.sin(2 * np.pi * RESONANCE_HZ * tt)
    rng = np.random.default_rng(seed)
    return x + rng.normal(0.0, noise_rms, n) + 5.0 * np.sin(2 * np.pi * 30.0 * t)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_kurtogram_finds_the_resonance_band_and_its_envelope_shows_the_repetition_rate(seed):
    x = _fault_signal(seed)
    kg = fast_kurtogram(x, FS_HZ)
    assert isinstance(kg, Kurtogram)
    lo, hi = kg.band_hz
    assert lo <= RESONANCE_HZ <= hi
    assert kg.max_kurtosis > 1.0
    assert kg.kurtosis[0, 0] < 0.0  # the whole band: the 30 Hz sinusoid hides the impacts
    spectrum = envelope_spectrum(kg.bandpass(x), FS_HZ, max_frequency_hz=1000.0)
    top = spectrum.frequency_hz[1 + int(np.argmax(spectrum.amplitude[1:]))]
    assert abs(top - REPETITION_HZ) <= spectrum.resolution_hz
    same = envelope_spectrum(x, FS_HZ, band_hz=kg.band_hz, max_frequency_hz=1000.0)
    np.testing.assert_allclose(same.amplitude, spectrum.amplitude, rtol=1e-9, atol=1e-12)


def test_kurtogram_rows_follow_antonis_one_third_binary_tree():
    kg = fast_kurtogram(np.random.default_rng(5).normal(size=2**15), 1000.0, max_level=4)
    np.testing.assert_allclose(kg.levels, [0, 1, math.log2(3), 2, 1 + math.log2(3), 3, 2 + math.log2(3), 4])
    assert kg.n_bands == (1, 2, 3, 4, 6, 8, 12, 16)
    assert kg.kurtosis.shape == (8, 48)
    centres, values = kg.band_values(4)
    np.testing.assert_allclose(centres, (np.arange(6) + 0.5) * 500.0 / 6)
    assert values.shape == (6,)
    assert kg.bandwidth_hz == pytest.approx(1000.0 / 2 ** (kg.level + 1), rel=1e-12)


def test_kurtogram_of_white_gaussian_noise_is_near_zero_and_a_tone_reads_minus_one():
    noise = np.random.default_rng(11).normal(size=2**17)
    kg = fast_kurtogram(noise, 1000.0)
    assert kg.levels[-1] == 7
    assert np.max(np.abs(kg.kurtosis)) < 0.5
    assert abs(kg.kurtosis[0, 0]) < 0.05
    t = np.arange(2**17) / 1000.0
    tone = fast_kurtogram(noise * 0.01 + np.sin(2 * np.pi * 130.0 * t), 1000.0, max_level=3)
    assert tone.band_values(5)[1][2] == pytest.approx(-1.0, abs=0.01)  # level 3, band 125-187.5 Hz


def test_spectral_kurtosis_of_white_gaussian_noise_is_bounded_near_zero():
    sk = spectral_kurtosis(np.random.default_rng(13).normal(size=2**18), 1000.0, 256)
    inner = sk.kurtosis[1:-1]  # DC and Nyquist bins are real: 1 for Gaussian noise
    assert abs(np.mean(inner)) < 0.02
    assert np.max(np.abs(inner)) < 0.3
    assert sk.kurtosis[0] == pytest.approx(1.0, abs=0.3) and sk.kurtosis[-1] == pytest.approx(1.0, abs=0.3)
    assert sk.n_frames == (2**18 - 256) // 64 + 1 and sk.frequency_hz[-1] == 500.0


def test_spectral_kurtosis_peaks_at_the_resonance_and_reads_minus_one_on_a_tone():
    sk = spectral_kurtosis(_fault_signal(0), FS_HZ, 64)  # 3.2 ms frames, shorter than the 10.3 ms spacing
    inner = sk.kurtosis[1:-1]
    assert abs(sk.frequency_hz[1 + int(np.argmax(inner))] - RESONANCE_HZ) <= sk.frequency_hz[1]
    assert np.max(inner) > 1.0
    t = np.arange(2**16) / 1000.0
    tone = np.sin(2 * np.pi * 40 * 1000.0 / 256 * t) + 0.01 * np.random.default_rng(2).normal(size=t.size)
    assert spectral_kurtosis(tone, 1000.0, 256).kurtosis[40] == pytest.approx(-1.0, abs=1e-3)


@pytest.mark.parametrize(
    ("call", "word"),
    [
        (lambda x: fast_kurtogram(x, 1000.0, max_level=0), "max_level"),
        (lambda x: fast_kurtogram(x, 1000.0, max_level=10), "max_level"),
        (lambda x: fast_kurtogram(x[:200], 1000.0), "256 samples"),
        (lambda x: fast_kurtogram(x, -1.0), "sample_rate_hz"),
        (lambda x: spectral_kurtosis(x, 1000.0, 4), "nperseg"),
        (lambda x: spectral_kurtosis(x, 1000.0, 2**20), "nperseg"),
    ],
)
def test_bad_arguments_are_input_errors_naming_them(call, word):
    with pytest.raises(InputError, match=word):
        call(np.random.default_rng(0).normal(size=2**16))
