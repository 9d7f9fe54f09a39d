"""One self-contained HTML page per run: summary, labelled spectrum (the bearings' defect frequencies
marked), the bearings' fault frequencies, folded K_d, TSA and indicators.

Engine-free: works on any :class:`~gearbody.result.Result` (simulated, or loaded from result.npz).
Figures (drawn by :mod:`gearbody.plotting.report`) are embedded as base64 PNG, so the page can be
mailed or archived on its own.
"""

from __future__ import annotations

import html
from pathlib import Path
from typing import Any

import numpy as np

from gearbody.analysis import (
    KinematicLine,
    condition_indicators_from_average,
    fold_over_mesh_period,
    gear_train_lines,
    peaks_to_rows,
    synchronous_average,
)
from gearbody.folders import write_text
from gearbody.plotting.figure import png_base64
from gearbody.plotting.report import kd_folded_figure, labelled_spectrum_figure, tsa_figure
from gearbody.result import Result
from gearbody.signals import signal_unit

__all__ = ["PEAK_COLUMNS", "bearing_html", "report_sections", "spectrum_lines", "write_report"]

MIN_TSA_REVOLUTIONS = 2


def spectrum_lines(input_hz: float, teeth: list[tuple[int, int]], f_max_hz: float) -> list[KinematicLine]:
    """The kinematic lines the report labels peaks with (those of ``Result.spectrum``):
    :func:`gearbody.analysis.gear_train_lines` with its defaults."""
    return gear_train_lines(input_hz, teeth, f_max_hz)


PEAK_COLUMNS = {
    "frequency_hz": "f [Hz]",
    "amplitude": "amplitude [{unit}]",
    "prominence_db": "prominence over the local floor [dB]",
    "label": "kinematic line",
    "offset_hz": "offset from the line [Hz]",
}
"""Header of each column of the peaks table (``{unit}``: the vibration signal's unit)."""


def _table(
    rows: list[dict[str, Any]], columns: list[str] | None = None, headers: dict[str, str] | None = None
) -> str:
    if not rows:
        return "<p><em>none</em></p>"
    columns = columns or list(rows[0])
    headers = headers or {}

    def cell(v):
        if v is None:
            return ""
        if isinstance(v, float):
            return f"{v:.4g}"
        if isinstance(v, (list, tuple)):
            return html.escape("; ".join(map(str, v)))
        return html.escape(str(v))

    head = "".join(f"<th>{html.escape(headers.get(c, c))}</th>" for c in columns)
    body = "".join(
        "<tr>" + "".join(f"<td>{cell(r.get(c, ''))}</td>" for c in columns) + "</tr>" for r in rows
    )
    return f"<table><tr>{head}</tr>{body}</table>"


def bearing_html(section) -> str:
    """A page's section of the bearings' fault frequencies (a
    :class:`~gearbody.reports.bearings.BearingSection`): heading, notes and the table."""
    parts = ["<h2>Bearing fault frequencies</h2>", *(f"<p>{html.escape(n)}</p>" for n in section.notes)]
    if section.rows:
        parts.append(_table(section.rows, list(section.columns), section.columns))
    return "\n".join(parts)


def report_sections(result: Result) -> dict[str, Any]:
    """The report's content as data: summary, labelled peaks, indicators, the bearings' fault frequencies
    (``bearings``: a :class:`~gearbody.reports.bearings.BearingSection`; its lines marked on the
    spectrum), and figures (base64 PNG)."""
    from .bearings import run_bearing_section

    bearings, input_hz = run_bearing_section(result)
    if result.planetary_stages:
        from .planetary import planetary_report_sections

        return {**planetary_report_sections(result, bearings, input_hz), "bearings": bearings}
    win = result.final_window()
    summary = result.summary()
    name = result.vibration_signal_name
    signal = result[name]
    z1 = int(result.meta["pinion_teeth"])
    f_mesh = float(np.mean(result["mesh_frequency_hz"][win]))
    out: dict[str, Any] = {"summary": summary, "signal": name, "figures": {}, "bearings": bearings}

    # the labelled spectrum of the vibration signal over the final window: Result.spectrum's, the one
    # composition of signal, window, lines and defaults
    labelled = result.spectrum(name)
    unit = signal_unit(name)
    peaks = labelled.peaks
    if f_mesh > 0:
        title = f"spectrum of {name} [{unit}], last {result.FINAL_FRACTION:.0%} of the run"
        marks = bearings.marks(input_hz, labelled.f_max_hz)
        fig = labelled_spectrum_figure(
            labelled.spectrum, peaks, title=title, unit=unit, f_max_hz=labelled.f_max_hz, marks=marks
        )
        out["figures"]["spectrum"] = png_base64(fig)
    out["peaks"] = peaks_to_rows(peaks)
    out["unit"] = unit

    # K_d folded over the mesh period
    if f_mesh > 0:
        bins = int(np.clip(result.sample_rate_hz / f_mesh, 10, 100))
        folded = fold_over_mesh_period(result.kd[win], result["pinion_angle_rad"][win], z1, bins=bins)
        title = f"K_d over the mesh period (last {result.FINAL_FRACTION:.0%} of the run)"
        fig = kd_folded_figure(folded, title=title)
        out["figures"]["kd_folded"] = png_base64(fig)

    # synchronous average over pinion revolutions, and condition indicators
    angle = result["pinion_angle_rad"][win]
    revs = (angle[-1] - angle[0]) / (2 * np.pi)
    out["indicators"] = {}
    if revs >= MIN_TSA_REVOLUTIONS + 1 and np.all(np.diff(angle) > 0):
        tsa = synchronous_average(signal[win], angle, teeth=z1)
        out["indicators"] = condition_indicators_from_average(tsa).as_dict()
        out["tsa_revolutions"] = tsa.n_revs
        fig = tsa_figure(tsa, name, unit)
        out["figures"]["tsa"] = png_base64(fig)
    else:
        out["tsa_note"] = (
            f"no TSA: the final window holds {revs:.1f} pinion revolutions "
            f"(needs {MIN_TSA_REVOLUTIONS + 1}, monotone angle)"
        )
    return out


def write_report(result: Result, path: str | Path) -> Path:
    """Write the report page for ``result`` to ``path`` (.html), atomically (OutputError naming it if it
    cannot be written)."""
    s = report_sections(result)
    title = html.escape(str(result.meta.get("title", result.meta.get("scene", "gearbody run"))))
    summary_rows = [
        {"quantity": k, "value": v} for k, v in s["summary"].items() if not isinstance(v, (dict, list))
    ]
    sources = [html.escape(str(src)) for src in s["summary"].get("sources") or []]
    fig = s["figures"]
    img = {k: f'<img src="data:image/png;base64,{v}" alt="{k}">' for k, v in fig.items()}
    parts = [
        "<!DOCTYPE html><html><head><meta charset='utf-8'>",
        f"<title>{title}</title>",
        "<style>body{font-family:sans-serif;max-width:1150px;margin:auto;padding:1em}"
        "table{border-collapse:collapse;font-size:13px}td,th{border:1px solid #ccc;padding:2px 6px;"
        "text-align:right}th{background:#eee}img{max-width:100%}</style></head><body>",
        f"<h1>{title}</h1>",
        f"<p>scene <code>{html.escape(str(result.meta.get('scene', '')))}</code>, gearbody "
        f"{html.escape(str(result.meta.get('gearbody_version', '')))}; analysed window: "
        f"{html.escape(s.get('window', f'the last {result.FINAL_FRACTION:.0%} of the run'))}; vibration "
        f"signal <code>{html.escape(s['signal'])}</code>.</p>",
        "<h2>Summary</h2>",
        _table(summary_rows),
        "<h2>K_d over the mesh period</h2>",
        img.get("kd_folded", "<p>no mesh frequency</p>"),
        "<h2>Labelled spectrum</h2>",
        *(f"<p><b>note:</b> {html.escape(s[k])}</p>" for k in ("window_note", "cancelled_note") if s.get(k)),
        img.get("spectrum", ""),
        _table(
            s["peaks"], list(PEAK_COLUMNS), {k: v.format(unit=s["unit"]) for k, v in PEAK_COLUMNS.items()}
        ),
        bearing_html(s["bearings"]),
        "<h2>Synchronous average and condition indicators</h2>",
        img.get("tsa", f"<p>{html.escape(s.get('tsa_note', ''))}</p>"),
        _table([{"indicator": k, "value": v} for k, v in s["indicators"].items()]),
        "<h2>Sources of the parameter values</h2>",
        "<ul>" + "".join(f"<li>{src}</li>" for src in sources) + "</ul>"
        if sources
        else "<p>the scene names no sources (<code>meta.sources</code>)</p>",
        "</body></html>",
    ]
    return write_text(Path(path), "\n".join(parts))  # atomic: a full disk leaves no part
