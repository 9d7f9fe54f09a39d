"""The force laws as C-callable kernels (numba ``cfunc``), for the compiled path: Exudyn calls them from
C++ with no Python (gearbody.engine.compiled_path). Engine-free.

Every kernel has one C signature, ``void kernel(double t, int64 n, const double *q, const double *q_t,
double *f, const double *P)``: ``q``, ``q_t`` the ``n`` coordinates of its force item, ``f`` the item's
forces, to which the kernel *adds* its own, and ``P`` its packed parameters, made by :func:`pack` from
the same arrays the Python path passes to the same compiled law, so both paths compute bit-identical
forces. An item's forces are the sum of its terms in order, from zero, as on the Python path.

A packed block ``P`` is ``[length, parts, (offset, rows, columns) per part, data...]`` (``columns`` 0: a
1-D part); :func:`part` and :func:`part2` read a part back as a view. Kernels are cached on disk by
numba (compiled once per machine and numba version).
"""

from __future__ import annotations

import numpy as np
from numba import carray, cfunc

from .bearings import law_force_xy
from .lateral import lateral_mesh_forces
from .mesh import contact_force, single_mesh_drive_forces, torsional_mesh_forces
from .motor import load_fraction_at, load_torque_at, motor_torque_at, synchronous_angle_at
from .packing import KERNEL_SIGNATURE, block, pack, part, part2
from .planetary_mesh import stage_bearing_law_forces, stage_forces

__all__ = ["KERNEL_SIGNATURE", "pack", "part", "part2"]

# --- kernels: (t, n, q, q_t, f, P) -------------------------------------------------------------------


@cfunc(KERNEL_SIGNATURE, cache=True)
def motor_kernel(t, n, q, q_t, f, P):
    """P = pack(motor coordinate, drive parameters D): the motor torque."""
    B = block(P)
    i = int(part(B, 0)[0])
    f[i] += motor_torque_at(t, q_t[i], part(B, 1))


@cfunc(KERNEL_SIGNATURE, cache=True)
def load_kernel(t, n, q, q_t, f, P):
    """P = pack(load coordinate, D): minus the load torque."""
    B = block(P)
    i = int(part(B, 0)[0])
    f[i] -= load_torque_at(t, part(B, 1))


@cfunc(KERNEL_SIGNATURE, cache=True)
def pair_mesh_kernel(t, n, q, q_t, f, P):
    """P = pack([pinion, wheel] coordinates, mesh law): a torsional mesh (eq. 1)."""
    B = block(P)
    at = part(B, 0)
    ip, iw = int(at[0]), int(at[1])
    a, b = torsional_mesh_forces(q[ip], q[iw], q_t[ip], q_t[iw], part(B, 1))
    f[ip] += a
    f[iw] += b


@cfunc(KERNEL_SIGNATURE, cache=True)
def single_mesh_drive_kernel(t, n, q, q_t, f, P):
    """P = pack(mesh law, D): motor, pinion, wheel, load in one law (the one-stage drive)."""
    B = block(P)
    a, b, c, d = single_mesh_drive_forces(t, q_t[0], q[1], q[2], q_t[1], q_t[2], part(B, 0), part(B, 1))
    f[0] += a
    f[1] += b
    f[2] += c
    f[3] += d


@cfunc(KERNEL_SIGNATURE, cache=True)
def lateral_mesh_kernel(t, n, q, q_t, f, P):
    """P = pack(coordinate index, geometry, mesh law): a mesh where a gear translates."""
    B = block(P)
    out = lateral_mesh_forces(
        carray(q, (n,)), carray(q_t, (n,)), part(B, 0).astype(np.int64), part(B, 1), part(B, 2)
    )
    for i in range(n):
        f[i] += out[i]


@cfunc(KERNEL_SIGNATURE, cache=True)
def bearing_law_kernel(t, n, q, q_t, f, P):
    """P = pack([free x, free y], law row): a bearing law (:func:`gearbody.physics.bearings.law_force_xy`)
    on a gear's [x, y, rotation], the directions with free 0 held."""
    B = block(P)
    m = part(B, 0)
    mx, my = m[0], m[1]
    fx, fy = law_force_xy(part(B, 1), q[0] * mx, q[1] * my, q_t[0] * mx, q_t[1] * my)
    f[0] += fx * mx
    f[1] += fy * my


@cfunc(KERNEL_SIGNATURE, cache=True)
def muller_kernel(t, n, q, q_t, f, P):
    """P = pack(mesh law, D, rated force): Muller's reduced mass (Fig. 1)."""
    B = block(P)
    Pm, D = part(B, 0), part(B, 1)
    F = contact_force(synchronous_angle_at(t, D), q[0], q_t[0], Pm)[0]
    f[0] += part(B, 2)[0] * load_fraction_at(t, D) - F


@cfunc(KERNEL_SIGNATURE, cache=True)
def planetary_stage_kernel(t, n, q, q_t, f, P):
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


@cfunc(KERNEL_SIGNATURE, cache=True)
def planetary_laws_kernel(t, n, q, q_t, f, P):
    """P = pack([first, size, carrier radius], law rows, pin rows): a planetary stage's bearing laws
    (:func:`gearbody.physics.planetary_mesh.stage_bearing_law_forces`) on its coordinates."""
    B = block(P)
    at = part(B, 0)
    a, size = int(at[0]), int(at[1])
    qa, qta = carray(q, (n,)), carray(q_t, (n,))
    out = stage_bearing_law_forces(qa[a : a + size], qta[a : a + size], part2(B, 1), at[2], part2(B, 2))
    for i in range(size):
        f[a + i] += out[i]
