"""Linear planar model of a planetary stage at mean mesh stiffness and its natural modes (Lin & Parker,
"Analytical characterization of the unique properties of planetary gear free vibration", J. Vib. Acoust.
121:316-321, 1999; Lin's thesis, Ohio State 2000). Engine-free; numpy/scipy only.

Coordinates (3 per member, 3 (N + 3) in all, in this order): carrier, ring, sun, planets 1..N; each
``(x, y, u)`` in the frame turning with the carrier (x towards planet 1), ``u = r theta`` the rotation
times the member's base radius (the carrier's: the planet-centre radius). The planets' translations are
``(zeta_n, eta_n)``, radial and tangential at their position angle ``psi_n``. Mesh deflections along the
lines of action (``psi_sn = psi_n - alpha_s``, ``psi_rn = psi_n + alpha_r``):

- sun-planet ``d_sn = -x_s sin psi_sn + y_s cos psi_sn - zeta_n sin alpha_s - eta_n cos alpha_s + u_s + u_n``
- ring-planet ``d_rn = -x_r sin psi_rn + y_r cos psi_rn + zeta_n sin alpha_r - eta_n cos alpha_r + u_r - u_n``
- carrier-planet bearing (isotropic ``k_p``) radial ``x_c cos psi_n + y_c sin psi_n - zeta_n`` and
  tangential ``-x_c sin psi_n + y_c cos psi_n + u_c - eta_n``;

central members sit on isotropic bearings ``k_h`` (x, y) and torsional supports ``k_hu`` (on u, N/m,
i.e. ``k_theta / r^2``). Mass matrix ``diag(m, m, I / r^2)`` per member. K is assembled from the closed-form
blocks of Lin & Parker 1999, eq. (2)-(6) (the same blocks as ``Lin_Parker_99.m``,
``stage_stiffness_matrix``, of the public MATLAB code gfsReboucas/Drivetrain, which served to check the
sign conventions). Gyroscopic and centripetal terms are left out, as in the paper's free-vibration
analysis; frequencies come from ``scipy.linalg.eigh(K, M)``.

Mode classes (Lin & Parker 1999, theorems for equally spaced planets), read from the central members'
share of each eigenspace's kinetic energy: ``planet`` (central members at rest, multiplicity N - 3),
``rotational`` (central members only rotate, simple), ``translational`` (central members only translate,
degenerate pairs), ``mixed`` (none of these: unequally spaced planets).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..errors import InputError

__all__ = [
    "MODE_KINDS",
    "ModeGroup",
    "PlanetaryModalParameters",
    "PlanetaryModalError",
    "PlanetaryModes",
    "lin_parker_1999_parameters",
    "mass_matrix",
    "natural_modes",
    "stiffness_matrix",
]

MODE_KINDS = ("rotational", "translational", "planet", "mixed")
CENTRAL = ("carrier", "ring", "sun")
DEGENERACY_RTOL = 1e-6  # eigenvalues within this relative distance form one eigenspace
ZERO_RTOL = 1e-10  # eigenvalues below this share of the largest are rigid-body modes (0 Hz)
MOTION_TOL = 1e-8  # energy share below which a motion is taken as absent


class PlanetaryModalError(InputError):
    """Unsound parameters of the planetary modal model (message: parameter, value, allowed range)."""


@dataclasses.dataclass(frozen=True)
class PlanetaryModalParameters:
    """Lumped parameters of a planetary stage (Lin & Parker 1999, Table 1 for the names).

    Equivalent rotary masses are ``I / r^2`` with r the base radius (carrier: planet-centre radius);
    torsional supports act on ``u = r theta`` (``k_theta / r^2``, N/m). Planet angles in the carrier frame,
    counterclockwise, planet 1 at 0.
    """

    carrier_mass_kg: float
    ring_mass_kg: float
    sun_mass_kg: float
    planet_mass_kg: float
    carrier_rotary_mass_kg: float
    ring_rotary_mass_kg: float
    sun_rotary_mass_kg: float
    planet_rotary_mass_kg: float
    carrier_bearing_N_per_m: float
    ring_bearing_N_per_m: float
    sun_bearing_N_per_m: float
    planet_bearing_N_per_m: float
    carrier_torsion_N_per_m: float
    ring_torsion_N_per_m: float
    sun_torsion_N_per_m: float
    sun_mesh_N_per_m: float
    ring_mesh_N_per_m: float
    sun_pressure_angle_rad: float
    ring_pressure_angle_rad: float
    planet_angles_rad: tuple[float, ...]

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.name == "planet_angles_rad":
                continue
            if f.name.endswith("_kg") and not (math.isfinite(value) and value > 0.0):
                raise PlanetaryModalError(f"{f.name} = {value!r}: a mass must be positive; allowed: > 0 kg")
            if f.name.endswith("_N_per_m") and not (math.isfinite(value) and value >= 0.0):
                raise PlanetaryModalError(
                    f"{f.name} = {value!r}: a stiffness must be finite and not negative; allowed: >= 0 N/m"
                )
            if f.name.endswith("_rad") and not 0.0 < value < math.pi / 2:
                raise PlanetaryModalError(
                    f"{f.name} = {value!r}: pressure angle; allowed: > 0 and < pi/2 rad"
                )
        angles = tuple(float(a) for a in self.planet_angles_rad)
        if not angles or not all(math.isfinite(a) for a in angles):
            raise PlanetaryModalError(
                f"planet_angles_rad = {self.planet_angles_rad!r}: no planet or an angle not finite; "
                "allowed: one finite angle per planet, at least one"
            )
        object.__setattr__(self, "planet_angles_rad", angles)

    @property
    def n_planets(self) -> int:
        return len(self.planet_angles_rad)

    @property
    def n_dof(self) -> int:
        return 3 * (self.n_planets + 3)


def lin_parker_1999_parameters(
    n_planets: int, planet_angles_rad: tuple[float, ...] | None = None
) -> PlanetaryModalParameters:
    """The example of Lin & Parker 1999, Table 1 (docs/planetary.md; docs/references.md): masses
    carrier/ring/sun/planet 5.43/2.35/0.4/0.66 kg, I/r^2 6.29/3.00/0.39/0.61 kg, meshes 5e8 N/m, all
    bearings 1e8 N/m, ring torsion 1e9 N/m (sun and carrier free), pressure angles 24.6 deg; planets
    equally spaced unless angles are given."""
    if isinstance(n_planets, bool) or not isinstance(n_planets, int) or n_planets < 1:
        raise PlanetaryModalError(
            f"n_planets = {n_planets!r}: whole number of planets; allowed: integer >= 1"
        )
    if planet_angles_rad is None:
        planet_angles_rad = tuple(2.0 * math.pi * k / n_planets for k in range(n_planets))
    alpha = math.radians(24.6)
    return PlanetaryModalParameters(
        carrier_mass_kg=5.43,
        ring_mass_kg=2.35,
        sun_mass_kg=0.4,
        planet_mass_kg=0.66,
        carrier_rotary_mass_kg=6.29,
        ring_rotary_mass_kg=3.00,
        sun_rotary_mass_kg=0.39,
        planet_rotary_mass_kg=0.61,
        carrier_bearing_N_per_m=1e8,
        ring_bearing_N_per_m=1e8,
        sun_bearing_N_per_m=1e8,
        planet_bearing_N_per_m=1e8,
        carrier_torsion_N_per_m=0.0,
        ring_torsion_N_per_m=1e9,
        sun_torsion_N_per_m=0.0,
        sun_mesh_N_per_m=5e8,
        ring_mesh_N_per_m=5e8,
        sun_pressure_angle_rad=alpha,
        ring_pressure_angle_rad=alpha,
        planet_angles_rad=tuple(planet_angles_rad),
    )


def mass_matrix(p: PlanetaryModalParameters) -> np.ndarray:
    """M = diag(m_c, m_c, I_c/r_c^2, m_r, m_r, I_r/r_r^2, m_s, m_s, I_s/r_s^2, (m_p, m_p, I_p/r_p^2) x N)."""
    central = [
        (p.carrier_mass_kg, p.carrier_rotary_mass_kg),
        (p.ring_mass_kg, p.ring_rotary_mass_kg),
        (p.sun_mass_kg, p.sun_rotary_mass_kg),
    ]
    planets = [(p.planet_mass_kg, p.planet_rotary_mass_kg)] * p.n_planets
    return np.diag([v for m, j in central + planets for v in (m, m, j)])


def stiffness_matrix(p: PlanetaryModalParameters) -> np.ndarray:
    """K = K_b + K_m from the closed-form blocks of Lin & Parker 1999 (module docstring)."""
    k_p, k_s, k_r = p.planet_bearing_N_per_m, p.sun_mesh_N_per_m, p.ring_mesh_N_per_m
    sa, ca = math.sin(p.sun_pressure_angle_rad), math.cos(p.sun_pressure_angle_rad)
    sr, cr = math.sin(p.ring_pressure_angle_rad), math.cos(p.ring_pressure_angle_rad)
    K = np.zeros((p.n_dof, p.n_dof))
    C, R, S = slice(0, 3), slice(3, 6), slice(6, 9)
    K[C, C] += np.diag([p.carrier_bearing_N_per_m] * 2 + [p.carrier_torsion_N_per_m])
    K[R, R] += np.diag([p.ring_bearing_N_per_m] * 2 + [p.ring_torsion_N_per_m])
    K[S, S] += np.diag([p.sun_bearing_N_per_m] * 2 + [p.sun_torsion_N_per_m])
    # planet-planet blocks: bearing (K_p1), ring mesh (K_r3), sun mesh (K_s3)
    k_r3 = np.array([[sr * sr, -sr * cr, -sr], [-sr * cr, cr * cr, cr], [-sr, cr, 1.0]])
    k_s3 = np.array([[sa * sa, sa * ca, -sa], [sa * ca, ca * ca, -ca], [-sa, -ca, 1.0]])
    k_pp = k_p * np.diag([1.0, 1.0, 0.0]) + k_r * k_r3 + k_s * k_s3
    for i, psi in enumerate(p.planet_angles_rad):
        P = slice(9 + 3 * i, 12 + 3 * i)
        s, c = math.sin(psi), math.cos(psi)
        ssn, csn = math.sin(psi - p.sun_pressure_angle_rad), math.cos(psi - p.sun_pressure_angle_rad)
        srn, crn = math.sin(psi + p.ring_pressure_angle_rad), math.cos(psi + p.ring_pressure_angle_rad)
        k_c1 = np.array([[1.0, 0.0, -s], [0.0, 1.0, c], [-s, c, 1.0]])
        k_c2 = np.array([[-c, s, 0.0], [-s, -c, 0.0], [0.0, -1.0, 0.0]])
        k_r1 = np.array([[srn * srn, -srn * crn, -srn], [-srn * crn, crn * crn, crn], [-srn, crn, 1.0]])
        k_r2 = np.array([[-srn * sr, srn * cr, srn], [crn * sr, -crn * cr, -crn], [sr, -cr, -1.0]])
        k_s1 = np.array([[ssn * ssn, -ssn * csn, -ssn], [-ssn * csn, csn * csn, csn], [-ssn, csn, 1.0]])
        k_s2 = np.array([[ssn * sa, ssn * ca, -ssn], [-csn * sa, -csn * ca, csn], [-sa, -ca, 1.0]])
        K[C, C] += k_p * k_c1
        K[R, R] += k_r * k_r1
        K[S, S] += k_s * k_s1
        for centre, block in ((C, k_p * k_c2), (R, k_r * k_r2), (S, k_s * k_s2)):
            K[centre, P] += block
            K[P, centre] += block.T
        K[P, P] += k_pp
    return K


@dataclasses.dataclass(frozen=True)
class ModeGroup:
    """One natural frequency with its multiplicity, class and the central members' energy shares."""

    frequency_hz: float
    multiplicity: int
    kind: str  # one of MODE_KINDS
    central_translation_share: float  # of the eigenspace's kinetic energy, 0..1
    central_rotation_share: float


@dataclasses.dataclass(frozen=True)
class PlanetaryModes:
    """Natural frequencies (ascending, Hz), M-orthonormal mode shapes (columns) and the modes table."""

    frequencies_hz: np.ndarray
    shapes: np.ndarray
    groups: tuple[ModeGroup, ...]

    def of_kind(self, kind: str) -> tuple[ModeGroup, ...]:
        if kind not in MODE_KINDS:
            raise PlanetaryModalError(f"kind = {kind!r}: unknown mode class; allowed: one of {MODE_KINDS}")
        return tuple(g for g in self.groups if g.kind == kind)

    def table(self) -> list[dict]:
        """Rows ``{frequency_hz, multiplicity, kind}`` in ascending frequency."""
        return [
            {"frequency_hz": g.frequency_hz, "multiplicity": g.multiplicity, "kind": g.kind}
            for g in self.groups
        ]


def _classify(translation: float, rotation: float) -> str:
    if translation + rotation < MOTION_TOL:
        return "planet"
    if translation < MOTION_TOL:
        return "rotational"
    if rotation < MOTION_TOL:
        return "translational"
    return "mixed"


def natural_modes(p: PlanetaryModalParameters) -> PlanetaryModes:
    """Eigen-solution of ``K v = w^2 M v`` (scipy.linalg.eigh), eigenvalues grouped into eigenspaces
    (relative gap below 1e-6) and each eigenspace classified (module docstring)."""
    from scipy.linalg import eigh

    M, K = mass_matrix(p), stiffness_matrix(p)
    lam, V = eigh(K, M)
    lam = np.where(np.abs(lam) < ZERO_RTOL * lam[-1], 0.0, lam)  # rigid-body modes: round-off to 0
    if lam.min() < 0.0:
        raise PlanetaryModalError(f"stiffness matrix: eigenvalue {lam.min():.6g} < 0; allowed: K >= 0")
    freqs = np.sqrt(lam) / (2.0 * math.pi)
    mdiag = np.diag(M)
    translation_dofs = np.array([0, 1, 3, 4, 6, 7])
    rotation_dofs = np.array([2, 5, 8])
    groups, start = [], 0
    floor = ZERO_RTOL * lam[-1]
    for k in range(1, len(lam) + 1):
        if k < len(lam) and lam[k] - lam[k - 1] <= DEGENERACY_RTOL * max(lam[k], floor):
            continue
        block = V[:, start:k]
        energy = mdiag[:, None] * block**2  # per coordinate and mode; each column sums to 1
        m = k - start
        translation = float(energy[translation_dofs].sum() / m)
        rotation = float(energy[rotation_dofs].sum() / m)
        groups.append(
            ModeGroup(
                frequency_hz=float(freqs[start:k].mean()),
                multiplicity=m,
                kind=_classify(translation, rotation),
                central_translation_share=translation,
                central_rotation_share=rotation,
            )
        )
        start = k
    return PlanetaryModes(frequencies_hz=freqs, shapes=V, groups=tuple(groups))
