"""Which way the shafts turned: a drive whose load overran its motor (a converter at 0 Hz under load, a
stop under load, a hoist or a downhill conveyor lowering) turns backwards, and a run must say so rather
than let it pass silently. Engine-free: speeds in, a small dataclass out."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

__all__ = ["BACKWARD_FRACTION", "RotationDirections", "rotation_directions"]

BACKWARD_FRACTION = 0.01
"""A rotation counts as turning backwards once its speed against its driven direction exceeds this
fraction of its nominal speed (the elastic wind-up of a start from rest stays far below it)."""


@dataclass(frozen=True)
class RotationDirections:
    """``driven_speed_min_rad_s``: per rotation, its smallest speed in its driven direction over the run
    (negative: it turned backwards); ``backward_since_s``: per rotation, the first time it turned
    backwards by more than :data:`BACKWARD_FRACTION` of its nominal speed (absent if never)."""

    driven_speed_min_rad_s: dict[str, float]
    backward_since_s: dict[str, float]

    @property
    def turned_backwards(self) -> bool:
        return bool(self.backward_since_s)

    @property
    def first(self) -> tuple[str, float] | None:
        """(rotation, time in s) of the first rotation to turn backwards, or None."""
        if not self.backward_since_s:
            return None
        return min(self.backward_since_s.items(), key=lambda item: (item[1], item[0]))

    def message(self) -> str:
        """One line for a user, or '' when every rotation kept its driven direction."""
        if not self.turned_backwards:
            return ""
        body, t = self.first
        slowest = min(self.driven_speed_min_rad_s[b] for b in self.backward_since_s)
        worst = min(self.backward_since_s, key=lambda b: self.driven_speed_min_rad_s[b])
        return (
            f"the drive turned backwards: {body} from t = {t:.4g} s ({len(self.backward_since_s)} rotations "
            f"in all; {worst} down to {slowest:.3g} rad/s against its driven direction): the load overran "
            "the motor"
        )


def rotation_directions(
    time_s: np.ndarray,
    speeds_rad_s: Mapping[str, np.ndarray],
    nominal_speeds_rad_s: Mapping[str, float],
    fraction: float = BACKWARD_FRACTION,
) -> RotationDirections:
    """Direction check of each rotation with a non-zero nominal speed (its sign is the driven direction,
    its size the scale of the threshold); rotations without a nominal speed (a fixed member) are left out."""
    mins, since = {}, {}
    for name, nominal in nominal_speeds_rad_s.items():
        if nominal == 0.0 or name not in speeds_rad_s:
            continue
        driven = np.sign(nominal) * np.asarray(speeds_rad_s[name], float)
        mins[name] = float(np.min(driven))
        backward = np.flatnonzero(driven < -fraction * abs(nominal))
        if backward.size:
            since[name] = float(time_s[backward[0]])
    return RotationDirections(mins, since)
