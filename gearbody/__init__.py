"""gearbody: gearbox vibration simulation for diagnostics, on the Exudyn multibody engine.

After W. Bartelmus, *Mathematical modelling and computer simulations as an aid to gearbox
diagnostics*, Mechanical Systems and Signal Processing 15(5), 2001.
"""

from .errors import GearbodyError, InputError, ScenarioError, SimulationError  # noqa: E402
from .model import (  # noqa: E402
    Operation,
    Scenario,
    dump_scenario,
    four_periods,
    list_scenes,
    load_scenario,
    scenario_to_dict,
    steady,
)
from .result import Result  # noqa: E402
from .version import __version__


def simulate(scenario, *, progress: bool = False) -> Result:
    """Simulate a :class:`Scenario` (or a scene name / TOML path) on Exudyn; see :mod:`gearbody.engine`."""
    from .engine import simulate as _simulate

    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    return _simulate(scenario, progress=progress)


__all__ = [
    "GearbodyError",
    "InputError",
    "Operation",
    "Result",
    "Scenario",
    "ScenarioError",
    "SimulationError",
    "__version__",
    "dump_scenario",
    "four_periods",
    "list_scenes",
    "load_scenario",
    "scenario_to_dict",
    "simulate",
    "steady",
]
