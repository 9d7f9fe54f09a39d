"""The one layout every drive is built from: bodies (each one Exudyn node and object) in coordinate order,
then items in the order the builder creates them (supports and constraints to the ground, shafts, separate
force items, constant-matrix items, the drive's one force item). Engine-free: the Exudyn builder
(:func:`gearbody.engine.build.build`) creates exactly what a :class:`SystemLayout` lists, and nothing else,
so a stage kind plugs in by listing its bodies and items (docs/extending.md).

Coordinates are numbered globally in body order; a body's coordinates are consecutive (a rotation or a
translation body has one, a planar body three: x, y, rotation). Items name coordinates (springs,
constraints) or bodies (matrix and force items, on all coordinates of those bodies in their order).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

__all__ = [
    "BearingItem",
    "Body",
    "Constraint",
    "DriveItem",
    "ForceItem",
    "MatrixItem",
    "MeshItem",
    "MullerItem",
    "PairMesh",
    "SliceTerm",
    "Spring",
    "SystemLayout",
    "TorqueItem",
]

BODY_SIZES = {"rotation": 1, "translation": 1, "planar": 3}


@dataclass(frozen=True)
class Body:
    """One node and its object: ``"rotation"`` (a 1D rotational mass, ``inertia_kg_m2``),
    ``"translation"`` (a 1D mass, ``mass_kg``) or ``"planar"`` (a planar rigid body: x, y, rotation)."""

    kind: str
    inertia_kg_m2: float = 0.0
    mass_kg: float = 0.0

    @property
    def size(self) -> int:
        return BODY_SIZES[self.kind]


@dataclass(frozen=True)
class Spring:
    """A coordinate spring-damper ``k (q_j - q_i) + C (q_j' - q_i')`` between coordinate ``i`` (None:
    the ground) and coordinate ``j``."""

    i: int | None
    j: int
    stiffness: float
    damping: float = 0.0


@dataclass(frozen=True)
class Constraint:
    """Coordinate ``j`` held at 0 (a ``CoordinateConstraint`` to the ground; in a modal layout the
    coordinate is listed as fixed instead)."""

    j: int


@dataclass(frozen=True)
class MatrixItem:
    """Constant stiffness (and damping) matrices on all coordinates of ``bodies``, in their order."""

    bodies: tuple[int, ...]
    stiffness: np.ndarray = field(repr=False)
    damping: np.ndarray | None = field(default=None, repr=False)


@dataclass(frozen=True)
class ForceItem:
    """A user-function force item on all coordinates of ``bodies``: ``factory(watchdog)`` returns the
    function Exudyn calls, ``f(mbs, t, item, q, q_t) -> forces`` on the item's coordinates."""

    bodies: tuple[int, ...]
    factory: Callable = field(repr=False)


@dataclass(frozen=True)
class MeshItem:
    """A gear mesh as its own force item on the pinion's and the wheel's body. Between two rotation
    bodies: the torsional law; with a planar body: the lateral law, ``geometry`` = line of action n,
    friction direction m and the free flags [pinion x, y, wheel x, y], ``index`` = positions in the item's
    coordinates of [pinion rotation, x, y, wheel rotation, x, y] (-1: none)."""

    bodies: tuple[int, int]
    parameters: np.ndarray = field(repr=False)
    geometry: np.ndarray | None = field(default=None, repr=False)
    index: np.ndarray | None = field(default=None, repr=False)


@dataclass(frozen=True)
class BearingItem:
    """A bearing law (``force_N(u, u')``, optionally ``force_xy``) between a planar body's centre and the
    ground, acting in ``free_directions`` (0 = x, 1 = y); a law that turns with the gear (``ROTATING``)
    gets its rotation times ``rotation_sense`` (+1: the coordinate turns counter-clockwise about +z) as
    the inner race's angle."""

    body: int
    law: object = field(repr=False)
    free_directions: tuple[int, ...] = (0, 1)
    rotation_sense: float = 1.0


@dataclass(frozen=True)
class TorqueItem:
    """The motor's (``"motor"``, with the run's watchdog) or the load's (``"load"``) torque as its own
    item on one rotation body, from the packed drive parameters."""

    body: int
    role: str
    drive: np.ndarray = field(repr=False)


@dataclass(frozen=True)
class MullerItem:
    """Muller's mesh on the reduced mass (Fig. 1): the rated force times the load fraction minus the
    contact force at the synchronous (kinematic) pinion angle."""

    body: int
    parameters: np.ndarray = field(repr=False)
    drive: np.ndarray = field(repr=False)
    rated_force_N: float


@dataclass(frozen=True)
class PairMesh:
    """A torsional mesh between two rotation coordinates (the compiled
    :func:`gearbody.physics.mesh.torsional_mesh_forces` with packed parameters ``parameters``)."""

    pinion: int
    wheel: int
    parameters: np.ndarray = field(repr=False)


@dataclass(frozen=True)
class SliceTerm:
    """Forces on the consecutive coordinates ``first .. first + size - 1``: ``forces(q, q_t)`` of those
    coordinates (numpy arrays) returns their generalised forces; ``factory()`` makes ``forces`` when the
    system is built (a layout is listed without compiling anything). A stage kind's laws enter the
    drive through it (compiled or plain Python); ``kernel()``, where given, returns the same forces as a
    C kernel and its parameters for the compiled path (docs/extending.md)."""

    first: int
    size: int
    factory: Callable = field(repr=False)  # factory() -> forces(q, q_t), made when the system is built
    # kernel() -> (numba cfunc, packed parameters) of the same forces for the compiled path
    # (gearbody.physics.kernels); None: the drive item runs on the Python path
    kernel: Callable | None = field(default=None, repr=False)


@dataclass(frozen=True)
class DriveItem:
    """The drive's one force item, on every body (one Python call per right-hand side): the motor torque
    at ``motor_at`` (and the run's watchdog), the load torque at ``load_at``, then every mesh and every
    slice term, added in that order."""

    motor_at: int
    load_at: int
    drive: np.ndarray = field(repr=False)
    meshes: tuple[PairMesh, ...] = ()
    terms: tuple[SliceTerm, ...] = ()

    def one_stage_mesh(self, coordinates: int) -> PairMesh | None:
        """The mesh of a one-stage drive (motor, pinion, wheel, load at coordinates 0-3 of ``coordinates``
        = 4, no slice terms), whose forces both force paths take from one fused law
        (:func:`gearbody.physics.mesh.single_mesh_drive_forces`); None for any other drive."""
        if self.terms or len(self.meshes) != 1 or coordinates != 4:
            return None
        m = self.meshes[0]
        return m if (self.motor_at, m.pinion, m.wheel, self.load_at) == (0, 1, 2, 3) else None


@dataclass(frozen=True)
class SystemLayout:
    """Coordinates, bodies and items of a drive (or of its linearised model, ``modal``)."""

    dof_names: tuple[str, ...]
    bodies: tuple[Body, ...]
    items: tuple = ()
    modal: bool = False

    def __post_init__(self) -> None:
        n = sum(b.size for b in self.bodies)
        if n != len(self.dof_names):
            raise ValueError(f"{len(self.dof_names)} coordinate names for {n} body coordinates")

    @property
    def first_coordinates(self) -> list[int]:
        """The index of each body's first coordinate."""
        out, i = [], 0
        for b in self.bodies:
            out.append(i)
            i += b.size
        return out

    def coordinates_of(self, bodies: tuple[int, ...]) -> list[int]:
        """Global coordinates of ``bodies`` in order: an item on ``bodies`` has them as its coordinates."""
        firsts = self.first_coordinates
        return [c for b in bodies for c in range(firsts[b], firsts[b] + self.bodies[b].size)]

    def body_of(self, coordinate: int) -> tuple[int, int]:
        """(body index, coordinate within the body) of a global coordinate."""
        for k, (first, b) in enumerate(zip(self.first_coordinates, self.bodies, strict=True)):
            if first <= coordinate < first + b.size:
                return k, coordinate - first
        raise IndexError(f"coordinate {coordinate} outside the layout's {len(self.dof_names)}")

    @property
    def masses(self) -> np.ndarray:
        """The diagonal of the mass matrix (kg for translations, kg m^2 for rotations)."""
        out = []
        for b in self.bodies:
            out += {"rotation": [b.inertia_kg_m2], "translation": [b.mass_kg]}.get(
                b.kind, [b.mass_kg, b.mass_kg, b.inertia_kg_m2]
            )
        return np.array(out, dtype=float)
