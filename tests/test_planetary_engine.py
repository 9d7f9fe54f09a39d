"""The planetary stage on Exudyn (gearbody.engine.planetary): static load sharing and reactions by hand,
energy conservation of the free stage (every force a gradient, Exudyn's planar rigid bodies carrying the
planets' centripetal motion), and rigid rolling without load."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearbody.assembly.planetary_layout import PlanetaryLayout, PlanetaryMember, rigid_speeds_rad_s
from gearbody.engine.planetary import build_planetary, planetary_mesh_forces, solve_planetary
from gearbody.physics.mesh import pack_mesh_parameters
from gearbody.physics.planetary_mesh import pair_deflection

ALPHA0 = math.radians(20.0)
MODULE = 0.004
Z_S, Z_P, Z_R = 21, 30, 81
R_S, R_P, R_R = (MODULE * z / 2 for z in (Z_S, Z_P, Z_R))
RB_S, RB_P, RB_R = (r * math.cos(ALPHA0) for r in (R_S, R_P, R_R))
K_MESH = 5e8


def _mesh(z1, z2, r1, r2, damping=0.0):
    return pack_mesh_parameters(
        r1_m=r1, r2_m=r2, z1=z1, z2=z2, stiffness_single_N_per_m=K_MESH, stiffness_double_N_per_m=K_MESH,
        contact_ratio=1.6, damping_Ns_per_m=damping, backlash_m=0.0, friction_coefficient=0.0,
        pitch_point_phase=0.5, pressure_angle_rad=ALPHA0, error_a=0.0, error_depths_m=np.zeros(z1),
    )  # fmt: skip


def _layout(n_planets=3, *, damping=0.0, torsion=1e7):
    c = damping
    held = (
        {"torsion_stiffness_Nm_per_rad": torsion, "torsion_damping_Nms_per_rad": 0.025 * c} if torsion else {}
    )
    return PlanetaryLayout(
        sun=PlanetaryMember("sun", 0.5, 0.5 * 0.5 * R_S**2, 1e8, c),
        ring=PlanetaryMember("ring", 3.0, 3.0 * R_R**2, 1e8, c, **held),
        carrier=PlanetaryMember("carrier", 5.0, 0.6 * 5.0 * (R_S + R_P) ** 2, 1e8, c, **held),
        planet=PlanetaryMember("planet", 0.8, 0.5 * 0.8 * R_P**2, 1e8, c),
        planet_angles_rad=tuple(2 * math.pi * n / n_planets for n in range(n_planets)),
        carrier_radius_m=R_S + R_P,
        base_radius_sun_m=RB_S,
        base_radius_planet_m=RB_P,
        base_radius_ring_m=RB_R,
        sun_mesh=_mesh(Z_S, Z_P, RB_S, RB_P, c),
        ring_mesh=_mesh(Z_R, Z_P, RB_R, RB_P, c),
    )


def test_a_sun_torque_is_shared_equally_and_the_reactions_balance():
    """Ring and carrier held by torsional supports: at rest every planet carries T / (N r_bs) on both
    meshes; the ring reacts T r_br / r_bs and the carrier T (1 + r_br / r_bs)."""
    T, n = 100.0, 3
    system = build_planetary(_layout(n, damping=2000.0), torques_Nm={"sun": T})
    states = solve_planetary(system, 0.1)
    forces = planetary_mesh_forces(system, states)
    for k in range(1, n + 1):
        for mesh in ("sun", "ring"):
            assert forces[f"planet_{k}_{mesh}_mesh_force_N"][-1] == pytest.approx(T / (n * RB_S), rel=1e-6)
    assert -1e7 * states["ring_q"][-1, 2] == pytest.approx(T * RB_R / RB_S, rel=1e-6)
    assert -1e7 * states["carrier_q"][-1, 2] == pytest.approx(-T * (1 + RB_R / RB_S), rel=1e-6)


def _energy(system, states) -> np.ndarray:
    """Kinetic + mesh + bearing energy of the undamped stage, computed here from the recorded states."""
    lay = system.layout
    E = np.zeros(len(states["time_s"]))
    for name, member in (("sun", lay.sun), ("ring", lay.ring), ("carrier", lay.carrier)):
        q, v = states[f"{name}_q"], states[f"{name}_v"]
        E += 0.5 * member.mass_kg * (v[:, 0] ** 2 + v[:, 1] ** 2) + 0.5 * member.inertia_kg_m2 * v[:, 2] ** 2
        E += 0.5 * member.bearing_stiffness_N_per_m * (q[:, 0] ** 2 + q[:, 1] ** 2)
    for n, psi in enumerate(lay.planet_angles_rad):
        G = lay.geometry(n)
        q, v = states[f"planet_{n + 1}_q"], states[f"planet_{n + 1}_v"]
        E += (
            0.5 * lay.planet.mass_kg * (v[:, 0] ** 2 + v[:, 1] ** 2)
            + 0.5 * lay.planet.inertia_kg_m2 * v[:, 2] ** 2
        )
        for i in range(len(E)):
            s, r, c = states["sun_q"][i], states["ring_q"][i], states["carrier_q"][i]
            phi_ref = c[2] + psi
            d_s = pair_deflection(np.r_[s, q[i]], RB_S, RB_P, False, phi_ref)[0] - G[9]
            d_r = pair_deflection(np.r_[r, q[i]], RB_R, RB_P, True, phi_ref)[0] - G[10]
            point = c[:2] + lay.carrier_radius_m * np.array([math.cos(phi_ref), math.sin(phi_ref)])
            e = q[i, :2] - point
            E[i] += 0.5 * K_MESH * (d_s**2 + d_r**2) + 0.5 * lay.planet.bearing_stiffness_N_per_m * float(
                e @ e
            )
    return E


def test_the_free_undamped_stage_conserves_energy_while_its_planets_circle():
    """No supports in torsion, no damping: started rigidly at 300 rad/s sun and 60 rad/s carrier, the
    planets' centripetal load stretches their bearings and sets the stage vibrating; the total energy
    stays constant (a sign or arm error in any of the forces, or a wrong reference, would break it)."""
    lay = _layout(3, torsion=None)
    system = build_planetary(lay, sun_speed_rad_s=300.0, carrier_speed_rad_s=60.0)
    states = solve_planetary(system, 0.02, absolute_tolerance=1e-10)
    E = _energy(system, states)
    assert states["carrier_q"][-1, 2] == pytest.approx(60.0 * 0.02, rel=0.01)  # ~1.2 rad: planets moved
    assert np.ptp(E) / E[0] < 1e-10, np.ptp(E) / E[0]  # measured 7e-15 over 5 ms
    forces = planetary_mesh_forces(system, states)
    assert np.ptp(forces["planet_1_sun_mesh_force_N"]) > 1.0  # it does vibrate (centripetal load)


def test_rigid_rolling_with_the_carrier_at_rest_loads_no_mesh():
    """Carrier at rest (no centripetal load), sun at 300 rad/s, ring and planets at their rolling speeds:
    over 10 sun revolutions' worth of angle the meshes stay unloaded and the speeds unchanged."""
    lay = _layout(3, torsion=None)
    system = build_planetary(lay, sun_speed_rad_s=300.0, carrier_speed_rad_s=0.0)
    states = solve_planetary(system, 0.2)
    forces = planetary_mesh_forces(system, states)
    for name, f in forces.items():
        assert np.max(np.abs(f)) < 1e-3, name  # of ~800 N under 100 N m
    speeds = rigid_speeds_rad_s(lay, 300.0, 0.0)
    assert speeds["ring"] == pytest.approx(-300.0 * RB_S / RB_R)
    assert states["ring_v"][-1, 2] == pytest.approx(speeds["ring"], rel=1e-9)
    assert states["planet_2_v"][-1, 2] == pytest.approx(speeds["planet"], rel=1e-9)


@pytest.mark.parametrize("angles_deg", [(0, 90, 180, 270), (0, 80, 200, 290)])
def test_the_exudyn_stage_at_rest_has_the_lin_parker_natural_frequencies(angles_deg):
    """Exudyn's linearisation of the stage at rest (numerical Jacobian of the user functions) against the
    hand-built Lin & Parker (1999) matrices of gearbody.physics.planetary_modal, same parameters: two
    independent assemblies of the same physics. Measured: 5.6e-7 relative (equal spacing)."""
    from gearbody.physics.planetary_modal import PlanetaryModalParameters, natural_modes

    base = _layout(4)
    lay = PlanetaryLayout(
        **{**base.__dict__, "planet_angles_rad": tuple(math.radians(a) for a in angles_deg)}
    )
    system = build_planetary(lay)
    values, _ = system.mbs.ComputeODE2Eigenvalues(
        useSparseSolver=False, convert2Frequencies=False, useAbsoluteValues=True
    )
    f_exudyn = np.sort(np.sqrt(np.abs(np.asarray(values))) / (2 * math.pi))
    rc = lay.carrier_radius_m
    p = PlanetaryModalParameters(
        carrier_mass_kg=lay.carrier.mass_kg, ring_mass_kg=lay.ring.mass_kg, sun_mass_kg=lay.sun.mass_kg,
        planet_mass_kg=lay.planet.mass_kg, carrier_rotary_mass_kg=lay.carrier.inertia_kg_m2 / rc**2,
        ring_rotary_mass_kg=lay.ring.inertia_kg_m2 / RB_R**2,
        sun_rotary_mass_kg=lay.sun.inertia_kg_m2 / RB_S**2,
        planet_rotary_mass_kg=lay.planet.inertia_kg_m2 / RB_P**2, carrier_bearing_N_per_m=1e8,
        ring_bearing_N_per_m=1e8, sun_bearing_N_per_m=1e8, planet_bearing_N_per_m=1e8,
        carrier_torsion_N_per_m=1e7 / rc**2, ring_torsion_N_per_m=1e7 / RB_R**2, sun_torsion_N_per_m=0.0,
        sun_mesh_N_per_m=K_MESH, ring_mesh_N_per_m=K_MESH, sun_pressure_angle_rad=ALPHA0,
        ring_pressure_angle_rad=ALPHA0, planet_angles_rad=lay.planet_angles_rad,
    )  # fmt: skip
    modes = natural_modes(p)
    f_lp = np.sort([g.frequency_hz for g in modes.groups for _ in range(g.multiplicity)])
    assert f_exudyn.size == f_lp.size == 21
    np.testing.assert_allclose(f_exudyn, f_lp, rtol=1e-5)


def _phasing_stage(z_s: int, z_p: int, z_r: int) -> tuple[PlanetaryLayout, float]:
    """Three equally spaced planets, time-varying mesh stiffness (4e8 / 6e8 N/m, contact ratio 1.6), ring
    held, carrier loaded by a viscous damper; returns the layout and the steady carrier speed."""
    from gearbody.physics.planetary import PlanetaryGeometry

    g = PlanetaryGeometry(z_sun=z_s, z_planet=z_p, z_ring=z_r, n_planets=3, module_m=MODULE)
    rbs, rbp, rbr = g.sun_base_radius_m, g.planet_base_radius_m, g.ring_base_radius_m

    def mesh(z1, z2, r1, r2):
        return pack_mesh_parameters(
            r1_m=r1, r2_m=r2, z1=z1, z2=z2, stiffness_single_N_per_m=4e8, stiffness_double_N_per_m=6e8,
            contact_ratio=1.6, damping_Ns_per_m=1500.0, backlash_m=0.0, friction_coefficient=0.0,
            pitch_point_phase=0.5, pressure_angle_rad=ALPHA0, error_a=0.0, error_depths_m=np.zeros(z1),
        )  # fmt: skip

    c_load = 24.3
    rs, rp, rr = g.sun_pitch_radius_m, g.planet_pitch_radius_m, g.ring_pitch_radius_m
    lay = PlanetaryLayout(
        sun=PlanetaryMember("sun", 0.5, 0.25 * rs**2, 1e8, 1000.0),
        ring=PlanetaryMember("ring", 3.0, 3.0 * rr**2, 1e8, 1000.0, 1e7, 20.0),
        carrier=PlanetaryMember("carrier", 5.0, 3.0 * (rs + rp) ** 2, 1e8, 1000.0, 0.0, c_load),
        planet=PlanetaryMember("planet", 0.8, 0.4 * rp**2, 1e8, 1000.0),
        planet_angles_rad=g.planet_angles_rad or tuple(2 * math.pi * k / 3 for k in range(3)),
        carrier_radius_m=g.carrier_radius_m,
        base_radius_sun_m=rbs, base_radius_planet_m=rbp, base_radius_ring_m=rbr,
        sun_mesh=mesh(z_s, z_p, rbs, rbp), ring_mesh=mesh(z_r, z_p, rbr, rbp),
    )  # fmt: skip
    return lay, 100.0 * (1 + rbr / rbs) / c_load


@pytest.mark.slow
@pytest.mark.parametrize(
    "teeth", [(21, 30, 81), (22, 29, 80)]
)  # in phase (z_s, z_r multiples of N); sequential
def test_each_planets_mesh_phase_follows_from_its_position_and_the_teeth(teeth):
    """Steady running under a sun torque: the mesh-frequency component of planet n's sun- and ring-mesh
    forces lags planet 1's by the delays of gearbody.physics.planetary.planet_mesh_phases (z psi_n / 2 pi
    mod 1 of a mesh period; no phase parameter was given to the Exudyn model: they come from the planets'
    positions). Measured: in phase 0 / 0 / 0; sequential 0 / 0.330 / 0.666 against 0 / 1/3 / 2/3."""
    from gearbody.physics.planetary import PlanetaryGeometry, planet_mesh_phases

    z_s, z_p, z_r = teeth
    lay, w_c = _phasing_stage(*teeth)
    w_s = w_c * (1 + lay.base_radius_ring_m / lay.base_radius_sun_m)
    system = build_planetary(lay, torques_Nm={"sun": 100.0}, sun_speed_rad_s=w_s, carrier_speed_rad_s=w_c)
    states = solve_planetary(system, 0.25)
    forces = planetary_mesh_forces(system, states)
    t = states["time_s"]
    sel = t > 0.2
    f_m = z_s * (states["sun_v"][sel, 2].mean() - states["carrier_v"][sel, 2].mean()) / (2 * math.pi)
    g = PlanetaryGeometry(z_sun=z_s, z_planet=z_p, z_ring=z_r, n_planets=3, module_m=MODULE)
    expected = planet_mesh_phases(g).delays(sun_ccw_relative_to_carrier=True)
    for mesh, delays in zip(("sun", "ring"), expected, strict=True):
        c = [
            np.trapezoid((f - f.mean()) * np.exp(-2j * math.pi * f_m * t[sel]), t[sel])
            for f in (forces[f"planet_{k}_{mesh}_mesh_force_N"][sel] for k in (1, 2, 3))
        ]
        lag = [(-np.angle(ck / c[0]) / (2 * math.pi)) % 1.0 for ck in c]
        for measured, want in zip(lag, delays, strict=True):
            assert min(abs(measured - want), 1 - abs(measured - want)) < 0.01, (mesh, lag, delays)


def test_contact_ratios_of_the_sun_and_ring_meshes_by_hand():
    """21/30/81 teeth, module 4 mm, 20 deg, standard addenda (hand: tip and base radii in mm, p_b = 11.809):
    sun (23.63 + 30.28 - 102 sin 20) / p_b = 1.611; ring (30.28 - 42.31 + 102 sin 20) / p_b = 1.936."""
    from gearbody.assembly.planetary_layout import contact_ratios
    from gearbody.physics.planetary import PlanetaryGeometry

    g = PlanetaryGeometry(z_sun=21, z_planet=30, z_ring=81, n_planets=3, module_m=MODULE)
    rb = [r * math.cos(ALPHA0) for r in (42.0, 60.0, 162.0)]
    s_s, s_p, s_r = (math.sqrt(a**2 - b**2) for a, b in zip((46.0, 64.0, 158.0), rb, strict=True))
    p_b = math.pi * 4.0 * math.cos(ALPHA0)
    sun, ring = contact_ratios(g)
    assert sun == pytest.approx((s_s + s_p - 102.0 * math.sin(ALPHA0)) / p_b, rel=1e-12)
    assert ring == pytest.approx((s_p - s_r + 102.0 * math.sin(ALPHA0)) / p_b, rel=1e-12)
    assert sun == pytest.approx(1.611, abs=1e-3) and ring == pytest.approx(1.936, abs=1e-3)


@pytest.mark.parametrize(
    "teeth, offset_periods, in_phase", [((21, 30, 81), 0.5, True), ((22, 29, 80), 0.0, False)]
)
def test_a_layout_from_the_geometry_shares_the_load_and_carries_the_ring_sun_offset(
    teeth, offset_periods, in_phase
):
    from gearbody.assembly.planetary_layout import layout_from_geometry
    from gearbody.physics.planetary import PlanetaryGeometry

    g = PlanetaryGeometry(z_sun=teeth[0], z_planet=teeth[1], z_ring=teeth[2], n_planets=3, module_m=MODULE)
    base = _layout(3, damping=2000.0)
    lay = layout_from_geometry(
        g, sun=base.sun, ring=base.ring, carrier=base.carrier, planet=base.planet,
        stiffness_single_N_per_m=(4e8, 4.5e8), stiffness_double_N_per_m=(6e8, 6.5e8),
        damping_Ns_per_m=(2000.0, 2000.0),
    )  # fmt: skip
    assert all(o == (0.0, 2 * math.pi * offset_periods / teeth[2]) for o in lay.mesh_angle_offsets_rad)
    system = build_planetary(lay, torques_Nm={"sun": 100.0})
    forces = planetary_mesh_forces(system, solve_planetary(system, 0.05))
    # at rest the sun's torque balance is exact; the planets share equally where their meshes sit at the
    # same phase (in phase), within a few per mille where they do not (sequential: stiffnesses differ)
    share = 100.0 / (3 * g.sun_base_radius_m)
    sun = [forces[f"planet_{k}_sun_mesh_force_N"][-1] for k in (1, 2, 3)]
    assert sum(sun) == pytest.approx(3 * share, rel=1e-6)
    for k in (1, 2, 3):
        tolerance = 1e-5 if in_phase else 1e-2
        assert forces[f"planet_{k}_sun_mesh_force_N"][-1] == pytest.approx(share, rel=tolerance)
        assert forces[f"planet_{k}_ring_mesh_force_N"][-1] == pytest.approx(share, rel=tolerance)
