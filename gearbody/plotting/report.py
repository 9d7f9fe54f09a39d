"""The figures of the HTML run report (:mod:`gearbody.reports.html`): the labelled spectrum, K_d folded
over the mesh period, and the synchronous average with its difference signal. Each returns a Figure
for :func:`gearbody.plotting.figure.png_base64`."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .figure import new_figure, set_title
from .spectrum import mark_lines, plot_labelled_spectrum, spectrum_panels

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from gearbody.analysis import FoldedSignal, LabelledPeak, Spectrum, SynchronousAverage

__all__ = ["kd_folded_figure", "labelled_spectrum_figure", "tsa_figure"]


def labelled_spectrum_figure(
    spec: Spectrum, peaks: list[LabelledPeak], title: str, unit: str, f_max_hz: float, marks=()
) -> Figure:
    """The spectrum with its labelled peaks (:func:`gearbody.plotting.spectrum.plot_labelled_spectrum`)
    and ``marks`` (lines, e.g. bearing defect frequencies, :func:`~gearbody.plotting.spectrum.mark_lines`;
    a panel below shows them apart when they crowd the foot of the axis)."""
    fig, ax, low = spectrum_panels(spec, peaks, marks, f_max_hz, unit)
    plot_labelled_spectrum(spec, peaks, ax=ax, title=title, unit=unit, f_max_hz=f_max_hz)
    mark_lines(ax, marks, f_max_hz, labels=low is None)
    return fig


def kd_folded_figure(folded: FoldedSignal, title: str) -> Figure:
    """Mean K_d with its min-max band over the mesh period, and the K_d = 2 line."""
    fig = new_figure((900, 400), 100)
    ax = fig.add_subplot(1, 1, 1)
    ax.fill_between(folded.percent_of_period, folded.minimum, folded.maximum, alpha=0.3, label="min-max")
    ax.plot(folded.percent_of_period, folded.mean, label="mean")
    ax.axhline(2.0, color="red", ls=":", lw=0.8)
    ax.set_xlabel("mesh period [%]")
    ax.set_ylabel("K_d")
    ax.legend()
    set_title(ax, title)
    return fig


def tsa_figure(tsa: SynchronousAverage, name: str, unit: str = "") -> Figure:
    """The synchronous average of signal ``name`` [``unit``] over pinion revolutions, and its difference
    signal."""
    fig = new_figure((1100, 500), 100)
    ax = fig.add_subplot(2, 1, 1)
    deg = np.degrees(tsa.angle_rad)
    ax.plot(deg, tsa.average, lw=0.7)
    ax.set_title(f"TSA of {name} over {tsa.n_revs} pinion revolutions", fontsize=9)
    ax.set_ylabel(f"average [{unit}]" if unit else "average")
    ax = fig.add_subplot(2, 1, 2)
    ax.plot(deg, tsa.difference(), lw=0.7, color="C3")
    ax.set_ylabel(f"difference [{unit}]" if unit else "difference")
    ax.set_title("difference signal (mesh harmonics, first sidebands, shaft orders 1-2 removed)", fontsize=9)
    ax.set_xlabel("pinion angle [deg]")
    return fig
