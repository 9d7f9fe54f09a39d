"""One error hierarchy for gearbody: every failure a user can meet is a :class:`GearbodyError`, and the
command line maps its type to an exit code (never its message text).

This module imports nothing from gearbody, so every layer may use it (physics included: its
:class:`~gearbody.physics.exceptions.GearGeometryError` is an :class:`InputError`, which the model wraps
into a :class:`ScenarioError` naming the scenario key). ``tests/test_errors_hierarchy.py`` checks that
every exception class defined in gearbody is a :class:`GearbodyError`.
"""

from __future__ import annotations


class GearbodyError(Exception):
    """Base of every gearbody error; ``exit_code`` is what the command line returns for it."""

    exit_code = 1


class InputError(GearbodyError, ValueError):
    """Bad input found before anything runs (exit code 2): the message names the key, value and range."""

    exit_code = 2


class ScenarioError(InputError):
    """Invalid scenario input; the message names file, key, value and allowed range."""


class StageError(InputError, LookupError):
    """A stage that does not exist, or a question that does not apply to the stage's kind (the pinion of
    a planetary stage, the planets of a parallel one); the message names the stage and what applies
    (exit code 2)."""


class SignalError(InputError, KeyError):
    """A signal a result does not hold; the message names it and the signals there are (a KeyError, so
    mapping-style lookups keep working; exit code 2)."""

    __str__ = Exception.__str__  # the message as given, not KeyError's quoted repr


class SimulationError(GearbodyError, RuntimeError):
    """Numerical failure of a run (exit code 3): the message names the simulated time and a hint."""

    exit_code = 3


class RenderError(InputError):
    """A picture or animation cannot be made from the given options or result (exit code 2)."""


class FolderInUse(InputError):
    """Another gearbody command is writing in the output folder (exit code 2): the message names its
    command and pid (:mod:`gearbody.folders`)."""


class OutputError(GearbodyError, OSError):
    """A file could not be written (a full disk, a lost permission; exit code 1): the message names it.
    Nothing half-written is left under its name (:func:`gearbody.folders.atomic_write`). Also an
    ``OSError`` with the original ``errno``."""

    exit_code = 1


class StudyError(GearbodyError):
    """A parameter study cannot run as specified (its specification or its store)."""

    exit_code = 2


class StudySpecError(StudyError, InputError):
    """A study specification (--vary, --random, --cases) is invalid (exit code 2)."""


class CalibrationFailed(GearbodyError):
    """Every evaluation of a calibration failed; all are recorded (exit code 1)."""

    exit_code = 1


class ReferenceMismatch(GearbodyError):
    """gearbody and the independent reference disagree beyond the validation tolerance (exit code 1)."""

    exit_code = 1


__all__ = [
    "CalibrationFailed",
    "FolderInUse",
    "GearbodyError",
    "InputError",
    "OutputError",
    "ReferenceMismatch",
    "RenderError",
    "ScenarioError",
    "SignalError",
    "SimulationError",
    "StageError",
    "StudyError",
    "StudySpecError",
]
