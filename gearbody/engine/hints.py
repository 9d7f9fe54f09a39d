"""Which scenario key most likely caused a numerical failure: the hints of SimulationError messages.

A failure is reported where the run noticed it (a stall, a diverged speed, a mesh out of its range);
these read the scenario for the likely cause (a soft or strongly jumping mesh stiffness, a wide
backlash, a tooth stiffness factor of 0) and name its key as the user can set it.
"""

from __future__ import annotations

import math

from ..assembly import mesh_parameters_from_scenario
from ..model import Scenario
from ..model.kinds import register_stage_kind, stage_kind
from ..model.params import stage_key
from ..physics import mean_stiffness_N_per_m

__all__ = ["divergence_hint", "mesh_range_hint", "stall_hint"]

STIFFNESS_JUMP_RATIO = 10.0
"""Single/double contact stiffnesses further apart than this make the mesh law jump hard."""


def _softest_stiffness_N_per_m(scenario: Scenario, stage: int) -> float:
    """The softest stiffness of a stage's mesh law (its mean for laws from the gear geometry), N/m."""
    mesh = scenario.stages[stage].mesh
    if mesh.stiffness_profile == "contact-ratio":
        return min(mesh.stiffness_single_N_per_m, mesh.stiffness_double_N_per_m)
    if mesh.stiffness_profile == "table":
        return max(min(mesh.table_stiffness_N_per_m), 1e-300)
    return mean_stiffness_N_per_m(mesh_parameters_from_scenario(scenario, stage))


def _zero_factor_teeth(scenario: Scenario) -> list[str]:
    """Every stage's teeth of stiffness factor 0 next to loaded ones (its kind's ``zero_factor_teeth``)."""
    out = []
    for k, st in enumerate(scenario.stages):
        hook = stage_kind(st).zero_factor_teeth
        out += hook(st, k) if hook is not None else []
    return out


def _parallel_zero_factor_teeth(st, k: int) -> list[str]:
    return [
        f"{stage_key(k, 'damaged_teeth')} ({t.gear} tooth {t.tooth})"
        for t in st.damaged_teeth
        if t.stiffness_factor == 0
    ]


def _jumps(where: str, m) -> list[str]:
    """A mesh whose stiffness jumps by more than STIFFNESS_JUMP_RATIO at a sharp tooth change."""
    lo, hi = sorted((m.stiffness_single_N_per_m, m.stiffness_double_N_per_m))
    if m.transition_width == 0 and hi > STIFFNESS_JUMP_RATIO * lo:
        return [
            f"{where}.stiffness_single_N_per_m / stiffness_double_N_per_m "
            f"({m.stiffness_single_N_per_m:.3g} / {m.stiffness_double_N_per_m:.3g} N/m)"
        ]
    return []


def _parallel_jumps(st, k: int) -> list[str]:
    return _jumps(stage_key(k, "mesh"), st.mesh) if st.mesh.stiffness_profile == "contact-ratio" else []


def _planetary_jumps(st, k: int) -> list[str]:
    return [
        line for name in ("sun_mesh", "ring_mesh") for line in _jumps(stage_key(k, name), getattr(st, name))
    ]


def _parallel_divergence_cause(scenario: Scenario, k: int) -> str:
    st = scenario.stages[k]
    p_b_m = 2 * math.pi * st.pinion.base_radius_m / st.pinion.teeth
    return _mesh_cause(scenario, k, 0.1 * p_b_m)


register_stage_kind(
    "parallel",
    stiffness_jumps=_parallel_jumps,
    zero_factor_teeth=_parallel_zero_factor_teeth,
    divergence_cause=_parallel_divergence_cause,
)
register_stage_kind("planetary", stiffness_jumps=_planetary_jumps)


def _jumping_meshes(scenario: Scenario) -> list[str]:
    out = []
    for k, st in enumerate(scenario.stages):
        hook = stage_kind(st).stiffness_jumps
        out += hook(st, k) if hook is not None else []
    return out


def stall_hint(scenario: Scenario) -> str:
    """Hint of a stalled run: a jump the step control cannot cross, named by its key."""
    teeth = _zero_factor_teeth(scenario)
    if teeth:
        return (
            f"a tooth with stiffness factor 0 next to a loaded one ({', '.join(teeth)}): use a small "
            "non-zero factor (e.g. 0.2)"
        )
    jumps = _jumping_meshes(scenario)
    if jumps:
        return (
            f"the mesh stiffness jumps by more than {STIFFNESS_JUMP_RATIO:g}x at each contact change "
            f"({'; '.join(jumps)}): bring the two closer"
        )
    return "loosen solver.relative_tolerance / absolute_tolerance, or set solver.accuracy = 'draft'"


def divergence_hint(scenario: Scenario) -> str:
    """Hint of a diverged run: a mesh that cannot carry the load, else the usual suspects."""
    for k, st in enumerate(scenario.stages):
        hook = stage_kind(st).divergence_cause
        cause = hook(scenario, k) if hook is not None else ""
        if cause:
            return cause
    return "check stiffness, inertia and load values, or tighten solver tolerances / lower solver.max_step_s"


def _mesh_cause(scenario: Scenario, stage: int, limit_m: float) -> str:
    mesh = scenario.stages[stage].mesh
    key = stage_key(stage, "mesh")
    load_N = max(scenario.operation.load_profile.fraction) * scenario.stage_rated_force_N(stage)
    soft = _softest_stiffness_N_per_m(scenario, stage)
    hints = []
    if load_N / soft > 0.25 * limit_m:
        hints.append(
            f"the softest mesh stiffness {soft:.3g} N/m deflects {load_N / soft * 1e3:.3g} mm under the "
            f"highest load ({load_N:.4g} N): raise {key}.stiffness_single_N_per_m / "
            "stiffness_double_N_per_m or lower the load"
        )
    if mesh.backlash_um * 1e-6 > 0.25 * limit_m:
        hints.append(
            f"{key}.backlash_um = {mesh.backlash_um:g} alone spans {mesh.backlash_um * 1e-6 / limit_m:.2g} "
            f"of the {limit_m * 1e3:.3g} mm the lumped mesh covers: narrow it"
        )
    if hints:
        return "; ".join(hints)
    teeth = _zero_factor_teeth(scenario)
    if teeth:
        return (
            f"a tooth stiffness factor of 0 ({', '.join(teeth)}) leaves no load path for a whole mesh "
            "period in the lumped model; use a factor > 0 (e.g. 0.2)"
        )
    jumps = _jumping_meshes(scenario)
    if jumps:
        return f"check {'; '.join(jumps)}: the soft contact lets the gears run through each other"
    return ""


def mesh_range_hint(scenario: Scenario, stage: int, limit_m: float) -> str:
    """Hint of a mesh whose deflection left the lumped model's range (``limit_m``)."""
    key = stage_key(stage, "mesh")
    return _mesh_cause(scenario, stage, limit_m) or (
        f"check the loads, the mesh stiffness ({key}.stiffness_single_N_per_m / stiffness_double_N_per_m) "
        "and the inertias"
    )
