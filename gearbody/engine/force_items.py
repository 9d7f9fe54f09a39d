"""A layout's force items as Exudyn user-function items, on either force path.

Exudyn's cost per force item and evaluation (its call, the coordinate vectors it copies) is the larger
part of a step once the laws are compiled, so the laws of a drive are ONE Exudyn item on all its bodies:
on the compiled path one C++ entry whose terms are every item's kernels in layout order (each adds into
the drive's force vector, on global coordinates); on the Python path one function that calls every item's
Python function in the same order and adds what it returns. The two paths therefore add the same numbers
in the same order: bit-identical runs. A drive with one force item (the torsional drives' DriveItem)
keeps that item as it is. A user's :class:`~gearbody.assembly.system.ForceItem` stays an item of its own;
on the compiled path an item without kernels goes through Python as an item of its own (said once).
"""

from __future__ import annotations

from collections.abc import Callable

from ..assembly.system import (
    BearingItem,
    DriveItem,
    ForceItem,
    MeshItem,
    MullerItem,
    SystemLayout,
    TorqueItem,
)
from .compiled_path import NotCompiled, compiled_item, item_terms, say_once
from .user_functions import (
    StallWatchdog,
    bearing_user_function,
    drive_user_function,
    lateral_mesh_user_function,
    load_user_function,
    mesh_user_function,
    motor_user_function,
    muller_user_function,
)

__all__ = ["FORCE_ITEMS", "force_functions"]

FORCE_ITEMS = (DriveItem, MeshItem, BearingItem, TorqueItem, MullerItem, ForceItem)

WHAT = {
    DriveItem: "the drive's force item",
    MeshItem: "a gear mesh",
    BearingItem: "a gear's bearing law",
    TorqueItem: "a motor or load torque",
    MullerItem: "Muller's mesh",
}


def force_functions(
    layout: SystemLayout, watchdog: StallWatchdog, compiled: bool
) -> list[tuple[tuple[int, ...], object]]:
    """(bodies, what Exudyn calls) of each Exudyn force item the layout's force items become, in order:
    a :class:`~gearbody.engine.compiled_path.CompiledItem` or a Python function."""
    items = [i for i in layout.items if isinstance(i, FORCE_ITEMS)]
    laws = [i for i in items if not isinstance(i, ForceItem)]
    out: list[tuple[tuple[int, ...], object]] = []
    every = tuple(range(len(layout.bodies)))
    n = len(layout.dof_names)
    if compiled:
        terms, python, watch = [], [], None
        for item in laws:
            try:
                terms += item_terms(item, layout)
            except NotCompiled as why:
                say_once(f"{WHAT[type(item)]} runs through Python (slower): {why}")
                python.append(item)
                continue
            watch = watch or _watched(item, layout, watchdog)
        if terms:
            out.append((every, compiled_item(terms, n, watch)))
        out += [_python_function(item, layout, watchdog) for item in python]
    elif len(laws) == 1:
        out.append(_python_function(laws[0], layout, watchdog))
    elif laws:
        parts = [_python_function(item, layout, watchdog) for item in laws]
        out.append((every, _summed(parts, layout)))
    out += [(item.bodies, item.factory(watchdog)) for item in items if isinstance(item, ForceItem)]
    return out


def _summed(parts: list[tuple[tuple[int, ...], Callable]], layout: SystemLayout) -> Callable:
    """One Python function on every coordinate adding the parts' forces in order (each part on the
    coordinates of its bodies)."""
    n = len(layout.dof_names)
    placed = [(layout.coordinates_of(part_bodies), fn) for part_bodies, fn in parts]

    def summed_forces(mbs, t, itemNumber, q, q_t):
        f = [0.0] * n
        for idx, fn in placed:
            out = fn(mbs, t, itemNumber, [q[i] for i in idx], [q_t[i] for i in idx])
            for k, i in enumerate(idx):
                f[i] += out[k]
        return f

    return summed_forces


def _python_function(item, layout: SystemLayout, watchdog: StallWatchdog) -> tuple[tuple[int, ...], Callable]:
    """(bodies, Python user function) of a force item."""
    if isinstance(item, DriveItem):
        return tuple(range(len(layout.bodies))), drive_user_function(item, len(layout.dof_names), watchdog)
    if isinstance(item, MeshItem):
        if item.geometry is None:
            return item.bodies, mesh_user_function(item.parameters)
        return item.bodies, lateral_mesh_user_function(item.parameters, item.geometry, item.index)
    if isinstance(item, BearingItem):
        return (item.body,), bearing_user_function(item.law, item.free_directions, item.rotation_sense)
    if isinstance(item, TorqueItem):
        if item.role == "motor":
            return (item.body,), motor_user_function(item.drive, watchdog)
        return (item.body,), load_user_function(item.drive)
    if isinstance(item, MullerItem):
        return (item.body,), muller_user_function(item, watchdog)
    raise TypeError(f"{type(item).__name__} is not a force item of a SystemLayout")


def _watched(item, layout: SystemLayout, watchdog: StallWatchdog):
    """(check, global speed coordinate) of the run's watchdog on the item that carries it, called every
    CHECK_CALLS evaluations as on the Python path; None for an item that carries none."""
    if isinstance(item, DriveItem):
        return watchdog.ticker()[1], item.motor_at
    if isinstance(item, MullerItem) or (isinstance(item, TorqueItem) and item.role == "motor"):
        return watchdog.ticker()[1], layout.first_coordinates[item.body]
    return None
