"""The force laws as C-callable kernels (numba ``cfunc``), for the compiled path: Exudyn calls them from
C++ with no Python (gearbody.engine.compiled_path). Engine-free.

Every kernel has one C signature, ``void kernel(double t, int64 n, const double *q, const double *q_t,
double *f, const double *P)``: ``q``, ``q_t`` the ``n`` coordinates of its force item, ``f`` the item's
forces, to which the kernel *adds* its own, and ``P`` its packed parameters, made by :func:`pack` from
the same arrays the Python path passes to the same compiled law, so both paths compute bit-identical
forces. An item's forces are the sum of its terms in order, from zero, as on the Python path.

A packed block ``P`` is ``[length, parts, (offset, rows, columns) per part, data...]`` (``columns`` 0: a
1-D part); :func:`part` and :func:`part2` read a part back as a view. Kernels are cached on disk by
numba (compiled once per machine and numba version), each on first use.
"""

from __future__ import annotations

import functools

import numpy as np
from numba import carray, cfunc

from .bearings import law_force_xy
from .lateral import lateral_mesh_forces
from .mesh import contact_force, single_mesh_drive_forces, torsional_mesh_forces
from .motor import load_fraction_at, load_torque_at, motor_torque_at, synchronous_angle_at
from .packing import KERNEL_SIGNATURE, block, pack, part, part2
from .planetary_mesh import stage_bearing_law_forces, stage_forces

__all__ = ["KERNEL_SIGNATURE", "KERNELS", "pack", "part", "part2"]

KERNELS: dict = {}
"""name -> the Python source of each kernel; ``kernels.<name>`` is its compiled ``cfunc``, compiled (or
loaded from numba's cache) on first use, so a run compiles only the kernels it calls."""


def _kernel(name: str):
    def register(fn):
        KERNELS[name] = fn
        return fn

    return register


@functools.cache
def _compiled(name: str):
    return cfunc(KERNEL_SIGNATURE, cache=True)(KERNELS[name])


def __getattr__(name: str):
    if name in KERNELS:
        return _compiled(name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


# --- kernels: (t, n, q, q_t, f, P) -------------------------------------------------------------------


@_kernel("motor_kernel")
def _motor(t, n, q, q_t, f, P):
    """P = pack(motor coordinate, drive parameters D): the motor torque."""
    B = block(P)
    i = int(part(B, 0)[0])
    f[i] += motor_torque_at(t, q_t[i], part(B, 1))


@_kernel("load_kernel")
def _load(t, n, q, q_t, f, P):
    """P = pack(load coordinate, D): minus the load torque."""
    B = block(P)
    i = int(part(B, 0)[0])
    f[i] -= load_torque_at(t, part(B, 1))


@_kernel("pair_mesh_kernel")
def _pair_mesh(t, n, q, q_t, f, P):
    """P = pack([pinion, wheel] coordinates, mesh law): a torsional mesh (eq. 1)."""
    B = block(P)
    at = part(B, 0)
    ip, iw = int(at[0]), int(at[1])
    a, b = torsional_mesh_forces(q[ip], q[iw], q_t[ip], q_t[iw], part(B, 1))
    f[ip] += a
    f[iw] += b


@_kernel("single_mesh_drive_kernel")
def _single_mesh_drive(t, n, q, q_t, f, P):
    """P = pack(mesh law, D): motor, pinion, wheel, load in one law (the one-stage drive)."""
    B = block(P)
    a, b, c, d = single_mesh_drive_forces(t, q_t[0], q[1], q[2], q_t[1], q_t[2], part(B, 0), part(B, 1))
    f[0] += a
    f[1] += b
    f[2] += c
    f[3] += d


@_kernel("lateral_mesh_kernel")
def _lateral_mesh(t, n, q, q_t, f, P):
    """P = pack(coordinate index, geometry, mesh law): a mesh where a gear translates, the index on the
    item's coordinates ([pinion rotation, x, y, wheel rotation, x, y], -1: none)."""
    B = block(P)
    index = part(B, 0).astype(np.int64)
    out = lateral_mesh_forces(carray(q, (n,)), carray(q_t, (n,)), index, part(B, 1), part(B, 2))
    for i in index:
        if i >= 0:
            f[i] += out[i]


@_kernel("bearing_law_kernel")
def _bearing_law(t, n, q, q_t, f, P):
    """P = pack([free x, free y, x coordinate, rotation sense], law row): a bearing law
    (:func:`gearbody.physics.bearings.law_force_xy`) on a gear's x and y, the directions with free 0 held,
    its rotation turning the inner race."""
    B = block(P)
    m = part(B, 0)
    mx, my, i, sense = m[0], m[1], int(m[2]), m[3]
    fx, fy = law_force_xy(
        part(B, 1), q[i] * mx, q[i + 1] * my, q_t[i] * mx, q_t[i + 1] * my, q[i + 2] * sense, 0.0
    )
    f[i] += fx * mx
    f[i + 1] += fy * my


@_kernel("muller_kernel")
def _muller(t, n, q, q_t, f, P):
    """P = pack(mesh law, D, [rated force, coordinate]): Muller's reduced mass (Fig. 1)."""
    B = block(P)
    Pm, D, c = part(B, 0), part(B, 1), part(B, 2)
    i = int(c[1])
    F = contact_force(synchronous_angle_at(t, D), q[i], q_t[i], Pm)[0]
    f[i] += c[0] * load_fraction_at(t, D) - F


@_kernel("planetary_stage_kernel")
def _planetary_stage(t, n, q, q_t, f, P):
    """P = pack([first, size], reference, geometry rows, sun law rows, ring law rows): a planetary
    stage's meshes and planet bearings on its coordinates (displacements from the reference)."""
    B = block(P)
    at = part(B, 0)
    a, size = int(at[0]), int(at[1])
    qa, qta = carray(q, (n,)), carray(q_t, (n,))
    out = stage_forces(
        qa[a : a + size] + part(B, 1), qta[a : a + size], part2(B, 2), part2(B, 3), part2(B, 4)
    )
    for i in range(size):
        f[a + i] += out[i]


@_kernel("planetary_laws_kernel")
def _planetary_laws(t, n, q, q_t, f, P):
    """P = pack([first, size, carrier radius], law rows, pin rows): a planetary stage's bearing laws
    (:func:`gearbody.physics.planetary_mesh.stage_bearing_law_forces`) on its coordinates."""
    B = block(P)
    at = part(B, 0)
    a, size = int(at[0]), int(at[1])
    qa, qta = carray(q, (n,)), carray(q_t, (n,))
    out = stage_bearing_law_forces(qa[a : a + size], qta[a : a + size], part2(B, 1), at[2], part2(B, 2))
    for i in range(size):
        f[a + i] += out[i]
