"""The version of gearbody (its own module, so any layer can name it without importing the package)."""

__version__ = "0.1.0"
"""gearbody's version, recorded in every result's metadata and output folder."""
