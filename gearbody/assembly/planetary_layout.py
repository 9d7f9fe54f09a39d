"""Layout of a planetary stage for the Exudyn builder (engine-free): sun, ring, carrier and N planets as
planar members, their supports, the planets' positions and bearings on the carrier, and the packed mesh
laws of the sun and ring meshes (issue 19, docs/design-notes.md "Planetary stages").

The members' nominal assembly: sun, ring and carrier centred at the origin, planet n on the carrier
circle at angle psi_n; every rotation 0. The deflections of that assembly (:func:`nominal_deflections_m`)
are the zero of each mesh law, so the nominal assembly is unloaded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import partial

import numpy as np

from ..physics.planetary_mesh import (
    G_ANGLE_RING,
    G_ANGLE_SUN,
    G_BEARING_C,
    G_BEARING_K,
    G_CARRIER_RADIUS,
    G_DELTA0_RING,
    G_DELTA0_SUN,
    G_PSI,
    G_RB_PLANET,
    G_RB_RING,
    G_RB_SUN,
    G_SIZE,
    pair_deflection,
)

__all__ = [
    "PlanetaryLayout",
    "PlanetaryMember",
    "contact_ratios",
    "layout_from_geometry",
    "layout_from_stage",
    "nominal_deflections_m",
    "rigid_speeds_rad_s",
]

CENTRAL = ("sun", "ring", "carrier")


@dataclass(frozen=True)
class PlanetaryMember:
    """A planar member: mass, inertia, an isotropic bearing (for a planet: its bearing on the carrier;
    otherwise its support to the housing) and an optional torsional support to the housing."""

    name: str
    mass_kg: float
    inertia_kg_m2: float
    bearing_stiffness_N_per_m: float
    bearing_damping_Ns_per_m: float = 0.0
    torsion_stiffness_Nm_per_rad: float | None = None  # None: free to turn
    torsion_damping_Nms_per_rad: float = 0.0
    bearing_law: object | None = None  # a gearbody.physics.bearings law replacing the linear bearing


@dataclass(frozen=True)
class PlanetaryLayout:
    """One planetary stage: members, geometry and the packed sun- and ring-mesh laws (z1 = z_sun and
    z1 = z_ring, :func:`gearbody.physics.mesh.pack_mesh_parameters`)."""

    sun: PlanetaryMember
    ring: PlanetaryMember
    carrier: PlanetaryMember
    planet: PlanetaryMember
    planet_angles_rad: tuple[float, ...]
    carrier_radius_m: float
    base_radius_sun_m: float
    base_radius_planet_m: float
    base_radius_ring_m: float
    sun_mesh: np.ndarray = field(repr=False)
    ring_mesh: np.ndarray = field(repr=False)
    mesh_angle_offsets_rad: tuple[tuple[float, float], ...] = ()  # per planet (sun, ring); () = zeros
    # faults (docs/planetary.md, "Faults"): per-planet packed laws (N x len, sun and ring meshes) when a
    # planet's own teeth carry factors (None: every planet uses sun_mesh / ring_mesh), pin errors along
    # the carrier circle (m) and factors on the planet bearings, one per planet (() = none)
    planet_meshes: tuple[np.ndarray, np.ndarray] | None = field(default=None, repr=False)
    pin_errors_m: tuple[float, ...] = ()
    bearing_factors: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        n = len(self.planet_angles_rad)
        if not n:
            raise ValueError("a planetary stage needs at least one planet")
        if self.mesh_angle_offsets_rad and len(self.mesh_angle_offsets_rad) != n:
            raise ValueError("mesh_angle_offsets_rad needs one (sun, ring) pair per planet")
        for name in ("pin_errors_m", "bearing_factors"):
            if getattr(self, name) and len(getattr(self, name)) != n:
                raise ValueError(f"{name} needs one value per planet")
        if self.planet_meshes is not None and any(P.shape[0] != n for P in self.planet_meshes):
            raise ValueError("planet_meshes need one packed law per planet")

    @property
    def members(self) -> tuple[PlanetaryMember, ...]:
        return (self.sun, self.ring, self.carrier)

    def pin_angle_rad(self, n: int) -> float:
        """Angle of planet n's pin on the carrier: psi_n plus its tangential error e_n / r_c."""
        if self.pin_errors_m:
            return self.planet_angles_rad[n] + self.pin_errors_m[n] / self.carrier_radius_m
        return self.planet_angles_rad[n]

    def planet_centre_m(self, n: int) -> tuple[float, float]:
        """Planet n's reference centre: its pin, r_c (cos, sin)(psi_n + e_n / r_c)."""
        psi = self.pin_angle_rad(n)
        return self.carrier_radius_m * math.cos(psi), self.carrier_radius_m * math.sin(psi)

    def mesh_arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """(sun, ring) laws for :func:`gearbody.physics.planetary_mesh.stage_forces`: the shared 1-D
        arrays, or one row per planet."""
        return (self.sun_mesh, self.ring_mesh) if self.planet_meshes is None else self.planet_meshes

    def sun_mesh_of(self, n: int) -> np.ndarray:
        """Packed sun-mesh law of planet n (0-based)."""
        return self.sun_mesh if self.planet_meshes is None else self.planet_meshes[0][n]

    def ring_mesh_of(self, n: int) -> np.ndarray:
        """Packed ring-mesh law of planet n (0-based)."""
        return self.ring_mesh if self.planet_meshes is None else self.planet_meshes[1][n]

    def geometry(self, n: int) -> np.ndarray:
        """The geometry array of planet n for :func:`gearbody.physics.planetary_mesh.planet_forces`."""
        G = np.zeros(G_SIZE)
        G[G_RB_SUN], G[G_RB_PLANET], G[G_RB_RING] = (
            self.base_radius_sun_m,
            self.base_radius_planet_m,
            self.base_radius_ring_m,
        )
        G[G_CARRIER_RADIUS], G[G_PSI] = self.carrier_radius_m, self.pin_angle_rad(n)
        G[G_BEARING_K] = self.planet.bearing_stiffness_N_per_m
        G[G_BEARING_C] = self.planet.bearing_damping_Ns_per_m
        if self.bearing_factors:
            G[G_BEARING_K] *= self.bearing_factors[n]
            G[G_BEARING_C] *= self.bearing_factors[n]
        if self.mesh_angle_offsets_rad:
            G[G_ANGLE_SUN], G[G_ANGLE_RING] = self.mesh_angle_offsets_rad[n]
        G[G_DELTA0_SUN], G[G_DELTA0_RING] = nominal_deflections_m(self, n)
        return G


def nominal_deflections_m(layout: PlanetaryLayout, n: int) -> tuple[float, float]:
    """(sun, ring) mesh deflections of planet n at the nominal, error-free assembly (every rotation 0,
    the planet at psi_n: a pin error preloads the meshes)."""
    psi = layout.planet_angles_rad[n]
    x, y = layout.carrier_radius_m * math.cos(psi), layout.carrier_radius_m * math.sin(psi)
    planet = [x, y, 0.0]
    d_s = pair_deflection(
        np.array([0.0, 0.0, 0.0, *planet]), layout.base_radius_sun_m, layout.base_radius_planet_m, False, psi
    )[0]
    d_r = pair_deflection(
        np.array([0.0, 0.0, 0.0, *planet]), layout.base_radius_ring_m, layout.base_radius_planet_m, True, psi
    )[0]
    return d_s, d_r


def rigid_speeds_rad_s(layout: PlanetaryLayout, sun_rad_s: float, carrier_rad_s: float) -> dict[str, float]:
    """Speeds of rigid rolling from the sun's and the carrier's (Willis, on base radii): the ring and
    every planet's absolute spin."""
    rbs, rbp, rbr = layout.base_radius_sun_m, layout.base_radius_planet_m, layout.base_radius_ring_m
    planet = carrier_rad_s - rbs / rbp * (sun_rad_s - carrier_rad_s)
    ring = carrier_rad_s + rbp / rbr * (planet - carrier_rad_s)
    return {"sun": sun_rad_s, "carrier": carrier_rad_s, "ring": ring, "planet": planet}


def contact_ratios(geometry) -> tuple[float, float]:
    """(sun-planet, ring-planet) transverse contact ratios of standard teeth (addendum one module):
    external ``(sqrt(r_a1^2 - r_b1^2) + sqrt(r_a2^2 - r_b2^2) - a sin(alpha)) / p_b``, internal
    ``(sqrt(r_ap^2 - r_bp^2) - sqrt(r_ar^2 - r_br^2) + a_r sin(alpha)) / p_b`` with the ring's tip
    circle inside its pitch circle (r_ar = r_r - m) and a_r = r_r - r_p."""
    g = geometry
    alpha = g.pressure_angle_rad
    p_b = math.pi * g.module_m * math.cos(alpha)
    r_as = g.sun_pitch_radius_m + g.module_m
    s_s = math.sqrt(r_as**2 - g.sun_base_radius_m**2)
    s_p = math.sqrt(g.planet_tip_radius_m**2 - g.planet_base_radius_m**2)
    s_r = math.sqrt(g.ring_tip_radius_m**2 - g.ring_base_radius_m**2)
    a_s = g.carrier_radius_m
    a_r = g.ring_pitch_radius_m - g.planet_pitch_radius_m
    return (s_s + s_p - a_s * math.sin(alpha)) / p_b, (s_p - s_r + a_r * math.sin(alpha)) / p_b


def layout_from_geometry(
    geometry,
    *,
    sun: PlanetaryMember,
    ring: PlanetaryMember,
    carrier: PlanetaryMember,
    planet: PlanetaryMember,
    stiffness_single_N_per_m: tuple[float, float],
    stiffness_double_N_per_m: tuple[float, float],
    damping_Ns_per_m: tuple[float, float] = (0.0, 0.0),
    backlash_m: tuple[float, float] = (0.0, 0.0),
    transition_width: float | tuple[float, float] = 0.0,
    contact_ratio: tuple[float | None, float | None] = (None, None),
    pitch_point_phase: tuple[float, float] = (0.5, 0.5),
    error_a: tuple[float, float] = (0.0, 0.0),
    error_depths_m: tuple[np.ndarray | None, np.ndarray | None] = (None, None),
    tooth_factors: tuple | None = None,
    pin_errors_m: tuple[float, ...] = (),
    bearing_factors: tuple[float, ...] = (),
    friction_coefficient: float = 0.0,
    friction_transition_speed_m_s: float = 1e-3,
) -> PlanetaryLayout:
    """A :class:`PlanetaryLayout` from a checked :class:`gearbody.physics.planetary.PlanetaryGeometry`:
    radii, planet angles, each mesh's contact ratio (:func:`contact_ratios` unless given) and the ring
    mesh's offset of half a mesh period when the planet has an even number of teeth
    (``planet_mesh_phases(...).ring_sun``). The pairs of mesh values are (sun mesh, ring mesh); the
    error depths are per sun (ring) tooth, None for none. Faults (docs/planetary.md, "Faults"):
    ``tooth_factors`` = (sun factors, ring factors, (planet 1 factors, ..., planet N)) per tooth, the
    planets' in their sun-mesh numbering (each planet then gets its own laws, its ring mesh's wheel
    factors shifted by M_n + floor(z_p / 2)); pin errors (m) and planet-bearing factors per planet.
    ``friction_coefficient``, ``friction_transition_speed_m_s``: mu and v_0 of every sun and ring mesh
    (docs/planetary.md, "Friction")."""
    from ..physics.planetary import planet_mesh_phases

    g = geometry
    standard = contact_ratios(g)
    rbs, rbp, rbr = g.sun_base_radius_m, g.planet_base_radius_m, g.ring_base_radius_m
    widths = transition_width if isinstance(transition_width, tuple) else (transition_width,) * 2
    given = {  # (sun mesh, ring mesh) of each value of the mesh law
        "stiffness_single_N_per_m": stiffness_single_N_per_m,
        "stiffness_double_N_per_m": stiffness_double_N_per_m,
        "contact_ratio": tuple(standard[k] if contact_ratio[k] is None else contact_ratio[k] for k in (0, 1)),
        "damping_Ns_per_m": damping_Ns_per_m,
        "backlash_m": backlash_m,
        "pitch_point_phase": pitch_point_phase,
        "error_a": error_a,
        "error_depths_m": error_depths_m,
        "transition_width": widths,
    }
    friction = {
        "friction_coefficient": friction_coefficient,
        "friction_transition_speed_m_s": friction_transition_speed_m_s,
    }
    ring_offset = 2.0 * math.pi * planet_mesh_phases(g).ring_sun / g.z_ring
    sun_mesh, ring_mesh, planet_meshes = _mesh_laws(g, given, friction, tooth_factors)
    return PlanetaryLayout(
        sun=sun,
        ring=ring,
        carrier=carrier,
        planet=planet,
        planet_angles_rad=tuple(g.planet_angles_rad),
        carrier_radius_m=g.carrier_radius_m,
        base_radius_sun_m=rbs,
        base_radius_planet_m=rbp,
        base_radius_ring_m=rbr,
        sun_mesh=sun_mesh,
        ring_mesh=ring_mesh,
        mesh_angle_offsets_rad=tuple((0.0, ring_offset) for _ in g.planet_angles_rad),
        planet_meshes=planet_meshes,
        pin_errors_m=tuple(pin_errors_m),
        bearing_factors=tuple(bearing_factors),
    )


def _mesh_laws(g, given: dict, friction: dict, tooth_factors: tuple | None) -> tuple:
    """(sun mesh law, ring mesh law, each planet's own laws or None) of :func:`layout_from_geometry`:
    ``given`` holds each value of the law as its (sun mesh, ring mesh) pair; each planet gets its own
    laws (rows per planet) when one of its teeth is damaged, its ring mesh's wheel factors shifted by
    :func:`ring_wheel_teeth`."""
    rbs, rbr = g.sun_base_radius_m, g.ring_base_radius_m
    sun_law, ring_law = (
        partial(_planet_mesh_law, g, {key: pair[k] for key, pair in given.items()}, z1, r1, **friction)
        for k, z1, r1 in ((0, g.z_sun, rbs), (1, g.z_ring, rbr))
    )
    sun_f, ring_f, planet_f = tooth_factors if tooth_factors is not None else (None, None, None)
    sun_mesh = sun_law(sun_f)
    ring_mesh = ring_law(ring_f)
    if planet_f is None or not any(min(f) < 1.0 for f in planet_f):
        return sun_mesh, ring_mesh, None
    rows_s, rows_r = [], []
    for n, f in enumerate(planet_f):
        f = np.asarray(f, float)
        rows_s.append(sun_law(sun_f, f))
        rows_r.append(ring_law(ring_f, f[ring_wheel_teeth(g, n)]))
    return sun_mesh, ring_mesh, (np.array(rows_s), np.array(rows_r))


def _planet_mesh_law(
    g, pair: dict, z1: int, r1: float, pinion=None, wheel=None, **friction: float
) -> np.ndarray:
    """The packed law of one mesh with the planet (the sun or the ring as its pinion, of ``z1`` teeth and
    base radius ``r1``; the planet as its wheel): ``pair`` holds that mesh's values of the law by their
    :func:`~gearbody.physics.mesh.pack_mesh_parameters` names (error depths None: none), ``pinion`` and
    ``wheel`` the per-tooth stiffness factors (None: sound teeth)."""
    from ..physics.mesh import pack_mesh_parameters

    depths = pair["error_depths_m"]
    return pack_mesh_parameters(
        **{**pair, "error_depths_m": np.zeros(z1) if depths is None else depths},
        pinion_factors=pinion,
        wheel_factors=wheel,
        r1_m=r1,
        r2_m=g.planet_base_radius_m,
        z1=z1,
        z2=g.z_planet,
        pressure_angle_rad=g.pressure_angle_rad,
        **friction,
    )


def ring_wheel_teeth(geometry, n: int) -> np.ndarray:
    """Planet tooth (sun-mesh numbering) in the ring mesh's period with wheel index k = 0..z_p - 1, for
    planet n (0-based): ``(k - M_n - floor(z_p / 2)) mod z_p``, ``M_n = (z_s + z_r) psi_n / 2 pi``
    (docs/planetary.md, "Faults": a tooth meets the ring (z_p - 1) / 2 mesh periods after the sun)."""
    g = geometry
    M = round((g.z_sun + g.z_ring) * g.planet_angles_rad[n] / (2.0 * math.pi))
    return (np.arange(g.z_planet) - M - g.z_planet // 2) % g.z_planet


def _member(name: str, m) -> PlanetaryMember:
    """An assembly member from a scenario member; a bearing law leaves the linear bearing at 0 (the law
    acts instead, assembly.compound.bearing_law_forces)."""
    return PlanetaryMember(
        name,
        m.mass_kg,
        m.inertia_kg_m2,
        m.bearing_stiffness_N_per_m or 0.0,
        m.bearing_damping_Ns_per_m,
        m.torsion_stiffness_Nm_per_rad,
        m.torsion_damping_Nms_per_rad,
        None if m.bearing is None else m.bearing.law(),
    )


def layout_from_stage(
    stage,
    stage_index: int,
    seed: int,
    *,
    modal: bool = False,
    friction_coefficient: float = 0.0,
    friction_transition_speed_m_s: float = 1e-3,
) -> PlanetaryLayout:
    """The :class:`PlanetaryLayout` of a scenario's planetary stage (:class:`gearbody.model.planetary.
    PlanetaryStage`, 0-based ``stage_index`` in power-flow order): members, meshes, error modes with the
    random tooth errors of ``seed`` (docs/planetary.md, "The stage in a drive"), friction mu and v_0 of
    the scenario's condition. ``modal``: every mesh a constant spring at its mean stiffness (no backlash,
    errors, damping or friction), for the linearised modes."""
    from ..physics.error_mode import planetary_tooth_error_depths_m
    from ..physics.mesh import mean_stiffness_N_per_m

    members = {name: _member(name, getattr(stage, name)) for name in ("sun", "ring", "carrier", "planet")}
    if modal:
        full = layout_from_stage(stage, stage_index, seed)
        k_mean = (mean_stiffness_N_per_m(full.sun_mesh), mean_stiffness_N_per_m(full.ring_mesh))
        return layout_from_geometry(
            stage.geometry,
            **members,
            stiffness_single_N_per_m=k_mean,
            stiffness_double_N_per_m=k_mean,
            bearing_factors=stage.bearing_factors() if stage.planet_bearing_defects else (),
        )

    meshes = (stage.sun_mesh, stage.ring_mesh)
    modes = {"sun": stage.sun_error_mode, "ring": stage.ring_error_mode}
    depths = tuple(
        planetary_tooth_error_depths_m(
            modes[m].e_um, modes[m].r, getattr(stage, m).teeth, seed, stage_index, m
        )
        for m in ("sun", "ring")
    )
    return layout_from_geometry(
        stage.geometry,
        **members,
        stiffness_single_N_per_m=tuple(m.stiffness_single_N_per_m for m in meshes),
        stiffness_double_N_per_m=tuple(m.stiffness_double_N_per_m for m in meshes),
        damping_Ns_per_m=tuple(m.damping_Ns_per_m for m in meshes),
        backlash_m=tuple(m.backlash_um * 1e-6 for m in meshes),
        transition_width=tuple(m.transition_width for m in meshes),
        contact_ratio=tuple(m.contact_ratio for m in meshes),
        pitch_point_phase=tuple(m.pitch_point_phase for m in meshes),
        error_a=(modes["sun"].a, modes["ring"].a),
        error_depths_m=depths,
        friction_coefficient=friction_coefficient,
        friction_transition_speed_m_s=friction_transition_speed_m_s,
        **_fault_keys(stage),
    )


def _fault_keys(stage) -> dict:
    """layout_from_geometry's fault arguments of a stage (none when it has no faults)."""
    if not stage.has_faults:
        return {}
    planets = [stage.tooth_factors("planet", n + 1) for n in range(stage.planets)]
    out = {
        "tooth_factors": (stage.tooth_factors("sun"), stage.tooth_factors("ring"), planets),
        "bearing_factors": stage.bearing_factors() if stage.planet_bearing_defects else (),
    }
    if any(e != 0.0 for e in stage.planet_position_errors_um):
        out["pin_errors_m"] = tuple(e * 1e-6 for e in stage.planet_position_errors_um)
    return out
