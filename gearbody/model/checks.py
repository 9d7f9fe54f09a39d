"""The checks a scenario makes of itself when it is built (:class:`gearbody.model.Scenario`), beyond
each key's own range: the chain's stages and shafts against its topology, a parallel stage's base
pitches and tooth faults, the turning senses along a train, and what a drive with a planetary stage
cannot have yet. Each refuses with a :class:`~gearbody.errors.ScenarioError` naming the key."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from .params import ScenarioError, stage_key

if TYPE_CHECKING:
    from .scenario import Design, Scenario, Stage

__all__ = ["check_planetary_in_drive", "check_stage", "check_topology", "check_turning_senses"]


def check_planetary_in_drive(k: int, scenario: Scenario) -> None:
    """What a drive with a planetary stage cannot have yet (refused, never ignored)."""
    if scenario.meta.topology != "train":
        raise ScenarioError(
            f"{stage_key(k, 'type')} = 'planetary': only topology 'train' has planetary stages, "
            f"got {scenario.meta.topology!r}"
        )
    if scenario.is_lateral:
        raise ScenarioError(
            f"{stage_key(k, 'type')} = 'planetary': parallel stages on lateral bearings are not yet "
            "combined with planetary stages; set their gears' lateral = 'none'"
        )


def check_topology(topology: str, design: Design) -> None:
    n = len(design.stages)
    if n < 1:
        raise ScenarioError("design.stages: a drive needs at least one gear stage")
    if topology == "train":
        if len(design.shafts) != n + 1:
            raise ScenarioError(
                f"design.shafts has {len(design.shafts)} entries: a train of {n} stage(s) needs {n + 1} "
                "(motor->stage 1, ..., last stage->machine)"
            )
    else:
        if n != 1:
            raise ScenarioError(f"design.stages: topology {topology!r} has exactly one stage, got {n}")
        if design.shafts:
            raise ScenarioError(
                f"design.shafts: topology {topology!r} has no shafts (motor and machine sit rigidly on the "
                "gears); remove them or use topology 'train'"
            )


def check_stage(k: int, stage: Stage) -> None:
    pb1 = 2 * math.pi * stage.pinion.base_radius_m / stage.pinion.teeth
    pb2 = 2 * math.pi * stage.wheel.base_radius_m / stage.wheel.teeth
    if abs(pb2 / pb1 - 1) > 0.005:
        raise ScenarioError(
            f"{stage_key(k, 'wheel')}.base_radius_m = {stage.wheel.base_radius_m}: base pitch 2 pi r_b / z = "
            f"{pb2 * 1e3:.4f} mm differs from the pinion's {pb1 * 1e3:.4f} mm by more than 0.5 %; "
            f"meshing gears need equal base pitches (r_b2 = r_b1 z2 / z1 = "
            f"{stage.pinion.base_radius_m * stage.wheel.teeth / stage.pinion.teeth:.6g} m)"
        )
    for key, entries in (("damaged_teeth", stage.damaged_teeth), ("pitted_teeth", stage.pitted_teeth)):
        seen: dict[tuple[str, int], int] = {}
        for i, t in enumerate(entries, start=1):
            z = getattr(stage, t.gear).teeth
            if t.tooth >= z:
                raise ScenarioError(
                    f"{stage_key(k, key)}.{i}.tooth = {t.tooth} on the {t.gear}: must be < its {z} teeth "
                    f"(0..{z - 1})"
                )
            if (t.gear, t.tooth) in seen:
                what = "one pit per tooth" if key == "pitted_teeth" else "one entry per damaged tooth"
                raise ScenarioError(
                    f"{stage_key(k, key)}.{i}: {what}: {t.gear} tooth {t.tooth} is also entry "
                    f"{seen[t.gear, t.tooth]}"
                    + ("; give its damage in one entry" if key == "damaged_teeth" else "")
                )
            seen[t.gear, t.tooth] = i
    for i, t in enumerate(stage.pitted_teeth, start=1):
        if not t.end_phase > t.start_phase:
            raise ScenarioError(
                f"{stage_key(k, 'pitted_teeth')}.{i}.end_phase = {t.end_phase} must be > start_phase = "
                f"{t.start_phase} (a pit spans [start_phase, end_phase) of the mesh period)"
            )
        w = stage.mesh.transition_width
        if t.end_phase - t.start_phase < w:
            raise ScenarioError(
                f"{stage_key(k, 'pitted_teeth')}.{i}: the pit on {t.gear} tooth {t.tooth} spans "
                f"{t.end_phase - t.start_phase:g} of the mesh period, less than the mesh's "
                f"transition_width = {w:g}; narrow the width or widen the pit"
            )
    gears = [e.gear for e in stage.eccentricity]
    if len(set(gears)) < len(gears):
        raise ScenarioError(f"{stage_key(k, 'eccentricity')}: at most one entry per gear, got {gears}")


def check_turning_senses(stages: tuple[Stage, ...]) -> None:
    """A stage's pinion turns with the previous stage's wheel, so the direction of its line of action is
    fixed by the chain; on bearings (lateral) a contradicting direction would put the mesh and friction
    forces on the wrong side of the gears."""
    sense = 1 if stages[0].mesh.line_of_action_normal_projection > 0 else -1
    for k, st in enumerate(stages):
        own = 1 if st.mesh.line_of_action_normal_projection > 0 else -1
        lateral = st.pinion.lateral != "none" or st.wheel.lateral != "none"
        if k > 0 and lateral and own != sense:
            turn = "counter-clockwise" if sense > 0 else "clockwise"
            raise ScenarioError(
                f"{stage_key(k, 'mesh')}.line_of_action_deg = {st.mesh.line_of_action_deg:g}: this "
                f"stage's pinion turns {turn} (with the previous wheel), so its line of action must "
                f"point the other way: centre_line_deg {'+' if sense > 0 else '-'} (90 - pressure "
                f"angle), e.g. {st.mesh.centre_line_deg + sense * 90:g} for a pure normal"
            )
        sense = -sense
