"""What a new stage kind needs from gearbody, in one place (docs/extending.md): the registry of stage
kinds, the base of scenario dataclasses, the parts of a drive's system layout, the signal naming rule, and
the C signature and packed parameters of a compiled kernel (the compiled path).

A stage kind is its model dataclass (the keys of its ``[[design.stages]]`` table, ``type = "<name>"``)
and its hooks: its part of the drive's layout (coordinates, bodies, supports, force terms), its signals,
its metadata, ... (:class:`StageKind` lists them). Register it with :func:`register_stage_kind`; the
builder, the run and the Result then treat it like the built-in parallel and planetary stages, and what
it does not provide is refused in one line where it is needed.
"""

from __future__ import annotations

from .assembly.system import (
    Body,
    Constraint,
    ForceItem,
    MatrixItem,
    PairMesh,
    SliceTerm,
    Spring,
    SystemLayout,
)
from .model.kinds import StageKind, register_stage_kind, stage_kind, stage_kinds, unregister_stage_kind
from .model.params import Node, param
from .physics.packing import KERNEL_SIGNATURE, block, pack, part, part2
from .signals import gear_names, signal_unit, stage_prefix, stage_signal

__all__ = [
    "KERNEL_SIGNATURE",
    "Body",
    "Constraint",
    "ForceItem",
    "MatrixItem",
    "Node",
    "PairMesh",
    "SliceTerm",
    "Spring",
    "block",
    "StageKind",
    "SystemLayout",
    "gear_names",
    "pack",
    "param",
    "part",
    "part2",
    "register_stage_kind",
    "signal_unit",
    "stage_kind",
    "stage_kinds",
    "stage_prefix",
    "stage_signal",
    "unregister_stage_kind",
]
