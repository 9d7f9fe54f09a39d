"""Potential-energy mesh stiffness (gearbody.physics.stiffness_energy): reference pair, cycle, damage."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from gearbody.physics.stiffness_energy import (
    RootCrack,
    Spall,
    SpurGear,
    SpurPair,
    ToothBreakage,
    damaged_mesh_stiffness_window,
    damaged_pair_stiffness_N_per_m,
    hertz_stiffness_N_per_m,
    mesh_stiffness_cycle,
    mesh_stiffness_summary,
    pair_stiffness_N_per_m,
    tooth_compliance_m_per_N,
)

N_PHASE = 200


def reference_pair() -> SpurPair:
    """docs/references.md: 62/62, m 2 mm, 20 deg, b 20 mm, E 206 GPa, nu 0.3, bore 35 mm (radius 17.5 mm)."""
    gear = SpurGear(teeth=62, module_m=0.002, face_width_m=0.02, bore_radius_m=0.0175)
    return SpurPair(gear, gear)


def one_stage_pair() -> SpurPair:
    """scenes/one-stage.toml pair; bores are not in the scene: shaft radii 30 / 45 mm assumed."""
    return SpurPair(SpurGear(29, 0.005, 0.06, 0.030), SpurGear(88, 0.005, 0.06, 0.045))


def stage2_pair() -> SpurPair:
    """scenes/two-stage.toml stage 2; bores assumed 45 / 60 mm radius."""
    return SpurPair(SpurGear(23, 0.008, 0.08, 0.045), SpurGear(71, 0.008, 0.08, 0.060))


@pytest.fixture(scope="module")
def ref_cycle():
    return mesh_stiffness_cycle(reference_pair(), N_PHASE)


def test_reference_contact_ratio_and_hertz():
    pair = reference_pair()
    assert pair.contact_ratio == pytest.approx(1.78978, abs=1e-4)
    assert hertz_stiffness_N_per_m(pair) == pytest.approx(3.5559e9, rel=1e-4)


def test_reference_mean_stiffness(ref_cycle):
    _, k, _ = ref_cycle
    print(f"\n62/62: mean {k.mean():.4e}  min {k.min():.4e}  max {k.max():.4e} N/m")
    assert k.mean() == pytest.approx(4.1e8, rel=0.10)


def test_quadrature_matches_tian_integrals():
    """Classical integrals (Tian 2004, integration angle alpha from -alpha_1 to alpha_2) by adaptive quad."""
    gear = reference_pair().pinion
    E, nu, b = gear.youngs_modulus_Pa, gear.poisson_ratio, gear.face_width_m
    a2 = gear.half_base_tooth_angle_rad
    for roll in (0.016, 0.0212, 0.0264):
        a1 = gear.load_angle_rad(roll)

        def den(a):
            return math.sin(a) + (a2 - a) * math.cos(a)

        kb = quad(
            lambda a, a1=a1: 3 * (1 + math.cos(a1) * ((a2 - a) * math.sin(a) - math.cos(a))) ** 2
            * (a2 - a) * math.cos(a) / (2 * E * b * den(a) ** 3),
            -a1, a2, epsabs=0, epsrel=1e-12,
        )[0]  # fmt: skip
        ks = quad(
            lambda a, a1=a1: 1.2 * (1 + nu) * (a2 - a) * math.cos(a) * math.cos(a1) ** 2 / (E * b * den(a)),
            -a1, a2, epsabs=0, epsrel=1e-12,
        )[0]  # fmt: skip
        ka = quad(
            lambda a, a1=a1: (a2 - a) * math.cos(a) * math.sin(a1) ** 2 / (2 * E * b * den(a)),
            -a1, a2, epsabs=0, epsrel=1e-12,
        )[0]  # fmt: skip
        c = tooth_compliance_m_per_N(gear, roll, tooth_root="base")
        assert c.bending == pytest.approx(kb, rel=1e-9)
        assert c.shear == pytest.approx(ks, rel=1e-9)
        assert c.axial == pytest.approx(ka, rel=1e-9)


def test_cycle_periodic_and_continuous(ref_cycle):
    pair = reference_pair()
    _, k_cycle, k_pairs = ref_cycle
    phase, k, _ = damaged_mesh_stiffness_window(pair, None, N_PHASE)
    assert phase[0] == -1.0 and phase[-1] < 2.0
    n = N_PHASE
    np.testing.assert_allclose(k[:n], k[n : 2 * n], rtol=1e-12)
    np.testing.assert_allclose(k[n : 2 * n], k[2 * n :], rtol=1e-12)
    np.testing.assert_allclose(k[n : 2 * n], k_cycle, rtol=1e-12)
    # continuous except where the number of pairs in contact changes (wrap-around included)
    count = (k_pairs > 0).sum(axis=0)
    jump = np.abs(np.diff(np.append(k_cycle, k_cycle[0])))
    changes = np.append(count, count[0])[1:] != count
    assert changes.sum() == 2
    assert jump[~changes].max() < 0.02 * k_cycle.mean()
    assert jump[changes].min() > 0.2 * k_cycle.mean()
    # one pair around p = 0.5, two near the tooth change; eps - 1 of the period in double contact
    h = 0.5 * (pair.contact_ratio - 1.0)
    p = np.arange(n) / n
    np.testing.assert_array_equal(count[np.abs(p - 0.5) < 0.5 - h - 1e-9], 1)
    np.testing.assert_array_equal(count[(p < h - 1e-9) | (p > 1 - h + 1e-9)], 2)


@pytest.mark.parametrize("make_pair", [reference_pair, one_stage_pair, stage2_pair])
def test_single_below_double(make_pair):
    _, k, k_pairs = mesh_stiffness_cycle(make_pair(), N_PHASE)
    count = (k_pairs > 0).sum(axis=0)
    assert set(np.unique(count)) == {1, 2}
    assert k[count == 1].max() < k[count == 2].min()


def test_pair_zero_out_of_contact():
    pair = reference_pair()
    assert pair_stiffness_N_per_m(pair, pair.contact_start_m - 1e-6) == 0.0
    assert pair_stiffness_N_per_m(pair, pair.contact_end_m + 1e-6) == 0.0
    assert pair_stiffness_N_per_m(pair, pair.contact_start_m) > 0.0


def test_equal_gears_symmetric_profile():
    pair = reference_pair()
    s = pair.roll_position_m(np.linspace(0.5 - 0.45 * pair.contact_ratio, 0.5, 7))
    mirror = pair.contact_start_m + pair.contact_end_m - s
    for a, b in zip(s, mirror, strict=True):
        assert pair_stiffness_N_per_m(pair, a) == pytest.approx(pair_stiffness_N_per_m(pair, b), rel=1e-10)


@pytest.mark.parametrize("make_pair", [reference_pair, stage2_pair])
@pytest.mark.parametrize("gear", ["pinion", "wheel"])
def test_crack_zero_is_healthy_and_depth_monotonic(make_pair, gear):
    pair = make_pair()
    _, k0, d0 = damaged_mesh_stiffness_window(pair, None, 100)
    _, kc, dc = damaged_mesh_stiffness_window(pair, RootCrack(0.0, 45.0, gear), 100)
    np.testing.assert_array_equal(kc, k0)
    np.testing.assert_array_equal(dc, d0)
    m = pair.pinion.module_m
    depths = [0.0, 0.25 * m, 0.5 * m, 0.75 * m, 1.0 * m]
    means, prev = [], d0
    for q in depths[1:]:
        _, k, d = damaged_mesh_stiffness_window(pair, RootCrack(q, 45.0, gear), 100)
        assert np.all(d <= prev * (1 + 1e-12))
        assert np.all(d[d0 > 0] < prev[d0 > 0])
        means.append(k.mean())
        prev = d
    assert np.all(np.diff([k0.mean(), *means]) < 0)


def test_crack_through_centre_line_rejected():
    pair = reference_pair()
    with pytest.raises(ValueError, match="centre line"):
        damaged_pair_stiffness_N_per_m(pair, 0.0212, RootCrack(0.005, 60.0))


def test_breakage():
    pair = reference_pair()
    s = pair.roll_position_m(np.linspace(0.5 - 0.5 * pair.contact_ratio, 0.5 + 0.5 * pair.contact_ratio, 41))
    healthy = np.array([pair_stiffness_N_per_m(pair, x) for x in s])
    zero = np.array([damaged_pair_stiffness_N_per_m(pair, x, ToothBreakage(0.0)) for x in s])
    np.testing.assert_array_equal(zero, healthy)
    brk = ToothBreakage(0.3, "pinion")
    r_keep = brk.remaining_radius_m(pair.pinion)
    broken = np.array([damaged_pair_stiffness_N_per_m(pair, x, brk) for x in s])
    on_missing = np.hypot(pair.pinion.base_radius_m, s) > r_keep
    assert 0 < on_missing.sum() < s.size
    assert np.all(broken[on_missing] == 0.0)
    np.testing.assert_array_equal(broken[~on_missing], healthy[~on_missing])
    # wheel breakage: the wheel's tip meets the pinion root, at the start of contact
    wb = [damaged_pair_stiffness_N_per_m(pair, x, ToothBreakage(0.3, "wheel")) for x in s]
    assert wb[0] == 0.0 and wb[-1] == healthy[-1]
    # partial-width breakage keeps the intact width
    half = [damaged_pair_stiffness_N_per_m(pair, x, ToothBreakage(0.3, "pinion", 0.5)) for x in s]
    np.testing.assert_allclose(np.array(half)[on_missing], 0.5 * healthy[on_missing], rtol=1e-12)


def test_spall():
    pair = reference_pair()
    g = pair.pinion
    r_lo, r_hi = 61.5e-3, 62.5e-3
    s = pair.roll_position_m(np.linspace(0.5 - 0.5 * pair.contact_ratio, 0.5 + 0.5 * pair.contact_ratio, 41))
    healthy = np.array([pair_stiffness_N_per_m(pair, x) for x in s])
    none = [damaged_pair_stiffness_N_per_m(pair, x, Spall(r_lo, r_hi, 0.0)) for x in s]
    np.testing.assert_array_equal(none, healthy)
    inside = (np.hypot(g.base_radius_m, s) >= r_lo) & (np.hypot(g.base_radius_m, s) <= r_hi)
    assert 0 < inside.sum() < s.size
    sp = np.array([damaged_pair_stiffness_N_per_m(pair, x, Spall(r_lo, r_hi, 0.4)) for x in s])
    np.testing.assert_allclose(sp[inside], 0.6 * healthy[inside], rtol=1e-12)
    np.testing.assert_array_equal(sp[~inside], healthy[~inside])
    hz = np.array(
        [damaged_pair_stiffness_N_per_m(pair, x, Spall(r_lo, r_hi, 0.4, hertz_only=True)) for x in s]
    )
    assert np.all(hz[inside] < healthy[inside]) and np.all(hz[inside] > sp[inside])


def test_damaged_window_spans_contact():
    pair = reference_pair()
    phase, k, d = damaged_mesh_stiffness_window(pair, ToothBreakage(1.0), 100)
    assert np.all(d == 0.0)
    _, k0, d0 = damaged_mesh_stiffness_window(pair, None, 100)
    on = d0 > 0
    assert np.all(np.abs(phase[on] - 0.5) <= 0.5 * pair.contact_ratio + 1e-9)
    np.testing.assert_allclose(k, k0 - d0, rtol=1e-12)


def test_profile_shift_geometry():
    a = SpurGear(29, 0.005, 0.06, 0.03, profile_shift=0.3)
    b = SpurGear(88, 0.005, 0.06, 0.045, profile_shift=-0.3)
    pair = SpurPair(a, b)
    assert pair.working_pressure_angle_rad == pytest.approx(math.radians(20.0), abs=1e-12)
    assert pair.operating_center_distance_m == pytest.approx(0.005 * 117 / 2)
    pos = SpurPair(a, SpurGear(88, 0.005, 0.06, 0.045, profile_shift=0.3))
    assert pos.working_pressure_angle_rad > math.radians(20.0)
    assert pos.operating_center_distance_m > 0.005 * 117 / 2


def test_print_scene_pairs():
    """Figures to compare with the hand-given k_z 1.2/1.3e9 (one stage) and 1.6/1.8e9 N/m (stage 2)."""
    for name, pair in [
        ("62/62", reference_pair()),
        ("one-stage", one_stage_pair()),
        ("stage 2", stage2_pair()),
    ]:
        s = mesh_stiffness_summary(pair, N_PHASE)
        print(
            f"\n{name}: eps {s['contact_ratio']:.5f} k_h {s['hertz_N_per_m']:.4e}"
            f" mean {s['mean_N_per_m']:.4e}"
            f" single {s['single_mean_N_per_m']:.4e} double {s['double_mean_N_per_m']:.4e}"
            f" min {s['min_N_per_m']:.4e} max {s['max_N_per_m']:.4e}"
        )
        assert s["single_mean_N_per_m"] < s["mean_N_per_m"] < s["double_mean_N_per_m"]
