"""Issue 30: the bearings' fault frequencies in every report: the run report (parallel and planetary), the
analysis of a recording, the comparison; the table's numbers from the one formula, the lines marked on
the spectra, and "no bearing geometry stated" where a scene gives none."""

from __future__ import annotations

import json

import numpy as np
import pytest

import gearbody as gb
from gearbody.analysis import KinematicLine
from gearbody.cli import main
from gearbody.diagnosis import DriveKinematics
from gearbody.plotting.report import labelled_spectrum_figure
from gearbody.plotting.result import spectrum_figure
from gearbody.plotting.spectrum import LINE_COLOURS, mark_lines, zoom_limit
from gearbody.reports.bearings import bearing_section, run_bearing_section
from gearbody.reports.html import bearing_html, report_sections, write_report

GEOMETRY = "{balls=12,ball_diameter_m=0.012,pitch_diameter_m=0.08}"


def _visible(fig) -> list[str]:
    return [t.get_text() for ax in fig.axes for t in ax.texts if t.get_visible()]


def test_the_table_holds_every_line_of_every_bearing_from_the_one_formula():
    drive = DriveKinematics.from_scenario(gb.load_scenario("lateral-8dof-ball"))
    section = bearing_section(drive, {"at 17 rev/s": 17.0})
    rows = {(r["bearing"], r["line"]): r for r in section.rows}
    assert len(rows) == 10 and {line for _, line in rows} == {"BPFO", "BPFI", "BSF", "2 BSF", "FTF"}
    # SKF 6308 as the scene states it: 8 balls of 15.081 mm on 65 mm, contact angle 0, inner race turning
    r = 0.015081 / 0.065
    pinion = {line: rows[("pinion bearing", line)] for line in ("BPFO", "BPFI", "BSF", "2 BSF", "FTF")}
    assert pinion["BPFO"]["shaft_order"] == pytest.approx(4 * (1 - r), rel=1e-12)
    assert pinion["BPFI"]["shaft_order"] == pytest.approx(4 * (1 + r), rel=1e-12)
    assert pinion["BSF"]["shaft_order"] == pytest.approx((1 - r**2) / (2 * r), rel=1e-12)
    assert pinion["2 BSF"]["shaft_order"] == pytest.approx(2 * pinion["BSF"]["shaft_order"], rel=1e-12)
    assert pinion["FTF"]["shaft_order"] == pytest.approx((1 - r) / 2, rel=1e-12)
    wheel = rows[("wheel bearing", "BPFO")]  # the wheel turns 29/88 of the input
    assert wheel["input_order"] == pytest.approx(wheel["shaft_order"] * 29 / 88, rel=1e-5)
    assert wheel["hz:at 17 rev/s"] == pytest.approx(17 * wheel["input_order"], rel=1e-12)
    nominal = drive.nominal_input_hz
    assert pinion["BPFO"]["hz:"] == pytest.approx(nominal * 4 * (1 - r), rel=1e-12)
    assert "(17 rev/s)" in section.columns["hz:at 17 rev/s"]
    # the marks are the catalogue's bearing lines: fundamentals of BPFO, BPFI, 2 BSF and FTF
    marks = section.marks(17.0, 100.0)
    assert sorted(m.label.split()[0] for m in marks if "pinion" in m.label) == ["2", "BPFI", "BPFO", "FTF"]
    catalogue = {round(line.frequency_hz, 9) for line in drive.lines(17.0, 100.0) if line.family == "bearing"}
    assert {round(m.frequency_hz, 9) for m in marks} <= catalogue
    assert all(m.frequency_hz <= 100.0 for m in marks) and section.marks(17.0, 5.0)[0].label.startswith("FTF")


@pytest.mark.parametrize(
    ("scene", "note"),
    [
        ("one-stage", "no bearing geometry stated (no gear of the scene has a bearing table)"),
        ("muller", "no bearing geometry stated (no gear of the scene has a bearing table)"),
        (
            "lateral-8dof",
            "no bearing geometry stated: pinion bearing (design.stages.1.pinion.bearing.geometry)",
        ),
    ],
)
def test_a_scene_without_geometry_says_so(scene, note):
    section = bearing_section(DriveKinematics.from_scenario(gb.load_scenario(scene)), {})
    assert not section.rows and section.notes[0].startswith(note)
    assert note in bearing_html(section).replace("&#x27;", "'")


def test_the_run_report_has_the_table_and_marks_the_lines_on_its_spectrum(tmp_path):
    result = gb.simulate(gb.load_scenario("lateral-8dof-ball", ["operation.t_end_s=0.3"]))
    section, input_hz = run_bearing_section(result)
    speed = np.mean(result["pinion_speed_rad_s"][result.final_window()]) / (2 * np.pi)
    assert input_hz == pytest.approx(speed, rel=1e-12) and len(section.rows) == 10
    s = report_sections(result)
    assert s["bearings"].rows == section.rows
    page = write_report(result, tmp_path / "report.html").read_text()
    assert "<h2>Bearing fault frequencies</h2>" in page and "2 BSF" in page and "order of the bearing" in page
    # the figure: the lines crowd the foot of a 0-3 kHz axis, so a panel shows them apart, labelled
    labelled = result.spectrum()
    marks = section.marks(input_hz, labelled.f_max_hz)
    fig = labelled_spectrum_figure(labelled.spectrum, labelled.peaks, "t", "m/s^2", labelled.f_max_hz, marks)
    assert len(fig.axes) == 2 and fig.axes[1].get_xlim()[1] == pytest.approx(zoom_limit(marks, 1e9))
    shown = [t for t in fig.axes[1].texts if t.get_visible() and "bearing" in t.get_text()]
    assert {"BPFO pinion bearing", "BPFI pinion bearing", "FTF wheel bearing"} <= {
        t.get_text() for t in shown
    }
    assert next(t for t in shown if t.get_text() == "BPFO pinion bearing").get_color() == LINE_COLOURS["BPFO"]
    assert not any("bearing" in t.get_text() for t in fig.axes[0].texts)  # the top axes: marks only
    # the run's spectrum.png: in its low-frequency panel of shaft frequencies, widened to hold them
    fig = spectrum_figure(
        labelled.spectrum, 494.0, {"f_1": 17.0, "f_2": 5.6}, marks=marks, log_amplitude=True
    )
    assert fig.axes[1].get_xlim()[1] >= max(m.frequency_hz for m in marks)
    assert "BPFI pinion bearing" in _visible(fig)


def test_the_planetary_report_has_the_table_and_marks_its_ring_sensor_spectrum(tmp_path):
    sc = gb.load_scenario(
        "planetary",
        ["operation.t_end_s=0.1", f"design.stages.1.planet.bearing_geometry={GEOMETRY}"],
    )
    result = gb.simulate(sc)
    s = report_sections(result)
    rows = s["bearings"].rows
    planet = next(r for r in rows if r["bearing"] == "planet 1 bearing" and r["line"] == "BPFO")
    assert planet["shaft"] == "planet_1 relative to carrier"
    ratios = DriveKinematics.from_scenario(sc).speed_ratios
    relative = abs(ratios["planet_1"] - ratios["carrier"]) / abs(ratios["sun"])
    assert planet["input_order"] == pytest.approx(planet["shaft_order"] * relative, rel=1e-12)
    assert any("no bearing geometry stated for sun bearing" in n for n in s["bearings"].notes)
    page = write_report(result, tmp_path / "report.html").read_text()
    assert "planet_1 relative to carrier" in page


def test_mark_lines_marks_what_is_in_range_in_its_colour_and_can_leave_labels_out():
    from gearbody.plotting.figure import new_figure

    ax = new_figure((800, 400)).add_subplot()
    ax.plot([0, 100], [1, 1])
    ax.set_xlim(0, 100)
    lines = [
        KinematicLine(f, f"{name} b", "bearing", ()) for f, name in ((10, "BPFO"), (50, "FTF"), (150, "BPFI"))
    ]
    drawn = mark_lines(ax, lines)
    assert [t.get_text() for t in drawn] == ["BPFO b", "FTF b"]
    assert [line.get_color() for line in ax.lines[1:]] == [LINE_COLOURS["BPFO"], LINE_COLOURS["FTF"]]
    assert mark_lines(ax, lines, x_max=20.0, labels=False) == [] and len(ax.lines) == 4
    assert zoom_limit(lines, 100.0) is None and zoom_limit(lines[:1], 100.0) == pytest.approx(11.5)


def test_the_analysis_and_the_comparison_show_the_bearings(tmp_path, capsys):
    run = tmp_path / "run"
    argv = ["run", "lateral-8dof-ball", "--t-end", "1", "--out", str(run), "--quiet", "--no-plots"]
    assert main(argv) == 0
    assert main(["analyze", str(run), "--out", str(tmp_path / "a")]) == 0
    page = (tmp_path / "a" / "report.html").read_text()
    assert "<h2>Bearing fault frequencies</h2>" in page and "at the recording&#x27;s mean input speed" in page
    features = json.loads((tmp_path / "a" / "features.json").read_text())
    assert any("BPFO pinion bearing" in k for k in features)  # the catalogue's bands, as before
    assert main(["compare", str(run), str(run), "--out", str(tmp_path / "c")]) == 0
    page = (tmp_path / "c" / "comparison.html").read_text()
    assert "at the run&#x27;s mean input speed" in page and "BPFI" in page
    capsys.readouterr()
