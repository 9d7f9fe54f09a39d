"""The ``recording`` feature: any feature of a recording's analysis (``gearbody analyze``'s
features.json: ``fm4:pinion``, ``band_peak:1 f_z1``, ``envelope_peak:BPFO pinion bearing``, ...) computed on
a run the same way, so calibration and sensitivity take a recording's features as targets.

``recording:feature=fm4:pinion,signal=pinion_housing_accel_y_m_s2`` analyses ``signal`` (default: the run's
vibration signal) over the feature's window (default the final quarter) with the run's scenario, its exact
input-shaft angle as the tacho; with ``target=V,sigma=S`` its value is the misfit (value - V) / S (a
recording's feature as the target of a sensitivity analysis). :mod:`gearbody.analysis.features`
registers the name and computes it with :data:`KIND` (imported on first use)."""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

from ..analysis.features import WINDOW_OPTIONS, FeatureError, FeatureKind

__all__ = ["KIND", "recording_feature_value", "target_from_features"]

NAME = "recording"


def _signals(spec, record) -> tuple[str, ...]:
    signal = spec.options.get("signal") or record.meta.get("vibration_signal")
    if not signal:
        raise FeatureError(f"feature {spec}: give the signal, e.g. {NAME}:feature=fm4:pinion,signal=...")
    if "feature" not in spec.options:
        raise FeatureError(f"feature {spec}: give the feature of the analysis, e.g. feature=fm4:pinion")
    if "scenario" not in record.meta:
        raise FeatureError(f"feature {spec}: needs a run's record (its scenario), not a bare record")
    return (str(signal),)


@lru_cache(maxsize=8)
def _drive(scenario_json: str):
    from ..model import load_scenario
    from .drive import DriveKinematics

    return DriveKinematics.from_scenario(load_scenario(json.loads(scenario_json)))


def recording_feature_value(spec, record, names: tuple[str, ...], mask) -> float:
    """The value of ``spec`` (``recording:feature=...``) on the run ``record`` over ``mask``."""
    from ..recording import Channel, Recording, Tacho
    from .analyze import analyze_recording

    feature = str(spec.options["feature"])
    drive = _drive(json.dumps(record.meta["scenario"], sort_keys=True, default=str))
    t = record.time_s[mask]
    angle_name = f"{drive.input_body}_angle_rad"
    if angle_name not in record.signals:
        raise FeatureError(f"feature {spec}: the run has no {angle_name} for the tacho")
    fs = (t.size - 1) / (t[-1] - t[0])
    channels = [
        Channel(names[0], record.signal(names[0])[mask]),
        Channel(angle_name, record.signal(angle_name)[mask], "rad", shaft=drive.input_body),
    ]
    rec = Recording(fs, channels, float(t[0]), Tacho(drive.input_body, 0, channel=angle_name))
    diag = analyze_recording(rec, drive, [names[0]], envelope=feature.startswith("envelope"))
    values = diag.channels[names[0]].features()
    if feature not in values:
        shown = ", ".join(sorted(values)[:30])
        raise FeatureError(f"feature {spec}: the analysis gives no {feature!r}; it gives {shown}, ...")
    if "target" in spec.options:  # the misfit to a recording's value, in its sigmas
        sigma = float(spec.options.get("sigma", 1.0))
        if not sigma > 0:
            raise FeatureError(f"feature {spec}: sigma = {sigma:g} must be > 0")
        return (float(values[feature]) - float(spec.options["target"])) / sigma
    return float(values[feature])


def target_from_features(path: str | Path, key: str) -> tuple[str, float]:
    """``(feature, value)`` of ``key`` in a features.json written by ``gearbody analyze`` (``path``: the
    file or its folder); ``key`` is ``<channel>/<feature>`` or ``<feature>`` (the first channel's)."""
    from ..errors import InputError

    path = Path(path)
    path = path / "features.json" if path.is_dir() else path
    try:
        values = json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: cannot read the features of a recording: {exc}") from None
    if key in values and "/" in key:
        return key.split("/", 1)[1], float(values[key])
    matches = [k for k in values if k.split("/", 1)[-1] == key]
    if not matches:
        raise InputError(f"{path}: no feature {key!r}; it holds e.g. {', '.join(list(values)[:8])}")
    return key, float(values[matches[0]])


KIND = FeatureKind(
    options=("feature", "signal", "target", "sigma", *WINDOW_OPTIONS),
    signals=_signals,
    value=recording_feature_value,
)
"""What ``gearbody.analysis.features`` computes the 'recording' feature it registers with."""
