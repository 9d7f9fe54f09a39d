"""Typed stage metadata of a run (``Result.meta["stages"]``): per stage, what its kind is and what a
:class:`~gearbody.result.Result` does with it (teeth, folding K_d over a mesh period, kinematic lines,
summary keys). A Result of any stage kind works through these, and a question a stage cannot answer (the
teeth of a planetary stage, the planets of a parallel one, any mesh of a kind without one) is refused in
one line naming the stage and what to ask instead.

Each entry reads like the dict it is saved as (``meta["stages"][1]["rated_mesh_force_N"]``), and
:meth:`StageMeta.to_dict` is exactly what ``save_npz`` writes, so saved runs read back unchanged. A kind
from outside gearbody needs no class here: its metadata dict becomes a :class:`KindStageMeta`, or it
registers a class of its own with :func:`register_stage_meta`.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar, NamedTuple

import numpy as np

from .errors import StageError
from .signals import stage_prefix

__all__ = [
    "KindStageMeta",
    "ParallelStageMeta",
    "PlanetaryStageMeta",
    "PlanetaryTeeth",
    "StageMeta",
    "register_stage_meta",
    "stage_meta",
]

PLANET_MESHES = ("sun", "ring")
"""The two meshes of every planet: with the sun and with the ring."""


class PlanetaryTeeth(NamedTuple):
    """Tooth counts of a planetary stage and its number of planets."""

    sun: int
    planet: int
    ring: int
    planets: int


@dataclass(frozen=True, eq=False)
class StageMeta(Mapping):
    """A stage of a run: its kind (``KIND``) and what the Result asks of it; the base refuses."""

    KIND: ClassVar[str] = ""
    FIELDS: ClassVar[tuple[str, ...]] = ()
    """The keys of the saved dict, in their order."""

    @property
    def kind(self) -> str:
        """The stage's type (``"parallel"``, ``"planetary"``, or a registered kind's name)."""
        return self.KIND

    # -- the saved form -----------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """The dict ``save_npz`` writes (and :func:`stage_meta` reads back): its fields but those a
        hand-made result left out (None)."""
        return {name: getattr(self, name) for name in self.FIELDS if getattr(self, name) is not None}

    def __getitem__(self, key: str) -> Any:
        return self.to_dict()[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self.to_dict())

    def __len__(self) -> int:
        return len(self.to_dict())

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.to_dict()!r})"

    # -- what a Result asks of a stage ----------------------------------------------------------------
    def _refuse(self, k: int, what: str, instead: str = "") -> StageError:
        return StageError(f"{what}: stage {k + 1} is a {self.kind} stage{'; ' + instead if instead else ''}")

    def teeth(self, k: int) -> tuple[int, int]:
        """(z_pinion, z_wheel) of a parallel stage."""
        raise self._refuse(k, f"Result.teeth({k})", "it has no pinion and wheel")

    def planetary_teeth(self, k: int) -> PlanetaryTeeth:
        """(sun, planet, ring, planets) of a planetary stage."""
        raise self._refuse(k, f"Result.planetary_teeth({k})", "it has no sun, planets and ring")

    def fold_kd(self, result, k: int, bins: int, window: np.ndarray, planet, mesh):
        """K_d folded over the stage's mesh period on ``window``."""
        raise self._refuse(k, f"Result.fold_kd({k})", "it has no mesh with a K_d")

    def missing_mesh_signal(self, name: str, suffix: str) -> None:
        """Called when the first stage lacks the plain mesh signal ``name``: a stage whose meshes carry
        other names says which (raises); the base lets the Result's own error name the signals."""

    def mesh_frequency_hz(self, result, k: int, fraction: float) -> float:
        """Its mean mesh frequency over the final ``fraction`` (0: a stage without a mesh)."""
        name = stage_prefix(k) + "mesh_frequency_hz"
        return float(np.mean(result[name][result.final_window(fraction)])) if name in result else 0.0

    def sensor_spectrum(self, result, k: int, name: str, min_prominence_db: float, max_peaks: int):
        """(spectrum, labelled peaks, f_max_hz) when ``name`` is a sensor of the stage's own with a
        spectrum of its own (a planetary stage's ring sensor), else None."""
        return None

    def mesh_signals(self, k: int) -> list[tuple[str, str]]:
        """(K_d, force) signal names of its meshes."""
        return []

    def gear_pair(self) -> tuple[int, int] | None:
        """(z1, z2) when the stage is a gear pair of a train (its lines are the train's), else None."""
        return None

    def stage_lines(self, result, k: int, f_max_hz: float, harmonics: int) -> list:
        """Kinematic lines of a stage that is no gear pair (its own sources); none by default."""
        return []

    @property
    def has_own_lines(self) -> bool:
        """True when the drive's spectrum is labelled stage by stage (a stage that is no gear pair)."""
        return self.gear_pair() is None

    def summary(self, result, k: int, window: np.ndarray) -> dict[str, Any]:
        """Its keys of a drive's summary (the first stage's K_d keys are the drive's own)."""
        return {}

    @property
    def has_kd_plots(self) -> bool:
        """True when the run plots draw its K_d over time and folded (one mesh: a parallel stage)."""
        return False


@dataclass(frozen=True, eq=False)
class ParallelStageMeta(StageMeta):
    """A pinion and a wheel: their teeth and the stage's rated mesh force."""

    KIND: ClassVar[str] = "parallel"
    FIELDS: ClassVar[tuple[str, ...]] = ("pinion_teeth", "wheel_teeth", "rated_mesh_force_N")
    pinion_teeth: int
    wheel_teeth: int
    rated_mesh_force_N: float

    def teeth(self, k: int) -> tuple[int, int]:
        return int(self.pinion_teeth), int(self.wheel_teeth)

    def planetary_teeth(self, k: int) -> PlanetaryTeeth:
        raise self._refuse(
            k, f"Result.planetary_teeth({k})", f"Result.teeth({k}) gives its pinion and wheel teeth"
        )

    def fold_kd(self, result, k: int, bins: int, window: np.ndarray, planet, mesh):
        from .analysis import fold_over_mesh_period

        if planet is not None or mesh is not None:
            raise StageError(
                f"Result.fold_kd({k}, planet={planet!r}, mesh={mesh!r}): stage {k + 1} is a parallel "
                "stage with one mesh; planet and mesh apply to planetary stages"
            )
        kd = result.stage_signal("kd", k)[window]
        angle = result.stage_signal("pinion_angle_rad", k)[window]
        return fold_over_mesh_period(kd, angle, self.teeth(k)[0], bins=bins)

    def gear_pair(self) -> tuple[int, int]:
        return self.teeth(0)

    def mesh_signals(self, k: int) -> list[tuple[str, str]]:
        return [(stage_prefix(k) + "kd", stage_prefix(k) + "mesh_force_N")]

    def summary(self, result, k: int, window: np.ndarray) -> dict[str, Any]:
        if k == 0:
            return {}
        prefix = stage_prefix(k)
        kd = result[prefix + "kd"]
        return {
            f"{prefix}kd_max": float(np.max(kd)),
            f"{prefix}kd_min": float(np.min(kd)),
            f"{prefix}kd_max_final": float(np.max(kd[window])),
            f"{prefix}kd_mean_final": float(np.mean(kd[window])),
        }

    @property
    def has_kd_plots(self) -> bool:
        return True


@dataclass(frozen=True, eq=False)
class PlanetaryStageMeta(StageMeta):
    """A planetary stage: teeth, planets and their angles, the members' roles, rated force per planet mesh."""

    KIND: ClassVar[str] = "planetary"
    FIELDS: ClassVar[tuple[str, ...]] = (
        "type",
        "sun_teeth",
        "planet_teeth",
        "ring_teeth",
        "planets",
        "planet_angles_deg",
        "input",
        "output",
        "fixed",
        "rated_mesh_force_N",
    )
    sun_teeth: int
    planet_teeth: int
    ring_teeth: int
    planets: int
    planet_angles_deg: list[float] | None = field(default=None, repr=False)
    input: str | None = None
    output: str | None = None
    fixed: str | None = None
    rated_mesh_force_N: float | None = None
    type: str = "planetary"

    def teeth(self, k: int) -> tuple[int, int]:
        raise StageError(
            f"Result.teeth({k}): stage {k + 1} is planetary (no pinion and wheel); "
            f"Result.planetary_teeth({k}) gives its sun, planet and ring teeth"
        )

    def planetary_teeth(self, k: int) -> PlanetaryTeeth:
        return PlanetaryTeeth(
            int(self.sun_teeth), int(self.planet_teeth), int(self.ring_teeth), int(self.planets)
        )

    def planet_mesh(self, k: int, planet: int | None, mesh: str | None) -> str:
        """``planet_<n>_<mesh>_mesh`` of this stage, checked (default planet 1, sun)."""
        n = int(self.planets)
        planet = 1 if planet is None else planet
        mesh = "sun" if mesh is None else mesh
        if isinstance(planet, bool) or not isinstance(planet, int | np.integer) or not 1 <= planet <= n:
            raise StageError(f"planet = {planet!r}: stage {k + 1} has planets 1..{n}")
        if mesh not in PLANET_MESHES:
            raise StageError(f"mesh = {mesh!r}: a planet of stage {k + 1} meshes with 'sun' or 'ring'")
        return f"planet_{planet}_{mesh}_mesh"

    def fold_kd(self, result, k: int, bins: int, window: np.ndarray, planet, mesh):
        from .analysis import fold_over_mesh_period

        name = self.planet_mesh(k, planet, mesh)
        phase = result.stage_signal(name + "_phase", k)[window]
        kd = result.stage_signal(name + "_kd", k)[window]
        return fold_over_mesh_period(kd, 2.0 * math.pi * phase, 1, bins=bins)

    def missing_mesh_signal(self, name: str, suffix: str) -> None:
        raise StageError(
            f"Result signal {name!r}: stage 1 is planetary, with one signal per planet mesh: "
            f"planet_<n>_sun_mesh_{suffix} and planet_<n>_ring_mesh_{suffix}, n = 1..{int(self.planets)}"
        )

    def stage_lines(self, result, k: int, f_max_hz: float, harmonics: int) -> list:
        from .analysis.planetary_lines import planetary_lines
        from .analysis.ring_sensor import planetary_sources

        return planetary_lines(planetary_sources(result, k), f_max_hz, harmonics=harmonics)

    def mesh_signals(self, k: int) -> list[tuple[str, str]]:
        p = stage_prefix(k)
        names = [f"{p}planet_{n + 1}_{m}_mesh" for n in range(int(self.planets)) for m in PLANET_MESHES]
        return [(name + "_kd", name + "_force_N") for name in names]

    def sensor_spectrum(self, result, k: int, name: str, min_prominence_db: float, max_peaks: int):
        if name != stage_prefix(k) + "ring_sensor_N":
            return None
        from .analysis.ring_sensor import ring_sensor_spectrum

        rs = ring_sensor_spectrum(result, k)
        return rs.spectrum, rs.peaks(min_prominence_db=min_prominence_db, max_peaks=max_peaks), rs.f_max_hz

    def summary(self, result, k: int, window: np.ndarray) -> dict[str, Any]:
        from .analysis import separation_stats

        prefix = stage_prefix(k)
        out: dict[str, Any] = {}
        for mesh in PLANET_MESHES:
            names = [f"{prefix}planet_{p + 1}_{mesh}_mesh" for p in range(int(self.planets))]
            kd = np.array([result[n + "_kd"] for n in names])
            means = kd[:, window].mean(axis=1)
            seps = [
                separation_stats(result[n + "_force_N"], result.time_s, kd=result[n + "_kd"]) for n in names
            ]
            out[f"{prefix}{mesh}_mesh_kd_max"] = float(kd.max())
            out[f"{prefix}{mesh}_mesh_kd_max_final"] = float(kd[:, window].max())
            out[f"{prefix}{mesh}_mesh_kd_min"] = float(kd.min())
            out[f"{prefix}{mesh}_mesh_kd_mean_final"] = float(means.mean())
            mean = means.mean()  # no load: no sharing to speak of (NaN)
            out[f"{prefix}{mesh}_mesh_load_sharing_factor"] = (
                float(means.max() / mean) if mean != 0.0 else float("nan")
            )
            out[f"{prefix}{mesh}_mesh_separation_fraction"] = float(max(s.separated_fraction for s in seps))
            out[f"{prefix}{mesh}_mesh_contact_losses"] = int(sum(s.contact_losses for s in seps))
        if k > 0:
            out[f"{prefix}mesh_frequency_hz"] = float(np.mean(result[prefix + "mesh_frequency_hz"][window]))
        out[f"{prefix}rated_mesh_force_N"] = float(self.rated_mesh_force_N)
        return out


@dataclass(frozen=True, eq=False)
class KindStageMeta(StageMeta):
    """A stage of a kind without a metadata class of its own: its saved dict, kept as it is."""

    data: dict[str, Any] = field(default_factory=dict)

    @property
    def kind(self) -> str:
        return str(self.data.get("type", ""))

    def to_dict(self) -> dict[str, Any]:
        return dict(self.data)


_META: dict[str, type[StageMeta]] = {"parallel": ParallelStageMeta, "planetary": PlanetaryStageMeta}


def register_stage_meta(cls: type[StageMeta]) -> None:
    """Use ``cls`` (a :class:`StageMeta` dataclass whose ``KIND`` is a stage type) for that type's stages."""
    _META[cls.KIND] = cls


def stage_meta(data: Mapping[str, Any]) -> StageMeta:
    """The typed metadata of a stage from its saved dict (``type`` absent: a parallel stage)."""
    if isinstance(data, StageMeta):
        return data
    cls = _META.get(str(data.get("type", "parallel")))
    if cls is None:
        return KindStageMeta(dict(data))
    return cls(**{name: data[name] for name in cls.FIELDS if name in data})
