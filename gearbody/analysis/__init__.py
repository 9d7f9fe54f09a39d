"""Engine-free analysis of simulated or measured signals (plain numpy arrays in, dataclasses out): spectra
and their labelled peaks, kinematic lines, synchronous averages and condition indicators, K_d statistics,
features (registered by name, evaluated on a run or a measurement), the measured side (tacho pulses to
shaft angle, tacholess speed, computed order tracking and order spectra, envelope spectra, kurtogram,
cepstrum, bearing fault frequencies, acceleration/velocity/displacement), and the modal results: a drive's
:class:`ModeSet` (from :func:`gearbody.modes`) and Lin & Parker's closed-form modes of a planetary stage.

Public: the names of ``__all__``, importable from here (``from gearbody.analysis import ...``).
"""

from gearbody.analysis.bearing_lines import BearingFrequencies, BearingGeometry, bearing_frequencies
from gearbody.analysis.cepstrum import (
    CepstralPeak,
    Cepstrum,
    cepstral_peak,
    cepstrum_prewhiten,
    lifter_family,
    real_cepstrum,
)
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
from gearbody.analysis.envelope import EnvelopeSpectrum, envelope_spectrum
from gearbody.analysis.features import (
    WINDOW_OPTIONS,
    FeatureError,
    FeatureKind,
    FeatureSpec,
    Record,
    evaluate_features,
    parse_feature,
    register_feature,
    resonance_speed,
    unregister_feature,
)
from gearbody.analysis.indicators import (
    ConditionIndicators,
    condition_indicators,
    condition_indicators_from_average,
    crest_factor,
    energy_ratio,
    fm0,
    fm4,
    kurtosis,
    m6a,
    m8a,
    na4,
    peak_to_peak,
    rms,
    sideband_energy_ratio,
)
from gearbody.analysis.integration import change_quantity
from gearbody.analysis.kinematics import (
    GearMesh,
    KinematicLine,
    KinematicSources,
    Shaft,
    gear_train_lines,
    kinematic_lines,
)
from gearbody.analysis.kurtogram import Kurtogram, SpectralKurtosis, fast_kurtogram, spectral_kurtosis
from gearbody.analysis.modal import ModeSet, campbell_lines, resonance_speeds_rad_s
from gearbody.analysis.order_maps import (
    OrderSlice,
    OrderSpectrum,
    RpmOrderMap,
    order_slice,
    order_spectrum,
    rpm_order_map,
)
from gearbody.analysis.orders import OrderTrackedSignal, order_track
from gearbody.analysis.peak_report import peaks_table, peaks_to_rows
from gearbody.analysis.peaks import LabelledPeak, label_peaks
from gearbody.analysis.planet_pass import (
    HannPassWindow,
    phasing_excitation,
    ring_sensor_signal,
    surviving_lines,
)
from gearbody.analysis.planetary_lines import PlanetaryLine, PlanetarySources, planetary_lines
from gearbody.analysis.psd import Psd, power_spectral_density
from gearbody.analysis.rotation import RotationDirections, rotation_directions
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
from gearbody.analysis.tacho import pulse_times, shaft_angle_from_pulses, shaft_speed_from_pulses
from gearbody.analysis.tacholess import TacholessSpeed, tacholess_angle
from gearbody.analysis.tsa import AngleDomainSignal, SynchronousAverage, angle_resample, synchronous_average

# Lin & Parker's modes of a planetary stage: engine-free like ModeSet (numpy's eigh on their matrices)
from gearbody.physics.planetary_modal import (
    PlanetaryModalParameters,
    PlanetaryModes,
    lin_parker_1999_parameters,
    natural_modes,
)

__all__ = [
    "BearingFrequencies",
    "BearingGeometry",
    "bearing_frequencies",
    "CepstralPeak",
    "Cepstrum",
    "cepstral_peak",
    "cepstrum_prewhiten",
    "lifter_family",
    "real_cepstrum",
    "EnvelopeSpectrum",
    "envelope_spectrum",
    "change_quantity",
    "Kurtogram",
    "SpectralKurtosis",
    "fast_kurtogram",
    "spectral_kurtosis",
    "OrderSlice",
    "OrderSpectrum",
    "RpmOrderMap",
    "order_slice",
    "order_spectrum",
    "rpm_order_map",
    "OrderTrackedSignal",
    "order_track",
    "pulse_times",
    "shaft_angle_from_pulses",
    "shaft_speed_from_pulses",
    "TacholessSpeed",
    "tacholess_angle",
    "HannPassWindow",
    "PlanetaryLine",
    "PlanetarySources",
    "phasing_excitation",
    "planetary_lines",
    "ring_sensor_signal",
    "surviving_lines",
    "GearMesh",
    "KinematicLine",
    "KinematicSources",
    "LabelledPeak",
    "Psd",
    "RotationDirections",
    "rotation_directions",
    "Shaft",
    "gear_train_lines",
    "kinematic_lines",
    "label_peaks",
    "peaks_table",
    "peaks_to_rows",
    "power_spectral_density",
    "AngleDomainSignal",
    "ConditionIndicators",
    "SynchronousAverage",
    "angle_resample",
    "condition_indicators",
    "condition_indicators_from_average",
    "crest_factor",
    "energy_ratio",
    "fm0",
    "fm4",
    "kurtosis",
    "m6a",
    "m8a",
    "na4",
    "peak_to_peak",
    "rms",
    "sideband_energy_ratio",
    "synchronous_average",
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
    "WINDOW_OPTIONS",
    "FeatureError",
    "FeatureKind",
    "FeatureSpec",
    "Record",
    "evaluate_features",
    "parse_feature",
    "register_feature",
    "resonance_speed",
    "unregister_feature",
    "ModeSet",
    "campbell_lines",
    "resonance_speeds_rad_s",
    "PlanetaryModalParameters",
    "PlanetaryModes",
    "lin_parker_1999_parameters",
    "natural_modes",
]
