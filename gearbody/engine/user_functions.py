"""The Python force functions Exudyn calls on every right-hand-side evaluation: mesh forces (torsional and
lateral), bearing laws, motor and load torques, and the stall watchdog that rides on them. Each closes
over its packed parameters and calls the compiled laws of :mod:`gearbody.physics` (the mesh force runs
millions of times per simulated second: keep these thin)."""

from __future__ import annotations

import itertools
import math
import signal
import threading
import time

import numba
import numpy as np

from ..assembly import Inertia
from ..physics import load_torque_at, motor_torque_at
from ..physics.lateral import lateral_mesh_forces
from ..physics.mesh import torsional_mesh_forces


def compiled(dispatcher, *example_args):
    """The machine-code entry point of a numba function for the argument types of ``example_args``
    (compiled, or loaded from numba's cache, on first use): calling it skips numba's per-call type
    dispatch, ~0.15 of ~0.6 us per call of the drive's force law (benchmarks/RESULTS.md)."""
    dispatcher(*example_args)
    signature = tuple(numba.typeof(a) for a in example_args)
    return dispatcher.overloads[signature].entry_point


def mesh_user_function(P: np.ndarray):
    forces = compiled(torsional_mesh_forces, 0.0, 0.0, 0.0, 0.0, P)

    def mesh_force(mbs, t, itemNumber, q, q_t):
        return forces(q[0], q[1], q_t[0], q_t[1], P)

    return mesh_force


def lateral_mesh_user_function(m, bp: Inertia, bw: Inertia, idx: np.ndarray):
    free = [float(d in b.lateral.free_directions) if b.lateral else 0.0 for b in (bp, bw) for d in (0, 1)]
    geometry = np.array([*m.line_of_action, *m.friction_direction, *free])
    P = m.parameters
    zeros = np.zeros(int(idx.max()) + 1)
    forces = compiled(lateral_mesh_forces, zeros, zeros, idx, geometry, P)

    def lateral_mesh_force(mbs, t, itemNumber, q, q_t):
        return forces(np.asarray(q), np.asarray(q_t), idx, geometry, P)

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
    """Raised from inside a user function when the run stalls or diverges (Exudyn passes it on as its own
    error; the watchdog's ``failure`` tells the caller what happened)."""


CHECK_CALLS = 2_000  # force evaluations between divergence checks and progress updates (~250 attempts)
STALL_CALLS = 200_000  # force evaluations per stall check (~30k steps: ~0.1 s simulated normally)
STALL_ADVANCE_S = 1e-9


class StallWatchdog:
    """Rides on the drive's force function, which every step attempt evaluates (no pre-step Python call
    per attempt): every CHECK_CALLS calls it checks the watched speed for divergence and draws the
    progress bar; every STALL_CALLS calls it checks that time advanced (Exudyn's step control can reject
    steps at the minimum step size forever). Hot force functions use :meth:`ticker`.

    While it watches (from :meth:`watch` to :meth:`close`) it also notes a Ctrl-C (SIGINT) in
    ``interrupted``: Exudyn turns a KeyboardInterrupt raised inside a user function into its own
    error, and the caller re-raises KeyboardInterrupt from this flag."""

    def __init__(self) -> None:
        self.calls, self.t_check, self.t_max = 0, -1.0, -1.0
        self.failure = ""
        self.speed_limit = math.inf
        self.speed_name, self.speed_unit = "motor speed", "rad/s"
        self.t_end = 0.0
        self.progress = False
        self.bar = None
        self.t_wall0 = self.last_draw = 0.0
        self.interrupted = False
        self._sigint_handler = None

    def watch(self, t_end: float, speed_limit: float, progress: bool, name: str, unit: str) -> None:
        """Set what the run watches: divergence above ``speed_limit`` of the watched speed, a progress bar."""
        self.t_end, self.speed_limit, self.progress = t_end, speed_limit, progress
        self.speed_name, self.speed_unit = name, unit
        self.t_wall0 = time.monotonic()
        self._note_interrupts()

    def _note_interrupts(self) -> None:
        """Chain a SIGINT handler that sets ``interrupted`` before the previous handler runs (only in the
        main thread, and only where SIGINT is handled by Python: not where it is ignored)."""
        if threading.current_thread() is not threading.main_thread() or self._sigint_handler is not None:
            return
        previous = signal.getsignal(signal.SIGINT)
        if not callable(previous):  # SIG_IGN (a pool worker) or SIG_DFL: nothing raises in Python
            return

        def note(signum, frame):
            self.interrupted = True
            previous(signum, frame)

        self._sigint_handler = previous
        signal.signal(signal.SIGINT, note)

    def __call__(self, t: float, speed: float) -> None:
        self.calls += 1
        if t > self.t_max:
            self.t_max = t
        if self.calls % CHECK_CALLS == 0:
            self._check(t, speed)

    def ticker(self):
        """``(tick, check)`` for a hot force function: ``if tick(): check(t, speed)`` costs one C call
        per evaluation (~40 ns against ~200 ns for ``self(t, speed)``); ``tick()`` is true on every
        CHECK_CALLS-th call, and ``check`` counts those calls and checks as ``self(t, speed)`` would."""
        tick = itertools.cycle([False] * (CHECK_CALLS - 1) + [True]).__next__

        def check(t: float, speed: float) -> None:
            self.calls += CHECK_CALLS
            self.t_max = max(self.t_max, t)
            self._check(t, speed)

        return tick, check

    def _check(self, t: float, speed: float) -> None:
        if not math.isfinite(speed) or abs(speed) > self.speed_limit:
            self.failure = (
                f"state diverged at t = {t:.6g} s ({self.speed_name} {speed:.3g} {self.speed_unit}). Hint: "
                "check stiffness, inertia and load values, or tighten solver tolerances / lower "
                "solver.max_step_s"
            )
            raise StallError(self.failure)
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
        if self.progress:
            now = time.monotonic()
            if self.bar is None and now - self.t_wall0 > 2.0:
                from tqdm import tqdm

                self.bar = tqdm(
                    total=round(self.t_end, 6),
                    unit="s sim",
                    desc="simulating",
                    bar_format="{l_bar}{bar}| {n:.3f}/{total:.3f} s sim [{elapsed}<{remaining}]",
                )
            if self.bar is not None and now - self.last_draw > 0.5:
                self.last_draw = now
                self.bar.n = round(self.t_max, 6)
                self.bar.refresh()

    def close(self) -> None:
        if self._sigint_handler is not None:
            signal.signal(signal.SIGINT, self._sigint_handler)
            self._sigint_handler = None
        if self.bar is not None:
            self.bar.n = self.bar.total
            self.bar.close()
            self.bar = None


def motor_user_function(D: np.ndarray, watchdog: StallWatchdog):
    """Motor torque (and the run's watchdog)."""
    torque = compiled(motor_torque_at, 0.0, 0.0, D)

    tick, check = watchdog.ticker()

    def motor_torque(mbs, t, itemNumber, q, q_t):
        if tick():
            check(t, q_t[0])
        return (torque(t, q_t[0], D),)

    return motor_torque


def load_user_function(D: np.ndarray):
    torque = compiled(load_torque_at, 0.0, D)

    def load_torque(mbs, t, itemNumber, q, q_t):
        return (-torque(t, D),)

    return load_torque
