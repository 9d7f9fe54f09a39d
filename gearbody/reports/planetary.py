"""The report's content for a run with planetary stages (:func:`gearbody.reports.html.report_sections`
dispatches here): the first planetary stage's ring-fixed sensor as the vibration signal, its spectrum
labelled with the stage's kinematic lines (carrier, planet pass, mesh harmonics and carrier sidebands,
tooth fault frequencies), planet 1's sun-mesh K_d folded over the mesh period, and the synchronous
average of the sensor over carrier revolutions when the window holds enough of them."""

from __future__ import annotations

from typing import Any

import numpy as np

from gearbody.analysis import (
    amplitude_spectrum,
    condition_indicators_from_average,
    fold_over_mesh_period,
    label_peaks,
    peaks_to_rows,
    synchronous_average,
)
from gearbody.analysis.planetary_lines import planetary_lines
from gearbody.plotting.figure import png_base64
from gearbody.plotting.planetary import planetary_sources
from gearbody.plotting.report import kd_folded_figure, labelled_spectrum_figure, tsa_figure
from gearbody.result import Result

__all__ = ["planetary_report_sections"]

MIN_TSA_REVOLUTIONS = 2


def planetary_report_sections(result: Result) -> dict[str, Any]:
    """summary, signal, unit, peaks, indicators and figures (base64 PNG) of a planetary run."""
    win = result.final_window()
    k = result.planetary_stages[0]
    prefix = "" if k == 0 else f"stage_{k + 1}_"
    meta = result.meta["stages"][k]
    name = prefix + "ring_sensor_N"
    signal = result[name]
    out: dict[str, Any] = {"summary": result.summary(), "signal": name, "unit": "N", "figures": {}}
    sources = planetary_sources(result, k)
    spec = amplitude_spectrum(signal[win], result.sample_rate_hz, window="hann")
    f_max = min(result.sample_rate_hz / 2, 3.5 * sources.mesh_hz)
    peaks = label_peaks(
        spec,
        planetary_lines(sources, f_max, harmonics=3),
        tolerance_hz=1.5 * spec.resolution_hz,
        min_prominence_db=12.0,
        max_peaks=40,
        f_max_hz=f_max,
    )
    title = f"spectrum of {name} [N] (stage {k + 1}), last {result.FINAL_FRACTION:.0%} of the run"
    out["figures"]["spectrum"] = png_base64(
        labelled_spectrum_figure(spec, peaks, title=title, unit="N", f_max_hz=f_max)
    )
    out["peaks"] = peaks_to_rows(peaks)
    # planet 1's sun mesh over its mesh period: the sun's angle relative to the carrier sets the phase
    rel = result[prefix + "sun_angle_rad"][win] - result[prefix + "carrier_angle_rad"][win]
    f_mesh = sources.mesh_hz
    if f_mesh > 0 and np.all(np.diff(rel) > 0):
        bins = int(np.clip(result.sample_rate_hz / f_mesh, 10, 100))
        folded = fold_over_mesh_period(
            result[prefix + "planet_1_sun_mesh_kd"][win], rel, meta["sun_teeth"], bins=bins
        )
        fig = kd_folded_figure(folded, title=f"planet 1 sun-mesh K_d over the mesh period (stage {k + 1})")
        out["figures"]["kd_folded"] = png_base64(fig)
    carrier = result[prefix + "carrier_angle_rad"][win] - result[prefix + "ring_angle_rad"][win]
    revs = abs(carrier[-1] - carrier[0]) / (2 * np.pi)
    out["indicators"] = {}
    if revs >= MIN_TSA_REVOLUTIONS + 1 and np.all(np.diff(carrier) > 0):
        tsa = synchronous_average(signal[win], carrier, teeth=meta["ring_teeth"])
        out["indicators"] = condition_indicators_from_average(tsa).as_dict()
        out["tsa_revolutions"] = tsa.n_revs
        out["figures"]["tsa"] = png_base64(tsa_figure(tsa, name, "N"))
    else:
        out["tsa_note"] = (
            f"no TSA: the final window holds {revs:.2f} carrier revolutions relative to the ring "
            f"(needs {MIN_TSA_REVOLUTIONS + 1}); run longer"
        )
    return out
