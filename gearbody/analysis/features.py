"""Scalar features of a run or of a measurement: the numbers a diagnostician compares, and what
sensitivity analysis ranks and calibration fits.

A :class:`Record` is signals on one uniform time grid plus the drive facts features need (tooth
counts, operating-period boundaries, natural frequencies when known). ``Result.record()`` gives one
for a simulation; a measurement is built directly (a tachometer's pinion angle and an accelerometer
signal suffice for the spectral features). A feature is named by a short spec, ``name`` or
``name:key=value,key=value``:

======================================  =======================================================
``kd_max``, ``kd_mean``, ``kd_min``,     K_d statistic [-] of stage ``stage`` (default 1) over the
``kd_std``, ``kd_p50/p95/p99``           analysed window; a planetary stage: over its planet meshes,
                                         all or ``planet`` (1..N) and ``mesh`` (sun or ring)
``separation_fraction``                  fraction of the window with no contact force [-] (a
                                         planetary stage: the largest of its planet meshes')
``rms``                                  RMS of ``signal`` over the window [signal unit]
``line_amplitude``                       amplitude [signal unit] of the spectral line at
                                         ``mesh`` x f_z + ``order`` x f_``shaft`` in ``signal``
                                         (mesh harmonics, sidebands, shaft orders)
``fm0``, ``fm4``, ``m6a``, ``m8a``,      condition indicators [-] of the synchronous average of
``na4``, ``energy_ratio``,               ``signal`` over revolutions of ``gear`` (pinion or wheel)
``crest_factor``, ``kurtosis``,
``tsa_rms``, ``tsa_peak_to_peak``
``natural_frequency_hz``                 elastic natural frequency number ``mode`` (1-based) [Hz]
======================================  =======================================================

The analysed window is operating period ``period`` (1-based, from ``Record.period_boundaries_s``), or
``from_s``/``to_s``, or by default the final ``fraction`` (0.25) of the record: the steady end of a
run. The resonance speed of a speed sweep is :func:`resonance_speed`.

A stage is planetary when the record holds its planet meshes' signals (``planet_<n>_sun_mesh_kd``,
stage k > 1: ``stage_k_planet_<n>_...``, as a Result names them). The spectral features
(``line_amplitude``) and the synchronous-average indicators read a parallel first stage's pinion (its
angle and the pinion and wheel teeth); a record without those (a drive whose first stage is planetary)
refuses them.

The record and its window are in :mod:`.feature_record`, the feature functions on plain arrays in
:mod:`.feature_functions`; this module holds the specs, the registry and gearbody's own features, and
every public name of the three.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError
from .dynamic_factor import separation_stats
from .feature_functions import (
    KD_STATISTICS,
    kd_statistic,
    line_amplitude,
    line_frequency_hz,
    natural_frequency_hz,
    resonance_speed,
)
from .feature_providers import PROVIDED, provided_kind
from .feature_record import (  # DEFAULT_FRACTION: this module's name before the split
    DEFAULT_FRACTION,  # noqa: F401
    FeatureError,
    Record,
    operating_periods_s,
    stage_name,
)
from .indicators import condition_indicators_from_average, rms
from .tsa import synchronous_average

__all__ = [
    "FEATURES",
    "FeatureError",
    "FeatureSpec",
    "Record",
    "FEATURE_KINDS",
    "FeatureKind",
    "evaluate_feature",
    "evaluate_features",
    "feature_signals",
    "kd_statistic",
    "line_amplitude",
    "line_frequency_hz",
    "natural_frequency_hz",
    "operating_periods_s",
    "parse_feature",
    "register_feature",
    "resonance_speed",
    "unregister_feature",
]

INDICATORS = {
    "fm0": "fm0",
    "fm4": "fm4",
    "m6a": "m6a",
    "m8a": "m8a",
    "na4": "na4",
    "energy_ratio": "energy_ratio",
    "crest_factor": "crest_factor",
    "kurtosis": "kurtosis",
    "tsa_rms": "rms",
    "tsa_peak_to_peak": "peak_to_peak",
}
WINDOW_OPTIONS = ("period", "from_s", "to_s", "fraction")
"""The options that choose a feature's window: an operating period (1-based), a span of time [s] or the
final fraction of the record (default 0.25); a registered :class:`FeatureKind` lists them among its
options to take a window."""
MESH_OPTIONS = ("stage", "planet", "mesh")
"""Which mesh a K_d feature reads: the stage (1-based) and, on a planetary stage, the planet (1..N) and
the mesh (``sun`` or ``ring``); without them every planet mesh of the stage."""
PLANET_MESHES = ("sun", "ring")
FEATURES: dict[str, tuple[str, ...]] = {}
"""Every feature name and the options it takes (filled by :func:`register_feature`, below)."""


@dataclass(frozen=True)
class FeatureSpec:
    """A feature name and its options, e.g. ``line_amplitude:signal=pinion_accel_rad_s2,mesh=1,order=-1``."""

    name: str
    options: Mapping[str, float | str] = field(default_factory=dict)

    def __str__(self) -> str:
        if not self.options:
            return self.name
        return self.name + ":" + ",".join(f"{k}={_fmt(v)}" for k, v in self.options.items())


def _fmt(value: float | str) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def parse_feature(text: str) -> FeatureSpec:
    """A :class:`FeatureSpec` from ``name`` or ``name:key=value,...`` (numbers become floats, or ints
    for the integer options); unknown names and options are refused with the valid ones."""
    name, _, rest = text.strip().partition(":")
    name = name.strip()
    if name not in FEATURES:
        raise FeatureError(f"feature {text!r}: no feature {name!r}; valid are {', '.join(FEATURES)}")
    options: dict[str, float | str] = {}
    for item in filter(None, (p.strip() for p in rest.split(","))):
        key, eq, value = item.partition("=")
        key, value = key.strip(), value.strip()
        if not eq or key not in FEATURES[name]:
            raise FeatureError(
                f"feature {text!r}: option {item!r} not understood; {name} takes "
                f"{', '.join(f'{o}=...' for o in FEATURES[name])}"
            )
        options[key] = _option_value(text, key, value, name)
    return FeatureSpec(name, options)


_INT_OPTIONS = ("period", "stage", "planet", "mesh", "order", "mode")
_STR_OPTIONS = ("signal", "shaft", "gear", "feature")


def _option_value(text: str, key: str, value: str, name: str = "") -> float | str:
    if key in _STR_OPTIONS or (key == "mesh" and "planet" in FEATURES.get(name, ())):
        return value
    try:
        number = float(value)
    except ValueError:
        raise FeatureError(f"feature {text!r}: {key} = {value!r} is not a number") from None
    if not math.isfinite(number):
        raise FeatureError(f"feature {text!r}: {key} = {value!r} must be finite")
    if key in _INT_OPTIONS:
        if number != int(number):
            raise FeatureError(f"feature {text!r}: {key} = {value!r} must be an integer")
        return int(number)
    return number


def _mesh_signals(spec: FeatureSpec, record: Record, quantity: str) -> tuple[str, ...]:
    """The ``quantity`` (``kd`` or ``force_N``) signals of the meshes ``spec`` names: a parallel stage's
    one mesh, or a planetary stage's planet meshes (all, or ``planet`` and/or ``mesh``)."""
    o = spec.options
    stage = int(o.get("stage", 1))
    planets = record.planets(stage)
    if not planets:
        if "planet" in o or "mesh" in o:
            raise FeatureError(
                f"feature {spec}: stage {stage} is no planetary stage (the record has no "
                f"{stage_name('planet_1_sun_mesh_kd', stage)!r}); planet and mesh apply to planetary stages"
            )
        return (stage_name("kd" if quantity == "kd" else "mesh_force_N", stage),)
    chosen = planets
    if "planet" in o:
        if int(o["planet"]) not in planets:
            raise FeatureError(
                f"feature {spec}: planet = {o['planet']}; stage {stage} has planets "
                f"{planets[0]}..{planets[-1]}"
            )
        chosen = (int(o["planet"]),)
    meshes = PLANET_MESHES
    if "mesh" in o:
        if o["mesh"] not in PLANET_MESHES:
            raise FeatureError(f"feature {spec}: mesh = {o['mesh']!r}; valid are 'sun', 'ring'")
        meshes = (str(o["mesh"]),)
    return tuple(stage_name(f"planet_{n}_{m}_mesh_{quantity}", stage) for n in chosen for m in meshes)


def _parallel_first_stage(spec: FeatureSpec, record: Record) -> tuple[int, int]:
    """(pinion, wheel) teeth of the record's parallel first stage, which the spectral and synchronous-
    average features read; refused when the record has none."""
    if record.pinion_teeth is None or record.wheel_teeth is None:
        raise FeatureError(
            f"feature {spec}: reads a parallel first stage (its pinion angle and pinion/wheel teeth) and "
            "this record has none (its first stage is planetary); on a planetary stage use kd_*, "
            "separation_fraction, rms or natural_frequency_hz"
        )
    return int(record.pinion_teeth), int(record.wheel_teeth)


# -- the registry: every feature is a FeatureKind, looked up by name --------------------------------------
@dataclass(frozen=True)
class FeatureKind:
    """What a feature is: the options it takes, the signals it reads from a record (``signals(spec,
    record)``, FeatureError where it does not apply) and its value (``value(spec, record, names, mask)``
    on those signals over the window ``mask``; ``windowed=False``: ``mask`` is None and no window
    option applies)."""

    options: tuple[str, ...]
    signals: Callable[[FeatureSpec, Record], tuple[str, ...]]
    value: Callable[[FeatureSpec, Record, tuple[str, ...], Any], float]
    windowed: bool = True


FEATURE_KINDS: dict[str, FeatureKind] = {}
"""Every feature by name (:func:`register_feature`); ``FEATURES`` lists their options."""


def register_feature(name: str, kind: FeatureKind) -> None:
    """Make feature ``name`` known to every feature user (``Result.features``, the studies' --feature,
    sensitivity and calibration targets): a new analysis is one module that registers its kind."""
    if not name.isidentifier():
        raise InputError(f"a feature name is an identifier, got {name!r}")
    FEATURE_KINDS[name] = kind
    FEATURES[name] = kind.options


def unregister_feature(name: str) -> None:
    """Forget feature ``name`` (a test's or a plug-in's clean-up)."""
    FEATURE_KINDS.pop(name, None)
    FEATURES.pop(name, None)


def _needs_signal(spec: FeatureSpec) -> str:
    if "signal" not in spec.options:
        raise FeatureError(f"feature {spec}: give the signal, e.g. {spec.name}:signal=pinion_accel_rad_s2")
    return str(spec.options["signal"])


def _kd_signals(spec: FeatureSpec, record: Record) -> tuple[str, ...]:
    return _mesh_signals(spec, record, "kd")


def _kd_value(spec: FeatureSpec, record: Record, names: tuple[str, ...], mask) -> float:
    return kd_statistic(np.concatenate([record.signal(n)[mask] for n in names]), spec.name[3:])


def _separation_signals(spec: FeatureSpec, record: Record) -> tuple[str, ...]:
    return _mesh_signals(spec, record, "force_N")


def _separation_value(spec: FeatureSpec, record: Record, names: tuple[str, ...], mask) -> float:
    t = record.time_s[mask]
    return float(max(separation_stats(record.signal(n)[mask], t).separated_fraction for n in names))


def _rms_signals(spec: FeatureSpec, record: Record) -> tuple[str, ...]:
    return (_needs_signal(spec),)


def _rms_value(spec: FeatureSpec, record: Record, names: tuple[str, ...], mask) -> float:
    return rms(record.signal(str(spec.options["signal"]))[mask])


def _first_stage_signals(spec: FeatureSpec, record: Record) -> tuple[str, ...]:
    """A spectral line or synchronous-average feature: its signal and the pinion angle (and the wheel's
    angle, when recorded, for an indicator of the wheel)."""
    signal = _needs_signal(spec)
    _parallel_first_stage(spec, record)
    o = spec.options
    extra = ("wheel_angle_rad",) if spec.name != "line_amplitude" and o.get("gear") == "wheel" else ()
    return (signal, "pinion_angle_rad", *(e for e in extra if e in record.signals))


def _line_amplitude_value(spec: FeatureSpec, record: Record, names: tuple[str, ...], mask) -> float:
    o = spec.options
    x = record.signal(str(o["signal"]))[mask]
    z1, z2 = _parallel_first_stage(spec, record)
    f = line_frequency_hz(
        record.pinion_hz(mask),
        z1,
        z2,
        int(o.get("mesh", 1)),
        int(o.get("order", 0)),
        str(o.get("shaft", "pinion")),
    )
    bins = float(o.get("tolerance_bins", 2.0))
    if int(o.get("order", 0)) != 0:  # a sideband or shaft order: its neighbours lie f_shaft away
        shaft = str(o.get("shaft", "pinion"))
        f_shaft = abs(line_frequency_hz(record.pinion_hz(mask), z1, z2, 0, 1, shaft))
        tolerance_hz = bins * record.sample_rate_hz / np.count_nonzero(mask)
        if tolerance_hz >= f_shaft / 2:
            duration = record.time_s[mask][-1] - record.time_s[mask][0]
            raise FeatureError(
                f"feature {spec}: a {duration:.3g} s window resolves lines to {tolerance_hz:.3g} Hz, not "
                f"the {f_shaft:.3g} Hz between this line and the next ({shaft} orders): use a window "
                f"longer than {2 * bins / f_shaft:.3g} s or fewer tolerance_bins"
            )
    return line_amplitude(x, record.sample_rate_hz, f, bins)


def _indicator_value(spec: FeatureSpec, record: Record, names: tuple[str, ...], mask) -> float:
    o = spec.options
    x = record.signal(str(o["signal"]))[mask]
    z1, z2 = _parallel_first_stage(spec, record)
    gear = str(o.get("gear", "pinion"))
    if gear not in ("pinion", "wheel"):
        raise FeatureError(f"feature {spec}: gear = {gear!r}; valid are 'pinion', 'wheel'")
    angle, teeth = record.signal("pinion_angle_rad")[mask], z1
    if gear == "wheel":  # its own angle if recorded, else the pinion's through the tooth ratio
        teeth = z2
        ratio = z1 / z2
        angle = (
            record.signal("wheel_angle_rad")[mask] if "wheel_angle_rad" in record.signals else angle * ratio
        )
    if abs(angle[-1] - angle[0]) < 4 * math.pi:
        raise FeatureError(f"feature {spec}: the window holds less than 2 revolutions of the {gear}")
    average = synchronous_average(x, angle, teeth=teeth)
    return float(condition_indicators_from_average(average).as_dict()[INDICATORS[spec.name]])


def _no_signals(spec: FeatureSpec, record: Record) -> tuple[str, ...]:
    return ()


def _natural_frequency_value(spec: FeatureSpec, record: Record, names: tuple[str, ...], mask) -> float:
    return natural_frequency_hz(record.natural_frequencies_hz, int(spec.options.get("mode", 1)))


# gearbody's own features, in the order messages list them
_KD_OPTIONS = (*MESH_OPTIONS, *WINDOW_OPTIONS)
for _statistic in KD_STATISTICS:
    register_feature(f"kd_{_statistic}", FeatureKind(_KD_OPTIONS, _kd_signals, _kd_value))
register_feature("separation_fraction", FeatureKind(_KD_OPTIONS, _separation_signals, _separation_value))
register_feature("rms", FeatureKind(("signal", *WINDOW_OPTIONS), _rms_signals, _rms_value))
register_feature(
    "line_amplitude",
    FeatureKind(
        ("signal", "mesh", "order", "shaft", "tolerance_bins", *WINDOW_OPTIONS),
        _first_stage_signals,
        _line_amplitude_value,
    ),
)
for _indicator in INDICATORS:
    register_feature(
        _indicator, FeatureKind(("signal", "gear", *WINDOW_OPTIONS), _first_stage_signals, _indicator_value)
    )
register_feature(
    "natural_frequency_hz", FeatureKind(("mode",), _no_signals, _natural_frequency_value, windowed=False)
)
del _statistic, _indicator

for _name, (_, _options) in PROVIDED.items():  # computed by a higher layer, known from the start
    register_feature(
        _name,
        FeatureKind(
            (*_options, *WINDOW_OPTIONS),
            lambda spec, record: provided_kind(spec.name).signals(spec, record),
            lambda spec, record, names, mask: provided_kind(spec.name).value(spec, record, names, mask),
        ),
    )


def feature_signals(spec: FeatureSpec | str, record: Record) -> tuple[str, ...]:
    """Names of the signals the feature reads from ``record`` (whether the record holds them or not);
    FeatureError when the feature does not apply to the stage it names (a planet of a parallel stage, a
    spectral line of a record without a parallel first stage)."""
    spec = parse_feature(spec) if isinstance(spec, str) else spec
    return FEATURE_KINDS[spec.name].signals(spec, record)


def evaluate_feature(spec: FeatureSpec | str, record: Record) -> float:
    """The value of one feature of ``record`` (see the module's table for names, options and units)."""
    spec = parse_feature(spec) if isinstance(spec, str) else spec
    kind = FEATURE_KINDS[spec.name]
    if not kind.windowed:
        return kind.value(spec, record, (), None)
    names = kind.signals(spec, record)
    mask = record.window(dict(spec.options))
    return kind.value(spec, record, names, mask)


def evaluate_features(specs: Sequence[FeatureSpec | str], record: Record) -> dict[str, float]:
    """``{str(spec): value}`` for every spec, in order."""
    parsed = [parse_feature(s) if isinstance(s, str) else s for s in specs]
    return {str(s): evaluate_feature(s, record) for s in parsed}
