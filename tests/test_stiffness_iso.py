"""ISO 6336-1 method B stiffness: ISO/TR 6336-30 Example 1, units, and gearbody's two-level profile."""

import math

import numpy as np
import pytest
from test_gear_geometry import iso_example_1 as example_1_geometry  # h_fP = 1.4 m_n, so C_B = 0.9

from gearbody.physics import mean_stiffness_N_per_m, pack_mesh_parameters
from gearbody.physics.gear_geometry import GearGeometryError, gear_pair_geometry
from gearbody.physics.stiffness_iso import (
    basic_rack_factor,
    blank_factor,
    iso_mesh_stiffness_profile,
    iso_stiffness,
    line_load_factor,
    stiffness_N_per_m,
    theoretical_single_stiffness_N_per_mm_um,
)

# ISO/TR 6336-30:2017 Example 1 (docs/references.md), N/(mm um)
EXAMPLE_1 = {
    "c_prime_th_N_per_mm_um": 17.856,
    "c_prime_N_per_mm_um": 12.370,
    "c_gamma_alpha_N_per_mm_um": 17.465,
    "c_gamma_beta_N_per_mm_um": 14.845,
}


def test_iso_tr_6336_30_example_1_is_reproduced_to_0_1_percent():
    iso = iso_stiffness(example_1_geometry())
    assert iso.virtual_teeth_pinion == pytest.approx(18.905, abs=1e-3)  # z_n = z / (cos²(beta_b) cos(beta))
    assert iso.virtual_teeth_wheel == pytest.approx(114.543, abs=1e-3)
    assert iso.C_B == pytest.approx(0.9, rel=1e-12)
    assert (iso.C_M, iso.C_R, iso.line_load_factor) == (0.8, 1.0, 1.0)
    for name, ref in EXAMPLE_1.items():
        value = getattr(iso, name)
        print(f"{name}: {value:.5f} (ISO/TR 6336-30: {ref}), relative error {value / ref - 1:+.2e}")
        assert value == pytest.approx(ref, rel=1e-3)


def test_example_1_with_the_tip_diameters_rounded_to_0_01_mm():
    """d_a = 159.66 / 872.35 mm (d + 2 m_n (1 + x) rounded) give eps_alpha = 1.54909, hence c_gamma_alpha
    = 17.4648 as published to its last digit; the exact tips give 1.54934 and 17.4672 (+0.014 %)."""
    g = example_1_geometry(tip_diameters_m=(0.15966, 0.87235))
    iso = iso_stiffness(g)
    assert g.transverse_contact_ratio == pytest.approx(1.54909, abs=1e-5)
    assert iso.c_gamma_alpha_N_per_mm_um == pytest.approx(17.465, abs=5e-4)
    assert iso.c_gamma_beta_N_per_mm_um == pytest.approx(14.845, abs=5e-4)


def test_theoretical_single_stiffness_from_the_fit_by_hand():
    # spur, z 20/40, x = 0: q' = C1 + C2/20 + C3/40
    q = 0.04723 + 0.15551 / 20 + 0.25791 / 40
    assert theoretical_single_stiffness_N_per_mm_um(virtual_teeth_pinion=20, virtual_teeth_wheel=40) == (
        pytest.approx(1 / q, rel=1e-12)
    )
    # a rack: z_n2 = inf drops the wheel terms
    q_rack = 0.04723 + 0.15551 / 20 - 0.00635 * 0.5 - 0.11654 * 0.5 / 20 + 0.00529 * 0.25
    assert theoretical_single_stiffness_N_per_mm_um(
        virtual_teeth_pinion=20, virtual_teeth_wheel=math.inf, profile_shift_pinion=0.5
    ) == pytest.approx(1 / q_rack, rel=1e-12)


def test_blank_rack_and_load_factors():
    assert blank_factor(face_width_m=0.1, module_m=8e-3) == 1.0  # solid
    c_r = blank_factor(face_width_m=0.1, module_m=8e-3, web_thickness_m=0.05, rim_thickness_m=0.016)
    assert c_r == pytest.approx(1 + math.log(0.5) / (5 * math.exp(2 / 5)), rel=1e-12)
    thin = blank_factor(face_width_m=0.1, module_m=8e-3, web_thickness_m=0.001, rim_thickness_m=0.001)
    assert thin == pytest.approx(1 + math.log(0.2) / (5 * math.exp(1 / 5)), rel=1e-12)  # limits 0.2, 1 m_n
    assert basic_rack_factor(dedendum_coefficient_pinion=1.25) == pytest.approx(0.975, rel=1e-12)
    mixed = basic_rack_factor(dedendum_coefficient_pinion=1.25, dedendum_coefficient_wheel=1.4)
    assert mixed == pytest.approx(0.5 * (0.975 + 0.9), rel=1e-12)  # ISO: mean of the two racks
    assert basic_rack_factor(dedendum_coefficient_pinion=1.25, rack_pressure_angle_deg=25) == pytest.approx(
        0.975 * 1.1
    )
    assert line_load_factor(None) == line_load_factor(150.0) == 1.0
    assert line_load_factor(50.0) == pytest.approx(0.5**0.25, rel=1e-12)
    with pytest.raises(GearGeometryError, match="line_load_N_per_mm"):
        line_load_factor(0.0)
    light = iso_stiffness(example_1_geometry(), line_load_N_per_mm=50.0)
    assert light.c_prime_N_per_mm_um == pytest.approx(12.3705 * 0.5**0.25, rel=1e-4)


def test_units_of_line_of_action_stiffness():
    # 1 N/(mm um) over 1 mm is 1 N/um = 1e6 N/m; the seed's 20 N/(mm um) over 60 mm is 1.2e9 N/m
    assert stiffness_N_per_m(1.0, 1e-3) == pytest.approx(1e6, rel=1e-12)
    assert stiffness_N_per_m(20.0, 0.060) == pytest.approx(1.2e9, rel=1e-12)
    iso = iso_stiffness(example_1_geometry())
    assert iso.single_N_per_m == pytest.approx(iso.c_prime_N_per_mm_um * 100 * 1e6, rel=1e-12)


def test_two_level_profile_mean_equals_c_gamma_alpha_b_by_hand():
    g = gear_pair_geometry(module_m=5e-3, teeth_pinion=29, teeth_wheel=88, face_width_m=0.06)
    iso = iso_stiffness(g)
    eps = g.transverse_contact_ratio
    k_s, k_d = iso_mesh_stiffness_profile(g)
    assert k_s == pytest.approx(iso.c_prime_N_per_mm_um * 60e6, rel=1e-12)
    # mean k_s (2 - eps) + k_d (eps - 1) = c' (0.75 eps + 0.25) b  =>  k_d = 1.75 k_s for any eps
    assert k_d == pytest.approx(1.75 * k_s, rel=1e-12)
    assert k_s * (2 - eps) + k_d * (eps - 1) == pytest.approx(iso.mesh_alpha_N_per_m, rel=1e-12)
    P = pack_mesh_parameters(
        r1_m=g.base_radius_pinion_m,
        r2_m=g.base_radius_wheel_m,
        z1=29,
        z2=88,
        stiffness_single_N_per_m=k_s,
        stiffness_double_N_per_m=k_d,
        contact_ratio=eps,
        damping_Ns_per_m=0.0,
        backlash_m=0.0,
        friction_coefficient=0.0,
        pitch_point_phase=g.pitch_point_phase,
        pressure_angle_rad=g.working_pressure_angle_rad,
        error_a=0.5,
        error_depths_m=np.zeros(29),
    )
    assert mean_stiffness_N_per_m(P) == pytest.approx(iso.mesh_alpha_N_per_m, rel=1e-12)


def test_flat_profile_when_two_or_more_pairs_always_carry():
    g = example_1_geometry()  # eps_gamma = 2.63
    k_s, k_d = iso_mesh_stiffness_profile(g)
    assert k_s == k_d == pytest.approx(iso_stiffness(g).mesh_alpha_N_per_m, rel=1e-12)


@pytest.mark.parametrize(
    ("label", "module_m", "z1", "z2", "face_width_m"),
    [
        ("one-stage", 5e-3, 29, 88, 0.060),
        ("two-stage stage 2", 8e-3, 23, 71, 0.080),
        ("62/62 reference pair", 2e-3, 62, 62, 0.020),
    ],
)
def test_method_b_for_the_scene_gears(label, module_m, z1, z2, face_width_m):
    g = gear_pair_geometry(module_m=module_m, teeth_pinion=z1, teeth_wheel=z2, face_width_m=face_width_m)
    iso = iso_stiffness(g)
    k_s, k_d = iso_mesh_stiffness_profile(g)
    eps = g.transverse_contact_ratio
    mean = k_s * (2 - eps) + k_d * (eps - 1)
    print(
        f"{label}: eps_alpha {eps:.5f}, c' {iso.c_prime_N_per_mm_um:.3f}, c_gamma_alpha "
        f"{iso.c_gamma_alpha_N_per_mm_um:.3f} N/(mm um); k_single {k_s:.4g}, k_double {k_d:.4g}, "
        f"mean {mean:.4g} N/m"
    )
    assert 10.0 < iso.c_prime_N_per_mm_um < 16.0  # ISO's usual range for steel spur gears (c' ~ 14)
    if label == "one-stage":
        # the seed's hand-given k_z = 1.2e9 / 1.3e9 N/m: same order as method B
        assert 0.5e9 < k_s < 2e9 and 0.5e9 < k_d < 2e9 and 0.5e9 < mean < 2e9
