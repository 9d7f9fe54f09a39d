"""Declarative model: scenario dataclasses (DPTOCC factors), validation, TOML input/output, scenes."""

from ..errors import ScenarioError
from .components import Bearing, Gear, Machine, Motor, RollingBearingSpec, RollingGeometry, Shaft
from .faults import DamagedTooth, Eccentricity, ErrorMode, PittedTooth
from .io import dump_scenario, load_scenario, parse_override, scenario_to_dict
from .mesh import Mesh, MeshGeometry
from .operation import Operation, Profile, four_periods, steady
from .scenario import TOPOLOGIES, Condition, Design, Meta, Scenario, Solver, Stage, Visual
from .scenes import list_scenes, scene_path

__all__ = [
    "TOPOLOGIES",
    "Bearing",
    "Condition",
    "DamagedTooth",
    "Design",
    "Eccentricity",
    "ErrorMode",
    "Gear",
    "Machine",
    "Mesh",
    "MeshGeometry",
    "Meta",
    "Motor",
    "Operation",
    "PittedTooth",
    "Profile",
    "RollingBearingSpec",
    "RollingGeometry",
    "Scenario",
    "ScenarioError",
    "Shaft",
    "Solver",
    "Stage",
    "Visual",
    "dump_scenario",
    "four_periods",
    "list_scenes",
    "load_scenario",
    "parse_override",
    "scenario_to_dict",
    "scene_path",
    "steady",
]
