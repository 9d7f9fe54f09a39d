"""Declarative model: scenario dataclasses (DPTOCC factors), validation and TOML input/output."""

from .io import dump_scenario, load_scenario, parse_override, scenario_to_dict
from .params import ScenarioError
from .scenario import (
    SCENES,
    Condition,
    DamagedTooth,
    Design,
    ErrorMode,
    Gear,
    Machine,
    Mesh,
    Meta,
    Motor,
    Operation,
    Production,
    Profile,
    Scenario,
    Shaft,
    Solver,
    Stage,
)

__all__ = [
    "SCENES",
    "Condition",
    "DamagedTooth",
    "Design",
    "ErrorMode",
    "Gear",
    "Machine",
    "Mesh",
    "Meta",
    "Motor",
    "Operation",
    "Production",
    "Profile",
    "Scenario",
    "ScenarioError",
    "Shaft",
    "Stage",
    "Solver",
    "dump_scenario",
    "load_scenario",
    "parse_override",
    "scenario_to_dict",
]
