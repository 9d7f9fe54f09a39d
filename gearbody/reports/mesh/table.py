"""The mesh report's geometry and stiffness table of one gear stage: rows (name, value, unit) with
section headings, as :func:`gearbody.reports.mesh.text.format_table` prints them.

Engine-free; the stiffness values come from the solver's own mesh law (:mod:`gearbody.physics.mesh`).
"""

from __future__ import annotations

import math

import numpy as np

from gearbody.physics import mesh as _mesh

from .stage import angles, get_stage, parameters

__all__ = ["Row", "geometry_table", "table_value"]

Row = tuple[str, object, str]  # (name, value, unit); value None: a section heading


def _mm(x_m: float) -> float:
    return x_m * 1e3


def geometry_table(scenario, stage: int = 0) -> list[Row]:
    """Rows (name, value, unit) of one stage (0-based): teeth, geometry (when the mesh states it),
    contact ratios, backlash and the stiffness (profile, single/double/mean k_z, ISO 6336-1 method B,
    potential-energy mean). Section headings are rows with value None. A hand-given mesh (no
    [geometry]) lists what is known and says that the geometry is not given."""
    from gearbody.model.resolve import pair_geometry

    st = get_stage(scenario, stage)
    mesh, z1, z2 = st.mesh, st.pinion.teeth, st.wheel.teeth
    geo = None if mesh.geometry is None else pair_geometry(mesh, z1, z2)
    rows: list[Row] = [
        ("gears", None, ""),
        ("teeth z1 (pinion)", z1, ""),
        ("teeth z2 (wheel)", z2, ""),
        ("gear ratio z2/z1", z2 / z1, ""),
    ]
    rows += _hand_given_rows(st) if geo is None else _geometry_rows(st, geo)
    rows += _stiffness_rows(scenario, stage, geo)
    return rows


def _hand_given_rows(st) -> list[Row]:
    mesh = st.mesh
    rb1, rb2 = st.pinion.base_radius_m, st.wheel.base_radius_m
    pb1, pb2 = 2.0 * math.pi * rb1 / st.pinion.teeth, 2.0 * math.pi * rb2 / st.wheel.teeth
    return [
        ("geometry", "not given (hand-given mesh)", ""),
        ("base radius r_b1 (pinion)", _mm(rb1), "mm"),
        ("base radius r_b2 (wheel)", _mm(rb2), "mm"),
        ("base pitch 2 pi r_b1 / z1", _mm(pb1), "mm"),
        ("base pitch 2 pi r_b2 / z2", _mm(pb2), "mm"),
        ("face width b (pinion)", "not given", "")
        if st.pinion.face_width_m is None
        else ("face width b (pinion)", _mm(st.pinion.face_width_m), "mm"),
        ("operating pressure angle (friction arms)", mesh.pressure_angle_deg, "deg"),
        ("contact", None, ""),
        ("transverse contact ratio eps_alpha", mesh.contact_ratio, ""),
        ("pitch point phase", mesh.pitch_point_phase, ""),
        ("backlash half-width l_u", mesh.backlash_um, "µm"),
    ]


def _geometry_rows(st, geo) -> list[Row]:
    g = st.mesh.geometry
    deg = math.degrees
    rows: list[Row] = [
        ("normal module m_n", g.module_mm, "mm"),
        ("transverse module m_t", _mm(geo.transverse_module_m), "mm"),
        ("normal pressure angle alpha_n", g.pressure_angle_deg, "deg"),
        ("transverse pressure angle alpha_t", deg(geo.transverse_pressure_angle_rad), "deg"),
        ("working pressure angle alpha_wt", deg(geo.working_pressure_angle_rad), "deg"),
        ("helix angle beta", g.helix_angle_deg, "deg"),
        ("face width b", g.face_width_mm, "mm"),
        ("profile shift x1 (pinion)", g.profile_shift_pinion, ""),
        ("profile shift x2 (wheel)", g.profile_shift_wheel, ""),
        ("addendum coefficient h_a*", g.addendum_coefficient, ""),
        ("dedendum coefficient h_f*", g.dedendum_coefficient, ""),
        ("radii", None, ""),
        ("reference radius r1", _mm(geo.pitch_radius_pinion_m), "mm"),
        ("reference radius r2", _mm(geo.pitch_radius_wheel_m), "mm"),
        ("base radius r_b1", _mm(geo.base_radius_pinion_m), "mm"),
        ("base radius r_b2", _mm(geo.base_radius_wheel_m), "mm"),
        ("tip radius r_a1", _mm(geo.tip_radius_pinion_m), "mm"),
        ("tip radius r_a2", _mm(geo.tip_radius_wheel_m), "mm"),
        ("root radius r_f1", _mm(geo.root_radius_pinion_m), "mm"),
        ("root radius r_f2", _mm(geo.root_radius_wheel_m), "mm"),
        ("working pitch radius r_w1", _mm(geo.working_pitch_radius_pinion_m), "mm"),
        ("working pitch radius r_w2", _mm(geo.working_pitch_radius_wheel_m), "mm"),
        ("reference centre distance a", _mm(geo.reference_centre_distance_m), "mm"),
        ("centre distance a_w", _mm(geo.centre_distance_m), "mm"),
        ("normal tip thickness s_an1", _mm(geo.tip_thickness_pinion_m), "mm"),
        ("normal tip thickness s_an2", _mm(geo.tip_thickness_wheel_m), "mm"),
        ("contact (line of action, from T1)", None, ""),
        ("transverse base pitch p_bt", _mm(geo.transverse_base_pitch_m), "mm"),
        ("line of action T1T2", _mm(geo.line_of_action_length_m), "mm"),
        ("contact start A", _mm(geo.contact_start_position_m), "mm"),
        ("single contact start B", _mm(geo.single_start_position_m), "mm"),
        ("pitch point C", _mm(geo.pitch_point_position_m), "mm"),
        ("single contact end D", _mm(geo.single_end_position_m), "mm"),
        ("contact end E", _mm(geo.contact_end_position_m), "mm"),
        ("length of path of contact g_alpha", _mm(geo.path_of_contact_m), "mm"),
        ("transverse contact ratio eps_alpha", geo.transverse_contact_ratio, ""),
        ("overlap ratio eps_beta", geo.overlap_ratio, ""),
        ("total contact ratio eps_gamma", geo.total_contact_ratio, ""),
        ("pitch point phase", geo.pitch_point_phase, ""),
        ("backlash half-width l_u", st.mesh.backlash_um, "µm"),
    ]
    if g.sets_backlash:
        rows.append(
            ("normal backlash j_bn", 2.0 * st.mesh.backlash_um * math.cos(geo.base_helix_angle_rad), "µm")
        )
    return rows


def _cycle_range(P: np.ndarray, z1: int, n: int = 20000) -> tuple[float, float]:
    """(min, max) of the healthy k_z over one period, sampled at ``n`` period midpoints."""
    u = (np.arange(n) + 0.5) / n
    k = _mesh.effective_stiffness_series(angles(u, z1), P)
    return float(k.min()), float(k.max())


def _stiffness_rows(scenario, stage: int, geo) -> list[Row]:
    """Stiffness rows; ``geo`` is the stage's pair geometry (None for a hand-given mesh)."""
    st = scenario.stages[stage]
    mesh = st.mesh
    P = parameters(scenario, stage, healthy=True)
    k_mean = _mesh.mean_stiffness_N_per_m(P)
    k_min, k_max = _cycle_range(P, st.pinion.teeth)
    force = scenario.stage_rated_force_N(stage)
    rows: list[Row] = [
        ("stiffness (healthy teeth)", None, ""),
        ("stiffness profile", mesh.stiffness_profile, ""),
    ]
    if mesh.stiffness_profile == "table":
        rows.append(("k_z table points", len(mesh.table_phase), ""))
    else:
        zone = " (zone mean)" if mesh.stiffness_profile == "potential-energy" else ""
        rows += [
            ("k_z single contact" + zone, mesh.stiffness_single_N_per_m, "N/m"),
            ("k_z double contact" + zone, mesh.stiffness_double_N_per_m, "N/m"),
        ]
    rows += [
        ("k_z mean over a mesh period", k_mean, "N/m"),
        ("k_z min over a mesh period", k_min, "N/m"),
        ("k_z max over a mesh period", k_max, "N/m"),
        ("k_z ripple (max - min)/mean", (k_max - k_min) / k_mean * 100.0, "%"),
        ("rated force F_rated (line of action)", force, "N"),
    ]
    if geo is None:
        return rows
    from gearbody.physics.stiffness_iso import iso_stiffness

    g = mesh.geometry
    line_load = force * math.cos(geo.transverse_pressure_angle_rad) / g.face_width_mm
    iso = iso_stiffness(geo, line_load_N_per_mm=line_load)
    rows += [
        ("ISO 6336-1 method B", None, ""),
        ("line load F_t/b at F_rated", line_load, "N/mm"),
        ("c'_th", iso.c_prime_th_N_per_mm_um, "N/(mm µm)"),
        ("c'", iso.c_prime_N_per_mm_um, "N/(mm µm)"),
        ("c_gamma_alpha", iso.c_gamma_alpha_N_per_mm_um, "N/(mm µm)"),
        ("c_gamma_beta", iso.c_gamma_beta_N_per_mm_um, "N/(mm µm)"),
        ("c' b (single pair)", iso.single_N_per_m, "N/m"),
        ("c_gamma_alpha b (mean)", iso.mesh_alpha_N_per_m, "N/m"),
    ]
    if (
        g.bore_diameter_pinion_mm is not None
        and g.bore_diameter_wheel_mm is not None
        and g.helix_angle_deg == 0
    ):
        from gearbody.physics.mesh_stiffness import pair_stiffness_table

        table = pair_stiffness_table(g, st.pinion.teeth, st.wheel.teeth)
        rows += [
            ("potential energy (Sainsot et al. 2004)", None, ""),
            ("k_z mean over a mesh period", table.mean_stiffness_N_per_m(), "N/m"),
            ("k of one pair, max over its contact", float(table.stiffness_N_per_m.max()), "N/m"),
        ]
    return rows


def table_value(rows: list[Row], name: str, occurrence: int = 0):
    """Value of the ``occurrence``-th row called ``name`` (KeyError if none)."""
    found = [value for n, value, _ in rows if n == name and value is not None]
    if len(found) <= occurrence:
        raise KeyError(name)
    return found[occurrence]
