"""Result of a simulation: named time signals on a fixed output grid, plus metadata.

Signals carry their unit in their name (``mesh_force_N``, ``pinion_speed_rad_s``). The metadata holds
the resolved scenario, the seed, gearbody and Exudyn versions, the output rate and solver statistics,
so a saved result says where it came from. The package: :class:`Result` here, its labelled spectrum in
:mod:`gearbody.result.spectrum`, its summary.json values in :mod:`gearbody.result.summary`.
"""

from __future__ import annotations

import json
import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SignalError, StageError
from ..signals import SIGNAL_UNITS, gear_names, stage_signal
from ..stage_meta import PLANET_MESHES, PlanetaryTeeth, StageMeta, stage_meta
from .spectrum import LabelledSpectrum

FINAL_FRACTION = 0.25
"""Share of the run, at its end, over which 'final' values are taken (the steady period)."""

__all__ = ["FINAL_FRACTION", "PLANET_MESHES", "LabelledSpectrum", "PlanetaryTeeth", "Result", "SIGNAL_UNITS"]


@dataclass
class Result:
    """A run: named time signals on the output grid ``time_s`` (``result["mesh_force_N"]``; units in the
    names) and ``meta`` (the resolved scenario, versions, seed, solver statistics, per-stage data), with
    the analyses of a run as methods (``kd``, ``fold_kd``, ``spectrum``, ``features``, ``summary``);
    ``save_npz`` writes it, :meth:`load_npz` reads it back."""

    time_s: np.ndarray
    signals: dict[str, np.ndarray]
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.meta.get("stages"):  # typed stage metadata (a saved run's dicts read back as such)
            self.meta["stages"] = [stage_meta(st) for st in self.meta["stages"]]

    @property
    def stages(self) -> tuple[StageMeta, ...]:
        """The typed metadata of every stage (:mod:`gearbody.stage_meta`), in power-flow order."""
        return tuple(self.meta.get("stages") or ())

    def __getitem__(self, name: str) -> np.ndarray:
        if name == "time_s":
            return self.time_s
        try:
            return self.signals[name]
        except KeyError:
            raise SignalError(f"no signal {name!r}; signals: {', '.join(sorted(self.signals))}") from None

    def __contains__(self, name: str) -> bool:
        return name == "time_s" or name in self.signals

    @property
    def names(self) -> list[str]:
        return ["time_s", *self.signals]

    # Short aliases the paper's reader expects.
    @property
    def time(self) -> np.ndarray:
        return self.time_s

    @property
    def mesh_force(self) -> np.ndarray:
        """The first stage's mesh force [N] (a planetary first stage has one per planet mesh)."""
        return self._first_mesh_signal("mesh_force_N", "force_N")

    @property
    def kd(self) -> np.ndarray:
        """The first stage's dynamic factor K_d [-] (a planetary first stage has one per planet mesh)."""
        return self._first_mesh_signal("kd", "kd")

    def _first_mesh_signal(self, name: str, planet_suffix: str) -> np.ndarray:
        if name not in self.signals and self.stages:
            self.stages[0].missing_mesh_signal(name, planet_suffix)  # names the stage's own signals
        return self[name]

    @property
    def sample_rate_hz(self) -> float:
        return float(self.meta["output_rate_hz"])

    # -- what the run was: scene, stages, teeth --------------------------------------------------
    @property
    def name(self) -> str:
        """The scene's name (``meta.name`` of the scenario)."""
        return str(self.meta.get("scene", ""))

    @property
    def n_stages(self) -> int:
        return len(self.meta.get("stages") or [None])

    @property
    def stage_names(self) -> list[str]:
        """``stage 1``, ``stage 2``, ... in power-flow order."""
        return [f"stage {k + 1}" for k in range(self.n_stages)]

    def stage_kind(self, stage: int = 0) -> str:
        """The type of stage ``stage`` (0-based): ``"parallel"`` (a pinion and a wheel), ``"planetary"``
        (sun, planets, ring, carrier), or a registered kind's name."""
        return self._stage(stage).kind

    def teeth(self, stage: int = 0) -> tuple[int, int]:
        """(z_pinion, z_wheel) of parallel stage ``stage`` (0-based); any other stage refuses, a planetary
        one naming :meth:`planetary_teeth`."""
        return self._stage(stage).teeth(stage)

    def planetary_teeth(self, stage: int = 0) -> PlanetaryTeeth:
        """(sun, planet, ring, planets): tooth counts and number of planets of planetary stage ``stage``
        (0-based); any other stage refuses, a parallel one naming :meth:`teeth`."""
        return self._stage(stage).planetary_teeth(stage)

    def stage_signal(self, name: str, stage: int = 0) -> np.ndarray:
        """Signal ``name`` of stage ``stage``: ``kd`` of stage 2 is ``stage_2_kd``, its pinion angle
        ``pinion_2_angle_rad``; a planetary stage 2's ``planet_1_sun_mesh_kd`` is
        ``stage_2_planet_1_sun_mesh_kd``."""
        self._stage(stage)
        if stage == 0:
            return self[name]
        for gear, named in zip(("pinion", "wheel"), gear_names(stage), strict=True):
            if name.startswith(gear + "_"):
                return self[f"{named}_{name[len(gear) + 1 :]}"]
        return self[stage_signal(name, stage)]

    FINAL_FRACTION = FINAL_FRACTION

    def final_window(self, fraction: float = FINAL_FRACTION) -> np.ndarray:
        """Boolean mask of the last ``fraction`` of the simulated time (the steady period of a run)."""
        if not 0 < fraction <= 1:
            raise ValueError(f"fraction = {fraction}: must be > 0 and <= 1")
        t = self.time_s
        return t >= t[-1] - fraction * (t[-1] - t[0])

    def mesh_frequency_hz(self, stage: int = 0, fraction: float = 0.25) -> float:
        """Mean mesh frequency of stage ``stage`` over the final ``fraction`` of the run (a stage without a
        mesh refuses)."""
        if stage_signal("mesh_frequency_hz", stage) not in self and stage != 0:
            self._stage(stage)
            raise StageError(
                f"Result.mesh_frequency_hz({stage}): stage {stage + 1} ({self.stage_kind(stage)}) has no mesh"
            )
        return float(np.mean(self.stage_signal("mesh_frequency_hz", stage)[self.final_window(fraction)]))

    # -- what a diagnostician looks at ------------------------------------------------------------
    def fold_kd(
        self,
        stage: int = 0,
        bins: int = 100,
        fraction: float = 0.25,
        *,
        planet: int | None = None,
        mesh: str | None = None,
    ):
        """K_d of stage ``stage`` folded over its mesh period (the paper's Figs. 5-8) over the final
        ``fraction`` of the run. A parallel stage: from the computed pinion angle. A planetary stage: the
        K_d of planet ``planet`` (1..N, default 1) in its ``mesh`` (``"sun"``, default, or ``"ring"``)
        over that mesh's phase as its law computed it (one period per sun or ring tooth)."""
        return self._stage(stage).fold_kd(self, stage, bins, self.final_window(fraction), planet, mesh)

    def spectrum(
        self,
        signal: str | None = None,
        fraction: float = FINAL_FRACTION,
        harmonics: int = 6,
        sidebands: int = 3,
        min_prominence_db: float = 12.0,
        max_peaks: int = 40,
    ):
        """Labelled amplitude spectrum of ``signal`` (default: the vibration signal of the report) over the
        final ``fraction`` of the run: a :class:`LabelledSpectrum` with the spectrum and its peaks, each
        labelled by the drive's shaft orders, mesh harmonics, sidebands and cross-modulation lines
        (:func:`gearbody.analysis.gear_train_lines`). The report and the run's spectrum plot show this
        spectrum, so a run is labelled the same everywhere. A
        planetary stage's ring sensor is read as in its run plot and report: order-tracked over the whole
        carrier revolutions of the run's steady part (``fraction`` does not apply), the lines the phasing
        rule cancels marked "(cancelled)" (docs/planetary-lines.md)."""
        from .spectrum import labelled_spectrum

        return labelled_spectrum(self, signal, fraction, harmonics, sidebands, min_prominence_db, max_peaks)

    @property
    def _gear_train(self) -> bool:
        """True when every stage is a gear pair of one train (its spectrum is labelled as a gear train)."""
        return all(st.gear_pair() is not None for st in self.stages)

    @property
    def vibration_signal_name(self) -> str:
        """The signal a sensor on the housing would read: the housing acceleration at the first lateral
        gear's bearing, otherwise the pinion's angular acceleration (Muller: the deflection's); a drive
        whose first stage is planetary: the ring-fixed sensor of that stage (``ring_sensor_N``)."""
        for name in ("pinion_housing_accel_y_m_s2", "wheel_housing_accel_y_m_s2"):
            if name in self and f"{name.split('_housing')[0]}_y_m" in self:
                return name
        if "pinion_accel_rad_s2" in self:
            return "pinion_accel_rad_s2"
        return "ring_sensor_N" if "ring_sensor_N" in self else "deflection_accel_m_s2"

    @property
    def bearing_gears(self) -> list[str]:
        """Names of the gears with bearing-force signals (gears on lateral bearings)."""
        return sorted({k.split("_bearing_force_")[0] for k in self.signals if "_bearing_force_" in k})

    def summary(self) -> dict[str, Any]:
        """What a diagnostician reads first (the values of summary.json): K_d over the run and over its
        final quarter (the steady, rated-load period of the four-period runs), separation, mesh frequency,
        speed, solver statistics and bearing forces; whole-run values say so by having no '_final'. Last,
        ``sources``: where the scene's parameter values come from (``meta.sources``)."""
        from .summary import run_summary

        return run_summary(self)

    def rotation_directions(self):
        """Which way each rotation turned (:class:`gearbody.analysis.RotationDirections`): its smallest
        speed in its driven direction and, if it turned backwards, since when (an overrunning load)."""
        from ..analysis import rotation_directions

        nominal = self.meta.get("nominal_speeds_rad_s") or {}
        speeds = {name: self[f"{name}_speed_rad_s"] for name in nominal if f"{name}_speed_rad_s" in self}
        return rotation_directions(self.time_s, speeds, nominal)

    @property
    def planetary_stages(self) -> list[int]:
        """Indices of the planetary stages (0-based)."""
        return [k for k, st in enumerate(self.stages) if st.kind == "planetary"]

    def period_boundaries_s(self) -> tuple[float, ...]:
        """The run's operating periods: its start, every breakpoint of the speed and load profiles inside
        the run, its end [s] (the four-period runs: 0, run-up end, load start, load rated, t_end)."""
        from ..analysis.features import operating_periods_s

        operation = self.meta.get("scenario", {}).get("operation", {})
        times = [
            t
            for profile in ("speed_profile", "load_profile")
            for t in operation.get(profile, {}).get("time_s", ())
        ]
        return operating_periods_s(float(self.time_s[0]), float(self.time_s[-1]), times)

    def record(self, natural_frequencies_hz=()):
        """The run as an :class:`~gearbody.analysis.features.Record` for features (``natural_frequencies_hz``:
        from ``gearbody.engine.natural_frequencies`` or measured, for the natural-frequency features)."""
        from ..analysis.features import Record

        if self.stages:
            teeth = self.stages[0].gear_pair() or (None, None)
        else:  # a result put together by hand: the teeth its metadata gives
            teeth = (self.meta.get("pinion_teeth"), self.meta.get("wheel_teeth"))
        return Record(
            time_s=self.time_s,
            signals=self.signals,
            pinion_teeth=teeth[0],
            wheel_teeth=teeth[1],
            period_boundaries_s=self.period_boundaries_s(),
            natural_frequencies_hz=tuple(float(f) for f in natural_frequencies_hz),
            meta={"scenario": self.meta.get("scenario"), "vibration_signal": self.vibration_signal_name}
            if self.meta.get("scenario")
            else {},
        )

    def features(self, specs, natural_frequencies_hz=()) -> dict[str, float]:
        """``{spec: value}`` of the named features (gearbody.analysis.features), e.g.
        ``result.features(["kd_max:period=4", "line_amplitude:signal=pinion_accel_rad_s2,mesh=1"])``."""
        from ..analysis.features import evaluate_features

        return evaluate_features(specs, self.record(natural_frequencies_hz))

    def to_recording(self, channels=None, *, tacho_shaft: str = "pinion", pulses_per_rev: int = 1):
        """The run as a :class:`gearbody.recording.Recording` (the container of measured signals):
        ``channels`` (default every signal) in their units, the exact shaft angles as encoder channels,
        and a virtual tacho of ``pulses_per_rev`` pulses per revolution of ``tacho_shaft``."""
        from ..recording.from_run import recording_from_run

        return recording_from_run(
            self.time_s,
            self.signals,
            self.meta,
            channels=channels,
            tacho_shaft=tacho_shaft,
            pulses_per_rev=pulses_per_rev,
            vibration_signal=self.vibration_signal_name,
        )

    def plot(self, out_dir: str | Path, marks=()) -> list[Path]:
        """The run's standard PNGs in ``out_dir``: per parallel stage K_d over time and folded over the
        mesh period, the spectrum of the vibration signal (``marks``, lines with ``frequency_hz`` and
        ``label`` such as bearing defect frequencies, drawn on it), bearing forces
        (gearbody.plotting.run); per planetary stage its planet meshes' K_d, load sharing and ring-sensor
        spectrum (gearbody.plotting.planetary)."""
        from ..plotting.run import write_plots

        Path(out_dir).mkdir(parents=True, exist_ok=True)
        paths = write_plots(self, out_dir, marks)
        if self.planetary_stages:
            from ..plotting.planetary import write_planetary_plots

            paths += write_planetary_plots(self, out_dir, marks)
        return paths

    def _stage(self, stage: int) -> StageMeta:
        stages = self.stages
        if isinstance(stage, bool) or not isinstance(stage, int | np.integer) or not 0 <= stage < len(stages):
            raise StageError(
                f"stage = {stage!r}: the result has {len(stages)} stage(s), 0..{len(stages) - 1} (0-based)"
            )
        return stages[stage]

    def save_npz(self, path: str | Path) -> Path:
        """Named arrays (``time`` and ``time_s``, every signal) plus the metadata as JSON in ``meta_json``."""
        path = Path(path)
        arrays = {"time": self.time_s, "time_s": self.time_s, **self.signals}
        arrays["meta_json"] = np.array(json.dumps(self.meta, default=_jsonable))
        # np.savez_compressed's format at zlib level 1: 1 % larger, half the time (0.27 -> 0.14 s, 2 s run)
        with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED, compresslevel=1) as archive:
            for name, value in arrays.items():
                with archive.open(f"{name}.npy", "w", force_zip64=True) as member:
                    np.lib.format.write_array(member, np.asanyarray(value), allow_pickle=False)
        return path

    @classmethod
    def load_npz(cls, path: str | Path) -> Result:
        with np.load(path, allow_pickle=False) as data:
            meta = json.loads(str(data["meta_json"])) if "meta_json" in data else {}
            signals = {k: data[k] for k in data.files if k not in ("time", "time_s", "meta_json")}
            return cls(time_s=data["time_s"], signals=signals, meta=meta)


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, StageMeta):
        return obj.to_dict()
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")
