"""Envelope spectra: the documented amplitude conventions on an amplitude-modulated tone (exact bins)."""

import numpy as np
import pytest

from gearbody.analysis.envelope import EnvelopeSpectrum, analytic_band, band_signal, envelope_spectrum
from gearbody.errors import InputError

FS_HZ = 10_000.0
N = 2**16  # 5-smooth: no zero padding, the record holds whole periods
DF_HZ = FS_HZ / N
FC_HZ, FM_HZ = 1000 * DF_HZ, 50 * DF_HZ  # carrier ~152.6 Hz, modulation ~7.63 Hz, both on bins
M = 0.5


def _am_tone() -> np.ndarray:
    t = np.arange(N) / FS_HZ
    return (1.0 + M * np.cos(2 * np.pi * FM_HZ * t)) * np.cos(2 * np.pi * FC_HZ * t)


def _at(spectrum: EnvelopeSpectrum, f_hz: float) -> float:
    k = int(round(f_hz / spectrum.resolution_hz))
    assert spectrum.frequency_hz[k] == pytest.approx(f_hz, rel=1e-12)
    return float(spectrum.amplitude[k])


@pytest.mark.parametrize("window", ["hann", "boxcar"])
def test_squared_envelope_of_an_am_tone_reads_its_dc_modulation_and_second_harmonic(window):
    s = envelope_spectrum(_am_tone(), FS_HZ, convention="squared", window=window)
    assert s.convention == "squared" and s.band_hz == (0.0, FS_HZ / 2) and s.n_fft == N
    # |a|^2 = 1 + m^2/2 + 2 m cos(w_m t) + m^2/2 cos(2 w_m t)
    assert _at(s, 0.0) == pytest.approx(1.0 + M**2 / 2, rel=1e-6)  # 1.125
    assert _at(s, FM_HZ) == pytest.approx(2 * M, rel=1e-6)  # 1.0
    assert _at(s, 2 * FM_HZ) == pytest.approx(M**2 / 2, rel=1e-6)  # 0.125
    assert _at(s, 3 * FM_HZ) < 1e-9


@pytest.mark.parametrize("window", ["hann", "boxcar"])
def test_envelope_convention_reads_the_modulation_depth(window):
    s = envelope_spectrum(_am_tone(), FS_HZ, convention="envelope", window=window)
    assert _at(s, 0.0) == pytest.approx(1.0, rel=1e-6)
    assert _at(s, FM_HZ) == pytest.approx(M, rel=1e-6)
    assert _at(s, 2 * FM_HZ) < 1e-9


def test_the_band_keeps_only_what_lies_inside_it():
    t = np.arange(N) / FS_HZ
    other = 0.8 * (1 + 0.5 * np.cos(2 * np.pi * 3 * FM_HZ * t)) * np.cos(2 * np.pi * 3000 * DF_HZ * t)
    x = _am_tone() + other
    inside = envelope_spectrum(x, FS_HZ, band_hz=(50.0, 300.0))
    assert _at(inside, FM_HZ) == pytest.approx(1.0, rel=1e-6)
    assert _at(inside, 3 * FM_HZ) < 1e-9  # the other carrier's modulation is outside the band
    both = envelope_spectrum(x, FS_HZ)
    assert _at(both, 3 * FM_HZ) > 0.1
    assert np.allclose(band_signal(x, FS_HZ, (50.0, 300.0)), _am_tone(), atol=1e-9)


def test_analytic_band_of_the_whole_band_is_scipy_hilbert():
    from scipy.signal import hilbert

    x = np.random.default_rng(3).normal(size=1000)  # 5-smooth: no padding
    np.testing.assert_allclose(analytic_band(x, 1.0), hilbert(x), atol=1e-12)


def test_max_frequency_truncates_and_a_padded_record_keeps_its_length():
    s = envelope_spectrum(_am_tone(), FS_HZ, max_frequency_hz=10 * FM_HZ)
    assert s.frequency_hz[-1] == pytest.approx(10 * FM_HZ) and s.amplitude.size == 501
    x = np.random.default_rng(4).normal(size=10_007)  # prime: zero-padded to a fast length
    padded = envelope_spectrum(x, 1000.0)
    assert padded.n_fft >= 10_007 and padded.amplitude.size == padded.n_fft // 2 + 1
    assert padded.amplitude[0] == pytest.approx(2 * np.mean(x**2), rel=0.05)  # |a|^2 = x^2 + H(x)^2


@pytest.mark.parametrize(
    ("kwargs", "word"),
    [
        ({"band_hz": (100.0, 50.0)}, "band_hz"),
        ({"band_hz": (0.0, 6000.0)}, "band_hz"),
        ({"band_hz": 300.0}, "band_hz"),
        ({"convention": "hilbert"}, "convention"),
        ({"max_frequency_hz": -1.0}, "max_frequency_hz"),
        ({"window": "no-such-window"}, "window"),
    ],
)
def test_bad_arguments_are_input_errors_naming_them(kwargs, word):
    with pytest.raises(InputError, match=word):
        envelope_spectrum(_am_tone(), FS_HZ, **kwargs)


def test_bad_signal_and_rate_are_input_errors():
    with pytest.raises(InputError, match="signal"):
        envelope_spectrum(np.ones((4, 4)), FS_HZ)
    with pytest.raises(InputError, match="finite"):
        envelope_spectrum(np.array([1.0, np.nan, 0.0, 1.0]), FS_HZ)
    with pytest.raises(InputError, match="sample_rate_hz"):
        envelope_spectrum(_am_tone(), 0.0)
