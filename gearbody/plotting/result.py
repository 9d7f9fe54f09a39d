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
) -> Figure:
    """The figure of :func:`plot_spectrum` (same arguments but ``path``), not saved.

    Amplitude spectrum against frequency [Hz] (as Figs. 13-16, 20).

    Mesh harmonics k f_z <= fmax_hz (at most ``max_harmonics``) are marked by dashed lines labelled
    f_z, 2f_z, ... (aligned inwards at the edges); shaft frequencies by green lines named with their
    frequency in a legend by the mapping keys (plain text) or f_s1, f_s2, .... Long titles wrap.
    ``log_amplitude`` uses a log y axis (bins below 1e-9 of the maximum are clipped to it).
    Pass ``ylabel`` with the signal's unit, e.g. "Acceleration amplitude [m/s^2]".
    """
    fmax = float(spectrum.frequency_hz[-1]) if fmax_hz is None else float(fmax_hz)
    shown = spectrum.frequency_hz <= fmax
    freq = spectrum.frequency_hz[shown]
    amp = spectrum.amplitude[shown]

    fig = new_figure(size_px, dpi)
    ax = fig.add_subplot()
    if log_amplitude:
        peak = float(np.max(amp)) if amp.size and np.max(amp) > 0 else 1.0
        amp = np.maximum(amp, peak * 1e-9)
        ax.set_yscale("log")
    ax.plot(freq, amp, color="tab:blue", linewidth=0.8)
    label_transform = ax.get_xaxis_transform()  # x in data, y in axes fraction

    if mesh_frequency_hz is not None:
        harmonics = mesh_harmonics(mesh_frequency_hz, fmax)[:max_harmonics]
        for f, label in zip(harmonics, harmonic_labels(harmonics.size), strict=True):
            ax.axvline(f, color="tab:red", linestyle="--", linewidth=0.8, alpha=0.8)
            # a label at either edge of the axes is aligned inwards, so that it stays in the figure
            align = "right" if f > 0.97 * fmax else "left" if f < 0.03 * fmax else "center"
            ax.text(
                f,
                1.0,
                f"${label}$",
                transform=label_transform,
                ha=align,
                va="bottom",
                color="tab:red",
                fontsize=8,
                clip_on=False,
            )

    if isinstance(shaft_frequencies_hz, Mapping):
        shafts = [(str(k), float(v)) for k, v in shaft_frequencies_hz.items()]
    else:
        shafts = [(f"$f_{{s{i}}}$", float(v)) for i, v in enumerate(shaft_frequencies_hz, start=1)]
    shown_shafts = [(label, f) for label, f in shafts if f <= fmax]
    styles = (":", "-.", (0, (1, 3)), (0, (5, 2, 1, 2)))
    for i, (label, f) in enumerate(shown_shafts):
        # shaft lines lie close together at the low end: named in a legend, not next to the line
        style = styles[i % len(styles)]
        ax.axvline(f, color="tab:green", linestyle=style, linewidth=1.0, label=f"{label} = {f:.4g} Hz")
    if shown_shafts:
        ax.legend(loc="upper right", fontsize=8, framealpha=0.9)

    ax.set_xlim(0.0, fmax)
    ax.set_xlabel("Frequency f [Hz]")
    ax.set_ylabel(ylabel)
    if title:
        set_title(ax, title, pad=14 if mesh_frequency_hz is not None else 6)
    ax.grid(True, alpha=0.3)
    return fig


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
    )
    return save_figure(fig, path, dpi)
