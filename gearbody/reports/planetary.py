"""The report's content for a run with planetary stages (:func:`gearbody.reports.html.report_sections`
dispatches here): the first planetary stage's ring-fixed sensor as the vibration signal, its spectrum
over whole carrier revolutions relative to the ring (:func:`gearbody.analysis.ring_sensor.ring_sensor_window`)
labelled with the stage's kinematic lines (carrier, planet pass, mesh harmonics and carrier sidebands,
tooth fault frequencies; lines the phasing rule cancels marked "(cancelled)"), planet 1's sun-mesh K_d
folded over the mesh period, and the synchronous average of the sensor over the window's carrier
revolutions when it holds enough of them."""

from __future__ import annotations

from typing import Any

import numpy as np

from gearbody.analysis import (
    condition_indicators_from_average,
    fold_over_mesh_period,
    peaks_to_rows,
    synchronous_average,
)
from gearbody.analysis.ring_sensor import equally_spaced, ring_sensor_spectrum
from gearbody.plotting.figure import png_base64
from gearbody.plotting.report import kd_folded_figure, labelled_spectrum_figure, tsa_figure
from gearbody.result import Result

from ..signals import stage_prefix

__all__ = ["planetary_report_sections"]

MIN_TSA_REVOLUTIONS = 2


def planetary_report_sections(
    result: Result, bearings=None, input_hz: float = float("nan")
) -> dict[str, Any]:
    """summary, signal, unit, peaks, indicators, figures (base64 PNG), the analysed window ("window") and,
    when it cannot resolve the carrier sidebands, a note ("window_note") of a planetary run; the lines of
    ``bearings`` (a :class:`~gearbody.reports.bearings.BearingSection`) at ``input_hz`` marked on the
    ring-sensor spectrum."""
    k = result.planetary_stages[0]
    prefix = stage_prefix(k)
    meta = result.meta["stages"][k]
    ring = ring_sensor_spectrum(result, k)
    win = ring.window.mask(result.time_s.size)
    name = ring.signal
    signal = result[name]
    out: dict[str, Any] = {"summary": result.summary(), "signal": name, "unit": "N", "figures": {}}
    out["window"] = f"stage {k + 1}'s ring sensor over {ring.window.describe()}"
    if ring.window.note():
        out["window_note"] = ring.window.note()
    if equally_spaced(result, k):
        out["cancelled_note"] = (
            'peaks labelled "(cancelled)" (open grey markers) sit at lines McFadden & Smith\'s rule cancels '
            "for equally spaced identical planets: tooth errors, unequal sharing or the planets' own motion "
            "bring them back"
        )
    sources = ring.sources
    peaks = ring.peaks(min_prominence_db=12.0, max_peaks=40)
    title = ring.title(f"spectrum of {name} [N] (stage {k + 1})")
    marks = bearings.marks(input_hz, ring.f_max_hz) if bearings is not None else []
    out["figures"]["spectrum"] = png_base64(
        labelled_spectrum_figure(
            ring.spectrum, peaks, title=title, unit="N", f_max_hz=ring.f_max_hz, marks=marks
        )
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
    if revs >= MIN_TSA_REVOLUTIONS + 1 - 1e-9 and np.all(np.diff(carrier) > 0):
        tsa = synchronous_average(signal[win], carrier, teeth=meta["ring_teeth"])
        out["indicators"] = condition_indicators_from_average(tsa).as_dict()
        out["tsa_revolutions"] = tsa.n_revs
        out["figures"]["tsa"] = png_base64(tsa_figure(tsa, name, "N"))
    else:
        out["tsa_note"] = (
            f"no TSA: the analysed window holds {revs:.2f} carrier revolutions relative to the ring "
            f"(needs {MIN_TSA_REVOLUTIONS + 1}); run longer"
        )
    return out
