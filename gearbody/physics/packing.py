"""The C signature of the compiled path's kernels and the packed parameter block they read (engine-free,
no kernel compiled here: :mod:`gearbody.physics.kernels` holds gearbody's own, docs/extending.md shows one
of a user's).

A kernel is ``void kernel(double t, int64 n, const double *q, const double *q_t, double *f, const double
*P)`` (:data:`KERNEL_SIGNATURE`, a numba ``cfunc``): it adds its forces on the ``n`` coordinates of its item
into ``f``. ``P`` is a block made by :func:`pack`: ``[length, parts, (offset, rows, columns) per part,
data...]`` (``columns`` 0: a 1-D part); in the kernel, ``block(P)`` is the block as an array and
:func:`part` / :func:`part2` read a part back as a view.
"""

from __future__ import annotations

import numpy as np
from numba import carray, njit, types

__all__ = ["KERNEL_SIGNATURE", "block", "pack", "part", "part2"]

_double_p = types.CPointer(types.float64)
KERNEL_SIGNATURE = types.void(types.float64, types.int64, _double_p, _double_p, _double_p, _double_p)
"""numba signature of a kernel: ``void(double t, int64 n, double *q, double *q_t, double *f, double *P)``,
for ``@numba.cfunc(KERNEL_SIGNATURE)``."""


def pack(*parts) -> np.ndarray:
    """One float64 block of ``parts`` (scalars, 1-D or 2-D arrays), in the layout :func:`part` reads."""
    arrays = [np.atleast_1d(np.asarray(p, dtype=np.float64)) for p in parts]
    header = 2 + 3 * len(arrays)
    out = [np.array([0.0, len(arrays)])]
    table, offset = [], header
    for a in arrays:
        if a.ndim > 2:
            raise ValueError(f"a packed part has at most 2 dimensions, not {a.ndim}")
        table += [offset, a.shape[0], a.shape[1] if a.ndim == 2 else 0]
        offset += a.size
    out.append(np.array(table, dtype=np.float64))
    out += [np.ascontiguousarray(a).ravel() for a in arrays]
    block = np.concatenate(out)
    block[0] = block.size
    return block


@njit(cache=True)
def part(P, i):
    """Part ``i`` of a packed block, 1-D view."""
    o, r, c = int(P[2 + 3 * i]), int(P[3 + 3 * i]), int(P[4 + 3 * i])
    return P[o : o + (r * c if c > 0 else r)]


@njit(cache=True)
def part2(P, i):
    """Part ``i`` of a packed block, 2-D view (a 1-D part as one row)."""
    o, r, c = int(P[2 + 3 * i]), int(P[3 + 3 * i]), int(P[4 + 3 * i])
    if c == 0:
        return P[o : o + r].reshape((1, r))
    return P[o : o + r * c].reshape((r, c))


@njit(cache=True)
def block(P):
    """The packed block at the C pointer ``P`` of a kernel, as an array (its length is its first entry)."""
    return carray(P, (int(P[0]),))
