"""Bearing defect frequencies in every report (issue 30): a table of every rolling bearing the scenario
gives a geometry (BPFO, BPFI, BSF, 2 BSF and FTF in Hz at the nominal input speed and at the analysed one,
and as orders of the bearing's own shaft and of the input shaft), the lines to mark on the spectra, and
"no bearing geometry stated" where the scenario gives none. Every number comes from
:meth:`gearbody.diagnosis.DriveKinematics.bearing_frequencies` (the formulas of
:mod:`gearbody.analysis.bearing_lines`), once."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

__all__ = ["BearingSection", "bearing_section", "run_bearing_section"]

COLUMNS = {
    "bearing": "bearing",
    "shaft": "turned by",
    "line": "line",
    "shaft_order": "order of the bearing's shaft",
    "input_order": "order of the input shaft",
}
"""The table's first columns (then one column of Hz per speed)."""

NOTE = (
    "Rigid rolling without slip (real bearings slip by 1-2 %, so measured lines sit slightly below and "
    "smear; a 'rolling-elements' bearing's seeded cage slip smears them about these values); "
    "a rolling element's defect strikes both races once per spin: its impacts repeat at 2 BSF. Marked on "
    "the spectra where in range (dotted): BPFO, BPFI, 2 BSF and FTF of each bearing."
)


class BearingSection:
    """What a report shows of the drive's bearings: ``rows`` (one per bearing and line), ``columns``
    (key -> header), ``notes`` and ``marks(input_hz, f_max)``, the lines to draw on a spectrum
    (:func:`gearbody.reports.html.bearing_html` writes it on a page)."""

    def __init__(self, drive, speeds: Mapping[str, float]):
        self.drive = drive
        self.columns = dict(COLUMNS)
        self.rows: list[dict[str, Any]] = []
        self.notes: list[str] = []
        if drive is None:
            self.notes.append("no scenario: the bearings' defect frequencies are not known")
            return
        every = {"": drive.nominal_input_hz} if drive.nominal_input_hz else {}
        every.update(speeds)
        for label, hz in every.items():
            name = "at the nominal input speed" if label == "" else label
            self.columns[f"hz:{label}"] = f"f [Hz] {name} ({hz:.4g} rev/s)"
        turning = drive.bearing_frequencies(1.0)  # in orders of the input shaft
        for b, f in turning:
            shaft = b.body if not b.reference else f"{b.body} relative to {b.reference}"
            for line, order in (("BPFO", f.bpfo_hz), ("BPFI", f.bpfi_hz), ("BSF", f.bsf_hz),
                                ("2 BSF", 2 * f.bsf_hz), ("FTF", f.ftf_hz)):  # fmt: skip
                row = {"bearing": b.name, "shaft": shaft, "line": line}
                row.update(shaft_order=order / f.shaft_hz, input_order=order)
                row.update({f"hz:{label}": order * hz for label, hz in every.items()})
                self.rows.append(row)
        still = [b.name for b in drive.bearings if b not in {t[0] for t in turning}]
        if not drive.bearings:
            missing = "; ".join(drive.bearings_without_geometry)
            self.notes.append(
                "no bearing geometry stated"
                + (
                    f": {missing} (a bearing's geometry table gives its lines)"
                    if missing
                    else " (no gear of the scene has a bearing table)"
                )
            )
        elif drive.bearings_without_geometry:
            self.notes.append(f"no bearing geometry stated for {'; '.join(drive.bearings_without_geometry)}")
        if still:
            self.notes.append(f"races that do not turn relative to each other, no lines: {', '.join(still)}")
        if self.rows:
            self.notes.append(NOTE)

    def marks(self, input_hz: float, f_max: float) -> list:
        """The bearing lines (fundamentals: BPFO, BPFI, 2 BSF, FTF) in (0, ``f_max``] with the input shaft
        at ``input_hz`` (1: in orders of the input shaft)."""
        if self.drive is None or not np.isfinite(input_hz) or input_hz <= 0:
            return []
        return self.drive.bearing_lines(input_hz, f_max, harmonics=1)


def bearing_section(drive, speeds: Mapping[str, float]) -> BearingSection:
    """The bearings of ``drive`` (a :class:`~gearbody.diagnosis.DriveKinematics`, None: unknown) with a
    column of Hz per entry of ``speeds`` (header text -> input shaft speed [rev/s])."""
    return BearingSection(drive, speeds)


def run_bearing_section(result) -> tuple[BearingSection, float]:
    """The section of a run (its scenario's drive; None when the run carries no scenario) and the input
    shaft's mean speed over the run's final window [rev/s] (NaN when unknown)."""
    from gearbody.errors import GearbodyError

    scenario = result.meta.get("scenario")
    drive = None
    if isinstance(scenario, dict):
        from gearbody.diagnosis import DriveKinematics
        from gearbody.model import load_scenario

        try:
            drive = DriveKinematics.from_scenario(load_scenario(scenario))
        except GearbodyError:
            drive = None
    input_hz = float("nan")
    if drive is not None:
        speed = f"{drive.input_body}_speed_rad_s"
        if speed in result:
            input_hz = abs(float(np.mean(result[speed][result.final_window()]))) / (2 * np.pi)
        elif drive.nominal_input_hz:
            input_hz = drive.nominal_input_hz
    label = f"in the analysed window (last {result.FINAL_FRACTION:.0%} of the run)"
    return bearing_section(drive, {label: input_hz} if np.isfinite(input_hz) else {}), input_hz
