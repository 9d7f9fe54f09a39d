"""Production-technology factor: tooth error mode E(a, e, r) with random per-tooth depths, eq. (6)."""

from __future__ import annotations

import numpy as np


def tooth_random_factors(teeth: int, seed: int, stage: int = 0) -> np.ndarray:
    """l_i in [0, 1), one per pinion tooth of a stage (0-based, power-flow order).

    ``numpy.random.default_rng(seed).random(teeth)`` for stage 0 and
    ``numpy.random.default_rng([seed, stage]).random(teeth)`` after it. This exact draw is part of the
    scenario format (docs/scenario.md): the same seed gives the same teeth in every run, on every machine.
    """
    rng = np.random.default_rng(seed) if stage == 0 else np.random.default_rng([seed, stage])
    return rng.random(teeth)


def tooth_error_depths_m(e_um: float, r: float, teeth: int, seed: int, stage: int = 0) -> np.ndarray:
    """Per-tooth maximum error e_i = [1 - r (1 - l_i)] e of eq. (6), in metres."""
    return (1.0 - r * (1.0 - tooth_random_factors(teeth, seed, stage))) * e_um * 1e-6


PLANETARY_STREAMS = {"sun": 1, "ring": 2}
"""Random streams of a planetary stage's error modes: ``default_rng([seed, stage, stream])``."""


def planetary_tooth_error_depths_m(
    e_um: float, r: float, teeth: int, seed: int, stage: int, member: str
) -> np.ndarray:
    """e_i of eq. (6) on the teeth of a planetary stage's sun or ring (every planet's mesh with that
    member meets the same teeth): ``l = default_rng([seed, stage, 1 (sun) or 2 (ring)]).random(teeth)``
    (docs/planetary.md, "Random tooth errors")."""
    rng = np.random.default_rng([seed, stage, PLANETARY_STREAMS[member]])
    return (1.0 - r * (1.0 - rng.random(teeth))) * e_um * 1e-6
