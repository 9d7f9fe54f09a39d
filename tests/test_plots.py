"""Plots write PNGs of the requested pixel size without a display."""

import matplotlib.image as mpimg
import numpy as np
import pytest

from gearbody.analysis import amplitude_spectrum, fold_over_mesh_period
from gearbody.plotting.result import harmonic_labels, plot_kd_folded, plot_kd_time, plot_spectrum


def _check_png(path, size_px):
    assert path.exists() and path.stat().st_size > 0
    image = mpimg.imread(path)
    assert (image.shape[1], image.shape[0]) == size_px


@pytest.fixture(scope="module")
def signals():
    fs_hz = 5000.0
    t = np.arange(5000) / fs_hz
    angle = 100.0 * t
    phase = (angle * 29 / (2 * np.pi)) % 1.0
    kd = 1.0 + 0.5 * np.sin(2 * np.pi * phase) + 0.05 * np.sin(2 * np.pi * 3.0 * t)
    return t, angle, kd, fs_hz


def test_plot_kd_time(tmp_path, signals):
    t, _, kd, _ = signals
    out = plot_kd_time(t, kd, tmp_path / "kd_time.png", title="K_d", boundaries_s=(0.25, 0.5))
    _check_png(out, (1000, 600))


def test_plot_kd_folded(tmp_path, signals):
    t, angle, kd, _ = signals
    folded = fold_over_mesh_period(kd, angle, 29, bins=40)
    out = plot_kd_folded(folded, tmp_path / "sub" / "folded.png", title="Fig. 6 like", size_px=(640, 480))
    _check_png(out, (640, 480))


@pytest.mark.parametrize("log_amplitude", [False, True])
def test_plot_spectrum(tmp_path, signals, log_amplitude):
    t, _, _, fs_hz = signals
    fz = 29 * 100.0 / (2 * np.pi)
    x = np.sin(2 * np.pi * fz * t) + 0.3 * np.sin(2 * np.pi * 2 * fz * t)
    spec = amplitude_spectrum(x, fs_hz)
    out = plot_spectrum(
        spec,
        str(tmp_path / f"spec_{log_amplitude}.png"),
        mesh_frequency_hz=fz,
        shaft_frequencies_hz=(100.0 / (2 * np.pi), 33.0),
        title="spectrum",
        fmax_hz=2000.0,
        ylabel="Acceleration amplitude [m/s^2]",
        log_amplitude=log_amplitude,
        size_px=(801, 333),
        dpi=72,
    )
    _check_png(out, (801, 333))


def test_plot_spectrum_defaults_and_named_shafts(tmp_path, signals):
    t, _, kd, fs_hz = signals
    out = plot_spectrum(amplitude_spectrum(kd, fs_hz), tmp_path / "s.png", shaft_frequencies_hz={"f_1": 16.0})
    _check_png(out, (1000, 600))


def test_harmonic_labels():
    assert harmonic_labels(3) == ["f_z", "2f_z", "3f_z"]
    assert harmonic_labels(2, "f_{z1}") == ["f_{z1}", "2f_{z1}"]
