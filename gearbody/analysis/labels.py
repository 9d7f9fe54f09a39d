"""Power spectral density and labelled spectrum peaks: which line is which shaft order, mesh harmonic,
sideband or cross-modulation line.

A drive is described by its shafts (rotation frequencies) and gear meshes (mesh frequency and the two
shafts each mesh couples), :class:`KinematicSources`. :func:`kinematic_lines` turns that into a catalogue
of labelled frequencies; :func:`label_peaks` finds the prominent local maxima of an amplitude spectrum
and names each one after the catalogue lines within a tolerance. Peaks that no line explains are kept
with an empty label, so they stay visible. :func:`peaks_table` and :func:`peaks_to_rows`
present the result; :func:`gearbody.plotting.spectrum.plot_labelled_spectrum` draws it.

Engine-free and free of matplotlib: works on any uniformly sampled 1-D signal, simulated or measured.

The code lives in :mod:`~gearbody.analysis.psd` (power spectral density),
:mod:`~gearbody.analysis.kinematics` (shafts, meshes, line catalogue), :mod:`~gearbody.analysis.peaks`
(peak finding and labelling) and :mod:`~gearbody.analysis.peak_report` (table, rows, plot); this module
re-exports their public names.
"""

from gearbody.analysis.kinematics import (
    Family,
    GearMesh,
    KinematicLine,
    KinematicSources,
    Shaft,
    kinematic_lines,
)
from gearbody.analysis.peak_report import UNEXPLAINED, peaks_table, peaks_to_rows
from gearbody.analysis.peaks import LABEL_SEPARATOR, LabelledPeak, label_peaks
from gearbody.analysis.psd import Psd, power_spectral_density

__all__ = [
    "LABEL_SEPARATOR",
    "UNEXPLAINED",
    "Family",
    "GearMesh",
    "KinematicLine",
    "KinematicSources",
    "LabelledPeak",
    "Psd",
    "Shaft",
    "kinematic_lines",
    "label_peaks",
    "peaks_table",
    "peaks_to_rows",
    "power_spectral_density",
]
