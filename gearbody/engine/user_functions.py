"""The Python force functions Exudyn calls on every right-hand-side evaluation: mesh forces (torsional and
lateral), bearing laws, motor and load torques, and the stall watchdog that rides on them. Each closes
over its packed parameters and calls the compiled laws of :mod:`gearbody.physics` (the mesh force runs
millions of times per simulated second: keep these thin)."""

from __future__ import annotations

import numpy as np

from ..assembly import Inertia
from ..physics import load_torque_at, motor_torque_at
from ..physics.lateral import lateral_mesh_forces
from ..physics.mesh import torsional_mesh_forces


def mesh_user_function(P: np.ndarray):
    def mesh_force(mbs, t, itemNumber, q, q_t):
        return torsional_mesh_forces(q[0], q[1], q_t[0], q_t[1], P)

    return mesh_force


def lateral_mesh_user_function(m, bp: Inertia, bw: Inertia, idx: np.ndarray):
    free = [float(d in b.lateral.free_directions) if b.lateral else 0.0 for b in (bp, bw) for d in (0, 1)]
    geometry = np.array([*m.line_of_action, *m.friction_direction, *free])
    P = m.parameters

    def lateral_mesh_force(mbs, t, itemNumber, q, q_t):
        return lateral_mesh_forces(np.asarray(q), np.asarray(q_t), idx, geometry, P)

    return lateral_mesh_force


def bearing_user_function(law, free_directions: tuple[int, ...]):
    mask = np.array([float(d in free_directions) for d in (0, 1)])
    mx, my = float(mask[0]), float(mask[1])
    if hasattr(law, "force_xy"):
        force_xy = law.force_xy

        def bearing_force_xy(mbs, t, itemNumber, q, q_t):
            fx, fy = force_xy(q[0] * mx, q[1] * my, q_t[0] * mx, q_t[1] * my)
            return [fx * mx, fy * my, 0.0]

        return bearing_force_xy

    def bearing_force(mbs, t, itemNumber, q, q_t):
        f = np.asarray(law.force_N(np.asarray(q[:2]) * mask, np.asarray(q_t[:2]) * mask), float) * mask
        return [f[0], f[1], 0.0]

    return bearing_force


class StallError(RuntimeError):
    """Raised from inside a user function when the solver makes no progress in time (Exudyn passes it on
    as its own error; the watchdog's ``failure`` tells the caller what happened)."""


STALL_CALLS = 200_000  # right-hand-side evaluations per check (~30k steps: ~0.1 s simulated normally)
STALL_ADVANCE_S = 1e-9


class StallWatchdog:
    """Called with t on every force evaluation: Exudyn's step control can reject steps at the minimum step
    size forever (no pre-step call happens then), but every attempt evaluates the drive's forces."""

    def __init__(self) -> None:
        self.calls, self.t_check, self.t_max = 0, -1.0, -1.0
        self.failure = ""

    def __call__(self, t: float) -> None:
        self.calls += 1
        if t > self.t_max:
            self.t_max = t
        if self.calls % STALL_CALLS == 0:
            if self.t_max - self.t_check < STALL_ADVANCE_S:
                self.failure = (
                    f"the solver stalled at t = {self.t_max:.9g} s: {STALL_CALLS} force evaluations "
                    f"advanced less than {STALL_ADVANCE_S:g} s (step size collapse at a discontinuity, "
                    "e.g. a tooth with stiffness factor 0 next to a loaded one). Hint: use a small "
                    "non-zero stiffness factor, or loosen solver.relative_tolerance / absolute_tolerance"
                )
                raise StallError(self.failure)
            self.t_check = self.t_max


def motor_user_function(D: np.ndarray, watchdog: StallWatchdog):
    """Motor torque (and the stall watchdog)."""

    def motor_torque(mbs, t, itemNumber, q, q_t):
        watchdog(t)
        return (motor_torque_at(t, q_t[0], D),)

    return motor_torque


def load_user_function(D: np.ndarray):
    def load_torque(mbs, t, itemNumber, q, q_t):
        return (-load_torque_at(t, D),)

    return load_torque
