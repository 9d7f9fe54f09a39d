"""The HTML report and the resonance tools (issue 4, items 3 and 5)."""

import html
import math

import numpy as np
import pytest

from gearbody.analysis.modal import campbell_lines
from gearbody.engine import scene_modes, simulate
from gearbody.model import load_scenario
from gearbody.plotting.campbell import plot_campbell
from gearbody.plotting.kd_speed import plot_kd_against_speed
from gearbody.reports.html import report_sections, write_report
from gearbody.studies import kd_speed_sweep, steady_overrides


@pytest.fixture(scope="module")
def steady_run():
    sc = load_scenario(
        "two-wheel", [*steady_overrides(1.0, 1.2), "production.error_mode={a=0.5,e_um=10.0,r=0.3}"]
    )
    return simulate(sc)


@pytest.mark.slow
def test_report_is_one_self_contained_page(steady_run, tmp_path):
    path = write_report(steady_run, tmp_path / "report.html")
    text = path.read_text()
    for heading in ("Summary", "K_d over the mesh period", "Labelled spectrum", "Synchronous average"):
        assert f"<h2>{heading}" in text
    assert text.count("data:image/png;base64,") == 3  # folded K_d, spectrum, TSA embedded
    assert 'src="http' not in text and "href=" not in text  # nothing external


def test_report_labels_the_mesh_line_and_computes_indicators(steady_run):
    s = report_sections(steady_run)
    mesh = [p for p in s["peaks"] if "1 f_z1" in p["label"]]
    assert mesh, s["peaks"][:5]
    f_z = float(np.mean(steady_run["mesh_frequency_hz"]))
    assert abs(mesh[0]["frequency_hz"] - f_z) <= 2 * (1 / 0.3)  # within the final window's resolution
    assert s["tsa_revolutions"] >= 3
    assert s["indicators"]["kurtosis"] > 1.0 and s["indicators"]["rms"] > 0


def test_campbell_crossings_by_hand():
    lines = campbell_lines([100.0, 2900.0], pinion_teeth=29, harmonics=2)
    # k z1 w / 2 pi = f  ->  w = 2 pi f / (k z1)
    np.testing.assert_allclose(lines["speed_rad_s"][0], [2 * math.pi * 100 / 29, 2 * math.pi * 100])
    np.testing.assert_allclose(lines["speed_rad_s"][1], [math.pi * 100 / 29, math.pi * 100])


def test_kd_peaks_at_the_mesh_mode(tmp_path):
    """two-wheel: the mesh mode (429 Hz) is met at 0.87 of the synchronous speed; K_d there exceeds
    K_d well below and above it (the paper's Figs. 5-8)."""
    sc = load_scenario("two-wheel", ["production.error_mode={a=0.5,e_um=10.0,r=0.0}"])
    sweep = kd_speed_sweep(sc, [0.6, 0.87, 1.3], settle_s=0.04, record_s=0.03)
    assert not any(sweep.errors)
    assert sweep.kd_max[1] > max(sweep.kd_max[0], sweep.kd_max[2])
    assert sweep.mesh_frequency_hz[1] == pytest.approx(429, rel=0.03)
    modes = scene_modes(sc).frequencies_hz
    assert plot_kd_against_speed(sweep, modes, tmp_path / "kd.png").stat().st_size > 1000
    assert plot_campbell(modes, 29, 200, tmp_path / "c.png", operating_speed_rad_s=107).stat().st_size > 1000
    with pytest.raises(ValueError, match="speed_fractions"):
        kd_speed_sweep(sc, [0.0])


def test_every_peaks_column_has_a_unit(steady_run, tmp_path):
    import re

    text = write_report(steady_run, tmp_path / "report.html").read_text()
    table = text[text.index("<h2>Labelled spectrum") :]
    headers = re.findall(r"<th>(.*?)</th>", table[: table.index("</tr>")])
    assert len(headers) == 5 and "kinematic line" in headers
    for header in headers:
        assert header == "kinematic line" or re.search(r"\[[^\]]+\]$", header), header
    assert "amplitude [rad/s^2]" in headers  # two-wheel's vibration signal is the pinion acceleration


def test_the_strongest_kinematic_lines_are_named():
    """One-stage-like spectrum: a pinion-runout sideband f_z1 + 4 f_pinion stronger than 12x pinion must
    be named like it (issue 17: it was unnamed while weaker lines were named)."""
    from gearbody.analysis import amplitude_spectrum, label_peaks
    from gearbody.reports.html import spectrum_lines

    fs_hz, f_pinion, z1, z2 = 8000.0, 17.03, 29, 88
    f_z = z1 * f_pinion
    t = np.arange(int(2 * fs_hz)) / fs_hz
    tones = {f_z: 400.0, 2 * f_z: 70.0, f_z + 4 * f_pinion: 20.0, 2 * f_z - 9 * f_pinion: 15.0}
    tones[12 * f_pinion] = 5.0
    rng = np.random.default_rng(0)
    x = sum(a * np.sin(2 * np.pi * f * t) for f, a in tones.items()) + 0.01 * rng.standard_normal(t.size)
    spec = amplitude_spectrum(x, fs_hz, window="hann")
    f_max = 6 * f_z
    peaks = label_peaks(
        spec,
        spectrum_lines(f_pinion, [(z1, z2)], f_max),
        tolerance_hz=1.5 * spec.resolution_hz,
        min_prominence_db=12.0,
        max_peaks=40,
        f_max_hz=f_max,
    )
    strongest = sorted(peaks, key=lambda p: -p.amplitude)[: len(tones)]
    assert all(p.explained for p in strongest), [(p.frequency_hz, p.label) for p in strongest]
    labels = " | ".join(p.label for p in strongest)
    assert "f_z1 + 4 f_pinion" in labels and "2 f_z1 - 9 f_pinion" in labels and "12x pinion" in labels


@pytest.mark.parametrize("scene", ["one-stage", "planetary"])
def test_the_scenes_sources_travel_into_the_summary_and_the_report(scene, tmp_path):
    """Where the parameter values come from (the scene's meta.sources) is in summary.json and the report,
    for a parallel and a planetary drive; a scene without sources says so."""
    scenario = load_scenario(scene, ["operation.t_end_s=0.01"])
    assert scenario.meta.sources
    result = simulate(scenario)
    assert result.summary()["sources"] == list(scenario.meta.sources)
    text = write_report(result, tmp_path / "report.html").read_text()
    assert "<h2>Sources of the parameter values</h2>" in text
    assert all(f"<li>{html.escape(src)}</li>" in text for src in scenario.meta.sources)
    bare = simulate(scenario.replace(meta=scenario.meta.replace(sources=())))
    assert bare.summary()["sources"] == []
    assert "the scene names no sources" in write_report(bare, tmp_path / "bare.html").read_text()


@pytest.mark.parametrize("scene", ["one-stage", "two-stage"])
def test_a_run_is_labelled_the_same_by_result_spectrum_the_report_and_the_plot(scene, tmp_path, monkeypatch):
    """One labelled spectrum: the report's peaks and the run plot's spectrum are Result.spectrum()'s
    (before issue 27 the report composed its own, with other lines and another f_max)."""
    import gearbody.plotting.run as run_plots
    from gearbody.analysis import peaks_to_rows

    result = simulate(load_scenario(scene, [*steady_overrides(1.0, 0.3)]))
    labelled = result.spectrum()
    assert labelled.peaks and any(p.labels for p in labelled.peaks)
    assert report_sections(result)["peaks"] == peaks_to_rows(labelled.peaks)
    drawn = {}

    def capture(spec, path, **kwargs):
        drawn["spec"] = spec
        return path

    monkeypatch.setattr(run_plots, "plot_spectrum", capture)
    run_plots._spectrum_plot(result, tmp_path, "run")
    assert np.array_equal(drawn["spec"].amplitude, labelled.spectrum.amplitude)
