"""PSD scaling, kinematic line catalogue and labelled spectrum peaks on synthetic signals with known lines."""

import csv
import io
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from gearbody.analysis.labels import (
    GearMesh,
    KinematicLine,
    KinematicSources,
    LabelledPeak,
    Shaft,
    kinematic_lines,
    label_peaks,
    peaks_table,
    peaks_to_rows,
    power_spectral_density,
)
from gearbody.analysis.spectrum import amplitude_spectrum
from gearbody.plotting.spectrum import plot_labelled_spectrum

# --- power spectral density -----------------------------------------------------------------------------

PSD_FS_HZ = 1000.0


def test_white_noise_psd_is_two_variance_over_sample_rate():
    sigma = 0.7
    x = sigma * np.random.default_rng(3).standard_normal(2**18)
    psd = power_spectral_density(x, PSD_FS_HZ, segment_s=1.024)
    assert psd.segment_samples == 1024 and psd.overlap_samples == 512
    assert psd.n_averages == 1 + (2**18 - 1024) // 512
    assert psd.resolution_hz == pytest.approx(PSD_FS_HZ / 1024)
    assert psd.segment_s == pytest.approx(1.024)
    assert psd.frequency_hz[-1] == pytest.approx(PSD_FS_HZ / 2)
    # one-sided: the variance sigma^2 spread over 0 .. fs/2
    assert np.mean(psd.psd[1:-1]) == pytest.approx(2 * sigma**2 / PSD_FS_HZ, rel=0.01)
    assert np.sum(psd.psd) * psd.resolution_hz == pytest.approx(sigma**2, rel=0.01)


def test_psd_integral_is_the_window_weighted_mean_square_exactly():
    x = np.random.default_rng(4).standard_normal(5000).cumsum()  # red noise, with a trend
    m = 800
    psd = power_spectral_density(x, PSD_FS_HZ, segment_s=m / PSD_FS_HZ, detrend="linear")
    w = np.hanning(m + 1)[:-1]  # periodic Hann
    starts = range(0, x.size - m + 1, m // 2)
    expected = []
    for s in starts:
        seg = x[s : s + m]
        t = np.arange(m)
        seg = seg - np.polyval(np.polyfit(t, seg, 1), t)
        expected.append(np.sum((w * seg) ** 2) / np.sum(w**2))
    assert psd.n_averages == len(expected)
    assert np.sum(psd.psd) * psd.resolution_hz == pytest.approx(np.mean(expected), rel=1e-10)


@pytest.mark.parametrize(("f_hz", "rel"), [(125.0, 1e-12), (125.37, 1e-4), (33.3, 1e-4)])
def test_sine_psd_integrated_over_its_line_is_half_amplitude_squared(f_hz, rel):
    amplitude = 2.5
    t = np.arange(2**16) / PSD_FS_HZ
    psd = power_spectral_density(amplitude * np.sin(2 * np.pi * f_hz * t + 0.4), PSD_FS_HZ, segment_s=1.024)
    band = np.abs(psd.frequency_hz - f_hz) <= 6 * psd.resolution_hz
    # 125 Hz completes 128 periods per segment: exact; off-bin lines leak a little beyond 6 bins
    assert np.sum(psd.psd[band]) * psd.resolution_hz == pytest.approx(amplitude**2 / 2, rel=rel)


def test_psd_defaults_quarter_segments_and_mean_removal():
    x = 5.0 + np.random.default_rng(5).standard_normal(4000)
    psd = power_spectral_density(x, PSD_FS_HZ)
    assert psd.segment_samples == 1000 and psd.n_averages == 7 and psd.window == "hann"
    same = power_spectral_density(x, PSD_FS_HZ, detrend=True)
    np.testing.assert_array_equal(psd.psd, same.psd)
    raw = power_spectral_density(x, PSD_FS_HZ, detrend=False)
    assert raw.psd[0] > 1000 * np.mean(raw.psd[2:])  # the 5.0 offset (Hann: also in bin 1)
    assert psd.psd[0] < 1e-3 * raw.psd[0]  # removed segment by segment


@pytest.mark.parametrize(
    ("kwargs", "parameter"),
    [
        ({"signal": np.zeros((4, 4))}, "signal"),
        ({"signal": [1.0, np.nan, 2.0]}, "signal"),
        ({"sample_rate_hz": 0.0}, "sample_rate_hz"),
        ({"sample_rate_hz": float("inf")}, "sample_rate_hz"),
        ({"segment_s": 2.0}, "segment_s"),  # longer than the 1 s signal
        ({"segment_s": 0.001}, "segment_s"),  # one sample
        ({"segment_s": -0.1}, "segment_s"),
        ({"detrend": "quadratic"}, "detrend"),
    ],
)
def test_psd_rejects_bad_inputs(kwargs, parameter):
    args = {"signal": np.ones(1000), "sample_rate_hz": PSD_FS_HZ} | kwargs
    with pytest.raises(ValueError, match=parameter):
        power_spectral_density(**args)


# --- kinematic lines ------------------------------------------------------------------------------------

F_PINION_HZ = 17.0
F_WHEEL_HZ = F_PINION_HZ * 29 / 88
F_OUTPUT_HZ = F_WHEEL_HZ * 23 / 71
F_Z1_HZ = 29 * F_PINION_HZ  # 493 Hz
F_Z2_HZ = 23 * F_WHEEL_HZ  # 128.85 Hz


def _two_stage() -> KinematicSources:
    return KinematicSources(
        shafts=(Shaft("pinion", F_PINION_HZ), Shaft("wheel", F_WHEEL_HZ), Shaft("output", F_OUTPUT_HZ)),
        meshes=(
            GearMesh("f_z1", F_Z1_HZ, ("pinion", "wheel")),
            GearMesh("f_z2", F_Z2_HZ, ("wheel", "output")),
        ),
    )


def _by_label(lines: list[KinematicLine]) -> dict[str, KinematicLine]:
    return {line.label: line for line in lines}


def test_one_stage_catalogue():
    drive = KinematicSources.gear_train(F_PINION_HZ, [(29, 88)])
    assert [s.name for s in drive.shafts] == ["pinion", "wheel"]
    assert drive.shaft("wheel").rotation_hz == pytest.approx(F_WHEEL_HZ)
    assert drive.meshes[0].mesh_hz == pytest.approx(F_Z1_HZ)
    lines = kinematic_lines(drive, 2000.0)
    # 2 shafts x 3 orders, 3 mesh harmonics, 3 harmonics x 2 shafts x 2 orders x 2 signs
    assert len(lines) == 6 + 3 + 24
    assert [line.frequency_hz for line in lines] == sorted(line.frequency_hz for line in lines)
    by = _by_label(lines)
    expected = {
        "1x pinion": (F_PINION_HZ, "shaft"),
        "3x pinion": (3 * F_PINION_HZ, "shaft"),
        "2x wheel": (2 * F_WHEEL_HZ, "shaft"),
        "1 f_z1": (F_Z1_HZ, "mesh"),
        "3 f_z1": (3 * F_Z1_HZ, "mesh"),
        "f_z1 + 2 f_pinion": (F_Z1_HZ + 2 * F_PINION_HZ, "sideband"),
        "f_z1 - f_wheel": (F_Z1_HZ - F_WHEEL_HZ, "sideband"),
        "2 f_z1 - f_pinion": (2 * F_Z1_HZ - F_PINION_HZ, "sideband"),
        "3 f_z1 + 2 f_wheel": (3 * F_Z1_HZ + 2 * F_WHEEL_HZ, "sideband"),
    }
    for label, (f_hz, family) in expected.items():
        assert by[label].frequency_hz == pytest.approx(f_hz, rel=1e-12)
        assert by[label].family == family
    assert by["2 f_z1 - f_pinion"].orders == (("f_z1", 2), ("f_pinion", -1))
    assert by["2x wheel"].orders == (("f_wheel", 2),)
    assert not [line for line in lines if line.family == "cross"]
    # f_max_hz cuts, harmonics/sidebands/shaft_orders count
    short = kinematic_lines(drive, 1000.0, harmonics=5, sidebands=1, shaft_orders=1)
    assert max(line.frequency_hz for line in short) <= 1000.0
    assert {line.label for line in short} == {
        "1x pinion", "1x wheel", "1 f_z1", "2 f_z1", "f_z1 + f_pinion", "f_z1 - f_pinion",
        "f_z1 + f_wheel", "f_z1 - f_wheel", "2 f_z1 - f_pinion", "2 f_z1 - f_wheel", "2 f_z1 + f_wheel",
    }  # fmt: skip


def test_two_stage_catalogue_has_cross_lines_and_matches_gear_train():
    lines = kinematic_lines(_two_stage(), 2000.0)
    by = _by_label(lines)
    assert by["f_z1 - f_z2"].frequency_hz == pytest.approx(F_Z1_HZ - F_Z2_HZ)
    assert by["f_z1 - f_z2"].family == "cross"
    assert by["2 f_z1 + 2 f_z2"].frequency_hz == pytest.approx(2 * F_Z1_HZ + 2 * F_Z2_HZ)
    assert by["f_z2 + f_output"].family == "sideband"  # the second mesh's own gears modulate it
    assert by["1x output"].frequency_hz == pytest.approx(F_OUTPUT_HZ)
    train = KinematicSources.gear_train(
        F_PINION_HZ, [(29, 88), (23, 71)], shaft_names=("pinion", "wheel", "output")
    )
    other = kinematic_lines(train, 2000.0)
    assert [line.label for line in other] == [line.label for line in lines]
    np.testing.assert_allclose(
        [line.frequency_hz for line in other], [line.frequency_hz for line in lines], rtol=1e-12
    )
    assert [s.name for s in KinematicSources.gear_train(10.0, [(20, 40), (15, 45)]).shafts] == [
        "input",
        "intermediate",
        "output",
    ]


def test_negative_combinations_fold_to_positive_frequencies():
    drive = KinematicSources(
        shafts=(Shaft("a", 5.0), Shaft("b", 2.5), Shaft("c", 1.0)),
        meshes=(GearMesh("f_z2", 70.0, ("b", "c")), GearMesh("f_z1", 100.0, ("a", "b"))),
    )
    by = _by_label(kinematic_lines(drive, 500.0))
    # the higher mesh frequency is the carrier, whatever the order of the meshes
    assert by["f_z1 - f_z2"].frequency_hz == pytest.approx(30.0)
    assert by["2 f_z2 - f_z1"].frequency_hz == pytest.approx(40.0)  # f_z1 - 2 f_z2 = -40 Hz
    assert by["2 f_z2 - f_z1"].orders == (("f_z1", -1), ("f_z2", 2))
    assert Shaft("pinion shaft", 17.03).symbol == "f_pinion_shaft"
    assert Shaft("pinion shaft", 17.03, symbol="f_1").symbol == "f_1"


@pytest.mark.parametrize(
    ("make", "parameter"),
    [
        (lambda: Shaft("pinion", -17.0), "rotation_hz"),
        (lambda: Shaft("", 17.0), "name"),
        (lambda: GearMesh("f_z1", 0.0, ("a", "b")), "mesh_hz"),
        (lambda: GearMesh("f_z1", 493.0, ("a", "a")), "shafts"),
        (lambda: KinematicSources((Shaft("a", 1.0), Shaft("a", 2.0))), "shafts"),
        (lambda: KinematicSources((Shaft("a", 1.0),), (GearMesh("f_z1", 29.0, ("a", "b")),)), "shaft"),
        (lambda: KinematicSources(()), "shafts"),
        (lambda: KinematicSources.gear_train(0.0, [(29, 88)]), "input_hz"),
        (lambda: KinematicSources.gear_train(17.0, [(29, 0)]), "teeth"),
        (lambda: KinematicSources.gear_train(17.0, [(29, 88.5)]), "teeth"),
        (lambda: KinematicSources.gear_train(17.0, []), "teeth"),
        (lambda: KinematicSources.gear_train(17.0, [(29, 88)], shaft_names=("a",)), "shaft_names"),
        (lambda: kinematic_lines(_two_stage(), 0.0), "f_max_hz"),
        (lambda: kinematic_lines(_two_stage(), 1000.0, harmonics=0), "harmonics"),
        (lambda: kinematic_lines(_two_stage(), 1000.0, sidebands=-1), "sidebands"),
        (lambda: kinematic_lines(_two_stage(), 1000.0, shaft_orders=1.5), "shaft_orders"),
        (lambda: kinematic_lines([Shaft("a", 1.0)], 1000.0), "sources"),
    ],
)
def test_kinematics_reject_bad_inputs(make, parameter):
    with pytest.raises(ValueError, match=parameter):
        make()


# --- labelled peaks on a synthetic two-stage signal ------------------------------------------------------

FS_HZ = 8192.0
DURATION_S = 16.0  # 0.0625 Hz bins: f_pinion, f_z1 and its pinion sidebands are on-bin, the rest not
NOISE_STD = 1e-3
ODD_HZ = 777.77  # explained by no kinematic line
ODD_AMPLITUDE = 0.05
WEAK_LABEL, WEAK_AMPLITUDE = "2x pinion", 5e-4  # ~35 dB over the noise floor
HANN_SCALLOP = (2 / np.pi) / 0.75  # Hann peak bin at half a bin off: 0.849 (-1.42 dB)

INJECTED = {  # label: (frequency [Hz], amplitude)
    "1x pinion": (F_PINION_HZ, 0.2),
    "1x wheel": (F_WHEEL_HZ, 0.1),
    "1 f_z1": (F_Z1_HZ, 1.0),
    "2 f_z1": (2 * F_Z1_HZ, 0.5),
    "3 f_z1": (3 * F_Z1_HZ, 0.25),
    "f_z1 + f_pinion": (F_Z1_HZ + F_PINION_HZ, 0.08),
    "f_z1 - f_pinion": (F_Z1_HZ - F_PINION_HZ, 0.06),
    "f_z1 + 2 f_pinion": (F_Z1_HZ + 2 * F_PINION_HZ, 0.03),
    "f_z1 - 2 f_pinion": (F_Z1_HZ - 2 * F_PINION_HZ, 0.02),
    "1 f_z2": (F_Z2_HZ, 0.3),
    "f_z1 + f_z2": (F_Z1_HZ + F_Z2_HZ, 0.04),
    "f_z1 - f_z2": (F_Z1_HZ - F_Z2_HZ, 0.05),
}


@pytest.fixture(scope="module")
def synthetic():
    rng = np.random.default_rng(1)
    t = np.arange(int(FS_HZ * DURATION_S)) / FS_HZ
    x = NOISE_STD * rng.standard_normal(t.size)
    for f_hz, amplitude in [*INJECTED.values(), (ODD_HZ, ODD_AMPLITUDE), (2 * F_PINION_HZ, WEAK_AMPLITUDE)]:
        x += amplitude * np.sin(2 * np.pi * f_hz * t + rng.uniform(0, 2 * np.pi))
    spectrum = amplitude_spectrum(x, FS_HZ)
    lines = kinematic_lines(_two_stage(), FS_HZ / 2)
    return spectrum, lines


def _on_bin(f_hz: float, df_hz: float) -> bool:
    return abs(f_hz / df_hz - round(f_hz / df_hz)) < 1e-9


def _near(peaks: list[LabelledPeak], f_hz: float, tol_hz: float) -> list[LabelledPeak]:
    return [p for p in peaks if abs(p.frequency_hz - f_hz) <= tol_hz]


def test_odd_line_is_far_from_every_kinematic_line(synthetic):
    spectrum, lines = synthetic
    assert min(abs(line.frequency_hz - ODD_HZ) for line in lines) > 10 * spectrum.resolution_hz


def test_every_injected_line_is_found_and_labelled(synthetic):
    spectrum, lines = synthetic
    df = spectrum.resolution_hz
    peaks = label_peaks(spectrum, lines)  # defaults: 1.5 bins, 6 dB, 50 peaks
    assert len(peaks) == 50
    assert [p.frequency_hz for p in peaks] == sorted(p.frequency_hz for p in peaks)
    noise_amplitude = NOISE_STD * math.sqrt(6 / (FS_HZ * DURATION_S))  # rms of a Hann bin of the noise
    for label, (f_hz, amplitude) in INJECTED.items():
        found = _near(peaks, f_hz, df)
        assert len(found) == 1, label
        peak = found[0]
        assert peak.labels[0] == label
        assert peak.explained and peak.label.split("; ")[0] == label
        assert abs(peak.offset_hz) <= 1.5 * df
        assert peak.offset_hz == pytest.approx(peak.frequency_hz - f_hz, abs=1e-9)
        if _on_bin(f_hz, df):
            assert peak.frequency_hz == pytest.approx(f_hz, abs=1e-9)
            assert peak.amplitude == pytest.approx(amplitude, abs=5 * noise_amplitude)
        else:
            assert abs(peak.frequency_hz - f_hz) <= df / 2
            assert HANN_SCALLOP * amplitude - 5 * noise_amplitude <= peak.amplitude
            assert peak.amplitude <= amplitude + 5 * noise_amplitude
        assert peak.prominence_db > 60.0
    (odd,) = _near(peaks, ODD_HZ, df)
    assert odd.labels == () and odd.label == "" and not odd.explained
    assert math.isnan(odd.offset_hz)
    assert HANN_SCALLOP * ODD_AMPLITUDE < odd.amplitude <= ODD_AMPLITUDE * 1.01


def test_strict_threshold_reports_exactly_the_injected_lines(synthetic):
    spectrum, lines = synthetic
    peaks = label_peaks(spectrum, lines, min_prominence_db=25.0, max_peaks=None)
    assert {p.labels[0] for p in peaks if p.explained} == set(INJECTED) | {WEAK_LABEL}
    unexplained = [p for p in peaks if not p.explained]
    assert len(unexplained) == 1 and abs(unexplained[0].frequency_hz - ODD_HZ) <= spectrum.resolution_hz


def test_lines_below_min_prominence_are_not_reported(synthetic):
    spectrum, lines = synthetic
    df = spectrum.resolution_hz
    (weak,) = _near(label_peaks(spectrum, lines, max_peaks=None), 2 * F_PINION_HZ, df)
    assert weak.labels == (WEAK_LABEL,)
    assert 25.0 < weak.prominence_db < 45.0
    above = label_peaks(spectrum, lines, min_prominence_db=weak.prominence_db + 0.5, max_peaks=None)
    assert not _near(above, 2 * F_PINION_HZ, df)
    below = label_peaks(spectrum, lines, min_prominence_db=weak.prominence_db - 0.5, max_peaks=None)
    assert _near(below, 2 * F_PINION_HZ, df)
    strong_only = label_peaks(spectrum, lines, min_prominence_db=50.0)
    assert {p.label for p in strong_only} == set(INJECTED) | {""}  # the odd line is strong too


def test_max_peaks_keeps_the_most_prominent(synthetic):
    spectrum, lines = synthetic
    peaks = label_peaks(spectrum, lines, max_peaks=2)
    assert [p.label for p in peaks] == ["1 f_z1", "2 f_z1"]


def test_tolerance_and_several_labels_sorted_by_distance(synthetic):
    spectrum, lines = synthetic
    df = spectrum.resolution_hz
    tight = label_peaks(spectrum, lines, tolerance_hz=0.01)
    (wheel,) = _near(tight, F_WHEEL_HZ, df)
    assert wheel.labels == ()  # 0.023 Hz off its line
    (mesh,) = _near(tight, F_Z1_HZ, df)
    assert mesh.labels == ("1 f_z1",)  # on-bin
    candidates = [
        KinematicLine(F_Z1_HZ + 0.05, "far", "mesh", (("f_z1", 1),)),
        KinematicLine(F_Z1_HZ - 0.02, "near", "mesh", (("f_z1", 1),)),
        KinematicLine(F_Z1_HZ + 1.0, "outside", "mesh", (("f_z1", 1),)),
    ]
    (peak,) = _near(label_peaks(spectrum, candidates, tolerance_hz=0.1), F_Z1_HZ, df)
    assert peak.labels == ("near", "far")
    assert peak.label == "near; far"
    assert peak.offset_hz == pytest.approx(0.02)
    assert all(not p.explained for p in label_peaks(spectrum, [], max_peaks=5))


@pytest.mark.parametrize(
    ("kwargs", "parameter"),
    [
        ({"tolerance_hz": 0.0}, "tolerance_hz"),
        ({"tolerance_hz": float("nan")}, "tolerance_hz"),
        ({"min_prominence_db": -1.0}, "min_prominence_db"),
        ({"max_peaks": 0}, "max_peaks"),
        ({"floor_bins": 0}, "floor_bins"),
        ({"f_max_hz": -5.0}, "f_max_hz"),
        ({"spectrum": np.ones(100)}, "spectrum"),
        ({"lines": [1.0, 2.0]}, "lines"),
    ],
)
def test_label_peaks_rejects_bad_inputs(synthetic, kwargs, parameter):
    spectrum, lines = synthetic
    args = {"spectrum": spectrum, "lines": lines} | kwargs
    with pytest.raises(ValueError, match=parameter):
        label_peaks(**args)


# --- presentation ---------------------------------------------------------------------------------------


def test_table_and_rows(synthetic):
    spectrum, lines = synthetic
    peaks = label_peaks(spectrum, lines, min_prominence_db=25.0)
    table = peaks_table(peaks, unit="m/s^2")
    rows_text = table.splitlines()
    header = ["f [Hz]", "amplitude [m/s^2]", "prominence [dB]", "label", "offset [Hz]"]
    assert [cell.strip() for cell in rows_text[0].split("  ") if cell.strip()] == header
    assert len(rows_text) == 2 + len(peaks)
    for label in [*INJECTED, WEAK_LABEL, "(unexplained)"]:
        assert label in table
    assert "493.000" in table and "777.750" in table
    short = peaks_table(peaks, max_rows=3)
    assert short.splitlines()[-1] == f"({len(peaks) - 3} less prominent peaks not shown)"
    assert "1 f_z1" in short and "amplitude [" not in short

    rows = peaks_to_rows(peaks)
    assert len(rows) == len(peaks)
    assert set(rows[0]) == {"frequency_hz", "amplitude", "prominence_db", "label", "offset_hz"}
    odd = next(r for r in rows if r["label"] == "")
    assert odd["offset_hz"] is None
    assert json.loads(json.dumps(rows))[0]["frequency_hz"] == pytest.approx(peaks[0].frequency_hz)
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(rows[0]))
    writer.writeheader()
    writer.writerows(rows)
    assert "f_z1 - f_z2" in buffer.getvalue()
    with pytest.raises(ValueError, match="max_rows"):
        peaks_table(peaks, max_rows=-1)
    with pytest.raises(ValueError, match="peaks"):
        peaks_to_rows([1.0])


def test_plot_marks_labelled_and_unexplained_peaks(synthetic, tmp_path):
    spectrum, lines = synthetic
    peaks = label_peaks(spectrum, lines, min_prominence_db=25.0)
    ax = plot_labelled_spectrum(spectrum, peaks, title="two-stage", unit="m/s^2", f_max_hz=1000.0)
    texts = {t.get_text(): t for t in ax.texts}
    assert "1 f_z1" in texts and "f_z1 - f_z2" in texts
    assert "3 f_z1" not in texts  # 1479 Hz is beyond f_max_hz
    assert texts["1 f_z1"].get_rotation() == 90
    assert texts["777.8 Hz"].get_color() == "0.5"  # unexplained: grey, with its frequency
    assert ax.get_yscale() == "log" and ax.get_xlim()[1] == pytest.approx(1000.0)
    assert ax.get_ylabel() == "Amplitude [m/s^2]" and ax.get_title() == "two-stage"
    path = tmp_path / "labelled.png"
    ax.figure.savefig(path)
    assert path.stat().st_size > 0
    from matplotlib.figure import Figure

    own = Figure().add_subplot()
    assert plot_labelled_spectrum(spectrum, peaks, ax=own, log=False) is own
    assert own.get_yscale() == "linear" and "1x pinion" in {t.get_text() for t in own.texts}
    with pytest.raises(ValueError, match="f_max_hz"):
        plot_labelled_spectrum(spectrum, peaks, f_max_hz=0.0)


def test_module_imports_without_matplotlib_or_engine():
    code = (
        "import sys, gearbody.analysis.labels; "
        "print(sorted(m for m in ('matplotlib', 'exudyn', 'gearbody.engine') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
