"""Features whose computation lives in a higher layer (the analysis of a recording needs the drive's
scenario, which analysis does not import): registered here by name, so that every feature user knows
them from the start, and computed by the named module's ``KIND``, imported on first use."""

from __future__ import annotations

import importlib

from .features import WINDOW_OPTIONS, FeatureKind, register_feature

__all__ = ["PROVIDED"]

PROVIDED = {"recording": "gearbody.diagnosis.features"}
"""Feature name -> the module whose ``KIND`` computes it."""


def _provided(name: str) -> FeatureKind:
    return importlib.import_module(PROVIDED[name]).KIND


register_feature(
    "recording",
    FeatureKind(
        ("feature", "signal", "target", "sigma", *WINDOW_OPTIONS),
        lambda spec, record: _provided("recording").signals(spec, record),
        lambda spec, record, names, mask: _provided("recording").value(spec, record, names, mask),
    ),
)
