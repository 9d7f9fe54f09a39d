"""Kinematic lines of a drive: which frequency is which shaft order, mesh harmonic, sideband or
cross-modulation line.

A drive is described by its shafts (rotation frequencies) and gear meshes (mesh frequency and the two
shafts each mesh couples), :class:`KinematicSources`. :func:`kinematic_lines` turns that into a catalogue
of labelled frequencies, :class:`KinematicLine`. Engine-free.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from gearbody.analysis._validate import integer_at_least, positive_frequency

from ..errors import InputError

__all__ = [
    "Family",
    "GearMesh",
    "KinematicLine",
    "KinematicSources",
    "Shaft",
    "gear_train_lines",
    "kinematic_lines",
]


@dataclass(frozen=True)
class Shaft:
    """A rotating shaft: its lines are the orders m * rotation_hz."""

    name: str
    """Used in labels, e.g. "pinion" gives "1x pinion"."""
    rotation_hz: float
    """Rotation frequency [Hz]."""
    symbol: str = ""
    """Symbol in sideband labels; default "f_" + name with blanks as "_", e.g. "f_pinion"."""

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise InputError(f"Shaft name must be a non-empty string, got {self.name!r}")
        object.__setattr__(self, "rotation_hz", positive_frequency("Shaft rotation_hz", self.rotation_hz))
        if not self.symbol:
            object.__setattr__(self, "symbol", "f_" + "_".join(self.name.split()))


@dataclass(frozen=True)
class GearMesh:
    """A gear mesh: its lines are the harmonics k * mesh_hz, modulated by the rotation of both gears."""

    name: str
    """Its symbol in labels, e.g. "f_z1" gives "2 f_z1" and "f_z1 + f_pinion"."""
    mesh_hz: float
    """Mesh frequency = teeth * rotation frequency of either gear [Hz]."""
    shafts: tuple[str, str]
    """Names of the two shafts carrying the meshing gears (pinion's first)."""

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise InputError(f"GearMesh name must be a non-empty string, got {self.name!r}")
        object.__setattr__(self, "mesh_hz", positive_frequency("GearMesh mesh_hz", self.mesh_hz))
        shafts = tuple(self.shafts)
        if len(shafts) != 2 or shafts[0] == shafts[1]:
            raise InputError(f"GearMesh shafts must name two different shafts, got {self.shafts!r}")
        object.__setattr__(self, "shafts", shafts)


@dataclass(frozen=True)
class KinematicSources:
    """The drive's shafts and gear meshes, the sources of the kinematic lines in its spectra."""

    shafts: tuple[Shaft, ...]
    meshes: tuple[GearMesh, ...] = ()

    def __post_init__(self) -> None:
        shafts, meshes = tuple(self.shafts), tuple(self.meshes)
        object.__setattr__(self, "shafts", shafts)
        object.__setattr__(self, "meshes", meshes)
        if not shafts:
            raise InputError("shafts must hold at least one Shaft, got none")
        names = [s.name for s in shafts]
        if len(set(names)) < len(names):
            raise InputError(f"shafts must have distinct names, got {names}")
        symbols = [s.symbol for s in shafts] + [m.name for m in meshes]
        if len(set(symbols)) < len(symbols):
            raise InputError(f"shaft symbols and mesh names must be distinct, got {symbols}")
        for mesh in meshes:
            for shaft in mesh.shafts:
                if shaft not in names:
                    raise InputError(f"mesh {mesh.name!r}: shaft {shaft!r} is not one of the shafts {names}")

    def shaft(self, name: str) -> Shaft:
        """The shaft called ``name``."""
        for s in self.shafts:
            if s.name == name:
                return s
        raise InputError(f"name must be one of {[s.name for s in self.shafts]}, got {name!r}")

    @classmethod
    def gear_train(
        cls,
        input_hz: float,
        teeth: Sequence[tuple[int, int]],
        shaft_names: Sequence[str] | None = None,
    ) -> KinematicSources:
        """A train of parallel-axis stages from tooth numbers.

        Stage i has ``teeth[i] = (z_pinion, z_wheel)``; its pinion sits on shaft i, its wheel on shaft i + 1,
        so f_{i+1} = f_i z_pinion / z_wheel and the mesh "f_z{i+1}" runs at z_pinion f_i. Default shaft
        names: ("pinion", "wheel") for one stage, ("input", "intermediate", "output") for two,
        "shaft1", "shaft2", ... otherwise.
        """
        f = positive_frequency("input_hz", input_hz)
        stages = [tuple(t) for t in teeth]
        if not stages:
            raise InputError("teeth must hold at least one (z_pinion, z_wheel) pair, got none")
        for i, stage in enumerate(stages):
            if len(stage) != 2 or not all(
                isinstance(z, (int, np.integer)) and not isinstance(z, bool) and z >= 1 for z in stage
            ):
                raise InputError(
                    f"teeth[{i}] must be a pair of positive integers (z_pinion, z_wheel), got {stage}"
                )
        if shaft_names is None:
            defaults = {1: ("pinion", "wheel"), 2: ("input", "intermediate", "output")}
            shaft_names = defaults.get(len(stages), tuple(f"shaft{i + 1}" for i in range(len(stages) + 1)))
        shaft_names = tuple(shaft_names)
        if len(shaft_names) != len(stages) + 1:
            raise InputError(
                f"shaft_names must hold {len(stages) + 1} names (stages + 1), got {len(shaft_names)}"
            )
        shafts, meshes = [Shaft(shaft_names[0], f)], []
        for i, (z_pinion, z_wheel) in enumerate(stages):
            meshes.append(GearMesh(f"f_z{i + 1}", z_pinion * f, (shaft_names[i], shaft_names[i + 1])))
            f = f * z_pinion / z_wheel
            shafts.append(Shaft(shaft_names[i + 1], f))
        return cls(tuple(shafts), tuple(meshes))


Family = Literal["shaft", "mesh", "sideband", "cross"]


@dataclass(frozen=True)
class KinematicLine:
    """A labelled frequency where kinematics puts a spectral line."""

    frequency_hz: float
    """sum(order * frequency of its symbol) [Hz], > 0."""
    label: str
    """E.g. "2x wheel", "1 f_z1", "2 f_z1 - f_pinion", "f_z1 + f_z2"."""
    family: Family
    """"shaft" (shaft order), "mesh" (mesh harmonic), "sideband" (mesh harmonic +- shaft orders) or
    "cross" (harmonic of one mesh +- orders of another)."""
    orders: tuple[tuple[str, int], ...]
    """(symbol, integer order) terms, e.g. (("f_z1", 2), ("f_pinion", -1))."""


def _term(symbol: str, order: int, first: bool) -> str:
    size = abs(order)
    text = symbol if size == 1 else f"{size} {symbol}"
    if first:
        return text if order > 0 else f"-{text}"
    return f"{'+' if order > 0 else '-'} {text}"


def _combination_label(orders: tuple[tuple[str, int], ...]) -> str:
    """ "2 f_z1 - f_pinion": positive terms first, order 1 not written."""
    ordered = [t for t in orders if t[1] > 0] + [t for t in orders if t[1] < 0]
    return " ".join(_term(s, k, i == 0) for i, (s, k) in enumerate(ordered))


def kinematic_lines(
    sources: KinematicSources,
    f_max_hz: float,
    harmonics: int = 3,
    sidebands: int | Mapping[str, int] = 2,
    shaft_orders: int = 3,
) -> list[KinematicLine]:
    """Catalogue of kinematic lines in (0, f_max_hz], sorted by frequency.

    - "shaft": m f_shaft, m = 1 .. shaft_orders, labelled "1x pinion", "2x wheel", ...
    - "mesh": k f_z, k = 1 .. harmonics, labelled "1 f_z1", "2 f_z1", ...
    - "sideband": k f_z +- n f_shaft for both shafts of the mesh, n = 1 .. sidebands, labelled
      "f_z1 + 2 f_pinion", "2 f_z1 - f_wheel", ... ``sidebands`` may map shaft names to their own
      count (e.g. {"pinion": 14, "wheel": 3}: a pinion runout modulates the mesh far out, while a slow
      wheel's closely spaced orders would otherwise explain nearly any peak); shafts it omits get 0,
      cross lines the least count.
    - "cross": for every pair of meshes, k f_c +- n f_m with f_c the higher and f_m the lower mesh
      frequency, k = 1 .. harmonics, n = 1 .. sidebands, labelled "f_z1 - f_z2", ... A combination that
      comes out negative shows at its absolute value and is labelled accordingly ("2 f_z2 - f_z1").

    Lines of different origin may coincide (29 f_pinion is f_z1 for a 29-tooth pinion); all are kept.
    """
    if not isinstance(sources, KinematicSources):
        raise InputError(f"sources must be a KinematicSources, got {type(sources).__name__}")
    f_max_hz = positive_frequency("f_max_hz", f_max_hz)
    harmonics = integer_at_least("harmonics", harmonics, 1)
    if isinstance(sidebands, Mapping):
        names = [s.name for s in sources.shafts]
        for name in sidebands:
            if name not in names:
                raise InputError(f"sidebands names shaft {name!r}, not one of the shafts {names}")
        sideband_count = {n: integer_at_least(f"sidebands[{n!r}]", k, 0) for n, k in sidebands.items()}
        cross_sidebands = min(sideband_count.values(), default=0)
    else:
        cross_sidebands = integer_at_least("sidebands", sidebands, 0)
        sideband_count = {s.name: cross_sidebands for s in sources.shafts}
    shaft_orders = integer_at_least("shaft_orders", shaft_orders, 0)
    frequency = {s.symbol: s.rotation_hz for s in sources.shafts}
    frequency.update({m.name: m.mesh_hz for m in sources.meshes})
    limit = f_max_hz * (1.0 + 1e-12)
    tiny = 1e-9 * max(frequency.values())
    lines: list[KinematicLine] = []

    def add(family: Family, orders: tuple[tuple[str, int], ...], label: str = "") -> None:
        f = sum(k * frequency[s] for s, k in orders)
        if f < 0:
            f, orders = -f, tuple((s, -k) for s, k in orders)
        if tiny < f <= limit:
            lines.append(KinematicLine(float(f), label or _combination_label(orders), family, orders))

    for shaft in sources.shafts:
        for m in range(1, shaft_orders + 1):
            add("shaft", ((shaft.symbol, m),), f"{m}x {shaft.name}")
    for mesh in sources.meshes:
        for k in range(1, harmonics + 1):
            add("mesh", ((mesh.name, k),), f"{k} {mesh.name}")
            for shaft_name in mesh.shafts:
                symbol = sources.shaft(shaft_name).symbol
                for n in range(1, sideband_count.get(shaft_name, 0) + 1):
                    for sign in (1, -1):
                        add("sideband", ((mesh.name, k), (symbol, sign * n)))
    for i, first in enumerate(sources.meshes):
        for second in sources.meshes[i + 1 :]:
            carrier, modulation = (first, second) if first.mesh_hz >= second.mesh_hz else (second, first)
            for k in range(1, harmonics + 1):
                for n in range(1, cross_sidebands + 1):
                    for sign in (1, -1):
                        add("cross", ((carrier.name, k), (modulation.name, sign * n)))
    lines.sort(key=lambda line: line.frequency_hz)
    return lines


def gear_train_lines(
    input_hz: float,
    teeth: Sequence[tuple[int, int]],
    f_max_hz: float,
    harmonics: int = 6,
    sidebands: int = 3,
    shaft_orders: int = 30,
) -> list[KinematicLine]:
    """The lines a gear train's spectrum is labelled with, everywhere gearbody labels one
    (``Result.spectrum``, the report): ``harmonics`` mesh harmonics, ``shaft_orders`` shaft orders,
    sidebands of a pinion's rotation out to half way to the next harmonic (z_pinion // 2 orders, at least
    ``sidebands``) and of the other shafts ``sidebands`` orders (closely spaced: few, or they would
    explain nearly any peak). ``input_hz``: the first pinion's rotation frequency; ``teeth``: (z_pinion,
    z_wheel) of each stage in power-flow order."""
    sources = KinematicSources.gear_train(input_hz, list(teeth))
    counts = {shaft.name: sidebands for shaft in sources.shafts}
    for (z_pinion, _), mesh in zip(teeth, sources.meshes, strict=True):
        pinion = mesh.shafts[0]
        counts[pinion] = max(counts[pinion], z_pinion // 2)
    return kinematic_lines(
        sources, f_max_hz, harmonics=harmonics, sidebands=counts, shaft_orders=shaft_orders
    )
