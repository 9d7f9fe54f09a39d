"""The compiled path: Exudyn calls gearbody's force laws from C++, with no Python call per evaluation.

Exudyn fills a force user function through pybind11's ``std::function`` caster, which unwraps a stateless
C++ function exported by a pybind11 module with exactly Exudyn's function type. The extension
``gearbody.engine._force_entry`` (built by ``pip install``) exports such entries, one per slot; a slot
holds the item's terms, each a numba ``cfunc`` of :mod:`gearbody.physics.kernels` and its packed
parameters, so the laws are the same compiled functions the Python path calls, and the forces are
bit-identical. Every CHECK_CALLS-th evaluation of the watched item calls the run's watchdog, as on the
Python path.

At first use a probe solves a one-mass system through an entry and checks that C++ counted its calls while
none came through Python; if not (or the extension was not built), runs use the Python path, and gearbody
says so once. ``solver.force_path`` chooses: ``"auto"`` (compiled where it works), ``"compiled"`` (an
error where it does not), ``"python"``.
"""

from __future__ import annotations

import functools
import importlib
import warnings
import weakref
from dataclasses import dataclass, field

import numpy as np

from ..assembly.system import (
    BearingItem,
    DriveItem,
    ForceItem,
    MeshItem,
    MullerItem,
    SystemLayout,
    TorqueItem,
)
from ..errors import GearbodyError, InputError

__all__ = [
    "CompiledItem",
    "NotCompiled",
    "PerformanceWarning",
    "compiled_item",
    "compiled_path_status",
    "item_terms",
    "resolve_force_path",
]


class PerformanceWarning(UserWarning):
    """gearbody runs, but slower than it could (the compiled path is not available, or an item of the
    run has no compiled kernel)."""


ABI_VERSION = 1
"""The extension's interface (slots, assign, watch, ...) this module speaks: an extension of another
version is not used."""


@functools.cache
def _native():
    """(the extension module, "") or (None, the reason it is missing). A checkout first on the path (tests'
    subprocesses, ``python -m`` from the checkout root) has no built extension of its own: then the one
    ``pip install`` built for the installed gearbody is loaded, if it speaks this ABI_VERSION."""
    try:
        module = importlib.import_module("gearbody.engine._force_entry")
    except ImportError as exc:
        module, why = (
            _installed_extension(),
            f"the extension gearbody.engine._force_entry is not built ({exc})",
        )
        if module is None:
            return None, why
    if getattr(module, "ABI_VERSION", None) != ABI_VERSION:
        return None, (
            f"the extension {module.__file__} speaks interface {getattr(module, 'ABI_VERSION', 0)}, this "
            f"gearbody interface {ABI_VERSION}"
        )
    return module, ""


def _installed_extension():
    """The compiled extension of an installed gearbody further down ``sys.path`` (a plain install's
    site-packages), loaded from its file, or None."""
    import importlib.machinery
    import importlib.util
    import sys
    from pathlib import Path

    here = Path(__file__).resolve().parent
    for entry in sys.path:
        for suffix in importlib.machinery.EXTENSION_SUFFIXES:
            path = Path(entry or ".") / "gearbody" / "engine" / f"_force_entry{suffix}"
            if not path.is_file() or path.resolve().parent == here:
                continue
            spec = importlib.util.spec_from_file_location("gearbody.engine._force_entry", path)
            if spec is None or spec.loader is None:
                continue
            try:
                module = importlib.util.module_from_spec(spec)
                spec.loader.exec_module(module)
            except ImportError:
                continue
            sys.modules["gearbody.engine._force_entry"] = module
            return module
    return None


@functools.cache
def compiled_path_status() -> tuple[bool, str]:
    """(works, why not): whether Exudyn calls the compiled entries from C++ with no Python call (probed
    once per process)."""
    native, why = _native()
    if native is None:
        return False, why + "; reinstall gearbody with a C++ compiler (g++ or clang) to build it"
    try:
        calls, through_python = _probe(native)
    except Exception as exc:  # noqa: BLE001 - any failure of the probe means: use the Python path
        return False, f"the probe of the compiled path failed ({type(exc).__name__}: {exc})"
    if calls == 0 or through_python:
        return False, (
            f"Exudyn called the compiled entry through Python ({through_python} of {calls} calls): the "
            "extension and Exudyn do not share pybind11's function records (build gearbody against "
            "the pybind11 release line of the installed Exudyn)"
        )
    return True, ""


def _probe(native) -> tuple[int, int]:
    """(calls counted in C++, calls that came through Python) of a one-mass system on a load kernel."""
    import exudyn as exu
    from exudyn.itemInterface import Node1D, ObjectGenericODE2, ObjectMass1D

    from ..physics.kernels import load_kernel, pack

    D = np.zeros(16)  # a drive block whose load torque is 0: the probe only counts calls
    block = pack([0.0], D)
    slot = native.acquire()
    if slot < 0:
        raise RuntimeError("no free slot")
    try:
        native.assign(slot, 1, [load_kernel.address], [block.ctypes.data])
        before = native.python_calls()
        SC = exu.SystemContainer()
        mbs = SC.AddSystem()
        nd = mbs.AddNode(
            Node1D(referenceCoordinates=[0.0], initialCoordinates=[0.0], initialVelocities=[1.0])
        )
        mbs.AddObject(ObjectMass1D(nodeNumber=nd, mass=1.0))
        mbs.AddObject(
            ObjectGenericODE2(
                nodeNumbers=[nd], massMatrix=np.zeros((1, 1)), forceUserFunction=native.entries[slot]
            )
        )
        mbs.Assemble()
        s = exu.SimulationSettings()
        s.timeIntegration.endTime = 1e-3
        s.timeIntegration.numberOfSteps = 10
        s.timeIntegration.verboseMode = 0
        s.solution.file.write = False
        s.show.computationTime = False
        exu.SolveDynamic(mbs, s, solverType=exu.DynamicSolverType.DOPRI5, showHints=False)
        return int(native.calls(slot)), int(native.python_calls() - before)
    finally:
        native.release(slot)


_SAID: set[str] = set()


def say_once(message: str) -> None:
    """Warn (PerformanceWarning) once per process per message."""
    if message not in _SAID:
        _SAID.add(message)
        warnings.warn(message, PerformanceWarning, stacklevel=3)


def resolve_force_path(setting: str) -> str:
    """``"compiled"`` or ``"python"`` for ``solver.force_path`` = ``setting`` (auto: compiled where it
    works, else python, said once; compiled where it does not work: InputError with the reason)."""
    if setting == "python":
        return "python"
    works, why = compiled_path_status()
    if works:
        return "compiled"
    if setting == "compiled":
        raise InputError(
            f"solver.force_path = 'compiled' is not available here: {why}. Use 'auto' or 'python'"
        )
    say_once(f"gearbody runs its force laws through Python (slower): {why}")
    return "python"


@dataclass
class CompiledItem:
    """A force item on the compiled path: its slot (one exported entry) and the parameter blocks the
    kernels read (kept alive here); the slot is released when this object goes."""

    slot: int
    entry: object
    blocks: list[np.ndarray] = field(repr=False)
    kernels: list = field(repr=False)

    def calls(self) -> int:
        """Evaluations of this item so far, counted in C++."""
        native, _ = _native()
        return int(native.calls(self.slot))


class NotCompiled(GearbodyError):
    """An item (or one of its terms) has no compiled kernel; the message says which (caught by the builder,
    which then puts the item on the Python path)."""


def compiled_item(terms: list[tuple[object, np.ndarray]], size: int, watch=None) -> CompiledItem:
    """The compiled entry of one Exudyn item on ``size`` coordinates whose forces are ``terms`` (kernel,
    packed parameters), added in order (``watch``: ``(check, speed coordinate)`` of the run's watchdog)."""
    native, why = _native()
    if native is None:
        raise NotCompiled(why)
    slot = native.acquire()
    if slot < 0:
        raise NotCompiled(f"all {native.SLOTS} compiled slots of this process are in use")
    blocks = [np.ascontiguousarray(b, dtype=np.float64) for _, b in terms]
    native.assign(slot, size, [k.address for k, _ in terms], [b.ctypes.data for b in blocks])
    if watch is not None:
        from .user_functions import CHECK_CALLS

        check, speed_index = watch
        native.watch(slot, check, CHECK_CALLS, speed_index)
    out = CompiledItem(slot, native.entries[slot], blocks, [k for k, _ in terms])
    weakref.finalize(out, native.release, slot)
    return out


def item_terms(item, layout: SystemLayout) -> list[tuple[object, np.ndarray]]:
    """(kernel, packed parameters) of each term of a force item on the layout's global coordinates, in
    the order its Python function adds them. Raises :class:`NotCompiled` for an item without kernels."""
    from ..physics import kernels as K

    if _native()[0] is None:
        raise NotCompiled(_native()[1])
    if isinstance(item, DriveItem):  # on every body: its coordinates are the global ones
        return _drive_terms(item, len(layout.dof_names), K)
    if isinstance(item, ForceItem):
        raise NotCompiled("a ForceItem is a Python function")
    at = layout.coordinates_of(_item_bodies(item))
    if isinstance(item, MeshItem):
        if item.geometry is None:
            return [(K.pair_mesh_kernel, K.pack([float(at[0]), float(at[1])], item.parameters))]
        index = [float(at[i]) if i >= 0 else -1.0 for i in item.index]
        return [(K.lateral_mesh_kernel, K.pack(index, item.geometry, item.parameters))]
    if isinstance(item, BearingItem):
        mask = [float(d in item.free_directions) for d in (0, 1)]
        if hasattr(item.law, "law_row"):  # a shipped law, by its row
            at_sense = [*mask, float(at[0]), float(item.rotation_sense)]
            return [(K.bearing_law_kernel, K.pack(at_sense, item.law.law_row()))]
        raise NotCompiled(f"the bearing law {type(item.law).__name__} has no law_row() for the compiled path")
    if isinstance(item, TorqueItem):
        kernel = K.motor_kernel if item.role == "motor" else K.load_kernel
        return [(kernel, K.pack([float(at[0])], item.drive))]
    if isinstance(item, MullerItem):
        return [(K.muller_kernel, K.pack(item.parameters, item.drive, [item.rated_force_N, float(at[0])]))]
    raise TypeError(f"{type(item).__name__} is not an item of a SystemLayout")


def _item_bodies(item) -> tuple[int, ...]:
    return (item.body,) if isinstance(item, BearingItem | TorqueItem | MullerItem) else item.bodies


def _drive_terms(item: DriveItem, size: int, K) -> list:
    one_stage = item.one_stage_mesh(size)
    if one_stage is not None:
        return [(K.single_mesh_drive_kernel, K.pack(one_stage.parameters, item.drive))]
    terms = [
        (K.motor_kernel, K.pack([float(item.motor_at)], item.drive)),
        (K.load_kernel, K.pack([float(item.load_at)], item.drive)),
    ]
    terms += [
        (K.pair_mesh_kernel, K.pack([float(m.pinion), float(m.wheel)], m.parameters)) for m in item.meshes
    ]
    for term in item.terms:
        if term.kernel is None:
            raise NotCompiled(
                f"its term on coordinates {term.first}..{term.first + term.size - 1} has no compiled kernel"
            )
        terms.append(term.kernel())
    return terms
