"""Every error a user can meet is a GearbodyError (issue 27): each exception class defined anywhere in
gearbody derives from :class:`gearbody.errors.GearbodyError`, so ``except gearbody.GearbodyError`` catches
whatever gearbody raises on purpose, and the command line maps it to its exit code."""

import importlib
import inspect
import pkgutil

import gearbody
from gearbody.errors import GearbodyError

NOT_ERRORS = {
    "gearbody.studies.runner.StudyInterrupted": "the user's Ctrl-C during a study: a KeyboardInterrupt "
    "(BaseException), so that no `except Exception` in between swallows it",
    "gearbody.engine.compiled_path.PerformanceWarning": "a warning (gearbody runs, slower: the Python path), "
    "issued with warnings.warn, never raised",
}
"""Exception classes that are deliberately no GearbodyError, with the reason."""


def _exception_classes() -> dict[str, type]:
    found = {}
    for info in pkgutil.walk_packages(gearbody.__path__, "gearbody."):
        if info.name.endswith(".__main__"):  # the command line's entry point runs when imported
            continue
        module = importlib.import_module(info.name)
        for name, obj in vars(module).items():
            if inspect.isclass(obj) and issubclass(obj, BaseException) and obj.__module__ == module.__name__:
                found[f"{module.__name__}.{name}"] = obj
    return found


def test_every_exception_class_of_gearbody_is_a_gearbody_error():
    classes = _exception_classes()
    assert len(classes) >= 20 and set(NOT_ERRORS) <= set(classes)
    outside = sorted(
        n for n, c in classes.items() if n not in NOT_ERRORS and not issubclass(c, GearbodyError)
    )
    assert not outside, outside


def test_the_physics_errors_stay_value_errors_and_are_input_errors():
    from gearbody.errors import InputError
    from gearbody.physics.exceptions import GearGeometryError
    from gearbody.physics.planetary import PlanetaryGeometryError
    from gearbody.physics.planetary_modal import PlanetaryModalError

    for cls in (GearGeometryError, PlanetaryGeometryError, PlanetaryModalError):
        assert issubclass(cls, InputError) and issubclass(cls, ValueError) and cls.exit_code == 2


def test_the_analysis_namespace_refuses_bad_arguments_with_input_errors():
    """What a user calls in gearbody.analysis refuses a bad argument with an InputError (still a
    ValueError): no bare ValueError is raised there."""
    import re
    from pathlib import Path

    import gearbody
    from gearbody.analysis import amplitude_spectrum
    from gearbody.errors import InputError

    folder = Path(gearbody.__file__).parent / "analysis"
    bare = [
        f"{p.name}:{n}"
        for p in sorted(folder.glob("*.py"))
        for n, line in enumerate(p.read_text().splitlines(), 1)
        if re.search(r"raise ValueError\(", line)
    ]
    assert bare == []
    import numpy as np
    import pytest

    with pytest.raises(InputError):
        amplitude_spectrum(np.zeros(8), -1.0)
