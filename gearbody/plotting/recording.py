"""Figures of a recording's analysis (:mod:`gearbody.reports.recording`): the labelled spectrum in Hz or
in orders, the synchronous average of a shaft, the envelope spectrum with the bearing lines, the
kurtogram, and a run beside a recording (overlaid order spectra). Each returns a Figure."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .figure import new_figure, set_title
from .spectrum import mark_lines, plot_labelled_spectrum, spectrum_panels

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "envelope_figure",
    "kurtogram_figure",
    "order_spectrum_figure",
    "overlay_figure",
    "rpm_order_figure",
    "shaft_tsa_figure",
]

MAX_PLOT_POINTS = 10_000
"""Points drawn of a spectrum at most (~9 per pixel column of a 1100-pixel figure): longer spectra are
reduced to each group's maximum, so every line stays in the picture."""


def reduced(spectrum, x_max: float):
    """The spectrum up to ``x_max`` with at most :data:`MAX_PLOT_POINTS` points (each kept point the largest
    of its group, so no line is lost from the picture)."""
    from gearbody.analysis import Spectrum

    f, a = np.asarray(spectrum.frequency_hz), np.asarray(spectrum.amplitude)
    keep = f <= x_max
    f, a = f[keep], a[keep]
    step = int(np.ceil(f.size / MAX_PLOT_POINTS))
    if step > 1:
        n = f.size // step * step
        groups = a[:n].reshape(-1, step)
        k = np.argmax(groups, axis=1) + np.arange(groups.shape[0]) * step
        f, a = f[k], a[k]
    return Spectrum(f, a, spectrum.sample_rate_hz, spectrum.window, spectrum.n_samples)


def order_spectrum_figure(spec, peaks, title: str, unit: str, max_order: float, marks=()) -> Figure:
    """An order spectrum (``spec.frequency_hz`` holds orders) with its labelled peaks and ``marks`` (lines
    in orders, :func:`~gearbody.plotting.spectrum.mark_lines`; a panel below shows them apart when they
    crowd the foot of the axis)."""
    fig, ax, low = spectrum_panels(reduced(spec, max_order), peaks, marks, max_order, unit)
    plot_labelled_spectrum(reduced(spec, max_order), peaks, ax=ax, title=title, unit=unit, f_max_hz=max_order)
    mark_lines(ax, marks, max_order, labels=low is None)
    for axes in fig.axes:
        axes.set_xlabel("order of the input shaft [cycles/rev]")
        for text in axes.texts:  # an unexplained peak's label is its order, not Hz
            if text.get_text().endswith(" Hz"):
                text.set_text(text.get_text()[:-3])
    return fig


def shaft_tsa_figure(tsa, channel: str, body: str, unit: str = "") -> Figure:
    """The synchronous average of ``channel`` over revolutions of ``body``, and its difference signal."""
    fig = new_figure((1100, 500), 100)
    deg = np.degrees(tsa.angle_rad)
    ax = fig.add_subplot(2, 1, 1)
    ax.plot(deg, tsa.average, lw=0.7)
    ax.set_title(f"TSA of {channel} over {tsa.n_revs} revolutions of {body}", fontsize=9)
    ax.set_ylabel(f"average [{unit}]" if unit else "average")
    ax = fig.add_subplot(2, 1, 2)
    ax.plot(deg, tsa.difference(), lw=0.7, color="C3")
    ax.set_ylabel(f"difference [{unit}]" if unit else "difference")
    ax.set_title("difference signal (mesh harmonics, first sidebands, shaft orders 1-2 removed)", fontsize=9)
    ax.set_xlabel(f"{body} angle [deg]")
    return fig


def envelope_figure(spec, peaks, title: str, unit: str, f_max_hz: float, marks=()) -> Figure:
    """The envelope spectrum with its labelled peaks (bearing lines, shaft orders) and ``marks``."""
    from dataclasses import replace

    fig = new_figure((1100, 450), 100)
    ax = fig.add_subplot(1, 1, 1)
    spec = reduced(spec, f_max_hz)
    amplitude = spec.amplitude.copy()
    amplitude[:2] = np.nan  # the mean (DC) and its leakage through the window would hide every line
    spec = replace(spec, amplitude=amplitude)
    plot_labelled_spectrum(spec, peaks, ax=ax, title=title, unit=unit, f_max_hz=f_max_hz, log=False)
    ax.set_xlabel("envelope frequency [Hz]")
    mark_lines(ax, marks, f_max_hz)
    return fig


def kurtogram_figure(kurtogram, title: str) -> Figure:
    """Spectral kurtosis over frequency (x) and decomposition level (y), the chosen band marked."""
    fig = new_figure((1100, 450), 100)
    ax = fig.add_subplot(1, 1, 1)
    k = np.asarray(kurtogram.kurtosis)
    fs = float(kurtogram.sample_rate_hz)
    levels = np.asarray(kurtogram.levels, dtype=float)
    rows = np.arange(levels.size)
    image = ax.imshow(
        np.clip(k, 0, None),
        aspect="auto",
        origin="upper",
        cmap="viridis",
        interpolation="nearest",
        extent=(0, fs / 2, rows[-1] + 0.5, -0.5),
    )
    ax.set_yticks(rows, [f"{lv:.1f}" for lv in levels])
    fig.colorbar(image, ax=ax, label="spectral kurtosis")
    lo = kurtogram.centre_hz - kurtogram.bandwidth_hz / 2
    ax.axvspan(lo, lo + kurtogram.bandwidth_hz, color="red", alpha=0.25, lw=0)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("level")
    set_title(ax, title)
    return fig


def rpm_order_figure(rpm_map, title: str, unit: str) -> Figure:
    """Amplitude [dB re its largest cell] over order (x) and speed in rpm (y): a run-up's map."""
    fig = new_figure((1100, 500), 100)
    ax = fig.add_subplot(1, 1, 1)
    a = np.asarray(rpm_map.amplitude)
    db = 20 * np.log10(np.maximum(a, np.max(a) * 1e-4) / np.max(a))
    order, rpm = np.asarray(rpm_map.order), np.asarray(rpm_map.speed_rpm)
    sorted_rows = np.argsort(rpm)
    image = ax.pcolormesh(
        order,
        rpm[sorted_rows],
        db[sorted_rows],
        shading="nearest",
        cmap="viridis",
        vmin=-60,
        vmax=0,
        rasterized=True,
    )
    fig.colorbar(image, ax=ax, label=f"amplitude [dB re {np.max(a):.3g} {unit}]")
    ax.set_xlabel("order of the input shaft [cycles/rev]")
    ax.set_ylabel("input shaft speed [rpm]")
    set_title(ax, title)
    return fig


def overlay_figure(
    spectra: list, labels: list[str], peaks, title: str, unit: str, max_order: float, marks=()
) -> Figure:
    """Order spectra of a run and a recording overlaid (the first one's peaks labelled; ``marks``: lines
    in orders, shown apart in a panel below when they crowd the foot of the axis)."""
    first = reduced(spectra[0], max_order)
    fig, ax, low = spectrum_panels(first, peaks, marks, max_order, unit)
    plot_labelled_spectrum(first, peaks, ax=ax, title=title, unit=unit, f_max_hz=max_order)
    ax.lines[0].set_label(labels[0])
    for spec, label, colour in zip(spectra[1:], labels[1:], ("tab:orange", "tab:green"), strict=False):
        s = reduced(spec, max_order)
        for axes in (ax, low) if low is not None else (ax,):
            axes.plot(
                s.frequency_hz,
                np.where(s.amplitude > 0, s.amplitude, np.nan),
                lw=0.6,
                color=colour,
                alpha=0.8,
                label=label,
            )
    mark_lines(ax, marks, max_order, labels=low is None)
    for axes in fig.axes:
        axes.set_xlabel("order of the input shaft [cycles/rev]")
    ax.legend(loc="upper right", fontsize=8)
    return fig
