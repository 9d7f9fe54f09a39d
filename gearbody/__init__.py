"""gearbody: gearbox vibration simulation for diagnostics, on the Exudyn multibody engine.

After W. Bartelmus, *Mathematical modelling and computer simulations as an aid to gearbox
diagnostics*, Mechanical Systems and Signal Processing 15(5), 2001.

The public API is this package's ``__all__``: :func:`load_scenario` and the scenario types,
:func:`simulate` (a :class:`Result`), :func:`modes` (a :class:`~gearbody.analysis.ModeSet`), the errors
(every one a :class:`GearbodyError`), and four namespaces with their own ``__all__``:
:mod:`gearbody.analysis` (engine-free signal analysis, simulated or measured), :mod:`gearbody.studies`
(parameter studies, sensitivity, calibration), :mod:`gearbody.render` (3D pictures and animations) and
:mod:`gearbody.extend` (what a new kind of stage needs, docs/extending.md).
Everything else is internal and may change. ``import gearbody`` stays light: the engine (Exudyn) and
the namespaces are imported when first used.
"""

import importlib
from typing import TYPE_CHECKING

from .errors import (
    CalibrationFailed,
    FolderInUse,
    GearbodyError,
    InputError,
    OutputError,
    ReferenceMismatch,
    RenderError,
    ScenarioError,
    SignalError,
    SimulationError,
    StageError,
    StudyError,
    StudySpecError,
)
from .model import (
    Bearing,
    Operation,
    RollingBearingSpec,
    RollingGeometry,
    Scenario,
    dump_scenario,
    four_periods,
    list_scenes,
    load_scenario,
    scenario_to_dict,
    steady,
)
from .physics.bearings import register_bearing
from .recording import Channel, Recording, Tacho
from .result import Result
from .version import __version__

if TYPE_CHECKING:  # what __getattr__ gives, for type checkers and editors
    from . import analysis, extend, render, studies
    from .diagnosis import DriveKinematics, analyze_recording
    from .diagnosis.virtual import virtual_recording
    from .engine import scene_modes as modes
    from .engine import simulate
    from .recording.files import read_recording, write_recording

_LAZY = {
    "simulate": ("gearbody.engine", "simulate"),
    "modes": ("gearbody.engine", "scene_modes"),
    "analysis": ("gearbody.analysis", None),
    "read_recording": ("gearbody.recording.files", "read_recording"),
    "write_recording": ("gearbody.recording.files", "write_recording"),
    "virtual_recording": ("gearbody.diagnosis.virtual", "virtual_recording"),
    "analyze_recording": ("gearbody.diagnosis", "analyze_recording"),
    "DriveKinematics": ("gearbody.diagnosis", "DriveKinematics"),
    "studies": ("gearbody.studies", None),
    "render": ("gearbody.render", None),
    "extend": ("gearbody.extend", None),
}
"""Public names imported on first use (the engine imports Exudyn; the namespaces take longer to import
than the rest of the package): name -> (module, its attribute, or None for the module itself)."""


def __getattr__(name: str):
    """``gearbody.simulate``, ``gearbody.modes`` and the namespaces, imported when first asked for."""
    try:
        module, attribute = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module 'gearbody' has no attribute {name!r}") from None
    found = importlib.import_module(module)
    return found if attribute is None else getattr(found, attribute)


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY})


__all__ = [
    "Bearing",
    "Channel",
    "DriveKinematics",
    "Recording",
    "Tacho",
    "analyze_recording",
    "read_recording",
    "write_recording",
    "virtual_recording",
    "CalibrationFailed",
    "FolderInUse",
    "GearbodyError",
    "InputError",
    "Operation",
    "OutputError",
    "ReferenceMismatch",
    "RenderError",
    "Result",
    "RollingBearingSpec",
    "RollingGeometry",
    "Scenario",
    "ScenarioError",
    "SignalError",
    "SimulationError",
    "StageError",
    "StudyError",
    "StudySpecError",
    "__version__",
    "analysis",
    "dump_scenario",
    "extend",
    "four_periods",
    "list_scenes",
    "load_scenario",
    "modes",
    "register_bearing",
    "render",
    "scenario_to_dict",
    "simulate",
    "steady",
    "studies",
]
