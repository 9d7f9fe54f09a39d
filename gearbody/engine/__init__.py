"""The only package that imports Exudyn: build the multibody system, solve it, linearise it."""

from .modes import ModeSet, natural_frequencies, scene_modes
from .simulate import SimulationError, build, simulate

__all__ = ["ModeSet", "SimulationError", "build", "natural_frequencies", "scene_modes", "simulate"]
