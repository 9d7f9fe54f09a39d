"""Features whose computation lives in a higher layer (the analysis of a recording needs the drive's
scenario, which analysis does not import): :mod:`.features` registers them by name, so that every
feature user knows them from the start, and computes them by the named module's ``KIND``, imported on
first use."""

from __future__ import annotations

import importlib
from typing import Any

__all__ = ["PROVIDED", "provided_kind"]

PROVIDED: dict[str, tuple[str, tuple[str, ...]]] = {
    "recording": ("gearbody.diagnosis.features", ("feature", "signal", "target", "sigma")),
}
"""Feature name -> (the module whose ``KIND`` computes it, its options besides the window's)."""


def provided_kind(name: str) -> Any:
    """The ``FeatureKind`` that computes provided feature ``name`` (its module imported now)."""
    return importlib.import_module(PROVIDED[name][0]).KIND
