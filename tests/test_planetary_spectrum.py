"""The ring-sensor spectrum of a simulated planetary run (gearbody.analysis.ring_sensor.ring_sensor_spectrum):
a run long enough for its window resolves f_m and f_m +- f_c at the bins their labels name, the labels
mark as cancelled exactly the lines McFadden and Smith's rule cancels, and a run too short says so."""

from __future__ import annotations

import pytest

from gearbody.analysis.carrier_window import MIN_CARRIER_REVOLUTIONS
from gearbody.analysis.planetary_lines import CANCELLED_MARK, is_cancelled_label, planetary_lines

# in phase: Z_r = 72 = 24 * 3 keeps f_m and f_m +- 3 f_c and cancels f_m +- f_c, f_m +- 2 f_c; planet 1's
# pin 20 um out of place (unequal sharing) brings f_m +- f_c back at ~1/10 of f_m
TEETH = (36, 18, 72)  # z_s + 2 z_p = z_r, (z_s + z_r) / 3 = 36
T_END_S = 1.0  # f_c ~ 8.1 Hz: the second half holds 4 whole carrier revolutions


@pytest.fixture(scope="module")
def run():
    from gearbody import load_scenario, simulate

    members = [
        f"design.stages.1.{m}.teeth={z}" for m, z in zip(("sun", "planet", "ring"), TEETH, strict=True)
    ]
    pin = "design.stages.1.planet_position_errors_um=[20.0, 0.0, 0.0]"
    sc = load_scenario(
        "planetary", [*members, pin, f"operation.t_end_s={T_END_S}", 'solver.accuracy="draft"']
    )
    return simulate(sc)


def test_a_short_run_says_what_it_resolves_and_how_long_a_run_would(tmp_path, capsys):
    from gearbody.cli import main

    assert main(["run", "planetary", "--t-end", "0.02", "--out", str(tmp_path), "--no-plots"]) == 0
    out = capsys.readouterr().out
    assert "note: the ring-sensor spectrum does not resolve the carrier sidebands" in out
    assert "100 Hz resolution" in out and "--t-end 1.5 or longer" in out  # 0.01 s steady; 2 x 4 / 5.4 Hz


@pytest.mark.slow
def test_a_long_enough_run_resolves_the_mesh_line_and_its_carrier_sidebands(run):
    from gearbody.analysis.ring_sensor import ring_sensor_notes, ring_sensor_spectrum

    ring = ring_sensor_spectrum(run, 0)
    n = ring.window.revolutions
    assert n >= MIN_CARRIER_REVOLUTIONS and ring.window.resolves_sidebands and ring_sensor_notes(run) == []
    a = ring.spectrum.amplitude
    z_r = TEETH[2]
    assert ring.spectrum.resolution_hz == pytest.approx(ring.sources.carrier_relative_hz / n, rel=1e-3)
    peaks = {p.label: p for p in ring.peaks(min_prominence_db=6.0, max_peaks=None)}
    for q, label in ((-1, f"f_m - f_c {CANCELLED_MARK}"), (0, "1 f_m"), (1, f"f_m + f_c {CANCELLED_MARK}")):
        j = n * (z_r + q)  # the bin of carrier order Z_r + q
        assert a[j] > 10 * max(a[j - 2], a[j + 2]), label  # a separate peak, the floor between neighbours
        assert label in peaks, sorted(peaks)
        assert peaks[label].frequency_hz == pytest.approx(ring.spectrum.frequency_hz[j], abs=1e-9)
    # the surviving mesh line stands far above the sidebands the rule cancels
    assert peaks["1 f_m"].amplitude > 5 * max(a[n * (z_r - 1)], a[n * (z_r + 1)])


@pytest.mark.slow
def test_the_labels_mark_exactly_the_lines_the_rule_cancels(run):
    from gearbody.analysis.ring_sensor import ring_sensor_spectrum

    ring = ring_sensor_spectrum(run, 0)
    rule = {
        line.label: line.survives_equal_spacing for line in planetary_lines(ring.sources, ring.f_max_hz, 3)
    }
    labels = [label for p in ring.peaks(min_prominence_db=6.0, max_peaks=None) for label in p.labels]
    assert any(is_cancelled_label(x) for x in labels) and any(not is_cancelled_label(x) for x in labels)
    for label in labels:
        plain = label.removesuffix(f" {CANCELLED_MARK}")
        assert is_cancelled_label(label) == (rule[plain] is False), label


@pytest.mark.slow
def test_the_report_and_the_plot_carry_the_window_and_the_marks(run, tmp_path):
    from gearbody.plotting.planetary import write_planetary_plots
    from gearbody.reports.html import report_sections, write_report

    s = report_sections(run)
    assert "4 carrier revolutions relative to the ring" in s["window"] and "window_note" not in s
    assert "cancelled_note" in s
    assert any(row["label"] == f"f_m + f_c {CANCELLED_MARK}" for row in s["peaks"])
    page = write_report(run, tmp_path / "report.html").read_text()
    assert "analysed window: stage 1&#x27;s ring sensor over 4 carrier revolutions" in page
    assert "(cancelled)" in page
    assert "ring_sensor_spectrum.png" in {p.name for p in write_planetary_plots(run, tmp_path)}


def test_result_spectrum_of_the_ring_sensor_is_the_run_plot_s(tmp_path):
    """result.spectrum() of a drive whose first stage is planetary reads the ring sensor as its plot and
    report do: over the whole carrier revolutions, the cancelled lines marked."""
    from gearbody import load_scenario, simulate
    from gearbody.analysis.ring_sensor import ring_sensor_spectrum

    res = simulate(load_scenario("planetary", ["operation.t_end_s=0.1", 'solver.accuracy="draft"']))
    ls, ring = res.spectrum(), ring_sensor_spectrum(res, 0)
    assert ls.signal == "ring_sensor_N" and ls.spectrum.resolution_hz == ring.spectrum.resolution_hz
    assert [p.label for p in ls.peaks] == [p.label for p in ring.peaks(min_prominence_db=12.0, max_peaks=40)]
    assert any(is_cancelled_label(label) for p in ls.peaks for label in p.label.split("; "))
