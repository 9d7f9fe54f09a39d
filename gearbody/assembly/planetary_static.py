"""The static state of a planetary stage under given torques (:func:`stage_static_displacements`): the
steady start of a drive with planetary stages and the state at which the modes linearise its bearing
laws (docs/planetary.md, "Initial state"). Newton on the stage's exact force law, first on the loaded
flanks (no backlash dead zone) and, with bearing laws that have a clearance, with a weak spring that
closes their contacts, then on the true laws."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..physics.mesh import I_LU, I_MU
from ..physics.planetary_mesh import G_BEARING_K, G_DELTA0_RING, G_DELTA0_SUN, stage_forces
from .planetary_layout import CENTRAL
from .planetary_link import PlanetaryLink, bearing_law_forces, has_bearing_laws

__all__ = ["stage_static_displacements"]

MAX_NEWTON_ITERATIONS = 30
REGULARISING_N_PER_M = 1e7
LAW_NEWTON_ITERATIONS = 300
"""The weak spring of the static start's first pass on members that sit on bearing laws, N/m."""
STATIC_TOLERANCE = 1e-9
"""Largest residual force of the static start, relative to the stage's largest external torque (N or
N m per N m)."""


def stage_static_displacements(
    link: PlanetaryLink,
    input_torque_Nm: float,
    output_torque_Nm: float,
    input_angle_rad: float = 0.0,
    carrier_speed_rad_s: float = 0.0,
) -> np.ndarray:
    """Static equilibrium of a planetary stage (displacements from the nominal assembly) under the signed
    external torques on its input and output members and the planets' centrifugal forces m_p w_c^2
    (c_n - c_c) of a carrier turning at ``carrier_speed_rad_s``: exact deflections, the mesh laws at this
    state without damping or friction; the input rotation held at ``input_angle_rad`` (the gauge);
    Newton from the nominal assembly (docs/planetary.md, "Initial state")."""
    G_true = link.geometry_rows()
    Ps_true, Pr_true = (P.copy() for P in link.layout.mesh_arrays())
    Ps_true[..., I_MU] = Pr_true[..., I_MU] = 0.0  # the steady start ignores friction (as for trains)
    # Solved on the loaded flanks: the backlash moved into the assembly deflection (delta - l_u with no
    # clearance is the law's contact branch), so Newton starts from a law without a dead zone; the
    # result is then checked with the true law (every loaded mesh on its flank).
    G, Ps, Pr = G_true.copy(), Ps_true.copy(), Pr_true.copy()
    G[:, G_DELTA0_SUN] += Ps[..., I_LU]
    G[:, G_DELTA0_RING] += Pr[..., I_LU]
    Ps[..., I_LU] = Pr[..., I_LU] = 0.0
    problem = _StaticProblem.of(link, input_torque_Nm, output_torque_Nm, input_angle_rad, carrier_speed_rad_s)
    problem.G, problem.Ps, problem.Pr = G, Ps, Pr
    # A bearing law with a clearance carries nothing at the nominal assembly (its members then hang on
    # the meshes alone, the carrier on nothing): first solved with a weak spring (REGULARISING_N_PER_M)
    # on every translation of a member on a law, then without it from there (the bearings in contact).
    problem.spring = REGULARISING_N_PER_M if has_bearing_laws(link) else 0.0
    G_soft = G.copy()
    if link.layout.planet.bearing_law is not None:  # the planets' weak spring acts on their pins
        G_soft[:, G_BEARING_K] += REGULARISING_N_PER_M
    # the residual's scale: the torques, or with no load the planets' centrifugal forces
    scale = max(abs(input_torque_Nm), abs(output_torque_Nm), problem.w2 * link.layout.carrier_radius_m, 1.0)
    x = np.zeros(problem.free.size)
    if problem.spring:  # steps of at most a micrometre while the bearing contacts close
        problem.G = G_soft
        x = _newton(problem, x, scale, LAW_NEWTON_ITERATIONS, 1e-6)
        problem.G, problem.spring = G, 0.0
        x = _newton(problem, x, scale, LAW_NEWTON_ITERATIONS, 1e-6)
    x = _newton(problem, x, scale)
    problem.G, problem.Ps, problem.Pr = G_true, Ps_true, Pr_true
    # with the backlash: one step at most when every loaded mesh is on its flank
    x = _newton(problem, x, scale)
    r = problem.residual(x)
    if not np.max(np.abs(r)) <= STATIC_TOLERANCE * scale:
        raise InputError(
            f"operation.initial_state = 'steady': stage {link.stage + 1}: no static equilibrium of the "
            f"planetary stage found in {MAX_NEWTON_ITERATIONS} Newton steps (largest residual "
            f"{np.max(np.abs(r)):.3g} N or N m); start from rest"
        )
    return problem.displacements(x)


@dataclass
class _StaticProblem:
    """The residual of a planetary stage's static equilibrium in its free coordinates (all but the input
    rotation, the gauge, held at ``input_angle_rad``): the stage's laws (``G``, ``Ps``, ``Pr``, swapped
    between Newton passes), its supports, the external torques, the planets' centrifugal forces
    (``w2`` = m_p w_c^2) and a weak spring ``spring`` on the translations ``soft`` of members on
    bearing laws; ``zero``: the velocities (at rest)."""

    link: PlanetaryLink
    ref: np.ndarray
    gauge: int
    free: np.ndarray
    input_angle_rad: float
    torques: np.ndarray
    w2: float
    soft: np.ndarray
    zero: np.ndarray
    G: np.ndarray | None = None
    Ps: np.ndarray | None = None
    Pr: np.ndarray | None = None
    spring: float = 0.0

    @classmethod
    def of(
        cls,
        link: PlanetaryLink,
        input_torque_Nm: float,
        output_torque_Nm: float,
        input_angle_rad: float,
        carrier_speed_rad_s: float,
    ) -> _StaticProblem:
        """The problem of :func:`stage_static_displacements` (its laws and spring still to be set)."""
        gauge = 3 * CENTRAL.index(link.input) + 2
        torques = np.zeros(link.size)
        torques[3 * CENTRAL.index(link.input) + 2] += input_torque_Nm
        torques[3 * CENTRAL.index(link.output) + 2] += output_torque_Nm
        lay = link.layout
        soft = np.array(
            [3 * m + d for m, mem in enumerate(lay.members) if mem.bearing_law for d in (0, 1)], dtype=int
        )
        return cls(
            link,
            link.reference(),
            gauge,
            np.array([i for i in range(link.size) if i != gauge]),
            input_angle_rad,
            torques,
            lay.planet.mass_kg * carrier_speed_rad_s**2,
            soft,
            np.zeros(link.size),
        )

    def displacements(self, x: np.ndarray) -> np.ndarray:
        """The stage's displacements: ``x`` on the free coordinates, the gauge at its angle."""
        q = np.zeros(self.link.size)
        q[self.gauge] = self.input_angle_rad
        q[self.free] = x
        return q

    def residual(self, x: np.ndarray) -> np.ndarray:
        """The net forces on the free coordinates at ``x``."""
        q = self.displacements(x)
        f = (
            stage_forces(self.ref + q, self.zero, self.G, self.Ps, self.Pr)
            + _support_forces(self.link, q)
            + self.torques
        )
        c = self.ref + q
        f[9::3] += self.w2 * (c[9::3] - c[6])
        f[10::3] += self.w2 * (c[10::3] - c[7])
        f[self.soft] -= self.spring * q[self.soft]
        return f[self.free]


def _newton(
    problem: _StaticProblem,
    x: np.ndarray,
    scale: float,
    iterations: int = MAX_NEWTON_ITERATIONS,
    max_step_m: float = np.inf,
) -> np.ndarray:
    """Newton on ``problem`` from ``x`` until its residual is below STATIC_TOLERANCE * ``scale``, with a
    central-difference Jacobian (the laws are piecewise linear in the deflections, the geometry smooth):
    steps of 1e-9 m on centres and 1e-9 m / r_c on rotations, each Newton step at most ``max_step_m``."""
    free = problem.free
    r_c = problem.link.layout.carrier_radius_m
    steps = np.array([1e-9 if i % 3 < 2 else 1e-9 / r_c for i in free])
    r = problem.residual(x)
    for _ in range(iterations):
        if np.max(np.abs(r)) <= STATIC_TOLERANCE * scale:
            break
        J = np.empty((free.size, free.size))
        for j, h in enumerate(steps):
            e = np.zeros(free.size)
            e[j] = h
            J[:, j] = (problem.residual(x + e) - problem.residual(x - e)) / (2 * h)
        try:
            dx = np.linalg.solve(J, r)
        except np.linalg.LinAlgError:  # a member free in the backlash (no load): any equilibrium will do
            dx = np.linalg.lstsq(J, r, rcond=None)[0]
        longest = np.max(np.abs(dx / steps)) * 1e-9  # in m (rotations times r_c)
        x = x - dx * min(1.0, max_step_m / longest)
        r = problem.residual(x)
    return x


def _support_forces(link: PlanetaryLink, q_rel: np.ndarray) -> np.ndarray:
    """Central members' bearings and the fixed member's torsional support (elastic part) on the stage's
    coordinates (displacements from the nominal assembly)."""
    f = np.zeros(link.size)
    for m, member in enumerate(link.layout.members):
        o = 3 * m
        f[o : o + 2] -= member.bearing_stiffness_N_per_m * q_rel[o : o + 2]
        if member.torsion_stiffness_Nm_per_rad is not None:
            f[o + 2] -= member.torsion_stiffness_Nm_per_rad * q_rel[o + 2]
    if has_bearing_laws(link):
        f += bearing_law_forces(link, q_rel, np.zeros(link.size))
    return f
