"""The solver section of a scenario (``[solver]``) and its defaults: Exudyn's explicit integrators
gearbody offers, the accuracy levels (method and absolute tolerance) and how their tolerance scales
with what a drive's coordinates are (Muller's deflection in metres, a planetary stage's moving centres).
docs/design-notes.md, "Solver tolerances"."""

from __future__ import annotations

from dataclasses import dataclass

from .params import Node, param

__all__ = [
    "ACCURACY_LEVELS",
    "MULLER_TOLERANCE_SCALE",
    "PLANETARY_TOLERANCE_SCALE",
    "SOLVER_METHODS",
    "Solver",
    "default_solver",
]

SOLVER_METHODS = ("DOPRI5", "ODE23", "RK44", "RK67")
"""Exudyn's explicit integrators gearbody offers. DVERK6 is not among them: Exudyn 1.13.6 names it but
does not implement it (a run failed at its start with NotImplementedFeatureError)."""


ACCURACY_LEVELS = {
    # level: (method, absolute tolerance of rotations in rad); Muller's deflection coordinate (m) gets
    # MULLER_TOLERANCE_SCALE times it. Measured against the independent reference on the full validation
    # cases (benchmarks/RESULTS.md, "Accuracy levels").
    "draft": ("ODE23", 3e-5),  # loaded steady running, torsional studies of error modes and faults:
    #                            0.15-0.26 %; misses impacts (1-35 % on separations) and bearing forces
    "default": ("DOPRI5", 1e-8),  # every validation case <= 0.06 %, impacts included (2026-12-02)
    "tight": ("DOPRI5", 1e-10),  # a yardstick: ~1e-4 % of F_rated
}
MULLER_TOLERANCE_SCALE = 3e-3
"""Muller integrates the deflection in metres, the other topologies angles in radians (1e-8 rad is
r_b 1e-8 ~ 1e-9 m of deflection). At 1e-8 m Muller's full separation and run-up cases missed by 0.66 % and
10.3 % (the re-engagement impacts of the load ramp); 3e-11 m gives 0.0001 % and 0.031 % (1e-9: 0.0016 /
2.1 %, 1e-10: 0.0001 / 0.21 %)."""


PLANETARY_TOLERANCE_SCALE = 0.1
"""A drive with planetary stages integrates the planets' centres in the fixed frame (metres, moving by
r_c w_c per second) with the rotations: at 1e-8 the conveyor scene's separation case (speed x5.6, the
carrier at 43 rad/s) drifted from the reference by 0.9 % of F_rated within 0.06 s; 1e-9 gives 0.03 %,
1e-10 0.0008 % (validation/compare.py cases)."""


def default_solver(accuracy: str, topology: str, planetary: bool = False) -> tuple[str, float]:
    """(method, absolute tolerance) of an accuracy level for a topology's coordinates (``planetary``: a
    drive with planetary stages)."""
    method, atol = ACCURACY_LEVELS[accuracy]
    if planetary:
        atol *= PLANETARY_TOLERANCE_SCALE
    return method, atol * (MULLER_TOLERANCE_SCALE if topology == "muller" else 1.0)


FORCE_PATHS = ("auto", "compiled", "python")


@dataclass(frozen=True, kw_only=True)
class Solver(Node):
    accuracy: str = param(
        "default", choices=tuple(ACCURACY_LEVELS), doc="sets method and absolute_tolerance where unset"
    )
    method: str | None = param(
        None, choices=SOLVER_METHODS, doc="Exudyn explicit integrator (unset: from accuracy)"
    )
    # The mesh force depends on r1 phi_p - r2 phi_w, a small difference of angles that grow past
    # 100 rad per simulated second. Exudyn scales each coordinate's error by atol + rtol * max(q0, q1)
    # (signed), so a relative tolerance loosens as the angles grow: rtol is kept negligible and the
    # absolute tolerance (SI units: rad, rad/s, m, m/s) sets the accuracy, so its default depends on what
    # the coordinates are (MULLER_TOLERANCE_SCALE); docs/design-notes.md, "Solver tolerances".
    relative_tolerance: float = param(1e-14, gt=0, lt=1, doc="adaptive step relative tolerance")
    absolute_tolerance: float | None = param(
        None, gt=0, doc="adaptive step absolute tolerance (unset: from accuracy, in the coordinates' units)"
    )
    max_step_s: float = param(1e-4, gt=0, doc="largest step")
    output_rate_hz: float = param(20000.0, gt=0, doc="results are sampled at k / output_rate_hz")
    # The mesh force jumps when the pair count changes; point samples of it alias (its 1/k harmonics
    # fold into the band of interest). docs/scenario.md, "Signals": which signals are band-limited.
    anti_aliasing: bool = param(
        True, doc="band-limit force and acceleration signals before sampling (measurement-chain filter)"
    )
    # Resource limits (gearbody.model.budget): checked before a run from estimates, and during it.
    memory_limit_MiB: float | None = param(
        None,
        gt=0,
        doc="memory budget of a run: refused before it when the output grid and stored steps are "
        "estimated above it, stopped when the process grows by more while solving (unset: 2048)",
    )
    wall_time_limit_s: float | None = param(
        None, gt=0, doc="stop a run cleanly after this much wall-clock time solving (unset: no limit)"
    )
    # Exudyn calls the force laws either through Python functions or, on the compiled path, as numba
    # kernels from C++ (gearbody.engine.compiled_path; the same laws, bit-identical forces).
    force_path: str = param(
        "auto",
        choices=FORCE_PATHS,
        doc="how Exudyn calls the force laws: compiled from C++, or through Python (auto: compiled where "
        "the extension works)",
    )
