"""The fault tables of a planetary stage (docs/planetary.md, "Faults"): damaged teeth of its sun, ring
and planets and weakened planet bearings, and the check that they name existing teeth and planets (with
the planet pin errors); :class:`gearbody.model.planetary.PlanetaryStage` holds them and makes the check
when it is built."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from .params import Node, ScenarioError, param

if TYPE_CHECKING:
    from .planetary import PlanetaryStage

__all__ = ["TOOTHED", "PlanetBearingDefect", "PlanetaryDamagedTooth", "check_faults"]

TOOTHED = ("sun", "ring", "planet")


@dataclass(frozen=True, kw_only=True)
class PlanetaryDamagedTooth(Node):
    """A cracked or broken tooth of a planetary member as a bare stiffness factor on every pair it is
    in (docs/planetary.md, "Faults"): a sun or ring tooth in every planet's mesh with that member, a
    planet tooth in its planet's sun and ring meshes."""

    member: str = param(choices=TOOTHED, doc="toothed member: sun, ring or planet")
    planet: int | None = param(None, ge=1, doc="planet number 1..N (member 'planet' only)")
    tooth: int = param(ge=0, doc="tooth index, 0-based (numbering: docs/planetary.md, 'Faults')")
    stiffness_factor: float = param(ge=0, le=1, doc="factor on k_z while this tooth meshes")


@dataclass(frozen=True, kw_only=True)
class PlanetBearingDefect(Node):
    """A worn or loose planet bearing: its (isotropic) stiffness and damping times a factor."""

    planet: int = param(ge=1, doc="planet number 1..N")
    stiffness_factor: float = param(gt=0, le=1, doc="factor on the planet bearing's stiffness and damping")


def check_faults(stage: PlanetaryStage) -> None:
    """Damaged teeth on existing teeth and planets (one entry per tooth), one pin error per planet
    within a tenth of a module, bearing defects on existing planets (one per planet)."""
    seen: dict[tuple, int] = {}
    for i, t in enumerate(stage.damaged_teeth, start=1):
        key = f"damaged_teeth.{i}"
        if t.member == "planet":
            if t.planet is None:
                raise ScenarioError(
                    f"{key}.planet: required for member 'planet'; allowed: 1..{stage.planets}"
                )
            if t.planet > stage.planets:
                raise ScenarioError(f"{key}.planet = {t.planet}: allowed: 1..{stage.planets}")
        elif t.planet is not None:
            raise ScenarioError(
                f"{key}.planet = {t.planet}: only for member 'planet' (a {t.member} tooth meets every "
                "planet); remove it"
            )
        z = getattr(stage, t.member).teeth
        if t.tooth >= z:
            raise ScenarioError(
                f"{key}.tooth = {t.tooth} on the {t.member}: must be < its {z} teeth (0..{z - 1})"
            )
        ident = (t.member, t.planet, t.tooth)
        if ident in seen:
            raise ScenarioError(
                f"{key}: one entry per damaged tooth: {t.member} tooth {t.tooth} is also entry {seen[ident]}"
            )
        seen[ident] = i
    errors = stage.planet_position_errors_um
    if errors and len(errors) != stage.planets:
        raise ScenarioError(
            f"planet_position_errors_um has {len(errors)} values: planets = {stage.planets} needs one "
            "per planet (or none)"
        )
    limit_um = 100.0 * stage.module_mm
    for n, e in enumerate(errors, start=1):
        if not abs(e) <= limit_um:
            raise ScenarioError(
                f"planet_position_errors_um.{n} = {e:g}: allowed: -{limit_um:g} .. {limit_um:g} um "
                "(a tenth of the module)"
            )
    if stage.planet_bearing_defects and stage.planet.bearing is not None:
        raise ScenarioError(
            "planet_bearing_defects: they weaken the linear planet bearing (bearing_stiffness_N_per_m); "
            "with a planet bearing law, state the defect in its parameters"
        )
    planets: dict[int, int] = {}
    for i, d in enumerate(stage.planet_bearing_defects, start=1):
        if d.planet > stage.planets:
            raise ScenarioError(
                f"planet_bearing_defects.{i}.planet = {d.planet}: allowed: 1..{stage.planets}"
            )
        if d.planet in planets:
            raise ScenarioError(
                f"planet_bearing_defects.{i}: planet {d.planet} is also entry {planets[d.planet]}; "
                "one defect per planet bearing"
            )
        planets[d.planet] = i
