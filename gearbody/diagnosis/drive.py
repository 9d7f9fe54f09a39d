"""What a scenario says about a recording of its drive: the speed ratio of every shaft to the shaft a
tacho sits on, the gears to average synchronously, and the catalogue of lines (shaft orders, mesh
harmonics and sidebands, planetary lines, bearing fault frequencies) at any measured speed.

Ratios come from the scenario's nominal kinematics (every rotation's speed when nothing deflects,
:func:`gearbody.assembly.operating_point.nominal_speeds_rad_s`), so one tacho gives every shaft's angle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ..analysis import KinematicLine, gear_train_lines
from ..errors import InputError
from ..signals import gear_names, stage_prefix

__all__ = ["BearingLineSource", "DriveKinematics", "GearShaft"]


@dataclass(frozen=True)
class GearShaft:
    """A rotating body to average synchronously: its name, its teeth (the mesh order on it) and stage."""

    body: str
    teeth: int | None
    stage: int


@dataclass(frozen=True)
class BearingLineSource:
    """A rolling bearing with geometry: it turns at the speed of ``body`` relative to ``reference``."""

    name: str
    body: str
    reference: str
    geometry: Any  # gearbody.analysis.bearing_lines.BearingGeometry
    outer_race_rotates: bool = False


@dataclass(frozen=True)
class DriveKinematics:
    """A drive's kinematics for the analysis of a recording: ``speed_ratios`` (body -> its speed over the
    input shaft's, signed), the stages' metadata, gears to average and bearings with geometry."""

    scene: str
    speed_ratios: dict[str, float]
    stages: tuple[dict[str, Any], ...]
    gears: tuple[GearShaft, ...]
    bearings: tuple[BearingLineSource, ...] = ()
    input_body: str = "pinion"
    nominal_input_hz: float | None = None
    """The input shaft's speed with the motor at its synchronous speed [rev/s] (None: Muller's model)."""
    bearings_without_geometry: tuple[str, ...] = ()
    """Rolling bearings of the scenario that state no geometry: ``"<name> (<its geometry key>)"``."""

    @classmethod
    def from_scenario(cls, scenario) -> DriveKinematics:
        """The kinematics of ``scenario`` (a :class:`gearbody.model.Scenario`)."""
        from ..assembly.operating_point import nominal_speeds_rad_s
        from ..engine.collect import _stage_meta

        stages = tuple(dict(_stage_meta(scenario, k)) for k in range(len(scenario.stages)))
        for st in stages:
            st.setdefault("type", "parallel")
        speeds = nominal_speeds_rad_s(scenario)
        nominal = None
        if not speeds:  # Muller's model: no rotation coordinates; its gears' ratio from the teeth
            z1, z2 = stages[0]["pinion_teeth"], stages[0]["wheel_teeth"]
            speeds = {"pinion": 1.0, "wheel": z1 / z2}
        input_body = _input_body(stages, speeds)
        w_in = speeds[input_body]
        if nominal is None and speeds.get("pinion") != 1.0:
            nominal = abs(w_in) / (2 * math.pi)
        ratios = {body: w / w_in for body, w in speeds.items()}
        gears = tuple(_gears(stages, ratios))
        bearings = tuple(_bearings(scenario, ratios))
        finder = getattr(scenario, "rolling_bearings", None)
        missing = tuple(f"{b.name} ({b.key})" for b in (finder() if finder else []) if b.geometry is None)
        return cls(
            str(scenario.meta.name or ""), ratios, stages, gears, bearings, input_body, nominal, missing
        )

    # -- speeds and angles ---------------------------------------------------------------------------
    def bodies(self) -> list[str]:
        """The rotating bodies (those with a non-zero speed)."""
        return [b for b, r in self.speed_ratios.items() if r != 0]

    def ratio(self, body: str, to: str) -> float:
        """Speed of ``body`` over the speed of ``to`` (signed)."""
        for name in (body, to):
            if name not in self.speed_ratios or self.speed_ratios[name] == 0 and name == to:
                raise InputError(
                    f"shaft {name!r}: not a rotating body of scene {self.scene!r}; bodies: "
                    f"{', '.join(self.bodies())}"
                )
        return self.speed_ratios[body] / self.speed_ratios[to]

    def resolve_body(self, name: str) -> str:
        """A body name from what a user may call a shaft: a body (``pinion``, ``wheel_2``), ``input``
        (the first stage's input), ``output`` (the machine, else the last body) or ``motor``."""
        if name in self.speed_ratios and self.speed_ratios[name] != 0:
            return name
        if name == "input":
            return self.input_body
        if name == "output":
            return "machine" if "machine" in self.speed_ratios else list(self.speed_ratios)[-1]
        raise InputError(
            f"shaft {name!r}: not a rotating body of scene {self.scene!r}; bodies: "
            f"input, output, {', '.join(self.bodies())}"
        )

    # -- the catalogue of lines ----------------------------------------------------------------------
    def lines(self, input_hz: float, f_max_hz: float, harmonics: int = 6, sidebands: int = 3) -> list:
        """Every line in (0, ``f_max_hz``] with the input shaft at ``input_hz`` (> 0): gear-train lines,
        each planetary stage's lines and each bearing's BPFO, BPFI, 2 BSF and FTF with two harmonics.
        ``input_hz = 1`` gives the lines in orders of the input shaft."""
        lines: list = []
        if all(st["type"] == "parallel" for st in self.stages):
            teeth = [(st["pinion_teeth"], st["wheel_teeth"]) for st in self.stages]
            lines += gear_train_lines(input_hz, teeth, f_max_hz, harmonics=harmonics, sidebands=sidebands)
        else:
            lines += self._compound_lines(input_hz, f_max_hz, harmonics, sidebands)
        lines += self.bearing_lines(input_hz, f_max_hz)
        return sorted(lines, key=lambda line: line.frequency_hz)

    def _compound_lines(self, input_hz: float, f_max_hz: float, harmonics: int, sidebands: int) -> list:
        from ..analysis import GearMesh, KinematicSources, Shaft, kinematic_lines
        from ..analysis.planetary_lines import PlanetarySources, planetary_lines

        out, shafts, meshes = [], [], []

        def flush() -> None:
            if shafts:
                sources = KinematicSources(tuple(shafts), tuple(meshes))
                out.extend(kinematic_lines(sources, f_max_hz, harmonics=harmonics, sidebands=sidebands))
                shafts.clear()
                meshes.clear()

        for k, st in enumerate(self.stages):
            if st["type"] == "planetary":
                flush()
                p = stage_prefix(k)
                f = {m: self.speed_ratios[p + m] * input_hz for m in ("sun", "ring", "carrier", "planet_1")}
                src = PlanetarySources(
                    st["sun_teeth"],
                    st["planet_teeth"],
                    st["ring_teeth"],
                    st["planets"],
                    f["carrier"],
                    f["sun"],
                    f["ring"],
                    f["planet_1"],
                    rtol=1e-6,
                )
                out.extend(planetary_lines(src, f_max_hz, harmonics=harmonics))
            elif st["type"] == "parallel":
                pinion, wheel = gear_names(k)
                f_p = abs(self.speed_ratios[pinion]) * input_hz
                tag = "" if k == 0 else f" {k + 1}"
                if not shafts:
                    shafts.append(Shaft(f"pinion{tag}", f_p))
                shafts.append(Shaft(f"wheel{tag}", abs(self.speed_ratios[wheel]) * input_hz))
                meshes.append(
                    GearMesh(f"f_z{k + 1}", st["pinion_teeth"] * f_p, (shafts[-2].name, shafts[-1].name))
                )
            else:
                flush()
        flush()
        return out

    def bearing_frequencies(self, input_hz: float) -> list[tuple[BearingLineSource, Any]]:
        """(bearing, its :class:`~gearbody.analysis.bearing_lines.BearingFrequencies`) of every bearing
        with geometry that turns, the input shaft at ``input_hz`` (1: in orders of the input shaft); its
        ``shaft_hz`` is the speed of its body relative to its reference."""
        from ..analysis.bearing_lines import bearing_frequencies

        out = []
        for b in self.bearings:
            shaft_hz = abs(self.speed_ratios[b.body] - self.speed_ratios.get(b.reference, 0.0)) * input_hz
            if shaft_hz > 0:
                out.append(
                    (b, bearing_frequencies(b.geometry, shaft_hz, outer_race_rotates=b.outer_race_rotates))
                )
        return out

    def bearing_lines(self, input_hz: float, f_max_hz: float, harmonics: int = 2) -> list[KinematicLine]:
        """Each bearing's BPFO, BPFI, 2 BSF (a rolling element's defect strikes both races) and FTF with
        ``harmonics`` (1 or 2) harmonics in (0, ``f_max_hz``], the input shaft at ``input_hz``."""
        out = []
        for b, freqs in self.bearing_frequencies(input_hz):
            for symbol, f, first in (
                ("BPFO", freqs.bpfo_hz, 1),
                ("BPFI", freqs.bpfi_hz, 1),
                ("BSF", freqs.bsf_hz, 2),
                ("FTF", freqs.ftf_hz, 1),
            ):
                for k in (first, 2 * first)[:harmonics]:
                    if 0 < k * f <= f_max_hz:
                        label = f"{'' if k == 1 else f'{k} '}{symbol} {b.name}"
                        out.append(KinematicLine(k * f, label, "bearing", ((f"{symbol} {b.name}", k),)))
        return out


def _input_body(stages, speeds) -> str:
    first = stages[0]
    if first["type"] == "planetary":
        member = first.get("input") or "sun"
        return member if member in speeds else next(iter(speeds))
    return "pinion" if "pinion" in speeds else next(iter(speeds))


def _gears(stages, ratios):
    for k, st in enumerate(stages):
        if st["type"] == "parallel":
            for body, key in zip(gear_names(k), ("pinion_teeth", "wheel_teeth"), strict=True):
                if ratios.get(body):
                    yield GearShaft(body, int(st[key]), k)
        elif st["type"] == "planetary":
            p = stage_prefix(k)
            for member, key in (("sun", "sun_teeth"), ("carrier", "ring_teeth"), ("ring", "ring_teeth")):
                if ratios.get(p + member):
                    yield GearShaft(p + member, int(st[key]), k)


def _bearings(scenario, ratios):
    finder = getattr(scenario, "rolling_bearings", None)
    if finder is None:
        return
    from ..analysis.bearing_lines import BearingGeometry

    for spec in finder():
        if spec.geometry is None or spec.body not in ratios:
            continue
        g = spec.geometry
        geometry = BearingGeometry(g.balls, g.ball_diameter_m, g.pitch_diameter_m, g.contact_angle_deg)
        outer = getattr(spec, "body_race", "inner") == "outer"
        yield BearingLineSource(spec.name, spec.body, getattr(spec, "reference", "") or "", geometry, outer)
