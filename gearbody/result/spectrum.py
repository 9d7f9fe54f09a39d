"""The labelled spectrum of a run (:meth:`gearbody.result.Result.spectrum`): the amplitude spectrum of a
signal over the steady end of the run with its prominent peaks labelled by the drive's kinematic lines
(shaft orders, mesh harmonics, sidebands, cross-modulation; a planetary stage's own lines and
ring-sensor spectrum), composed here once for the report, the plots and ``Result.spectrum``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ..signals import SIGNAL_UNITS

if TYPE_CHECKING:
    from . import Result

__all__ = ["LabelledSpectrum", "compound_lines", "labelled_spectrum"]


@dataclass(frozen=True)
class LabelledSpectrum:
    """An amplitude spectrum with its prominent peaks labelled by the drive's kinematic lines."""

    signal: str
    spectrum: Any  # gearbody.analysis.Spectrum
    peaks: list
    f_max_hz: float

    def table(self, max_rows: int | None = 20) -> str:
        """The peaks as a text table (frequency, amplitude, labels)."""
        from ..analysis import peaks_table

        return peaks_table(self.peaks, max_rows=max_rows)

    def plot(self, ax=None, title: str | None = None):
        """The spectrum with its labelled peaks (matplotlib axes; a new figure when ``ax`` is None)."""
        from ..plotting.spectrum import plot_labelled_spectrum

        unit = next((u for suffix, u in SIGNAL_UNITS if self.signal.endswith(suffix)), "")
        return plot_labelled_spectrum(
            self.spectrum,
            self.peaks,
            ax=ax,
            title=title or f"spectrum of {self.signal}",
            unit=unit,
            f_max_hz=self.f_max_hz,
        )


def labelled_spectrum(
    result: Result,
    signal: str | None,
    fraction: float,
    harmonics: int,
    sidebands: int,
    min_prominence_db: float,
    max_peaks: int,
) -> LabelledSpectrum:
    """:meth:`Result.spectrum <gearbody.result.Result.spectrum>` of ``result`` (its docstring says what
    is labelled and how)."""
    from ..analysis import amplitude_spectrum, gear_train_lines, label_peaks

    name = signal or result.vibration_signal_name
    for k, st in enumerate(result.stages):  # a stage's own sensor (a planetary stage's ring sensor)
        own = st.sensor_spectrum(result, k, name, min_prominence_db, max_peaks)
        if own is not None:
            spectrum, peaks, f_max = own
            return LabelledSpectrum(signal=name, spectrum=spectrum, peaks=peaks, f_max_hz=f_max)
    win = result.final_window(fraction)
    spec = amplitude_spectrum(result[name][win], result.sample_rate_hz, window="hann")
    peaks = []
    f_max = result.sample_rate_hz / 2
    if result._gear_train:  # one train: its lines from the first mesh frequency and every pair's teeth
        f_top = result.mesh_frequency_hz(0, fraction)
    else:
        f_top = max(st.mesh_frequency_hz(result, k, fraction) for k, st in enumerate(result.stages))
    if f_top > 0:
        f_max = min(f_max, (harmonics + 0.5) * f_top)
        if result._gear_train:
            teeth = [st.gear_pair() for st in result.stages]
            lines = gear_train_lines(
                f_top / teeth[0][0], teeth, f_max, harmonics=harmonics, sidebands=sidebands
            )
        else:
            lines = compound_lines(result, fraction, f_max, harmonics, sidebands)
        peaks = label_peaks(
            spec,
            lines,
            tolerance_hz=1.5 * spec.resolution_hz,
            min_prominence_db=min_prominence_db,
            max_peaks=max_peaks,
            f_max_hz=f_max,
        )
    return LabelledSpectrum(signal=name, spectrum=spec, peaks=peaks, f_max_hz=f_max)


def compound_lines(result: Result, fraction: float, f_max: float, harmonics: int, sidebands: int) -> list:
    """Kinematic lines of a drive whose stages are not all gear pairs: each run of consecutive gear
    pairs as a gear train (shafts named after its pinions and wheels, meshes f_z<stage>), each other
    stage's own lines (a planetary stage's, docs/planetary-lines.md; labelled with their stage when
    the drive has several such stages)."""
    from dataclasses import replace

    from ..analysis import GearMesh, KinematicSources, Shaft, kinematic_lines

    lines: list = []
    shafts: list = []
    meshes: list = []

    def flush() -> None:
        if shafts:
            sources = KinematicSources(tuple(shafts), tuple(meshes))
            lines.extend(
                kinematic_lines(sources, f_max, harmonics=harmonics, sidebands=sidebands, shaft_orders=30)
            )
            shafts.clear()
            meshes.clear()

    several = sum(st.gear_pair() is None for st in result.stages) > 1
    for k, st in enumerate(result.stages):
        pair = st.gear_pair()
        if pair is None:
            flush()
            lines.extend(
                replace(line, label=f"{line.label} (stage {k + 1})") if several else line
                for line in st.stage_lines(result, k, f_max, harmonics)
            )
            continue
        z1, z2 = pair
        f_mesh = st.mesh_frequency_hz(result, k, fraction)
        if f_mesh <= 0:
            flush()
            continue
        tag = "" if k == 0 else f" {k + 1}"
        if not shafts:
            shafts.append(Shaft(f"pinion{tag}", f_mesh / z1))
        shafts.append(Shaft(f"wheel{tag}", f_mesh / z2))
        meshes.append(GearMesh(f"f_z{k + 1}", f_mesh, (shafts[-2].name, shafts[-1].name)))
    flush()
    return sorted(lines, key=lambda line: line.frequency_hz)
