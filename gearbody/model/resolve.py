"""Resolve meshes stated by gear geometry into the numbers the mesh law uses (docs/scenario.md, "Gear
geometry"): base radii, face widths, contact ratio, pitch-point phase, working pressure angle, backlash
and the single/double stiffness. Values the user also gave must agree with the computed ones (a dumped
scenario reloads unchanged); otherwise the key is refused, naming both values.
"""

from __future__ import annotations

import dataclasses
import math

from .mesh import MESH_DEFAULTS
from .params import ScenarioError, stage_key

_REL_TOL = 1e-9


def _agree(where: str, key: str, given, computed: float) -> float:
    """The value of a key the geometry fixes: the computed one, or the given one when it agrees to 1e-9
    (a resolved scenario.toml re-runs with exactly its own numbers, whatever round-off a later version
    of the geometry code has); a disagreeing value is refused."""
    if given is None:
        return computed
    if not math.isclose(given, computed, rel_tol=_REL_TOL, abs_tol=1e-15):
        raise ScenarioError(
            f"{where}{key} = {given:.10g}: the gear geometry gives {computed:.10g}; leave the key out (it is "
            "computed from [geometry]) or remove the geometry"
        )
    return given


def pair_geometry(mesh, teeth_pinion: int, teeth_wheel: int, where: str = "design.mesh."):
    """:class:`~gearbody.physics.gear_geometry.GearPairGeometry` of a mesh's [geometry] table."""
    from ..physics.exceptions import GearGeometryError
    from ..physics.gear_geometry import gear_pair_geometry

    g = mesh.geometry
    try:
        return gear_pair_geometry(
            module_m=g.module_mm * 1e-3,
            teeth_pinion=teeth_pinion,
            teeth_wheel=teeth_wheel,
            face_width_m=g.face_width_mm * 1e-3,
            pressure_angle_deg=g.pressure_angle_deg,
            helix_angle_deg=g.helix_angle_deg,
            profile_shift_pinion=g.profile_shift_pinion,
            profile_shift_wheel=g.profile_shift_wheel,
            addendum_coefficient=g.addendum_coefficient,
            dedendum_coefficient=g.dedendum_coefficient,
            centre_distance_m=None if g.centre_distance_mm is None else g.centre_distance_mm * 1e-3,
        )
    except GearGeometryError as exc:
        raise ScenarioError(f"{where}geometry: {exc}") from None


def resolve_stage_geometry(pinion, wheel, mesh, where: str):
    """(pinion, wheel, mesh) with everything the geometry fixes filled in; stiffness left for later."""
    if mesh.geometry is None:
        for name, gear in (("pinion", pinion), ("wheel", wheel)):
            if gear.base_radius_m is None:
                raise ScenarioError(
                    f"{where.replace('mesh.', '')}{name}.base_radius_m is required (or give the mesh a "
                    "[geometry] table with module_mm and face_width_mm)"
                )
        return pinion, wheel, mesh
    geo = pair_geometry(mesh, pinion.teeth, wheel.teeth, where)
    _check_pair(geo, mesh, where)
    out_gears = []
    for name, gear, rb in (
        ("pinion", pinion, geo.base_radius_pinion_m),
        ("wheel", wheel, geo.base_radius_wheel_m),
    ):
        gw = where.replace("mesh.", "") + name + "."
        out_gears.append(
            dataclasses.replace(
                gear,
                base_radius_m=_agree(gw, "base_radius_m", gear.base_radius_m, rb),
                face_width_m=_agree(gw, "face_width_m", gear.face_width_m, geo.face_width_m),
            )
        )
    derived = {
        "contact_ratio": _agree(where, "contact_ratio", mesh.contact_ratio, geo.transverse_contact_ratio),
        "pitch_point_phase": _agree(
            where, "pitch_point_phase", mesh.pitch_point_phase, geo.pitch_point_phase
        ),
        "pressure_angle_deg": _agree(
            where, "pressure_angle_deg", mesh.pressure_angle_deg, math.degrees(geo.working_pressure_angle_rad)
        ),
    }
    if mesh.geometry.sets_backlash:
        derived["backlash_um"] = _agree(
            where, "backlash_um", mesh.backlash_um, _backlash_um(geo, mesh, where)
        )
    derived.update(_stiffness_values(mesh, pinion.teeth, wheel.teeth, where))
    return out_gears[0], out_gears[1], dataclasses.replace(mesh, **derived)


def _check_pair(geo, mesh, where: str) -> None:
    """What the mesh law of gearbody can take of a pair's geometry: spur teeth (a helical pair only with
    the ISO stiffness), a transverse contact ratio below 2, the pitch point inside the mesh period."""
    g = mesh.geometry
    if g.helix_angle_deg > 0 and mesh.stiffness_profile != "iso-6336-b":
        raise ScenarioError(
            f"{where}geometry.helix_angle_deg = {g.helix_angle_deg:g}: the potential-energy stiffness and "
            "hand-given profiles are for spur gears; use stiffness_profile = 'iso-6336-b' for a helical pair"
        )
    eps = geo.transverse_contact_ratio
    if eps >= 2.0:
        raise ScenarioError(
            f"{where}geometry: transverse contact ratio {eps:.5f} >= 2; the mesh law of gearbody has at most "
            "two pairs in contact (allowed: 1 <= eps_alpha < 2)"
        )
    pitch = geo.pitch_point_phase
    if not 0.0 <= pitch <= 1.0:
        raise ScenarioError(
            f"{where}geometry: the pitch point lies outside the period's pair's mesh period (phase "
            f"{pitch:.4f}, allowed [0, 1]); balance the addenda or the profile shifts"
        )


def _backlash_um(geo, mesh, where: str) -> float:
    """Half the normal backlash the geometry's thickness allowances and centre-distance deviation give,
    in µm (the mesh's backlash_um); a negative backlash (the teeth jam) is refused."""
    from ..physics.gear_geometry import backlash_half_width_m, normal_backlash_m

    g = mesh.geometry
    allowances = (g.thickness_allowance_pinion_um, g.thickness_allowance_wheel_um)
    j_bn = normal_backlash_m(
        geo,
        thickness_allowance_pinion_m=(allowances[0] or 0.0) * 1e-6,
        thickness_allowance_wheel_m=(allowances[1] or 0.0) * 1e-6,
        centre_distance_deviation_m=g.centre_distance_deviation_um * 1e-6,
    )
    if j_bn < 0:
        raise ScenarioError(
            f"{where}geometry: the allowances give a negative backlash ({j_bn * 1e6:.3g} µm): the teeth jam"
        )
    return backlash_half_width_m(geo, j_bn) * 1e6


def _stiffness_values(mesh, teeth_pinion: int, teeth_wheel: int, where: str) -> dict[str, float]:
    """The single/double stiffness the geometry fixes: the potential-energy profile's zone means (a given
    value must agree), the defaults for the contact-ratio and table profiles where unset; none for the
    ISO profile (computed later, at the rated force)."""
    if mesh.stiffness_profile == "potential-energy":
        from ..physics.mesh_stiffness import pair_stiffness_table

        _check_bores(mesh, teeth_pinion, teeth_wheel, where)
        try:
            table = pair_stiffness_table(mesh.geometry, teeth_pinion, teeth_wheel)
        except ValueError as exc:
            raise ScenarioError(f"{where}{exc}") from None
        except ArithmeticError:
            raise ScenarioError(
                f"{where}geometry: the potential-energy stiffness overflows for this geometry; check "
                "its bore diameters, module and face width"
            ) from None
        single, double = table.zone_means_N_per_m()
        return {
            "stiffness_single_N_per_m": _agree(
                where, "stiffness_single_N_per_m", mesh.stiffness_single_N_per_m, single
            ),
            "stiffness_double_N_per_m": _agree(
                where, "stiffness_double_N_per_m", mesh.stiffness_double_N_per_m, double
            ),
        }
    if mesh.stiffness_profile in ("contact-ratio", "table"):
        keys = ("stiffness_single_N_per_m", "stiffness_double_N_per_m")
        return {key: MESH_DEFAULTS[key] for key in keys if getattr(mesh, key) is None}
    return {}


def _check_bores(mesh, teeth_pinion: int, teeth_wheel: int, where: str) -> None:
    """A bore lies inside its gear's root circle (the rim under the teeth has a thickness)."""
    from ..physics.mesh_stiffness import spur_pair

    try:
        pair = spur_pair(mesh.geometry, teeth_pinion, teeth_wheel)
    except ValueError as exc:
        raise ScenarioError(f"{where}{exc}") from None
    for name, gear in (("pinion", pair.pinion), ("wheel", pair.wheel)):
        if not gear.bore_radius_m < gear.root_radius_m:
            raise ScenarioError(
                f"{where}geometry.bore_diameter_{name}_mm = {2e3 * gear.bore_radius_m:g}: must be < the "
                f"{name}'s root diameter {2e3 * gear.root_radius_m:.4g} mm"
            )


def resolve_iso_stiffness(mesh, teeth_pinion: int, teeth_wheel: int, rated_force_N: float, where: str):
    """Mesh with the ISO 6336-1 method B single/double stiffness; line load F_t / b with the rated
    tangential force at the reference circle, F_t = F_rated cos(alpha_t) (F_rated: line of action)."""
    from ..physics.exceptions import GearGeometryError
    from ..physics.stiffness_iso import iso_mesh_stiffness_profile

    geo = pair_geometry(mesh, teeth_pinion, teeth_wheel, where)
    line_load = rated_force_N * math.cos(geo.transverse_pressure_angle_rad) / mesh.geometry.face_width_mm
    try:
        single, double = iso_mesh_stiffness_profile(geo, line_load_N_per_mm=line_load)
    except GearGeometryError as exc:
        raise ScenarioError(str(exc)) from None
    return dataclasses.replace(
        mesh,
        stiffness_single_N_per_m=_agree(
            where, "stiffness_single_N_per_m", mesh.stiffness_single_N_per_m, single
        ),
        stiffness_double_N_per_m=_agree(
            where, "stiffness_double_N_per_m", mesh.stiffness_double_N_per_m, double
        ),
    )


def resolve_planetary_iso(stage, rated_force_N: float, k: int):
    """A planetary stage with each iso-6336-b mesh's single/double stiffness computed at the rated force
    per planet mesh (line load F_rated cos(alpha) / b); a given value must agree (as for parallel meshes)."""
    from ..physics.stiffness_iso import planetary_mesh_stiffness_profile

    changes = {}
    for name, teeth_2 in (("sun_mesh", stage.sun.teeth), ("ring_mesh", None)):
        mesh = getattr(stage, name)
        if mesh.stiffness_profile != "iso-6336-b":
            continue
        alpha = math.radians(stage.pressure_angle_deg)
        single, double = planetary_mesh_stiffness_profile(
            teeth_1=stage.planet.teeth,
            teeth_2=teeth_2,
            face_width_m=mesh.face_width_mm * 1e-3,
            pressure_angle_deg=stage.pressure_angle_deg,
            line_load_N_per_mm=rated_force_N * math.cos(alpha) / mesh.face_width_mm,
        )
        where = stage_key(k, name + ".")
        changes[name] = dataclasses.replace(
            mesh,
            stiffness_single_N_per_m=_agree(
                where, "stiffness_single_N_per_m", mesh.stiffness_single_N_per_m, single
            ),
            stiffness_double_N_per_m=_agree(
                where, "stiffness_double_N_per_m", mesh.stiffness_double_N_per_m, double
            ),
        )
    return dataclasses.replace(stage, **changes) if changes else stage


def resolve_design(design):
    """The design with every stage resolved by its kind (``resolve_geometry``, then ``resolve_rating`` at
    its rated force): a parallel stage's gears and mesh (base radii, contact ratio, pitch point,
    backlash, stiffness), then the ISO stiffness at each stage's rated force, and the damaged teeth
    checked against the stiffness profile they need. Pure: returns a new Design."""
    from .kinds import stage_kind

    stages = []
    for k, st in enumerate(design.stages):
        hook = stage_kind(st).resolve_geometry
        stages.append(st if hook is None else hook(st, k))
    design = dataclasses.replace(design, stages=tuple(stages))
    for k, st in enumerate(design.stages):
        hook = stage_kind(st).resolve_rating
        if hook is not None:
            stages[k] = hook(st, k, design.stage_rated_force_N(k))
    return dataclasses.replace(design, stages=tuple(stages))


def resolve_parallel_geometry(st, k: int):
    """A parallel stage with its [geometry] resolved: gears and mesh."""
    p, w, m = resolve_stage_geometry(st.pinion, st.wheel, st.mesh, stage_key(k, "mesh."))
    return dataclasses.replace(st, pinion=p, wheel=w, mesh=m)


def resolve_parallel_rating(st, k: int, rated_force_N: float):
    """A parallel stage with its ISO stiffness at its rated force, its damaged teeth checked."""
    where = stage_key(k, "mesh.")
    resolved = st
    if st.mesh.stiffness_profile == "iso-6336-b":
        mesh = resolve_iso_stiffness(st.mesh, st.pinion.teeth, st.wheel.teeth, rated_force_N, where)
        resolved = dataclasses.replace(st, mesh=mesh)
    for tooth in st.damaged_teeth:
        if tooth.has_geometric_damage and st.mesh.stiffness_profile != "potential-energy":
            raise ScenarioError(
                f"{stage_key(k, 'damaged_teeth')}: {tooth.gear} tooth {tooth.tooth} has a crack, "
                f"breakage or spall; these need {where}stiffness_profile = 'potential-energy' (got "
                f"{st.mesh.stiffness_profile!r})"
            )
    if st.mesh.stiffness_profile == "potential-energy" and any(
        t.has_geometric_damage for t in st.damaged_teeth
    ):
        from ..physics.mesh_stiffness import stage_pair_table

        try:
            stage_pair_table(st)
        except ValueError as exc:
            raise ScenarioError(f"{stage_key(k, 'damaged_teeth')}: {exc}") from None
        except ArithmeticError:
            raise ScenarioError(
                f"{stage_key(k, 'damaged_teeth')}: the damaged teeth's potential-energy stiffness "
                "overflows; check their damage sizes and the mesh's geometry"
            ) from None
    return resolved
