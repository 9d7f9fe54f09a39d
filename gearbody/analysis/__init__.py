"""Engine-free analysis of simulated or measured signals (plain numpy arrays in, dataclasses out)."""

from gearbody.analysis.dynamic_factor import (
    INSTABILITY_KD,
    FoldedSignal,
    SeparationStats,
    fold_over_mesh_period,
    mesh_phase,
    periods_stats,
    separation_stats,
    unstable,
)
from gearbody.analysis.spectrum import (
    Peak,
    SidebandLine,
    Spectrum,
    amplitude_spectrum,
    mesh_harmonics,
    peak_at,
    peak_near,
    sideband_lines,
)

__all__ = [
    "INSTABILITY_KD",
    "FoldedSignal",
    "Peak",
    "SeparationStats",
    "SidebandLine",
    "Spectrum",
    "amplitude_spectrum",
    "fold_over_mesh_period",
    "mesh_harmonics",
    "mesh_phase",
    "peak_at",
    "peak_near",
    "periods_stats",
    "separation_stats",
    "sideband_lines",
    "unstable",
]
