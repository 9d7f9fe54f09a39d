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


def _text_boxes(fig):
    """Window extents of every text drawn in ``fig`` (tick labels only where their tick is in view)."""
    from matplotlib.text import Text

    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    ticks = set()
    for ax in fig.axes:
        for axis, (low, high) in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                inside = min(low, high) <= tick.get_loc() <= max(low, high)
                ticks.update({id(tick.label1), id(tick.label2)} if not inside else set())
    texts = [
        t
        for t in fig.findobj(Text)
        if t.get_visible() and t.get_text().strip() and id(t) not in ticks and t.get_alpha() != 0
    ]
    return [(t.get_text(), t.get_window_extent(renderer)) for t in texts]


def _assert_no_overlap_inside(fig):
    boxes = _text_boxes(fig)
    frame = fig.bbox
    for text, box in boxes:
        assert box.x0 >= frame.x0 - 0.5 and box.x1 <= frame.x1 + 0.5, f"{text!r} leaves the figure"
        assert box.y0 >= frame.y0 - 0.5 and box.y1 <= frame.y1 + 0.5, f"{text!r} leaves the figure"
    for i, (a, box_a) in enumerate(boxes):
        for b, box_b in boxes[i + 1 :]:
            assert not box_a.overlaps(box_b), f"{a!r} overlaps {b!r}"
    return boxes


def test_spectrum_labels_neither_overlap_nor_leave_the_figure():
    """The run's spectrum.png: f_1, f_2 lie 11 Hz apart at the left edge, the 8th harmonic sits on the
    right edge, and the title is longer than the axes (issue 17)."""
    from gearbody.plotting.result import spectrum_figure

    fs_hz, f_mesh = 8000.0, 493.8
    t = np.arange(4000) / fs_hz
    x = sum(np.sin(2 * np.pi * k * f_mesh * t) / k for k in range(1, 9))
    title = "Lateral gear train with 8 degrees of freedom, bearings and housing, run-up of Fig. 12: " * 2
    fig = spectrum_figure(
        amplitude_spectrum(x, fs_hz),
        mesh_frequency_hz=f_mesh,
        shaft_frequencies_hz={"f_1": f_mesh / 29, "f_2": f_mesh / 88},
        title=title,
        fmax_hz=8 * f_mesh,
        log_amplitude=True,
    )
    texts = [text for text, _ in _assert_no_overlap_inside(fig)]
    assert "$8f_z$" in texts and any("f_1" in s for s in texts) and any("f_2" in s for s in texts)


def test_labelled_spectrum_labels_do_not_overlap():
    """report.html's spectrum: peaks 17 Hz apart near 1000-1200 Hz keep only labels that do not overlap."""
    from gearbody.analysis import LabelledPeak
    from gearbody.plotting.spectrum import plot_labelled_spectrum

    fs_hz = 8000.0
    t = np.arange(8000) / fs_hz
    spec = amplitude_spectrum(np.sin(2 * np.pi * 1000 * t), fs_hz)
    peaks = [
        LabelledPeak(1000 + 17 * i, 1.0 / (1 + i), 30.0, (f"2 f_z1 + {i} f_pinion",) if i % 3 else (), 0.0)
        for i in range(15)
    ]
    ax = plot_labelled_spectrum(spec, peaks, title="spectrum " * 30, unit="m/s^2", f_max_hz=3000)
    texts = [text for text, _ in _assert_no_overlap_inside(ax.figure)]
    assert "2 f_z1 + 1 f_pinion" in texts  # the strongest explained peak keeps its label


def test_shaft_markers_are_readable_and_every_marker_label_stays_inside_its_axes():
    """The run's spectrum: shaft frequencies of 17 and 5.6 Hz on a 4 kHz axis were drawn as one line on
    its left edge, and the highest harmonic's label at its corner (issue 25). They get a panel of their
    own, where their lines stand well apart and off the edge, and every label sits inside its axes."""
    from matplotlib.colors import to_rgba

    from gearbody.plotting.result import spectrum_figure

    fs_hz, f_mesh = 20000.0, 493.8
    t = np.arange(10000) / fs_hz
    x = sum(np.sin(2 * np.pi * k * f_mesh * t) / k for k in range(1, 9)) + 0.01 * np.sin(2 * np.pi * 17 * t)
    shafts = {"f_1": f_mesh / 29, "f_2": f_mesh / 88}
    fig = spectrum_figure(
        amplitude_spectrum(x, fs_hz),
        mesh_frequency_hz=f_mesh,
        shaft_frequencies_hz=shafts,
        title="One-stage gearbox system: spectrum of pinion_accel_rad_s2",
        fmax_hz=8 * f_mesh,  # the 8th harmonic on the right edge
        log_amplitude=True,
    )
    _assert_no_overlap_inside(fig)
    renderer = fig.canvas.get_renderer()
    green = to_rgba("tab:green")
    drawn = [
        (ax, line.get_xdata()[0])
        for ax in fig.axes
        for line in ax.get_lines()
        if to_rgba(line.get_color()) == green
    ]
    assert sorted(f for _, f in drawn) == sorted(shafts.values())
    ax = drawn[0][0]
    assert all(a is ax for a, _ in drawn)  # one panel holds the shaft markers
    frame = ax.get_window_extent(renderer)
    xs = sorted(ax.transData.transform((f, 1.0))[0] for _, f in drawn)
    assert xs[0] - frame.x0 >= 40 and xs[1] - xs[0] >= 40, (frame, xs)  # pixels: apart and off the edge
    labels = {}
    for axes in fig.axes:
        box = axes.get_window_extent(renderer)
        for text in axes.texts:
            extent = text.get_window_extent(renderer)
            inside = box.x0 - 0.5 <= extent.x0 and extent.x1 <= box.x1 + 0.5 and extent.y1 <= box.y1 + 0.5
            assert inside, text.get_text()
            labels[text.get_text()] = axes
    assert labels["$8f_z$"] is labels["$f_z$"] is not ax
    assert labels["f_1 = 17.03 Hz"] is labels["f_2 = 5.611 Hz"] is ax
