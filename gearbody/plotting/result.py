"""PNG plots of a run's signals: K_d over time, K_d folded over the mesh period, spectra and several
signals of one unit (as the paper's Figs. 6-8, 12 and 13-16).

Drawn with :func:`gearbody.plotting.figure.new_figure` (Agg canvas, no pyplot). Every function writes
one PNG of exactly ``size_px`` pixels and returns its path. Engine-free: plain arrays in.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

if TYPE_CHECKING:
    from matplotlib.figure import Figure

from gearbody.analysis.dynamic_factor import INSTABILITY_KD, FoldedSignal
from gearbody.analysis.spectrum import Spectrum, mesh_harmonics

from .figure import DEFAULT_SIZE_PX, PathLike, new_figure, save_figure, set_title

__all__ = [
    "harmonic_labels",
    "plot_kd_folded",
    "plot_kd_time",
    "plot_signals",
    "plot_spectrum",
    "spectrum_figure",
]


def _threshold_line(ax, kd_threshold: float | None) -> None:
    if kd_threshold is not None:
        ax.axhline(
            kd_threshold,
            color="tab:red",
            linestyle="--",
            linewidth=1.0,
            label=f"K_d = {kd_threshold:g} (instability)",
        )


def harmonic_labels(count: int, symbol: str = "f_z") -> list[str]:
    """Labels "f_z", "2f_z", ..., for the first ``count`` harmonics of ``symbol``."""
    return [symbol if k == 1 else f"{k}{symbol}" for k in range(1, count + 1)]


def plot_kd_time(
    time_s: ArrayLike,
    kd: ArrayLike,
    path: PathLike,
    title: str = "",
    boundaries_s: Sequence[float] = (),
    kd_threshold: float | None = INSTABILITY_KD,
    size_px: tuple[int, int] = DEFAULT_SIZE_PX,
    dpi: int = 100,
) -> Path:
    """K_d [-] against time [s] (as Fig. 12); optional operating-period boundaries and K_d = 2 line."""
    fig = new_figure(size_px, dpi)
    ax = fig.add_subplot()
    ax.plot(np.asarray(time_s, dtype=float), np.asarray(kd, dtype=float), linewidth=0.6, color="tab:blue")
    for t in boundaries_s:
        ax.axvline(t, color="0.5", linestyle=":", linewidth=1.0)
    _threshold_line(ax, kd_threshold)
    ax.set_xlabel("Time t [s]")
    ax.set_ylabel("Dynamic factor K_d [-]")
    if title:
        set_title(ax, title)
    if kd_threshold is not None:
        ax.legend(loc="upper left")
    ax.grid(True, alpha=0.3)
    return save_figure(fig, path, dpi)


def plot_signals(
    time_s: ArrayLike,
    signals: Mapping[str, ArrayLike],
    path: PathLike,
    title: str = "",
    ylabel: str = "",
    size_px: tuple[int, int] = DEFAULT_SIZE_PX,
    dpi: int = 100,
) -> Path:
    """Several signals of one unit against time [s], one line each, labelled by their names."""
    fig = new_figure(size_px, dpi)
    ax = fig.add_subplot()
    t = np.asarray(time_s, dtype=float)
    for name, values in signals.items():
        ax.plot(t, np.asarray(values, dtype=float), linewidth=0.6, label=name)
    ax.set_xlabel("Time t [s]")
    ax.set_ylabel(ylabel)
    if title:
        set_title(ax, title)
    if signals:
        ax.legend(loc="upper left", fontsize="small")
    ax.grid(True, alpha=0.3)
    return save_figure(fig, path, dpi)


def plot_kd_folded(
    folded: FoldedSignal,
    path: PathLike,
    title: str = "",
    show_range: bool = True,
    kd_threshold: float | None = None,
    size_px: tuple[int, int] = DEFAULT_SIZE_PX,
    dpi: int = 100,
) -> Path:
    """Mean K_d [-] over % of the mesh period (as Figs. 6-8), with the min-max band if ``show_range``."""
    fig = new_figure(size_px, dpi)
    ax = fig.add_subplot()
    x = folded.percent_of_period
    if show_range:
        ax.fill_between(
            x, folded.minimum, folded.maximum, color="tab:blue", alpha=0.2, linewidth=0, label="min-max"
        )
    ax.plot(x, folded.mean, color="tab:blue", linewidth=1.5, label="mean")
    _threshold_line(ax, kd_threshold)
    ax.set_xlim(0.0, 100.0)
    ax.set_xlabel("% of mesh period")
    ax.set_ylabel("K_d [-]")
    if title:
        set_title(ax, title)
    ax.legend(loc="upper right")
    ax.grid(True, alpha=0.3)
    return save_figure(fig, path, dpi)


SHAFT_PANEL_ORDERS = 4.5
"""The low-frequency panel of a spectrum spans 0 .. this many times the fastest shaft frequency."""


def spectrum_figure(
    spectrum: Spectrum,
    mesh_frequency_hz: float | None = None,
    shaft_frequencies_hz: Sequence[float] | Mapping[str, float] = (),
    title: str = "",
    fmax_hz: float | None = None,
    ylabel: str = "Amplitude [signal units]",
    log_amplitude: bool = False,
    max_harmonics: int = 20,
    size_px: tuple[int, int] = DEFAULT_SIZE_PX,
    dpi: int = 100,
    marks: Sequence = (),
) -> Figure:
    """The figure of :func:`plot_spectrum` (same arguments but ``path``), not saved.

    Amplitude spectrum against frequency [Hz] (as Figs. 13-16, 20). Mesh harmonics k f_z <= fmax_hz
    (at most ``max_harmonics``) are marked by dashed lines labelled f_z, 2f_z, ... inside the axes.
    Shaft frequencies, a few Hz on an axis of kHz, get a second, low-frequency panel below (0 to
    :data:`SHAFT_PANEL_ORDERS` times the fastest shaft, shaded in the upper panel) where they are marked
    by green lines labelled inside it with the mapping keys (plain text) or f_s1, f_s2, ... and their
    frequency. Long titles wrap. ``log_amplitude`` uses log y axes (bins below 1e-9 of the maximum are
    clipped to it). Pass ``ylabel`` with the signal's unit, e.g. "Acceleration amplitude [m/s^2]".
    ``marks`` (lines such as bearing defect frequencies) are drawn by
    :func:`gearbody.plotting.spectrum.mark_lines` in the upper panel.
    """
    fmax = float(spectrum.frequency_hz[-1]) if fmax_hz is None else float(fmax_hz)
    shown = spectrum.frequency_hz <= fmax
    freq = spectrum.frequency_hz[shown]
    amp = spectrum.amplitude[shown]
    if log_amplitude:
        peak = float(np.max(amp)) if amp.size and np.max(amp) > 0 else 1.0
        amp = np.maximum(amp, peak * 1e-9)

    if isinstance(shaft_frequencies_hz, Mapping):
        shafts = [(str(k), float(v)) for k, v in shaft_frequencies_hz.items()]
    else:
        shafts = [(f"$f_{{s{i}}}$", float(v)) for i, v in enumerate(shaft_frequencies_hz, start=1)]
    shown_shafts = sorted(((label, f) for label, f in shafts if 0.0 < f <= fmax), key=lambda s: s[1])

    fig = new_figure(size_px, dpi)
    if shown_shafts:
        grid = fig.add_gridspec(2, 1, height_ratios=(2.4, 1.0))
        ax, low = fig.add_subplot(grid[0]), fig.add_subplot(grid[1])
    else:
        ax, low = fig.add_subplot(), None
    _spectrum_axes(ax, freq, amp, log_amplitude, (0.0, fmax), ylabel)

    labelled: list[tuple] = []  # (axes, labels, colour): labelled once the layout is final
    if mesh_frequency_hz is not None:
        harmonics = mesh_harmonics(mesh_frequency_hz, fmax)[:max_harmonics]
        names = harmonic_labels(harmonics.size)
        for f in harmonics:
            ax.axvline(f, color="tab:red", linestyle="--", linewidth=0.8, alpha=0.8)
        labelled.append(
            (ax, [(f"${n}$", float(f)) for f, n in zip(harmonics, names, strict=True)], "tab:red")
        )

    if low is not None:  # the shaft frequencies, and bearing lines up to 10 shaft orders
        f_low = _low_panel_top(fmax, shown_shafts[-1][1], marks)
        inside = freq <= f_low
        _spectrum_axes(low, freq[inside], amp[inside], log_amplitude, (0.0, f_low), ylabel)
        resolution = f", bins of {freq[1] - freq[0]:.3g} Hz" if freq.size > 1 else ""
        low.set_title(f"0-{f_low:.3g} Hz: shaft frequencies{resolution}", fontsize=9, pad=3)
        ax.axvspan(0.0, f_low, color="tab:green", alpha=0.15, linewidth=0)
        styles = (":", "-.", (0, (1, 3)), (0, (5, 2, 1, 2)))
        for i, (_, f) in enumerate(shown_shafts):
            low.axvline(f, color="tab:green", linestyle=styles[i % len(styles)], linewidth=1.2)
        labelled.append((low, [(f"{label} = {f:.4g} Hz", f) for label, f in shown_shafts], "tab:green"))

    if title:
        set_title(ax, title, pad=6)
    fig.draw_without_rendering()  # the final layout: labels inside the axes are measured in it
    for axes, labels, colour in labelled:
        _marker_labels(axes, labels, colour)
    _mark(ax, low, marks, fmax)
    return fig


def _low_panel_top(fmax: float, fastest_shaft_hz: float, marks: Sequence) -> float:
    """The low panel's top: SHAFT_PANEL_ORDERS shaft orders, widened to the marks up to 10 of them."""
    crowded = [float(m.frequency_hz) for m in marks if 0 < m.frequency_hz <= 10 * fastest_shaft_hz]
    return min(fmax, max(SHAFT_PANEL_ORDERS * fastest_shaft_hz, 1.1 * max(crowded, default=0.0)))


def _mark(ax, low, marks: Sequence, fmax: float) -> None:
    """``marks`` on the spectrum: labelled in the low panel when there is one, else in ``ax``."""
    from .spectrum import mark_lines

    if marks:
        mark_lines(ax, marks, fmax, labels=low is None)
        if low is not None:
            mark_lines(low, marks, low.get_xlim()[1])


def _spectrum_axes(ax, freq, amp, log_amplitude: bool, xlim: tuple[float, float], ylabel: str) -> None:
    """The amplitude curve with room above it for the marker labels."""
    if log_amplitude:
        ax.set_yscale("log")
    ax.plot(freq, amp, color="tab:blue", linewidth=0.8)
    top, bottom = (float(np.max(amp)), float(np.min(amp))) if amp.size else (0.0, 0.0)
    if top > max(bottom, 0.0):  # room above the peak: 12 % of the decades shown, or of the range
        if log_amplitude:
            ax.set_ylim(bottom, top * (top / bottom) ** 0.12)
        else:
            ax.set_ylim(min(0.0, bottom), top * 1.15)
    ax.set_xlim(*xlim)
    ax.set_xlabel("Frequency f [Hz]")
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)


def _marker_labels(ax, labels: Sequence[tuple[str, float]], color: str) -> None:
    """Each (text, frequency) at the top of ``ax``, inside it: centred on its line, or aligned inwards
    near an edge; a label that would overlap the previous one goes one row lower."""
    from matplotlib.transforms import blended_transform_factory

    lo, hi = ax.get_xlim()
    width = hi - lo
    transform = blended_transform_factory(ax.transData, ax.transAxes)
    fig = ax.get_figure()
    renderer = fig.canvas.get_renderer()
    frame = ax.get_window_extent(renderer)
    rows: list = []  # the extent of the last label of each row
    for text, f in labels:
        align = "right" if f > lo + 0.96 * width else "left" if f < lo + 0.04 * width else "center"
        for row in range(len(rows) + 1):
            label = ax.text(
                f,
                0.985 - 0.075 * row,
                text,
                transform=transform,
                ha=align,
                va="top",
                color=color,
                fontsize=8,
                bbox={"facecolor": "white", "edgecolor": "none", "alpha": 0.8, "pad": 0.5},
                in_layout=False,
            )
            box = label.get_window_extent(renderer)
            if box.x0 < frame.x0:  # aligned inwards, but wider than the room left: keep it inside
                label.set_ha("left")
                label.set_x(lo)
            elif box.x1 > frame.x1:
                label.set_ha("right")
                label.set_x(hi)
            box = label.get_window_extent(renderer)
            if row == len(rows):
                rows.append(box)
                break
            if box.x0 > rows[row].x1 + 2 or box.x1 < rows[row].x0 - 2:
                rows[row] = box
                break
            label.remove()


def plot_spectrum(
    spectrum: Spectrum,
    path: PathLike,
    mesh_frequency_hz: float | None = None,
    shaft_frequencies_hz: Sequence[float] | Mapping[str, float] = (),
    title: str = "",
    fmax_hz: float | None = None,
    ylabel: str = "Amplitude [signal units]",
    log_amplitude: bool = False,
    max_harmonics: int = 20,
    size_px: tuple[int, int] = DEFAULT_SIZE_PX,
    dpi: int = 100,
    marks: Sequence = (),
) -> Path:
    """Amplitude spectrum against frequency [Hz] as PNG at ``path`` (:func:`spectrum_figure`)."""
    fig = spectrum_figure(
        spectrum,
        mesh_frequency_hz,
        shaft_frequencies_hz,
        title,
        fmax_hz,
        ylabel,
        log_amplitude,
        max_harmonics,
        size_px,
        dpi,
        marks,
    )
    return save_figure(fig, path, dpi)
