"""A recording of a drive analysed as a simulated run is: its shafts' angles from one tacho through the
scenario's ratios (:mod:`.speed`), the catalogue of its lines (:mod:`.drive`), and per channel the
labelled spectra, synchronous averages, indicators, fault bands, kurtogram and envelope spectrum
(:mod:`.analyze`); :mod:`.compare` sets a run beside a recording."""

from .analyze import ChannelDiagnosis, Diagnosis, analyze_recording
from .bands import BandMetric, band_metrics
from .drive import DriveKinematics
from .speed import ShaftAngles, shaft_angles

__all__ = [
    "BandMetric",
    "ChannelDiagnosis",
    "Diagnosis",
    "DriveKinematics",
    "ShaftAngles",
    "analyze_recording",
    "band_metrics",
    "shaft_angles",
]
