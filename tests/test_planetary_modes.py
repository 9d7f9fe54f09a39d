"""Planetary stage, engine-free: geometry checks, Willis kinematics, mesh phases (Parker & Lin 2004) and the
Lin & Parker (1999) linear model's natural modes against the paper's Table 2 (docs/references.md)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gearbody.physics.exceptions import GearGeometryError
from gearbody.physics.planetary import (
    PlanetaryGeometry,
    PlanetaryGeometryError,
    planet_mesh_phases,
    planetary_speeds,
)
from gearbody.physics.planetary_modal import (
    PlanetaryModalError,
    lin_parker_1999_parameters,
    mass_matrix,
    natural_modes,
    stiffness_matrix,
)

# Lin & Parker 1999, Table 2, as given in docs/references.md (Hz; translational: pairs)
PUBLISHED = {
    3: {
        "rotational": [0.0, 1475.7, 1930.3, 2658.3, 7462.8, 11775.3],
        "translational": [743.2, 1102.4, 1896.0, 2276.4, 6986.3, 9647.9],
        "planet": [],
    },
    4: {
        "rotational": [0.0, 1536.6, 1970.6, 2625.7, 7773.6, 13071.1],
        "translational": [727.0, 1091.0, 1892.8, 2342.5, 7189.9, 10437.6],
        "planet": [1808.2, 5963.8, 6981.7],
    },
    5: {
        "rotational": [0.0, 1567.4, 2006.1, 2614.8, 8065.4, 14253.1],
        "translational": [710.0, 1072.0, 1888.1, 2425.3, 7382.4, 11172.3],
        "planet": [1808.2, 5963.8, 6981.7],
    },
}


def _published_spectrum(n: int) -> np.ndarray:
    table = PUBLISHED[n]
    freqs = table["rotational"] + 2 * table["translational"] + (n - 3) * table["planet"]
    return np.sort(np.array(freqs))


# ------------------------------------------------------------------------------------ Lin & Parker 1999
@pytest.mark.parametrize("n", [3, 4, 5])
def test_natural_frequencies_reproduce_lin_parker_1999_table_2_within_0p1_percent(n):
    modes = natural_modes(lin_parker_1999_parameters(n))
    expected = _published_spectrum(n)
    assert modes.frequencies_hz.shape == expected.shape == (3 * (n + 3),)
    assert modes.frequencies_hz[0] == pytest.approx(0.0, abs=1e-3)
    assert expected[0] == 0.0
    np.testing.assert_allclose(modes.frequencies_hz[1:], expected[1:], rtol=1e-3)


@pytest.mark.parametrize("n", [3, 4, 5])
def test_each_mode_class_matches_its_column_of_table_2(n):
    modes = natural_modes(lin_parker_1999_parameters(n))
    for kind, published in PUBLISHED[n].items():
        groups = modes.of_kind(kind)
        computed = [g.frequency_hz for g in groups]
        assert len(computed) == len(published), kind
        np.testing.assert_allclose(
            computed[1:] if kind == "rotational" else computed,
            published[1:] if kind == "rotational" else published,
            rtol=1e-3,
        )
        want = {"rotational": 1, "translational": 2, "planet": n - 3}[kind]
        assert all(g.multiplicity == want for g in groups), kind


def _check_equally_spaced_structure(modes, n: int) -> None:
    rot, tra, pla = (modes.of_kind(k) for k in ("rotational", "translational", "planet"))
    assert not modes.of_kind("mixed")
    assert len(rot) == 6 and all(g.multiplicity == 1 for g in rot)
    assert len(tra) == 6 and all(g.multiplicity == 2 for g in tra)
    if n == 3:
        assert not pla
    else:
        assert len(pla) == 3 and all(g.multiplicity == n - 3 for g in pla)
    assert sum(g.multiplicity for g in modes.groups) == 3 * (n + 3)


@pytest.mark.parametrize("n", [3, 4, 5, 6, 7])
def test_equally_spaced_structure_6_rotational_6_translational_pairs_3_planet_frequencies(n):
    modes = natural_modes(lin_parker_1999_parameters(n))
    _check_equally_spaced_structure(modes, n)
    assert modes.of_kind("rotational")[0].frequency_hz == pytest.approx(0.0, abs=1e-3)  # rigid body
    table = modes.table()
    assert [r["frequency_hz"] for r in table] == sorted(r["frequency_hz"] for r in table)
    assert sum(r["multiplicity"] for r in table) == 3 * (n + 3)
    assert {r["kind"] for r in table} == ({"rotational", "translational"} | ({"planet"} if n > 3 else set()))


@settings(max_examples=25, deadline=None)
@given(
    n=st.integers(min_value=3, max_value=6),
    scales=st.lists(st.floats(min_value=0.3, max_value=3.0), min_size=9, max_size=9),
    alpha_deg=st.floats(min_value=15.0, max_value=30.0),
)
def test_structure_theorems_hold_for_any_parameters(n, scales, alpha_deg):
    base = lin_parker_1999_parameters(n)
    names = [
        "carrier_mass_kg",
        "ring_mass_kg",
        "sun_mass_kg",
        "planet_mass_kg",
        "planet_rotary_mass_kg",
        "sun_mesh_N_per_m",
        "ring_mesh_N_per_m",
        "planet_bearing_N_per_m",
        "sun_bearing_N_per_m",
    ]
    changes = {name: getattr(base, name) * s for name, s in zip(names, scales, strict=True)}
    p = dataclasses.replace(
        base,
        **changes,
        sun_pressure_angle_rad=math.radians(alpha_deg),
        ring_pressure_angle_rad=math.radians(alpha_deg + 1.0),
    )
    _check_equally_spaced_structure(natural_modes(p), n)


def test_planet_mode_frequencies_do_not_depend_on_the_number_of_planets():
    # planet modes leave the central members at rest: only planet parameters set them (Lin & Parker 1999)
    ref = [g.frequency_hz for g in natural_modes(lin_parker_1999_parameters(4)).of_kind("planet")]
    for n in (5, 6, 8):
        got = [g.frequency_hz for g in natural_modes(lin_parker_1999_parameters(n)).of_kind("planet")]
        np.testing.assert_allclose(got, ref, rtol=1e-9)


# ------------------------------------------------------------------------- matrices, independently
def _independent_stiffness(p, r_sun_base_m=0.04, r_planet_base_m=0.03):
    """K assembled spring by spring from planar rigid-body kinematics of a consistent geometry, in
    (x, y, theta) coordinates, then changed to u = r theta. Shares nothing with stiffness_matrix but the
    coordinate order and the meaning of the parameters."""
    a_s, a_r = p.sun_pressure_angle_rad, p.ring_pressure_angle_rad
    a_m = (r_sun_base_m + r_planet_base_m) / math.cos(a_s)  # planet-centre radius
    r_ring_base_m = a_m * math.cos(a_r) + r_planet_base_m  # internal gear: tangent points on one ray
    n = p.n_planets
    dof = 3 * (n + 3)
    radius = [a_m, r_ring_base_m, r_sun_base_m] + [r_planet_base_m] * n

    def point_row(body, centre, point, direction, planet_angle=None):
        """Coefficients of direction . (displacement of the body's material point) in (x, y, theta)."""
        row = np.zeros(dof)
        d = np.asarray(direction, float)
        arm = np.asarray(point, float) - np.asarray(centre, float)
        if planet_angle is None:
            row[3 * body : 3 * body + 2] = d
        else:  # planet translation zeta e_r + eta e_t
            e_r = np.array([math.cos(planet_angle), math.sin(planet_angle)])
            e_t = np.array([-math.sin(planet_angle), math.cos(planet_angle)])
            row[3 * body] = d @ e_r
            row[3 * body + 1] = d @ e_t
        row[3 * body + 2] = arm[0] * d[1] - arm[1] * d[0]  # (k theta x arm) . d
        return row

    springs = []  # (stiffness, row)
    origin = (0.0, 0.0)
    for h, (kb, kt) in enumerate(
        [
            (p.carrier_bearing_N_per_m, p.carrier_torsion_N_per_m),
            (p.ring_bearing_N_per_m, p.ring_torsion_N_per_m),
            (p.sun_bearing_N_per_m, p.sun_torsion_N_per_m),
        ]
    ):
        for axis in range(2):
            row = np.zeros(dof)
            row[3 * h + axis] = 1.0
            springs.append((kb, row))
        row = np.zeros(dof)
        row[3 * h + 2] = radius[h]  # the torsional support is given on u = r theta: deflection r theta
        springs.append((kt, row))
    for i, psi in enumerate(p.planet_angles_rad):
        b = 3 + i
        centre = a_m * np.array([math.cos(psi), math.sin(psi)])
        for d in ((1.0, 0.0), (0.0, 1.0)):  # isotropic planet bearing, in fixed x and y
            row = point_row(0, origin, centre, d) - point_row(b, centre, centre, d, psi)
            springs.append((p.planet_bearing_N_per_m, row))
        phi = psi - a_s  # sun: tangent point of the line of action on the sun base circle
        e = np.array([math.cos(phi), math.sin(phi)])
        d = np.array([-math.sin(phi), math.cos(phi)])
        row = point_row(2, origin, r_sun_base_m * e, d) - point_row(
            b, centre, centre - r_planet_base_m * e, d, psi
        )
        springs.append((p.sun_mesh_N_per_m, row))
        phi = psi + a_r  # ring: tangent points on the ring and planet base circles, same side
        e = np.array([math.cos(phi), math.sin(phi)])
        d = np.array([-math.sin(phi), math.cos(phi)])
        row = point_row(1, origin, r_ring_base_m * e, d) - point_row(
            b, centre, centre + r_planet_base_m * e, d, psi
        )
        springs.append((p.ring_mesh_N_per_m, row))
    k_theta = sum(k * np.outer(r, r) for k, r in springs)
    to_theta = np.diag([v for r in radius for v in (1.0, 1.0, 1.0 / r)])  # q_theta = T q_u
    return to_theta.T @ k_theta @ to_theta


@pytest.mark.parametrize("angles", [None, (0.0, 1.7, 3.3, 4.6), (0.0, 2.0, 4.3)])
def test_stiffness_matrix_equals_a_spring_by_spring_kinematic_assembly(angles):
    n = 4 if angles is None else len(angles)
    p = lin_parker_1999_parameters(n, angles)
    K, K_ref = stiffness_matrix(p), _independent_stiffness(p)
    np.testing.assert_allclose(K, K_ref, rtol=0, atol=1e-12 * np.abs(K).max())
    from scipy.linalg import eigh

    lam = eigh(K, mass_matrix(p), eigvals_only=True)
    lam_ref = eigh(K_ref, mass_matrix(p), eigvals_only=True)
    np.testing.assert_allclose(lam, lam_ref, rtol=1e-6, atol=1e-6 * lam.max())


def test_frequencies_equal_eigh_and_an_independent_standard_eigenproblem_to_1e6():
    p = lin_parker_1999_parameters(5)
    M, K = mass_matrix(p), stiffness_matrix(p)
    m_half = np.diag(1.0 / np.sqrt(np.diag(M)))
    lam = np.linalg.eigvalsh(m_half @ K @ m_half)
    f_ref = np.sqrt(np.clip(lam, 0.0, None)) / (2 * math.pi)
    np.testing.assert_allclose(natural_modes(p).frequencies_hz, f_ref, rtol=1e-6, atol=1e-3)


def test_matrices_are_symmetric_m_positive_k_semidefinite():
    p = lin_parker_1999_parameters(4, (0.0, 1.7, 3.3, 4.6))
    M, K = mass_matrix(p), stiffness_matrix(p)
    assert (
        np.array_equal(M, M.T) and np.all(np.diag(M) > 0) and np.count_nonzero(M - np.diag(np.diag(M))) == 0
    )
    np.testing.assert_allclose(K, K.T, rtol=0, atol=1e-9)
    assert np.linalg.eigvalsh(K).min() > -1e-6 * np.abs(K).max()


def test_modes_are_mass_orthonormal():
    modes = natural_modes(lin_parker_1999_parameters(4))
    V, M = modes.shapes, mass_matrix(lin_parker_1999_parameters(4))
    np.testing.assert_allclose(V.T @ M @ V, np.eye(V.shape[1]), atol=1e-9)


# ------------------------------------------------------------------------------- rigid-body modes
@pytest.mark.parametrize(
    "torsion, zeros",
    [({}, 1), ({"ring_torsion_N_per_m": 0.0}, 2), ({"carrier_torsion_N_per_m": 1e9}, 0)],
)
def test_rigid_body_modes_exist_exactly_when_members_turn_freely(torsion, zeros):
    p = dataclasses.replace(lin_parker_1999_parameters(3), **torsion)
    f = natural_modes(p).frequencies_hz
    assert np.count_nonzero(f < 1.0) == zeros
    if zeros < len(f):
        assert f[zeros] > 100.0


def test_rigid_body_mode_turns_sun_and_carrier_as_the_willis_equation_says():
    alpha_deg = 24.6
    p = lin_parker_1999_parameters(3)
    v = natural_modes(p).shapes[:, 0]
    u_c, u_r, u_s = v[2], v[5], v[8]
    assert abs(u_r) < 1e-9 * abs(u_c)
    # same ratio from the kinematics: u = r_b theta, carrier arm = planet-centre radius
    g = PlanetaryGeometry(
        z_sun=20, z_planet=25, z_ring=70, n_planets=3, module_m=0.002, pressure_angle_deg=alpha_deg
    )
    w = planetary_speeds(g, input="sun", output="carrier", fixed="ring", input_speed_rad_s=1.0)
    expected = g.sun_base_radius_m * w.sun_rad_s / (g.carrier_radius_m * w.carrier_rad_s)
    assert u_s / u_c == pytest.approx(expected, rel=1e-9)
    assert expected == pytest.approx(2 * math.cos(math.radians(alpha_deg)), rel=1e-12)
    # planets ride with the carrier (eta_n = u_c, zeta_n = 0) and spin backwards: u_n = -u_c cos(alpha)
    for i in range(3):
        zeta, eta, u_n = v[9 + 3 * i : 12 + 3 * i]
        assert abs(zeta) < 1e-9 * abs(u_c) and eta == pytest.approx(u_c, rel=1e-9)
        assert u_n == pytest.approx(-u_c * math.cos(math.radians(alpha_deg)), rel=1e-9)


# ---------------------------------------------------------------------------------- unequal spacing
def test_unequal_spacing_splits_the_translational_pairs():
    modes = natural_modes(lin_parker_1999_parameters(4, (0.0, 1.7, 3.3, 4.6)))
    central = [g for g in modes.groups if g.kind != "planet"]
    assert all(g.multiplicity == 1 for g in central)
    assert all(g.kind == "mixed" for g in central if g.frequency_hz > 1.0)
    assert len(modes.of_kind("planet")) == 3  # central members at rest: survives any spacing


def test_diametrically_opposed_planets_keep_rotational_modes_and_split_pairs():
    # Lin & Parker 2000 (JSV 233:921): opposed pairs keep the rotational modes; translational pairs split
    even = natural_modes(lin_parker_1999_parameters(4))
    opposed = natural_modes(
        lin_parker_1999_parameters(4, (0.0, math.pi / 2 + 0.1, math.pi, 1.5 * math.pi + 0.1))
    )
    np.testing.assert_allclose(
        [g.frequency_hz for g in opposed.of_kind("rotational")][1:],
        [g.frequency_hz for g in even.of_kind("rotational")][1:],
        rtol=1e-6,
    )
    tra = opposed.of_kind("translational")
    assert len(tra) == 12 and all(g.multiplicity == 1 for g in tra)


def test_modal_parameters_refuse_bad_values_naming_them():
    base = lin_parker_1999_parameters(3)
    with pytest.raises(PlanetaryModalError, match=r"sun_mesh_N_per_m = -1.0.*>= 0 N/m"):
        dataclasses.replace(base, sun_mesh_N_per_m=-1.0)
    with pytest.raises(PlanetaryModalError, match=r"planet_mass_kg = 0.0.*> 0 kg"):
        dataclasses.replace(base, planet_mass_kg=0.0)
    with pytest.raises(PlanetaryModalError, match=r"ring_pressure_angle_rad = 2.0"):
        dataclasses.replace(base, ring_pressure_angle_rad=2.0)
    with pytest.raises(PlanetaryModalError, match=r"planet_angles_rad = \(\)"):
        dataclasses.replace(base, planet_angles_rad=())
    with pytest.raises(PlanetaryModalError, match="kind = 'wobble'"):
        natural_modes(base).of_kind("wobble")


# -------------------------------------------------------------------------------------- geometry
def test_geometry_radii_by_hand():
    g = PlanetaryGeometry(z_sun=20, z_planet=25, z_ring=70, n_planets=3, module_m=0.002)
    assert g.sun_pitch_radius_m == pytest.approx(0.020)
    assert g.ring_pitch_radius_m == pytest.approx(0.070)
    assert g.carrier_radius_m == pytest.approx(0.045)
    assert g.planet_base_radius_m == pytest.approx(0.025 * math.cos(math.radians(20.0)))
    assert g.planet_tip_radius_m == pytest.approx(0.027) and g.ring_tip_radius_m == pytest.approx(0.068)
    assert g.equally_spaced and g.planet_angles_rad[1] == pytest.approx(2 * math.pi / 3)


def test_equal_spacing_refused_unless_sum_of_teeth_divides_by_n():
    with pytest.raises(PlanetaryGeometryError, match=r"n_planets = 4.*20 \+ 70 = 90.*N = 4") as info:
        PlanetaryGeometry(z_sun=20, z_planet=25, z_ring=70, n_planets=4, module_m=0.002)
    assert isinstance(info.value, GearGeometryError) and isinstance(info.value, ValueError)
    PlanetaryGeometry(z_sun=20, z_planet=25, z_ring=70, n_planets=2, module_m=0.002)  # 90 / 2 = 45
    PlanetaryGeometry(z_sun=28, z_planet=20, z_ring=68, n_planets=4, module_m=0.002)  # 96 / 4 = 24


def test_ring_teeth_must_equal_sun_plus_two_planets_within_the_stated_tolerance():
    with pytest.raises(PlanetaryGeometryError, match=r"z_ring = 71.*= 70 \(off by 1"):
        PlanetaryGeometry(z_sun=20, z_planet=25, z_ring=71, n_planets=1, module_m=0.002)
    PlanetaryGeometry(z_sun=20, z_planet=25, z_ring=71, n_planets=1, module_m=0.002, ring_teeth_tolerance=1)
    with pytest.raises(PlanetaryGeometryError, match="ring_teeth_tolerance = 3"):
        PlanetaryGeometry(
            z_sun=20, z_planet=25, z_ring=73, n_planets=1, module_m=0.002, ring_teeth_tolerance=3
        )


def test_unequal_angles_must_satisfy_the_mesh_condition_and_the_error_gives_valid_ones():
    kwargs = dict(z_sun=20, z_planet=25, z_ring=70, n_planets=4, module_m=0.002)
    angles = (0.0, 1.6, 3.1, 4.7)
    with pytest.raises(
        PlanetaryGeometryError, match=r"planet_angles_rad\[1\] = 1.6.*nearest valid angles"
    ) as info:
        PlanetaryGeometry(**kwargs, planet_angles_rad=angles)
    listed = info.value.args[0].split("nearest valid angles [")[1].split("]")[0]
    nearest = tuple(float(x) for x in listed.split(", "))
    step = 2 * math.pi / 90
    g = PlanetaryGeometry(**kwargs, planet_angles_rad=tuple(round(a / step) * step for a in nearest))
    assert not g.equally_spaced
    for a in g.planet_angles_rad:  # (z_s + z_r) psi / 2 pi integer
        assert 90 * a / (2 * math.pi) == pytest.approx(round(90 * a / (2 * math.pi)), abs=1e-9)
    with pytest.raises(PlanetaryGeometryError, match=r"planet_angles_rad\[0\] = 0.1"):
        PlanetaryGeometry(**kwargs, planet_angles_rad=(0.1, 1.6, 3.1, 4.7))
    with pytest.raises(PlanetaryGeometryError, match="3 angles for n_planets = 4"):
        PlanetaryGeometry(**kwargs, planet_angles_rad=(0.0, 2.0, 4.0))


def test_planets_whose_tip_circles_overlap_are_refused():
    # 16 + 96 = 112 = 8 * 14: assembly holds, but 8 planets of 40 teeth do not fit on a 56 mm circle
    with pytest.raises(
        PlanetaryGeometryError, match=r"n_planets = 8: planets 1 and 2 overlap.*tip diameter 0.084"
    ):
        PlanetaryGeometry(z_sun=16, z_planet=40, z_ring=96, n_planets=8, module_m=0.002)
    # by hand: 2 a sin(pi / N) = 112, 79.2, 42.9 mm for N = 2, 4, 8 against the 84 mm tip diameter
    PlanetaryGeometry(z_sun=16, z_planet=40, z_ring=96, n_planets=2, module_m=0.002)
    with pytest.raises(PlanetaryGeometryError, match="n_planets = 4"):
        PlanetaryGeometry(z_sun=16, z_planet=40, z_ring=96, n_planets=4, module_m=0.002)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(z_sun=4), "z_sun = 4"),
        (dict(z_planet=25.0), r"z_planet = 25.0: tooth count must be a whole number"),
        (dict(module_m=0.0), "module_m = 0"),
        (dict(pressure_angle_deg=50.0), "pressure_angle_deg = 50"),
        (dict(n_planets=0), "n_planets = 0"),
    ],
)
def test_geometry_refuses_bad_numbers(kwargs, match):
    base = dict(z_sun=20, z_planet=25, z_ring=70, n_planets=3, module_m=0.002)
    with pytest.raises(PlanetaryGeometryError, match=match):
        PlanetaryGeometry(**{**base, **kwargs})


# ------------------------------------------------------------------------------------ kinematics
GEOM = PlanetaryGeometry(z_sun=20, z_planet=25, z_ring=70, n_planets=3, module_m=0.002)


def test_ring_fixed_sun_input_carrier_turns_at_zs_over_zs_plus_zr():
    w = planetary_speeds(GEOM, input="sun", output="carrier", fixed="ring", input_speed_rad_s=90.0)
    assert w.carrier_rad_s == pytest.approx(20.0)  # 90 * 20 / 90
    assert w.ratio == pytest.approx(4.5) and w.ring_rad_s == 0.0
    assert w.planet_relative_rad_s == pytest.approx(-(20 / 25) * 70.0)  # -56 rad/s
    assert w.mesh_frequency_hz == pytest.approx(70 * 20.0 / (2 * math.pi))  # z_r |w_r - w_c|


def test_carrier_fixed_is_an_ordinary_train_and_sun_fixed_an_overdrive():
    w = planetary_speeds(GEOM, input="sun", output="ring", fixed="carrier", input_speed_rad_s=7.0)
    assert w.ring_rad_s == pytest.approx(-2.0) and w.ratio == pytest.approx(-3.5)  # -z_r / z_s
    w = planetary_speeds(GEOM, input="carrier", output="ring", fixed="sun", input_speed_rad_s=7.0)
    assert w.ring_rad_s == pytest.approx(9.0) and w.ratio == pytest.approx(7 / 9)  # (z_s + z_r) / z_r


@pytest.mark.parametrize(
    "inp, out, fixed",
    [
        (i, o, f)
        for i in ("sun", "ring", "carrier")
        for o in ("sun", "ring", "carrier")
        for f in ("sun", "ring", "carrier")
        if len({i, o, f}) == 3
    ],
)
def test_every_role_assignment_rolls_without_slip_at_both_pitch_points(inp, out, fixed):
    w = planetary_speeds(GEOM, input=inp, output=out, fixed=fixed, input_speed_rad_s=3.0)
    assert w.of(fixed) == 0.0 and w.of(inp) == 3.0
    r_s, r_p, r_r, a = (
        GEOM.sun_pitch_radius_m,
        GEOM.planet_pitch_radius_m,
        GEOM.ring_pitch_radius_m,
        GEOM.carrier_radius_m,
    )
    # pitch-point velocities (tangential, planet 1 on the x axis): sun side and ring side of the planet
    assert w.sun_rad_s * r_s == pytest.approx(w.carrier_rad_s * a - w.planet_rad_s * r_p)
    assert w.ring_rad_s * r_r == pytest.approx(w.carrier_rad_s * a + w.planet_rad_s * r_p)
    assert w.mesh_frequency_hz == pytest.approx(70 * abs(w.ring_rad_s - w.carrier_rad_s) / (2 * math.pi))
    assert w.mesh_frequency_hz == pytest.approx(25 * abs(w.planet_relative_rad_s) / (2 * math.pi))


def test_speed_roles_refused_when_unknown_or_repeated():
    with pytest.raises(PlanetaryGeometryError, match="input = 'moon'"):
        planetary_speeds(GEOM, input="moon", output="ring", fixed="carrier", input_speed_rad_s=1.0)
    with pytest.raises(PlanetaryGeometryError, match="each member takes exactly one role"):
        planetary_speeds(GEOM, input="sun", output="sun", fixed="carrier", input_speed_rad_s=1.0)
    with pytest.raises(PlanetaryGeometryError, match="input_speed_rad_s = 0"):
        planetary_speeds(GEOM, input="sun", output="ring", fixed="carrier", input_speed_rad_s=0.0)


# ----------------------------------------------------------------------------------- mesh phases
def test_mesh_phases_by_hand_sequential_and_in_phase():
    ph = planet_mesh_phases(GEOM)  # z_s = 20, z_r = 70, N = 3: 20/3 and 70/3 not integers
    np.testing.assert_allclose(ph.sun, (0.0, 2 / 3, 1 / 3), atol=1e-12)
    np.testing.assert_allclose(ph.ring, (0.0, 1 / 3, 2 / 3), atol=1e-12)
    assert ph.ring_sun == 0.0  # odd z_p
    inphase = planet_mesh_phases(
        PlanetaryGeometry(z_sun=21, z_planet=27, z_ring=75, n_planets=3, module_m=0.002)
    )
    assert inphase.sun == (0.0, 0.0, 0.0) and inphase.ring == (0.0, 0.0, 0.0)
    even = planet_mesh_phases(
        PlanetaryGeometry(z_sun=22, z_planet=26, z_ring=74, n_planets=3, module_m=0.002)
    )
    assert even.ring_sun == 0.5


def _first_crossing_time(teeth_angle0, teeth, omega, target, period):
    """First t >= 0 at which some tooth (angles teeth_angle0 + 2 pi j / teeth + omega t) is at target."""
    times = [
        ((target - teeth_angle0 - 2 * math.pi * j / teeth) / omega) % (2 * math.pi / abs(omega))
        for j in range(teeth)
    ]
    return min(times) % period


@pytest.mark.parametrize("sun_ccw", [True, False])
def test_mesh_delays_equal_a_tooth_by_tooth_timing_in_the_carrier_frame(sun_ccw):
    g = PlanetaryGeometry(
        z_sun=20,
        z_planet=25,
        z_ring=70,
        n_planets=4,
        module_m=0.002,
        planet_angles_rad=tuple(2 * math.pi * k / 90 for k in (0, 22, 45, 68)),
    )
    w_s = 1.0 if sun_ccw else -1.0  # relative to the carrier
    w_r = -w_s * g.z_sun / g.z_ring  # Willis, carrier at rest
    period = 2 * math.pi / (g.z_sun * abs(w_s))
    sun_delay, ring_delay = planet_mesh_phases(g).delays(sun_ccw)
    t_s1 = _first_crossing_time(0.3, g.z_sun, w_s, 0.0, period)
    t_r1 = _first_crossing_time(0.1, g.z_ring, w_r, 0.0, period)
    for n, psi in enumerate(g.planet_angles_rad):
        d_s = ((_first_crossing_time(0.3, g.z_sun, w_s, psi, period) - t_s1) / period) % 1.0
        d_r = ((_first_crossing_time(0.1, g.z_ring, w_r, psi, period) - t_r1) / period) % 1.0
        assert min(abs(d_s - sun_delay[n]), 1 - abs(d_s - sun_delay[n])) < 1e-9
        assert min(abs(d_r - ring_delay[n]), 1 - abs(d_r - ring_delay[n])) < 1e-9
        assert min(abs(d_s - d_r), 1 - abs(d_s - d_r)) < 1e-9  # both meshes of a planet shift alike


@pytest.mark.parametrize("sun_flank_sign", [-1.0, 1.0])
@pytest.mark.parametrize("z_planet", [25, 26, 27, 30])
def test_ring_sun_offset_equals_flank_passages_of_a_half_pitch_tooth(z_planet, sun_flank_sign):
    # planet frame: sun pitch point at angle pi, ring pitch point at 0. Sun and ring push the planet with
    # parallel tangential forces at the ends of a diameter, so they load opposite flanks: the sun the
    # clockwise flanks (sign -1) and the ring the counterclockwise ones, or the reverse under reversed load
    half_tooth = math.pi / (2 * z_planet)  # tooth thickness p/2 at the pitch circle
    omega = 1.0
    period = 2 * math.pi / z_planet
    t_sun = _first_crossing_time(0.2 + sun_flank_sign * half_tooth, z_planet, omega, math.pi, period)
    t_ring = _first_crossing_time(0.2 - sun_flank_sign * half_tooth, z_planet, omega, 0.0, period)
    offset = ((t_ring - t_sun) / period) % 1.0
    offset = 0.0 if min(offset, 1 - offset) < 1e-9 else offset
    g = PlanetaryGeometry(z_sun=20, z_planet=z_planet, z_ring=20 + 2 * z_planet, n_planets=1, module_m=0.002)
    assert planet_mesh_phases(g).ring_sun == pytest.approx(offset, abs=1e-9)


# ---------------------------------------------------------------------------------------- the doc
def test_docs_table_holds_the_published_and_the_computed_frequencies():
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "planetary.md").read_text()
    table = text[text.index("### Computed vs published") :]
    table = table[: table.index("```")]  # the table ends where the example code starts
    rows = [line for line in table.splitlines() if line.startswith("| ") and " / " in line]
    kind = None
    seen = {n: {k: [] for k in PUBLISHED[n]} for n in PUBLISHED}
    for line in rows:
        cells = [c.strip() for c in line.strip("|").split("|")]
        kind = cells[0].split(" ")[0] or kind
        for n, cell in zip((3, 4, 5), cells[1:], strict=True):
            if " / " in cell:
                pub, comp = (float(x) for x in cell.replace("(x2)", "").split(" / "))
                seen[n][kind].append((pub, comp))
    for n in PUBLISHED:
        modes = natural_modes(lin_parker_1999_parameters(n))
        for k, published in PUBLISHED[n].items():
            assert [p for p, _ in seen[n][k]] == published, (n, k)
            computed = [round(g.frequency_hz, 2) for g in modes.of_kind(k)]
            assert [c for _, c in seen[n][k]] == pytest.approx(computed, abs=0.006), (n, k)
