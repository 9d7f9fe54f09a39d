"""The machine-code entry point of a numba kernel, for callers that call it millions of times."""

from __future__ import annotations

import numba

__all__ = ["compiled"]


def compiled(dispatcher, *example_args):
    """The machine-code entry point of a numba function for the argument types of ``example_args``
    (compiled, or loaded from numba's cache, on first use): calling it skips numba's per-call type
    dispatch, ~0.15 of ~0.6 us per call of the drive's force law (benchmarks/RESULTS.md)."""
    dispatcher(*example_args)
    signature = tuple(numba.typeof(a) for a in example_args)
    return dispatcher.overloads[signature].entry_point
