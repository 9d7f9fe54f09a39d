"""The page of ``gearbody compare``: a run beside a recording (features with ratios, overlaid order spectra
labelled with the drive's lines), and overlay_orders.png."""

from __future__ import annotations

import base64
import csv
import html
import io
import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from gearbody.analysis import Spectrum  # noqa: F401 (the type of what _normalised takes)
from gearbody.folders import atomic_write, write_text
from gearbody.plotting.figure import png_bytes
from gearbody.plotting.recording import overlay_figure

from .bearings import bearing_section
from .html import _table, bearing_html
from .recording import STYLE

__all__ = ["write_comparison"]


def _normalised(spec: Spectrum) -> Spectrum:
    top = float(np.max(spec.amplitude[1:])) if spec.amplitude.size > 1 else 1.0
    return replace(spec, amplitude=spec.amplitude / (top or 1.0))


def write_comparison(comparison, out: str | Path, title: str) -> list[Path]:
    """Write comparison.json, comparison.csv (feature, run, recording, ratio), comparison.html and
    overlay_orders.png of ``comparison`` into ``out``."""
    out = Path(out)
    write_text(out / "comparison.json", json.dumps(comparison.as_dict(), indent=2) + "\n")
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=["feature", "run", "recording", "ratio"])
    writer.writeheader()
    writer.writerows(comparison.rows)
    write_text(out / "comparison.csv", buffer.getvalue())
    run, rec = comparison.run_side, comparison.recording_side
    bearings = bearing_section(
        comparison.run.drive,
        {
            "at the run's mean input speed": comparison.run.mean_input_hz,
            "at the recording's mean input speed": comparison.recording.mean_input_hz,
        },
    )
    written = []
    image = ""
    if run.order_spectrum is not None and rec.order_spectrum is not None:
        same_unit = run.unit == rec.unit
        spectra = [run.order_spectrum, rec.order_spectrum]
        if not same_unit:  # different quantities: each over its own largest line
            spectra = [_normalised(s) for s in spectra]
        max_order = float(min(s.frequency_hz[-1] for s in spectra))
        unit = run.unit if same_unit else "relative to each one's largest line"
        peaks = run.order_peaks if same_unit else []
        note = "" if same_unit else f" ({run.unit} and {rec.unit}: each over its largest line)"
        fig = overlay_figure(
            spectra,
            [f"run: {comparison.run_channel}", f"recording: {comparison.recording_channel}"],
            peaks,
            f"order spectra, run and recording{note}",
            unit,
            max_order,
            marks=bearings.marks(1.0, max_order),
        )
        data = png_bytes(fig)  # drawn once, written and embedded
        image = base64.b64encode(data).decode("ascii")
        path = out / "overlay_orders.png"
        atomic_write(path, lambda p: Path(p).write_bytes(data))
        written.append(path)
    page = [
        "<!DOCTYPE html><html><head><meta charset='utf-8'>",
        f"<title>{html.escape(title)}</title>{STYLE}</head><body>",
        f"<h1>{html.escape(title)}</h1>",
        f"<p>run channel <code>{html.escape(comparison.run_channel)}</code> [{html.escape(run.unit)}], input "
        f"shaft {comparison.run.mean_input_hz:.4f} rev/s; recording channel "
        f"<code>{html.escape(comparison.recording_channel)}</code> [{html.escape(rec.unit)}], input shaft "
        f"{comparison.recording.mean_input_hz:.4f} rev/s; drive "
        f"<code>{html.escape(comparison.run.drive.scene)}</code>.</p>",
        "<h2>Order spectra</h2>",
        f'<img src="data:image/png;base64,{image}" alt="overlay">' if image else "<p>no order spectrum</p>",
        bearing_html(bearings),
        "<h2>Features (ratio = recording / run)</h2>",
        _table(comparison.rows),
        "</body></html>",
    ]
    write_text(out / "comparison.html", "\n".join(page))
    return [out / "comparison.json", out / "comparison.csv", out / "comparison.html", *written]
