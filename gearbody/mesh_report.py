"""Mesh report of a scenario's gear stages (``gearbody mesh SCENE``): geometry table, k_z over the mesh
cycle (healthy, and around each damaged tooth) and the static transmission error under load.

Engine-free (no Exudyn): everything is evaluated with the mesh law of :mod:`gearbody.physics.mesh` and the
scenario's packed parameters, so the curves are exactly what the solver uses. The functions here return
plain dataclasses, arrays and text (testable); :func:`gearbody.mesh_plots.plot_stage` draws them, one PNG
per stage. docs/mesh.md describes the output.

Coordinates: ``u = phi_p z1 / (2 pi)`` counts mesh periods along the pinion angle phi_p; period
``n = floor(u)`` is the pair of pinion tooth ``n mod z1`` and wheel tooth ``n mod z2``, at mesh phase
``p = u - n`` (docs/scenario.md, "Phase convention").
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .physics import mesh as _mesh
from .physics.mesh_stiffness import static_transmission_error_m

__all__ = [
    "DamageWindow",
    "StaticTransmissionError",
    "StiffnessCycle",
    "damage_windows",
    "format_table",
    "geometry_table",
    "stage_label",
    "static_transmission_error",
    "stiffness_cycle",
    "summary_text",
    "table_value",
]

Row = tuple[str, object, str]  # (name, value, unit); value None: a section heading


# -- parameters ------------------------------------------------------------------------------------
def _healthy_scenario(scenario, stage: int):
    """The scenario with stage ``stage``'s gears perfect: no damaged or pitted teeth, no run-out, no
    tooth errors (e_um = 0). Re-validated (dataclasses.replace runs the checks; the values agree)."""
    if scenario.meta.scene == "train":
        stages = list(scenario.design.stages)
        st = stages[stage]
        stages[stage] = dataclasses.replace(
            st,
            damaged_teeth=(),
            pitted_teeth=(),
            eccentricity=(),
            error_mode=dataclasses.replace(st.error_mode, e_um=0.0),
        )
        return dataclasses.replace(
            scenario, design=dataclasses.replace(scenario.design, stages=tuple(stages))
        )
    return dataclasses.replace(
        scenario,
        production=dataclasses.replace(
            scenario.production,
            error_mode=dataclasses.replace(scenario.production.error_mode, e_um=0.0),
            eccentricity=(),
        ),
        condition=dataclasses.replace(scenario.condition, damaged_teeth=(), pitted_teeth=()),
    )


def _stage(scenario, stage: int):
    """The scenario's stage ``stage`` (0-based); IndexError if there is none."""
    n = len(scenario.stages)
    if not (isinstance(stage, int) and 0 <= stage < n):
        raise IndexError(f"stage = {stage!r}: the scenario has {n} stage(s) (0-based index 0..{n - 1})")
    return scenario.stages[stage]


def _parameters(scenario, stage: int, healthy: bool = False) -> np.ndarray:
    """Packed mesh parameters (friction off: it does not enter k_z, E or the static TE)."""
    source = _healthy_scenario(scenario, stage) if healthy else scenario
    return _mesh.mesh_parameters_from_scenario(source, stage, friction=False)


def _parameter_pair(scenario, stage: int) -> tuple[np.ndarray, np.ndarray]:
    """Packed mesh parameters as given and with perfect gears (:func:`_healthy_scenario`)."""
    return _parameters(scenario, stage), _parameters(scenario, stage, healthy=True)


def _half_double(mesh) -> float:
    """h = (eps_alpha - 1)/2: double contact for mesh phase p < h and p >= 1 - h."""
    return 0.5 * (mesh.contact_ratio - 1.0)


def _angles(periods: np.ndarray, z1: int) -> np.ndarray:
    return np.ascontiguousarray(2.0 * math.pi * np.asarray(periods, float) / z1)


def stage_label(scenario, stage: int) -> str:
    """ "stage 1 of 2 (design.stages[0])" or "stage 1 of 1 (design.mesh)"."""
    where = f"design.stages[{stage}]" if scenario.meta.scene == "train" else "design.mesh"
    return f"stage {stage + 1} of {len(scenario.stages)} ({where})"


# -- geometry table --------------------------------------------------------------------------------
def _mm(x_m: float) -> float:
    return x_m * 1e3


def geometry_table(scenario, stage: int = 0) -> list[Row]:
    """Rows (name, value, unit) of one stage (0-based): teeth, geometry (when the mesh states it),
    contact ratios, backlash and the stiffness (profile, single/double/mean k_z, ISO 6336-1 method B,
    potential-energy mean). Section headings are rows with value None. A hand-given mesh (no
    [geometry]) lists what is known and says that the geometry is not given."""
    from .model.resolve import pair_geometry

    st = _stage(scenario, stage)
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
    k = _mesh.effective_stiffness_series(_angles(u, z1), P)
    return float(k.min()), float(k.max())


def _stiffness_rows(scenario, stage: int, geo) -> list[Row]:
    """Stiffness rows; ``geo`` is the stage's pair geometry (None for a hand-given mesh)."""
    st = scenario.stages[stage]
    mesh = st.mesh
    P = _parameters(scenario, stage, healthy=True)
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
    from .physics.stiffness_iso import iso_stiffness

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
        from .physics.mesh_stiffness import pair_stiffness_table

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


def _format_value(value) -> str:
    if isinstance(value, bool | str):
        return str(value)
    if isinstance(value, int | np.integer):
        return str(int(value))
    v = float(value)
    if v != 0.0 and (abs(v) >= 1e6 or abs(v) < 1e-3):
        return f"{v:.5e}"
    return f"{v:.6g}"


def format_table(rows: list[Row], title: str = "") -> str:
    """The rows as aligned text: name, value, unit; headings on their own lines."""
    width = max((len(n) for n, v, _ in rows if v is not None), default=10) + 2
    lines = [title] if title else []
    for name, value, unit in rows:
        if value is None:
            lines.append(f"  {name}")
        else:
            lines.append(f"    {name:<{width}}{_format_value(value):>14}  {unit}".rstrip())
    return "\n".join(lines)


# -- stiffness over the mesh cycle -----------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class StiffnessCycle:
    """Healthy k_z over ``periods`` mesh periods from p = 0 of the stage's first pair (tooth 0)."""

    periods: np.ndarray  # u = phi_p z1 / 2 pi
    stiffness_N_per_m: np.ndarray
    half_double: float  # h = (eps_alpha - 1)/2: double contact for p < h and p >= 1 - h
    pitch_point_phase: float
    mean_N_per_m: float
    profile: str


def stiffness_cycle(
    scenario, stage: int = 0, periods: int = 2, points_per_period: int = 400
) -> StiffnessCycle:
    """k_z of healthy teeth over ``periods`` mesh periods, as the solver evaluates it."""
    st = _stage(scenario, stage)
    P = _parameters(scenario, stage, healthy=True)
    u = np.arange(periods * points_per_period + 1) / points_per_period
    u[-1] -= 1e-9  # stay inside the last period
    return StiffnessCycle(
        periods=u,
        stiffness_N_per_m=_mesh.effective_stiffness_series(_angles(u, st.pinion.teeth), P),
        half_double=_half_double(st.mesh),
        pitch_point_phase=st.mesh.pitch_point_phase,
        mean_N_per_m=_mesh.mean_stiffness_N_per_m(P),
        profile=st.mesh.stiffness_profile,
    )


@dataclasses.dataclass(frozen=True)
class DamageWindow:
    """k_z around the periods in which one damaged tooth's pair meshes, as given and healthy."""

    gear: str
    tooth: int
    description: str
    periods: np.ndarray  # u = phi_p z1 / 2 pi
    stiffness_N_per_m: np.ndarray
    healthy_stiffness_N_per_m: np.ndarray
    contact: tuple[float, float]  # u span [start, end) where the tooth acts on k_z

    @property
    def ratio(self) -> np.ndarray:
        """k_z / k_z,healthy (1 where both are 0)."""
        k, k0 = self.stiffness_N_per_m, self.healthy_stiffness_N_per_m
        return np.divide(k, k0, out=np.ones_like(k), where=k0 > 0)

    @property
    def min_ratio(self) -> float:
        """Least k_z / k_z,healthy while the tooth acts (within ``contact``)."""
        inside = (self.periods >= self.contact[0]) & (self.periods < self.contact[1])
        return float(self.ratio[inside].min()) if inside.any() else 1.0


def _describe(tooth) -> str:
    parts = []
    if tooth.stiffness_factor < 1.0:
        parts.append(f"stiffness factor {tooth.stiffness_factor:g}")
    if tooth.crack_depth_mm > 0:
        parts.append(f"root crack {tooth.crack_depth_mm:g} mm at {tooth.crack_angle_deg:g} deg")
    if tooth.broken_height_fraction > 0:
        parts.append(
            f"tip broken off, {tooth.broken_height_fraction:.0%} of the height over "
            f"{tooth.broken_width_fraction:.0%} of the face width"
        )
    if tooth.spall_width_fraction > 0:
        parts.append(
            f"spall d = {tooth.spall_start_diameter_mm:g}..{tooth.spall_end_diameter_mm:g} mm, "
            f"{tooth.spall_width_fraction:.0%} of the contact width"
        )
    return ", ".join(parts) or "no damage"


def _first_period(gear: str, tooth: int, z1: int, z2: int) -> int:
    """First period n >= 0 whose pair contains the tooth (n mod z1 = tooth, or n mod z2 = tooth)."""
    return tooth % z1 if gear == "pinion" else tooth % z2


def damage_windows(
    scenario, stage: int = 0, before: float = 1.5, after: float = 2.5, points_per_period: int = 400
) -> list[DamageWindow]:
    """One window per damaged tooth of the stage (stiffness factor < 1 or crack/breakage/spall): k_z
    over periods ``n0 - before .. n0 + after`` around the first period n0 of that tooth's pair."""
    st = _stage(scenario, stage)
    z1, z2 = st.pinion.teeth, st.wheel.teeth
    P, P0 = _parameter_pair(scenario, stage)
    h = _half_double(st.mesh)
    whole_contact = st.mesh.stiffness_profile == "potential-energy"
    merged: dict[tuple[str, int], list] = {}
    for tooth in st.damaged_teeth:
        if tooth.stiffness_factor < 1.0 or tooth.has_geometric_damage:
            merged.setdefault((tooth.gear, tooth.tooth), []).append(tooth)
    out = []
    for (gear, index), teeth in sorted(merged.items()):
        n0 = _first_period(gear, index, z1, z2)
        n = int(round((before + after) * points_per_period))
        u = n0 - before + (np.arange(n) + 0.5) / points_per_period
        phi = _angles(u, z1)
        out.append(
            DamageWindow(
                gear=gear,
                tooth=index,
                description="; ".join(_describe(t) for t in teeth),
                periods=u,
                stiffness_N_per_m=_mesh.effective_stiffness_series(phi, P),
                healthy_stiffness_N_per_m=_mesh.effective_stiffness_series(phi, P0),
                contact=(n0 - h, n0 + 1 + h) if whole_contact else (float(n0), n0 + 1.0),
            )
        )
    return out


# -- static transmission error ---------------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class StaticTransmissionError:
    """Loaded static TE along the line of action, TE = F/k(p) - E(p) + l_u, over whole pinion turns."""

    periods: np.ndarray  # u = phi_p z1 / 2 pi
    pinion_turns: int
    force_N: float
    rated_force_N: float
    backlash_um: float
    te_um: np.ndarray  # as given: damage, tooth errors, run-out, pits
    healthy_te_um: np.ndarray  # perfect gears: F/k_healthy + l_u
    stiffness_N_per_m: np.ndarray
    healthy_stiffness_N_per_m: np.ndarray
    error_um: np.ndarray  # E(p) as given

    @property
    def load_fraction(self) -> float:
        return self.force_N / self.rated_force_N


def _turns(st) -> int:
    """Pinion turns that show every damaged or pitted tooth (wheel teeth >= z1 need more than one)."""
    z1 = st.pinion.teeth
    last = max(
        [t.tooth + 2 for t in (*st.damaged_teeth, *st.pitted_teeth) if t.gear == "wheel"],
        default=0,
    )
    return max(1, math.ceil(last / z1))


def static_transmission_error(
    scenario, stage: int = 0, load_fraction: float = 1.0, points_per_period: int = 200
) -> StaticTransmissionError:
    """Static TE at ``load_fraction`` of the stage's rated force over one pinion turn (or the turns that
    reach the damaged or pitted wheel teeth), µm: as given and with perfect gears."""
    st = _stage(scenario, stage)
    if not (math.isfinite(load_fraction) and load_fraction >= 0.0):
        raise ValueError(f"load_fraction = {load_fraction!r}: must be finite and >= 0")
    z1 = st.pinion.teeth
    P, P0 = _parameter_pair(scenario, stage)
    turns = _turns(st)
    u = (np.arange(turns * z1 * points_per_period) + 0.5) / points_per_period
    phi = _angles(u, z1)
    k, k0 = _mesh.effective_stiffness_series(phi, P), _mesh.effective_stiffness_series(phi, P0)
    error = _mesh.mesh_gap_series(phi, np.zeros_like(phi), P)
    rated = scenario.stage_rated_force_N(stage)
    force = load_fraction * rated
    lu = st.mesh.backlash_um * 1e-6
    return StaticTransmissionError(
        periods=u,
        pinion_turns=turns,
        force_N=force,
        rated_force_N=rated,
        backlash_um=st.mesh.backlash_um,
        te_um=static_transmission_error_m(k, force, error, lu) * 1e6,
        healthy_te_um=static_transmission_error_m(k0, force, 0.0, lu) * 1e6,
        stiffness_N_per_m=k,
        healthy_stiffness_N_per_m=k0,
        error_um=error * 1e6,
    )


# -- text summary ----------------------------------------------------------------------------------
def _stage_data(scenario, stage: int, load_fraction: float, cycle, windows, te):
    """(cycle, windows, te) of a stage for :func:`summary_text` and ``plot_stage``: those passed in (not
    None), the others computed with default sampling."""
    return (
        stiffness_cycle(scenario, stage) if cycle is None else cycle,
        damage_windows(scenario, stage) if windows is None else windows,
        static_transmission_error(scenario, stage, load_fraction) if te is None else te,
    )


def _tooth_label(w: DamageWindow) -> str:
    return f"{w.gear} tooth {w.tooth}"


def _load_label(te: StaticTransmissionError) -> str:
    return f"{te.load_fraction * 100:.3g} % of F_rated"


def _stats(x: np.ndarray) -> str:
    finite = x[np.isfinite(x)]
    lost = x.size - finite.size
    text = (
        f"mean {finite.mean():.3f}, min {finite.min():.3f}, max {finite.max():.3f}, "
        f"peak-to-peak {finite.max() - finite.min():.3f} µm"
    )
    return text + (f" ({lost} samples with k_z = 0: no contact)" if lost else "")


def summary_text(
    scenario,
    stage: int = 0,
    load_fraction: float = 1.0,
    cycle: StiffnessCycle | None = None,
    windows: list[DamageWindow] | None = None,
    te: StaticTransmissionError | None = None,
) -> str:
    """Printed summary of one stage: the geometry table, k_z over the cycle, the damaged teeth and the
    static TE (computed here unless passed in)."""
    cycle, windows, te = _stage_data(scenario, stage, load_fraction, cycle, windows, te)
    lines = [format_table(geometry_table(scenario, stage), stage_label(scenario, stage))]
    lines.append("  damaged teeth" if windows else "  damaged teeth: none")
    for w in windows:
        lines.append(
            f"    {_tooth_label(w)} ({w.description}): min k_z/k_z,healthy {w.min_ratio:.4f}, "
            f"acts over u = {w.contact[0]:.3f} .. {w.contact[1]:.3f} mesh periods"
        )
    inv_mean = float(np.mean(1.0 / te.healthy_stiffness_N_per_m))
    lines.append(
        f"  static transmission error at F = {te.force_N:.6g} N ({_load_label(te)} "
        f"{te.rated_force_N:.6g} N), l_u = {te.backlash_um:.4g} µm, over {te.pinion_turns} pinion turn(s)"
    )
    lines.append(
        f"    F/k_mean {te.force_N / cycle.mean_N_per_m * 1e6:.3f} µm, "
        f"mean F/k {te.force_N * inv_mean * 1e6:.3f} µm (healthy)"
    )
    lines.append(f"    healthy:  {_stats(te.healthy_te_um)}")
    lines.append(f"    as given: {_stats(te.te_um)}")
    return "\n".join(lines)
