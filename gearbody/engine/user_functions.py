"""The Python force functions Exudyn calls on every right-hand-side evaluation: mesh forces (torsional and
lateral), bearing laws, motor and load torques, and the stall watchdog that rides on them. Each closes
over its packed parameters and calls the compiled laws of :mod:`gearbody.physics` (the mesh force runs
millions of times per simulated second: keep these thin)."""

from __future__ import annotations

import itertools
import math
import os
import signal
import threading
import time

import numpy as np

from ..assembly.system import DriveItem, MullerItem
from ..errors import SimulationError
from ..physics import load_fraction_at, load_torque_at, motor_torque_at, synchronous_angle_at
from ..physics.compiled import compiled
from ..physics.lateral import lateral_mesh_forces
from ..physics.mesh import contact_force, single_mesh_drive_forces, torsional_mesh_forces


def mesh_user_function(P: np.ndarray):
    forces = compiled(torsional_mesh_forces, 0.0, 0.0, 0.0, 0.0, P)

    def mesh_force(mbs, t, itemNumber, q, q_t):
        return forces(q[0], q[1], q_t[0], q_t[1], P)

    return mesh_force


def lateral_mesh_user_function(P: np.ndarray, geometry: np.ndarray, idx: np.ndarray):
    """A mesh where one or both gears translate: :func:`gearbody.physics.lateral.lateral_mesh_forces`."""
    zeros = np.zeros(int(idx.max()) + 1)
    forces = compiled(lateral_mesh_forces, zeros, zeros, idx, geometry, P)

    def lateral_mesh_force(mbs, t, itemNumber, q, q_t):
        return forces(np.asarray(q), np.asarray(q_t), idx, geometry, P)

    return lateral_mesh_force


def bearing_user_function(law, free_directions: tuple[int, ...], rotation_sense: float = 1.0):
    mask = np.array([float(d in free_directions) for d in (0, 1)])
    mx, my = float(mask[0]), float(mask[1])
    if getattr(law, "ROTATING", False):  # the gear's rotation turns the inner race (outer in the housing)
        force_turning, sense = law.force_xy, float(rotation_sense)

        def bearing_force_turning(mbs, t, itemNumber, q, q_t):
            fx, fy = force_turning(q[0] * mx, q[1] * my, q_t[0] * mx, q_t[1] * my, q[2] * sense, 0.0)
            return [fx * mx, fy * my, 0.0]

        return bearing_force_turning
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


class StallError(SimulationError):
    """Raised from inside a user function when the run stalls or diverges (Exudyn passes it on as its own
    error; the watchdog's ``failure`` tells the caller what happened, in the :class:`SimulationError`
    that :func:`gearbody.simulate` raises). A :class:`SimulationError` itself, should it escape."""


CHECK_CALLS = 2_000  # force evaluations between divergence checks and progress updates (~250 attempts)
STALL_CALLS = 200_000  # force evaluations per stall check (~30k steps: ~0.1 s simulated normally)
STALL_ADVANCE_S = 1e-9
STALL_FRACTION = 1e-2
"""A stall: STALL_CALLS force evaluations advanced less than STALL_FRACTION of the shortest period the
run resolves, 1 / max(solver.output_rate_hz, 1 / solver.max_step_s) (5e-7 s by default), and at least
STALL_ADVANCE_S. A run's steps are never shorter than ~1 / (2 pi) of the fastest rate it may hold,
MODE_RATE_FACTOR = 10 times that resolved rate (gearbody.assembly.stiff_modes): its ~30k steps per check
advance ~5e2 such periods, 5e4 times the threshold. A run chattering at a jump of a force law crept on
at ~1e-12 s per step: 0.01 s simulated had not finished after 5 min, and the absolute 1e-9 s alone
never called it stalled."""


PAGE_BYTES = os.sysconf("SC_PAGE_SIZE") if hasattr(os, "sysconf") else 4096


def resident_memory_bytes() -> int:
    """Resident memory of this process, bytes (Linux: /proc/self/statm; elsewhere the peak so far)."""
    try:
        with open("/proc/self/statm", "rb") as f:
            return int(f.read().split()[1]) * PAGE_BYTES
    except (OSError, IndexError, ValueError):
        import resource

        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


class StallWatchdog:
    """Rides on the drive's force function, which every step attempt evaluates (no pre-step Python call
    per attempt): every CHECK_CALLS calls it checks the watched speed for divergence, the wall-time
    limit, and draws the progress bar; every STALL_CALLS calls it checks that time advanced (Exudyn's
    step control can reject steps at the minimum step size forever) and the memory limit (growth of the
    process's resident memory while solving). Hot force functions use :meth:`ticker`.

    While it watches (from :meth:`watch` to :meth:`close`) it also notes a Ctrl-C (SIGINT), or a SIGTERM
    that the command line turns into the same stop, in ``interrupted``: Exudyn turns a KeyboardInterrupt
    raised inside a user function into its own error, and the caller re-raises KeyboardInterrupt from
    this flag."""

    def __init__(self) -> None:
        self.calls, self.t_check, self.t_max = 0, -1.0, -1.0
        self.failure = ""
        self.speed_limit = math.inf
        self.speed_name, self.speed_unit = "motor speed", "rad/s"
        self.t_end = 0.0
        self.progress = False
        self.bar = None
        self.t_wall0 = self.last_draw = 0.0
        self.wall_time_limit_s = math.inf
        self.memory_limit_bytes = math.inf
        self.memory_limit_default = False
        self.memory0_bytes = 0
        self.max_step_s = math.inf
        self.stall_advance_s = STALL_ADVANCE_S
        self.stall_hint = ""
        self.divergence_hint = (
            "check stiffness, inertia and load values, or tighten solver tolerances / lower solver.max_step_s"
        )
        self.interrupted = False
        self.finished = False  # set by the caller when the solver reached t_end
        self._chained: dict[int, object] = {}  # signal -> the handler it replaced while watching

    def watch(
        self,
        t_end: float,
        speed_limit: float,
        progress: bool,
        name: str,
        unit: str,
        *,
        wall_time_limit_s: float | None = None,
        memory_limit_bytes: float | None = None,
        memory_limit_default: bool = False,
        max_step_s: float = math.inf,
        resolved_period_s: float = 0.0,
        stall_hint: str = "",
        divergence_hint: str = "",
    ) -> None:
        """Set what the run watches: divergence above ``speed_limit`` of the watched speed, a progress
        bar, the wall-time and memory budgets (None: unlimited), the largest step, the shortest period
        the run resolves (the stall threshold, STALL_FRACTION of it) and the scenario's likely causes of
        a stall or a divergence (hints for the messages)."""
        self.t_end, self.speed_limit, self.progress = t_end, speed_limit, progress
        self.speed_name, self.speed_unit = name, unit
        self.wall_time_limit_s = math.inf if wall_time_limit_s is None else wall_time_limit_s
        self.memory_limit_bytes = math.inf if memory_limit_bytes is None else memory_limit_bytes
        self.memory_limit_default = memory_limit_default
        self.max_step_s, self.stall_hint = max_step_s, stall_hint
        self.stall_advance_s = max(STALL_ADVANCE_S, STALL_FRACTION * resolved_period_s)
        self.divergence_hint = divergence_hint or self.divergence_hint
        if memory_limit_bytes is not None:
            self.memory0_bytes = resident_memory_bytes()
        self.t_wall0 = time.monotonic()
        self._note_interrupts()

    def _note_interrupts(self) -> None:
        """Chain a SIGINT (and SIGTERM) handler that sets ``interrupted`` before the previous handler
        runs (only in the main thread, and only where the signal is handled by Python: not where it is
        ignored or left to its default action)."""
        if threading.current_thread() is not threading.main_thread() or self._chained:
            return
        for signum in (signal.SIGINT, signal.SIGTERM):
            previous = signal.getsignal(signum)
            if not callable(previous):  # SIG_IGN (a pool worker, `cmd &`) or SIG_DFL: nothing raises
                continue

            def note(signum, frame, previous=previous):
                self.interrupted = True
                previous(signum, frame)

            self._chained[signum] = previous
            signal.signal(signum, note)

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
                f"state diverged at t = {t:.6g} s ({self.speed_name} {speed:.3g} {self.speed_unit}). "
                f"Hint: {self.divergence_hint}"
            )
            raise StallError(self.failure)
        now = time.monotonic()
        if now - self.t_wall0 > self.wall_time_limit_s:
            self.failure = (
                f"stopped at t = {self.t_max:.6g} s of {self.t_end:g} s: the wall-time limit "
                f"solver.wall_time_limit_s = {self.wall_time_limit_s:g} s was reached. Hint: raise "
                "solver.wall_time_limit_s, shorten operation.t_end_s, or use solver.accuracy = 'draft'"
            )
            raise StallError(self.failure)
        if self.calls % STALL_CALLS == 0:
            if self.t_max - self.t_check < self.stall_advance_s:
                raise StallError(self._stalled())
            self.t_check = self.t_max
            if self.memory_limit_bytes < math.inf:
                grown = resident_memory_bytes() - self.memory0_bytes
                if grown > self.memory_limit_bytes:
                    self.failure = (
                        f"stopped at t = {self.t_max:.6g} s of {self.t_end:g} s: the run grew by "
                        f"{grown / 2**20:.4g} MiB while solving, more than the memory budget "
                        f"solver.memory_limit_MiB = {self.memory_limit_bytes / 2**20:g}"
                        + (" (default)" if self.memory_limit_default else "")
                        + ". Hint: every solver step is stored; shorten operation.t_end_s, loosen "
                        "solver.absolute_tolerance (fewer steps), or raise solver.memory_limit_MiB"
                    )
                    raise StallError(self.failure)
        if self.progress:
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

    def _stalled(self) -> str:
        what = (
            f"the solver stalled at t = {self.t_max:.9g} s: {STALL_CALLS} force evaluations advanced "
            f"less than {self.stall_advance_s:g} s"
        )
        if self.max_step_s * STALL_CALLS < 100 * self.stall_advance_s:  # the largest step itself is too short
            self.failure = (
                f"{what}: solver.max_step_s = {self.max_step_s:g} s caps every step. Hint: raise "
                "solver.max_step_s (default 1e-4 s)"
            )
        elif self.stall_hint:
            self.failure = f"{what} (step size collapse at a jump of the mesh law). Hint: {self.stall_hint}"
        else:
            self.failure = (
                f"{what} (step size collapse at a discontinuity, e.g. a tooth with stiffness factor 0 "
                "next to a loaded one). Hint: use a small non-zero stiffness factor, or loosen "
                "solver.relative_tolerance / absolute_tolerance"
            )
        return self.failure

    def close(self) -> None:
        for signum, previous in self._chained.items():
            signal.signal(signum, previous)
        self._chained = {}
        if self.bar is not None:  # full when the run got to its end, else where it stopped
            self.bar.n = self.bar.total if self.finished else round(max(self.t_max, 0.0), 6)
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


def muller_user_function(item: MullerItem, watchdog: StallWatchdog):
    """Muller's one-mass model (Fig. 1): the reduced mass driven by the rated force at the load fraction
    against the contact force at the kinematic pinion angle (and the run's watchdog)."""
    P, D, F_rated = item.parameters, item.drive, item.rated_force_N
    contact = compiled(contact_force, 0.0, 0.0, 0.0, P)
    angle = compiled(synchronous_angle_at, 0.0, D)
    load = compiled(load_fraction_at, 0.0, D)

    tick, check = watchdog.ticker()

    def muller_force(mbs, t, itemNumber, q, q_t):
        if tick():
            check(t, q_t[0])
        F = contact(angle(t, D), q[0], q_t[0], P)[0]
        return [F_rated * load(t, D) - F]

    return muller_force


def drive_user_function(item: DriveItem, n: int, watchdog: StallWatchdog):
    """The drive's one force function on all its ``n`` coordinates: motor torque (and the run's
    watchdog), load torque, every torsional mesh and every slice term, one Python call per right-hand
    side instead of one per item (Exudyn's per-call overhead dominates the cost). The one-stage drive
    (motor, pinion, wheel, load) calls one fused compiled law; a drive without slice terms works on
    Python lists, which is faster than numpy for a few coordinates."""
    D, im, il = item.drive, item.motor_at, item.load_at
    one_stage = item.one_stage_mesh(n)
    if one_stage is not None:
        P = one_stage.parameters
        forces = compiled(single_mesh_drive_forces, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, P, D)

        tick, check = watchdog.ticker()

        def drive_and_mesh(mbs, t, itemNumber, q, q_t):
            if tick():
                check(t, q_t[0])
            return forces(t, q_t[0], q[1], q[2], q_t[1], q_t[2], P, D)

        return drive_and_mesh
    motor = compiled(motor_torque_at, 0.0, 0.0, D)
    load = compiled(load_torque_at, 0.0, D)
    meshes = [(m.pinion, m.wheel, m.parameters) for m in item.meshes]
    mesh_forces = compiled(torsional_mesh_forces, 0.0, 0.0, 0.0, 0.0, meshes[0][2]) if meshes else None
    tick, check = watchdog.ticker()
    if not item.terms:

        def drive_and_meshes(mbs, t, itemNumber, q, q_t):
            if tick():
                check(t, q_t[im])
            f = [0.0] * n
            f[im] = motor(t, q_t[im], D)
            f[il] -= load(t, D)
            for ip, iw, P in meshes:
                a, b = mesh_forces(q[ip], q[iw], q_t[ip], q_t[iw], P)
                f[ip] += a
                f[iw] += b
            return f

        return drive_and_meshes
    terms = [(term.first, term.first + term.size, term.factory()) for term in item.terms]

    def drive_items(mbs, t, itemNumber, q, q_t):
        if tick():
            check(t, q_t[im])
        q, q_t = np.asarray(q), np.asarray(q_t)
        f = np.zeros(n)
        f[im] = motor(t, q_t[im], D)
        f[il] -= load(t, D)
        for ip, iw, P in meshes:
            a, b = mesh_forces(q[ip], q[iw], q_t[ip], q_t[iw], P)
            f[ip] += a
            f[iw] += b
        for a, b, forces in terms:
            f[a:b] += forces(q[a:b], q_t[a:b])
        return f

    return drive_items
