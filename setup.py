"""Builds the compiled path's extension (gearbody.engine._force_entry); pyproject.toml holds the rest.

The extension is optional: without a C++ compiler the build skips it and gearbody runs its force laws
through Python (it says so once). pybind11 comes from the build requirements, pinned to the release line
of the installed Exudyn (its function records must match Exudyn's: gearbody.engine.compiled_path).
"""

from pybind11.setup_helpers import Pybind11Extension
from setuptools import setup

setup(
    ext_modules=[
        Pybind11Extension(
            "gearbody.engine._force_entry",
            ["gearbody/engine/_force_entry.cpp"],
            cxx_std=17,
            optional=True,
        )
    ]
)
