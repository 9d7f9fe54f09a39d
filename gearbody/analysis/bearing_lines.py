"""Kinematic defect frequencies of a rolling-element bearing (BPFO, BPFI, BSF, FTF).

Engine-free: a validated :class:`BearingGeometry` in, a frozen :class:`BearingFrequencies` out.

Rigid-body rolling without slip (real bearings slip by 1-2 %, so measured lines sit slightly off these).
With n rolling elements of diameter d on a pitch diameter D, contact angle a, r = (d/D) cos a and
relative shaft speed f [Hz] between the two rings:

- FTF (cage, fundamental train) = f/2 (1 - r) with the outer race still (inner race turning at f);
  f/2 (1 + r) with the inner race still and the outer race turning (``outer_race_rotates=True``);
- BPFO (ball pass, outer race) = n f/2 (1 - r), BPFI (ball pass, inner race) = n f/2 (1 + r);
  both depend only on the relative speed of the rings, so they do not change with which race turns;
- BSF (ball spin relative to the cage) = (D / 2d) (1 - r^2) f. A rolling-element defect strikes both
  races once per spin, so its impacts repeat at 2 BSF (``rolling_element_defect_hz``); tables that list
  "BSF" as twice this value (e.g. the CWRU bearing data centre's 4.7135 x shaft speed for the 6205-2RS
  JEM SKF, whose BSF here is 2.3567) use that convention.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InputError
from ._validate import integer_at_least, is_real, positive_frequency

__all__ = ["BearingFrequencies", "BearingGeometry", "bearing_frequencies"]


def _positive_length(name: str, value: float) -> float:
    if not (is_real(value) and math.isfinite(value) and value > 0):
        raise InputError(f"{name} must be a positive length [m], got {value!r}")
    return float(value)


@dataclass(frozen=True)
class BearingGeometry:
    """Rolling-element bearing geometry (validated on construction)."""

    n_balls: int
    """Number of rolling elements (>= 1)."""
    ball_diameter_m: float
    """Rolling-element diameter d [m] (> 0, < pitch_diameter_m)."""
    pitch_diameter_m: float
    """Pitch (cage) diameter D [m]."""
    contact_angle_deg: float = 0.0
    """Contact angle a [deg] in [0, 90)."""

    def __post_init__(self) -> None:
        integer_at_least("n_balls", self.n_balls, 1)
        d = _positive_length("ball_diameter_m", self.ball_diameter_m)
        pitch = _positive_length("pitch_diameter_m", self.pitch_diameter_m)
        if not d < pitch:
            raise InputError(
                f"ball_diameter_m must be smaller than pitch_diameter_m = {pitch!r} m, got {d!r} m"
            )
        a = self.contact_angle_deg
        if not (is_real(a) and math.isfinite(a) and 0.0 <= a < 90.0):
            raise InputError(f"contact_angle_deg must be in [0, 90) deg, got {a!r}")

    @property
    def diameter_ratio(self) -> float:
        """r = (d / D) cos a, in [0, 1)."""
        return self.ball_diameter_m / self.pitch_diameter_m * math.cos(math.radians(self.contact_angle_deg))


@dataclass(frozen=True)
class BearingFrequencies:
    """Bearing defect frequencies [Hz] at one shaft speed."""

    shaft_hz: float
    """Relative speed of the two races [Hz]."""
    bpfo_hz: float
    """Ball pass frequency, outer race [Hz]."""
    bpfi_hz: float
    """Ball pass frequency, inner race [Hz]."""
    bsf_hz: float
    """Ball spin frequency relative to the cage [Hz] (a ball defect strikes at twice this)."""
    ftf_hz: float
    """Fundamental train (cage) frequency [Hz]."""

    @property
    def rolling_element_defect_hz(self) -> float:
        """Impact rate of a rolling-element defect, 2 BSF [Hz]."""
        return 2.0 * self.bsf_hz

    def as_orders(self) -> BearingFrequencies:
        """The same lines as multiples of the shaft speed (shaft_hz = 1)."""
        s = self.shaft_hz
        return BearingFrequencies(1.0, self.bpfo_hz / s, self.bpfi_hz / s, self.bsf_hz / s, self.ftf_hz / s)


def bearing_frequencies(
    geometry: BearingGeometry, shaft_hz: float = 1.0, *, outer_race_rotates: bool = False
) -> BearingFrequencies:
    """BPFO, BPFI, BSF and FTF [Hz] of ``geometry`` at ``shaft_hz`` (the module docstring states the
    formulas); ``outer_race_rotates`` changes only the FTF (the cage follows the turning race)."""
    if not isinstance(geometry, BearingGeometry):
        raise InputError(f"geometry must be a BearingGeometry, got {type(geometry).__name__}")
    f = positive_frequency("shaft_hz", shaft_hz)
    r = geometry.diameter_ratio
    n = geometry.n_balls
    ftf = 0.5 * f * (1.0 + r) if outer_race_rotates else 0.5 * f * (1.0 - r)
    return BearingFrequencies(
        shaft_hz=f,
        bpfo_hz=0.5 * n * f * (1.0 - r),
        bpfi_hz=0.5 * n * f * (1.0 + r),
        bsf_hz=geometry.pitch_diameter_m / (2.0 * geometry.ball_diameter_m) * (1.0 - r * r) * f,
        ftf_hz=ftf,
    )
