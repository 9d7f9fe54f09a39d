"""The report of a recording's analysis (``gearbody analyze``): one self-contained HTML page and the same
figures as PNG files, plus features.json (every feature by name) -- for a measured recording and a
simulated one alike."""

from __future__ import annotations

import base64
import html
import json
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from gearbody.analysis import peaks_to_rows
from gearbody.folders import atomic_write, write_text
from gearbody.plotting.figure import png_bytes
from gearbody.plotting.recording import (
    envelope_figure,
    kurtogram_figure,
    order_spectrum_figure,
    reduced,
    rpm_order_figure,
    shaft_tsa_figure,
)
from gearbody.plotting.report import labelled_spectrum_figure

from .html import PEAK_COLUMNS, _table, bearing_html

__all__ = ["diagnosis_figures", "write_diagnosis"]

STYLE = (
    "<style>body{font-family:sans-serif;max-width:1150px;margin:auto;padding:1em}"
    "table{border-collapse:collapse;font-size:13px}td,th{border:1px solid #ccc;padding:2px 6px;"
    "text-align:right}th{background:#eee}img{max-width:100%}</style>"
)


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_")


def diagnosis_figures(diag) -> Iterator[tuple[str, Any]]:
    """``(file stem, Figure)`` of every channel, one at a time (a long recording's figures are drawn and
    let go in turn): spectrum, orders, TSA per shaft, kurtogram, envelope; the spectra with the bearings'
    defect frequencies marked (:mod:`gearbody.reports.bearings`)."""
    f_in = diag.mean_input_hz
    bearings = _bearings(diag)
    for name, ch in diag.channels.items():
        tag = _slug(name)
        f_max = max((p.frequency_hz for p in ch.peaks), default=ch.spectrum.frequency_hz[-1]) * 1.05
        yield (
            f"spectrum_{tag}",
            labelled_spectrum_figure(
                reduced(ch.spectrum, float(ch.spectrum.frequency_hz[-1])),
                ch.peaks,
                f"spectrum of {name} [{ch.unit}], input shaft {f_in:.3f} rev/s",
                ch.unit,
                min(float(ch.spectrum.frequency_hz[-1]), f_max),
                marks=bearings.marks(f_in, min(float(ch.spectrum.frequency_hz[-1]), f_max)),
            ),
        )
        if ch.order_spectrum is not None:
            max_order = float(ch.order_spectrum.frequency_hz[-1])
            yield (
                f"orders_{tag}",
                order_spectrum_figure(
                    ch.order_spectrum,
                    ch.order_peaks,
                    f"order spectrum of {name} [{ch.unit}]",
                    ch.unit,
                    max_order,
                    marks=bearings.marks(1.0, max_order),
                ),
            )
        if ch.rpm_order_map is not None:
            title = (
                f"rpm-order map of {name} ({ch.rpm_order_map.revolutions_per_block:g} revolutions per block)"
            )
            yield f"rpm_orders_{tag}", rpm_order_figure(ch.rpm_order_map, title, ch.unit)
        for body, tsa in ch.averages.items():
            yield f"tsa_{tag}_{_slug(body)}", shaft_tsa_figure(tsa, name, body, ch.unit)
        if ch.kurtogram is not None:
            k = ch.kurtogram
            title = f"kurtogram of {name}: band {k.centre_hz:.0f} Hz +- {k.bandwidth_hz / 2:.0f} Hz"
            yield f"kurtogram_{tag}", kurtogram_figure(k, title)
        if ch.envelope is not None:
            f_top = max(10 * f_in, max((b.centre for b in ch.envelope_bands), default=0.0) * 2.2)
            f_top = min(f_top, float(ch.envelope.frequency_hz[-1]))
            white = " (cepstrum-prewhitened)" if ch.prewhitened else ""
            yield (
                f"envelope_{tag}",
                envelope_figure(
                    ch.envelope_spectrum(),
                    ch.envelope_peaks,
                    f"squared-envelope spectrum of {name}{white} in the kurtogram's band",
                    "relative" if ch.prewhitened else f"({ch.unit})^2",
                    f_top,
                    marks=bearings.marks(f_in, f_top),
                ),
            )


def _bearings(diag):
    """The bearings' section of a diagnosis: Hz at its mean input speed."""
    from .bearings import bearing_section

    return bearing_section(diag.drive, {"at the recording's mean input speed": diag.mean_input_hz})


def write_diagnosis(diag, out: str | Path, title: str = "") -> list[Path]:
    """Write report.html, features.json and the PNG figures of ``diag`` into folder ``out``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    images = {}
    for stem, fig in diagnosis_figures(diag):
        data = png_bytes(fig)  # drawn once, written and embedded
        images[stem] = base64.b64encode(data).decode("ascii")
        path = out / f"{stem}.png"
        atomic_write(path, lambda p, data=data: Path(p).write_bytes(data))
        written.append(path)
    features = diag.features()
    write_text(out / "features.json", json.dumps(features, indent=2, sort_keys=True) + "\n")
    write_text(out / "report.html", _page(diag, images, title))
    return [out / "report.html", out / "features.json", *written]


def _page(diag, images: dict[str, str], title: str) -> str:
    rec = diag.recording
    title = html.escape(title or str(rec.meta.get("title") or rec.meta.get("source") or "recording"))

    def img(stem: str) -> str:
        return f'<img src="data:image/png;base64,{images[stem]}" alt="{stem}">' if stem in images else ""

    tacho = rec.tacho.describe() if rec.tacho is not None else "none (tacholess)"
    parts = [
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{title}</title>{STYLE}</head><body>",
        f"<h1>{title}</h1>",
        f"<p>scene <code>{html.escape(diag.drive.scene)}</code>; {rec.n_samples} samples at "
        f"{rec.sample_rate_hz:g} Hz ({rec.duration_s:.3f} s); tacho {html.escape(str(tacho))} "
        f"({html.escape(diag.angles.source)}); mean input shaft speed {diag.mean_input_hz:.4f} rev/s "
        f"({60 * diag.mean_input_hz:.1f} rpm).</p>",
        *(f"<p><b>note:</b> {html.escape(n)}</p>" for n in diag.notes),
        bearing_html(_bearings(diag)),
    ]
    for name, ch in diag.channels.items():
        tag = _slug(name)
        headers = {k: v.format(unit=ch.unit) for k, v in PEAK_COLUMNS.items()}
        ind_rows = [{"shaft": body, **vals} for body, vals in ch.indicators.items()]
        parts += [
            f"<h2>Channel <code>{html.escape(name)}</code> [{html.escape(ch.unit)}]</h2>",
            *(f"<p><b>note:</b> {html.escape(n)}</p>" for n in ch.notes),
            "<h3>Labelled spectrum</h3>",
            img(f"spectrum_{tag}"),
            _table(peaks_to_rows(ch.peaks), list(PEAK_COLUMNS), headers),
            "<h3>Order spectrum (orders of the input shaft)</h3>",
            img(f"orders_{tag}"),
            img(f"rpm_orders_{tag}"),
            _table([b.as_row() for b in ch.bands]),
            "<h3>Synchronous averages and condition indicators</h3>",
            _table(ind_rows),
            *(img(f"tsa_{tag}_{_slug(body)}") for body in ch.averages),
            "<h3>Kurtogram and envelope spectrum</h3>",
            img(f"kurtogram_{tag}"),
            img(f"envelope_{tag}"),
            _table([b.as_row() for b in ch.envelope_bands]),
            "<h3>Features</h3>",
            _table([{"feature": k, "value": v} for k, v in ch.features().items()]),
        ]
    parts.append("</body></html>")
    return "\n".join(parts)
