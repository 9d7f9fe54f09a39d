"""The mesh report of a planetary stage (``gearbody mesh SCENE`` on a drive with one): the stage's geometry
and stiffness table, each planet mesh's k_z over the mesh cycle (the sun-planet and the ring-planet law),
k_z around each damaged tooth in the meshes it enters, and each mesh's static transmission error under
load. Evaluated with the solver's own packed laws (:func:`gearbody.assembly.planetary_layout.
layout_from_stage`); engine-free.

Coordinates of a planet mesh (docs/planetary.md, "Tooth numbering"): ``u`` = (law angle) z1 / 2 pi counts
mesh periods, z1 = z_s for the sun mesh and z_r for the ring mesh; period ``n = floor(u)`` is the pair of
sun (ring) tooth ``n mod z1`` and planet tooth ``n mod z_p`` (the ring mesh's planet teeth shifted by
``M_n + floor(z_p / 2)``).
"""

from __future__ import annotations

import math

import numpy as np

from gearbody.assembly.planetary_layout import contact_ratios, layout_from_stage, ring_wheel_teeth
from gearbody.model.planetary import PlanetaryStage
from gearbody.physics import mesh as _mesh
from gearbody.physics.mesh_stiffness import static_transmission_error_m
from gearbody.physics.planetary import planet_mesh_phases

from .curves import DamageWindow, StaticTransmissionError, StiffnessCycle, load_label, tooth_label
from .stage import angles, get_stage, stage_label
from .table import Row
from .text import _stats, format_table

__all__ = [
    "PLANET_MESHES",
    "planetary_damage_windows",
    "planetary_geometry_table",
    "planetary_static_transmission_errors",
    "planetary_stiffness_cycles",
    "planetary_summary_text",
]

PLANET_MESHES = ("sun", "ring")
"""A planet's two meshes, by the central member it meshes with."""


def _planetary(scenario, stage: int):
    st = get_stage(scenario, stage)
    if not isinstance(st, PlanetaryStage):
        raise ValueError(f"stage {stage + 1} is no planetary stage (the parallel report: reports.mesh)")
    return st


def _healthy(scenario, stage: int):
    """The scenario with the planetary stage's teeth perfect: no damaged teeth, no tooth errors."""
    st = scenario.stages[stage]
    return scenario.with_stage(
        stage,
        damaged_teeth=(),
        sun_error_mode=st.sun_error_mode.replace(e_um=0.0),
        ring_error_mode=st.ring_error_mode.replace(e_um=0.0),
    )


def _layout(scenario, stage: int, healthy: bool = False):
    source = _healthy(scenario, stage) if healthy else scenario
    return layout_from_stage(source.stages[stage], stage, source.meta.seed)


def _law(layout, mesh: str, planet: int = 0) -> np.ndarray:
    """Packed law of ``mesh`` (sun or ring) of planet ``planet`` (0-based)."""
    return layout.sun_mesh_of(planet) if mesh == "sun" else layout.ring_mesh_of(planet)


def _z1(st, mesh: str) -> int:
    return st.sun.teeth if mesh == "sun" else st.ring.teeth


def _contact_ratio(st, mesh: str) -> float:
    given = getattr(st, f"{mesh}_mesh").contact_ratio
    return contact_ratios(st.geometry)[PLANET_MESHES.index(mesh)] if given is None else given


def planetary_stiffness_cycles(
    scenario, stage: int, periods: int = 2, points_per_period: int = 400
) -> dict[str, StiffnessCycle]:
    """Healthy k_z of the sun and the ring mesh over ``periods`` mesh periods from u = 0, as the solver's
    law evaluates it (every planet's mesh of one kind uses the same law, shifted in phase)."""
    st = _planetary(scenario, stage)
    layout = _layout(scenario, stage, healthy=True)
    u = np.arange(periods * points_per_period + 1) / points_per_period
    u[-1] -= 1e-9  # stay inside the last period
    out = {}
    for mesh in PLANET_MESHES:
        P = _law(layout, mesh)
        spec = getattr(st, f"{mesh}_mesh")
        out[mesh] = StiffnessCycle(
            periods=u,
            stiffness_N_per_m=_mesh.effective_stiffness_series(angles(u, _z1(st, mesh)), P),
            half_double=0.5 * (_contact_ratio(st, mesh) - 1.0),
            pitch_point_phase=spec.pitch_point_phase,
            mean_N_per_m=_mesh.mean_stiffness_N_per_m(P),
            profile=spec.stiffness_profile,
        )
    return out


def planetary_damage_windows(
    scenario, stage: int, before: float = 1.5, after: float = 2.5, points_per_period: int = 400
) -> list[DamageWindow]:
    """One window per damaged tooth and mesh it enters: a sun (ring) tooth in the sun (ring) mesh, a
    planet's tooth in that planet's sun and ring mesh; k_z over periods ``n0 - before .. n0 + after``
    around the first period n0 of the tooth's pair, as given and with perfect teeth. ``gear`` names the
    member (``sun``, ``ring``, ``planet 2``), ``description`` the factor and the mesh."""
    st = _planetary(scenario, stage)
    if not st.damaged_teeth:
        return []
    given, healthy = _layout(scenario, stage), _layout(scenario, stage, healthy=True)
    out = []
    for tooth in sorted(st.damaged_teeth, key=lambda t: (t.member, t.planet or 0, t.tooth)):
        if tooth.stiffness_factor >= 1.0:
            continue
        planet = 0 if tooth.planet is None else tooth.planet - 1
        if tooth.member == "planet":
            # its sun mesh's wheel tooth j meshes in periods n = j (mod z_p); in the ring mesh the wheel
            # index k whose planet tooth is j
            ring_k = int(np.flatnonzero(ring_wheel_teeth(st.geometry, planet) == tooth.tooth)[0])
            firsts = {"sun": tooth.tooth, "ring": ring_k}
            gear = f"planet {tooth.planet}"
        else:
            firsts = {tooth.member: tooth.tooth}
            gear = tooth.member
        for mesh, n0 in firsts.items():
            n = int(round((before + after) * points_per_period))
            u = n0 - before + (np.arange(n) + 0.5) / points_per_period
            phi = angles(u, _z1(st, mesh))
            out.append(
                DamageWindow(
                    gear=gear,
                    tooth=tooth.tooth,
                    description=f"stiffness factor {tooth.stiffness_factor:g}, {mesh} mesh"
                    + ("" if tooth.member == "planet" else " (every planet)"),
                    periods=u,
                    stiffness_N_per_m=_mesh.effective_stiffness_series(phi, _law(given, mesh, planet)),
                    healthy_stiffness_N_per_m=_mesh.effective_stiffness_series(
                        phi, _law(healthy, mesh, planet)
                    ),
                    contact=(float(n0), n0 + 1.0),
                )
            )
    return out


def planetary_static_transmission_errors(
    scenario, stage: int, load_fraction: float = 1.0, points_per_period: int = 200
) -> dict[str, StaticTransmissionError]:
    """Static TE = F/k - E + l_u [µm] of planet 1's sun and ring mesh at ``load_fraction`` of the stage's
    rated force per planet mesh, over one revolution of the sun (ring) relative to the line of centres
    (z1 periods): as given (damaged teeth, tooth errors) and with perfect teeth. ``pinion_turns`` counts
    those revolutions."""
    st = _planetary(scenario, stage)
    if not (math.isfinite(load_fraction) and load_fraction >= 0.0):
        raise ValueError(f"load_fraction = {load_fraction!r}: must be finite and >= 0")
    given, healthy = _layout(scenario, stage), _layout(scenario, stage, healthy=True)
    rated = scenario.stage_rated_force_N(stage)
    force = load_fraction * rated
    out = {}
    for mesh in PLANET_MESHES:
        z1 = _z1(st, mesh)
        u = (np.arange(z1 * points_per_period) + 0.5) / points_per_period
        phi = angles(u, z1)
        P, P0 = _law(given, mesh), _law(healthy, mesh)
        k, k0 = _mesh.effective_stiffness_series(phi, P), _mesh.effective_stiffness_series(phi, P0)
        error = _mesh.mesh_gap_series(phi, np.zeros_like(phi), P)
        backlash_um = getattr(st, f"{mesh}_mesh").backlash_um
        lu = backlash_um * 1e-6
        out[mesh] = StaticTransmissionError(
            periods=u,
            pinion_turns=1,
            force_N=force,
            rated_force_N=rated,
            backlash_um=backlash_um,
            te_um=static_transmission_error_m(k, force, error, lu) * 1e6,
            healthy_te_um=static_transmission_error_m(k0, force, 0.0, lu) * 1e6,
            stiffness_N_per_m=k,
            healthy_stiffness_N_per_m=k0,
            error_um=error * 1e6,
        )
    return out


def _mm(x_m: float) -> float:
    return x_m * 1e3


def _angles(values) -> str:
    return ", ".join(f"{v:.4g}" for v in values)


def planetary_geometry_table(scenario, stage: int) -> list[Row]:
    """Rows (name, value, unit) of a planetary stage (0-based): teeth, planets and their angles, roles,
    radii, and per mesh (sun-planet, ring-planet) contact ratio, pitch-point phase, backlash, the planets'
    mesh phases and the stiffness of the law (single, double, mean, min, max over a mesh period); section
    headings are rows with value None."""
    st = _planetary(scenario, stage)
    g = st.geometry
    layout = _layout(scenario, stage, healthy=True)
    phases = planet_mesh_phases(g)
    per_rev = 2.0 * math.pi * st.mesh_frequency_hz(1.0)
    rows: list[Row] = [
        ("gears", None, ""),
        ("teeth z_s (sun)", st.sun.teeth, ""),
        ("teeth z_p (planet)", st.planet.teeth, ""),
        ("teeth z_r (ring)", st.ring.teeth, ""),
        ("planets N", st.planets, ""),
        ("planet angles psi_n", _angles(math.degrees(a) for a in g.planet_angles_rad), "deg"),
        ("module m", st.module_mm, "mm"),
        ("pressure angle alpha", st.pressure_angle_deg, "deg"),
        ("input / output / fixed", f"{st.input} / {st.output} / {st.fixed}", ""),
        ("speed ratio input/output", st.ratio, ""),
        ("mesh periods per input revolution f_m/f_in", per_rev, ""),
        ("radii", None, ""),
        ("pitch radius r_s (sun)", _mm(g.sun_pitch_radius_m), "mm"),
        ("pitch radius r_p (planet)", _mm(g.planet_pitch_radius_m), "mm"),
        ("pitch radius r_r (ring)", _mm(g.ring_pitch_radius_m), "mm"),
        ("base radius r_bs (sun)", _mm(g.sun_base_radius_m), "mm"),
        ("base radius r_bp (planet)", _mm(g.planet_base_radius_m), "mm"),
        ("base radius r_br (ring)", _mm(g.ring_base_radius_m), "mm"),
        ("tip radius (sun)", _mm(g.sun_pitch_radius_m + g.module_m), "mm"),
        ("tip radius (planet)", _mm(g.planet_tip_radius_m), "mm"),
        ("tip radius (ring, internal)", _mm(g.ring_tip_radius_m), "mm"),
        ("carrier radius r_c (planet centres)", _mm(g.carrier_radius_m), "mm"),
    ]
    force = scenario.stage_rated_force_N(stage)
    for mesh in PLANET_MESHES:
        spec = getattr(st, f"{mesh}_mesh")
        z1 = _z1(st, mesh)
        P = _law(layout, mesh)
        u = (np.arange(20000) + 0.5) / 20000
        k = _mesh.effective_stiffness_series(angles(u, z1), P)
        k_mean = _mesh.mean_stiffness_N_per_m(P)
        rows += [
            (f"{mesh}-planet mesh", None, ""),
            ("transverse contact ratio eps_alpha", _contact_ratio(st, mesh), ""),
            ("pitch point phase", spec.pitch_point_phase, ""),
            ("backlash half-width l_u", spec.backlash_um, "µm"),
            ("planet mesh phases gamma_n", _angles(getattr(phases, mesh)), ""),
            ("stiffness profile", spec.stiffness_profile, ""),
            ("k_z single contact", spec.stiffness_single_N_per_m, "N/m"),
            ("k_z double contact", spec.stiffness_double_N_per_m, "N/m"),
            ("k_z mean over a mesh period", k_mean, "N/m"),
            ("k_z min over a mesh period", float(k.min()), "N/m"),
            ("k_z max over a mesh period", float(k.max()), "N/m"),
            ("k_z ripple (max - min)/mean", (float(k.max()) - float(k.min())) / k_mean * 100.0, "%"),
            ("rated force per planet mesh F_rated", force, "N"),
        ]
    return rows


def planetary_summary_text(
    scenario,
    stage: int,
    load_fraction: float = 1.0,
    cycles: dict[str, StiffnessCycle] | None = None,
    windows: list[DamageWindow] | None = None,
    tes: dict[str, StaticTransmissionError] | None = None,
) -> str:
    """Printed summary of a planetary stage: the table, its damaged teeth and each mesh's static TE
    (computed here unless passed in)."""
    cycles = planetary_stiffness_cycles(scenario, stage) if cycles is None else cycles
    windows = planetary_damage_windows(scenario, stage) if windows is None else windows
    tes = planetary_static_transmission_errors(scenario, stage, load_fraction) if tes is None else tes
    title = f"{stage_label(scenario, stage)}, planetary"
    lines = [format_table(planetary_geometry_table(scenario, stage), title)]
    lines.append("  damaged teeth" if windows else "  damaged teeth: none")
    for w in windows:
        lines.append(
            f"    {tooth_label(w)} ({w.description}): min k_z/k_z,healthy {w.min_ratio:.4f}, "
            f"acts over u = {w.contact[0]:.3f} .. {w.contact[1]:.3f} mesh periods"
        )
    for mesh in PLANET_MESHES:
        te = tes[mesh]
        inv_mean = float(np.mean(1.0 / te.healthy_stiffness_N_per_m))
        lines.append(
            f"  {mesh}-planet mesh (planet 1): static transmission error at F = {te.force_N:.6g} N "
            f"({load_label(te)} {te.rated_force_N:.6g} N), l_u = {te.backlash_um:.4g} µm, over one "
            f"{mesh} revolution relative to the line of centres"
        )
        lines.append(
            f"    F/k_mean {te.force_N / cycles[mesh].mean_N_per_m * 1e6:.3f} µm, "
            f"mean F/k {te.force_N * inv_mean * 1e6:.3f} µm (healthy)"
        )
        lines.append(f"    healthy:  {_stats(te.healthy_te_um)}")
        lines.append(f"    as given: {_stats(te.te_um)}")
    return "\n".join(lines)
