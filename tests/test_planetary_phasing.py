"""Planet phasing in the forced response of the simulated drive (validation/planetary_phasing.py): the
ring-fixed sensor keeps only McFadden & Smith's lines, and the sun feels Parker's phasing rule."""

import pytest
from gearbody_validation.planetary_phasing import VARIANTS, run_variant

pytestmark = pytest.mark.slow  # two runs of one carrier revolution each (~10 s each)


@pytest.fixture(scope="module")
def results():
    return {name: run_variant(teeth, revolutions=1) for name, teeth in VARIANTS.items()}


def test_in_phase_planets_keep_the_mesh_harmonics_on_the_ring_sensor(results):
    """Z_r = 42 = 0 mod 3: the mesh harmonics k f_m (orders 42, 84) carry the signal; the orders between
    them that the rule cancels stay below 3 % of the strongest line (the full-width Hann window adds no
    sidebands at +-3 f_c)."""
    res = results["in phase"]
    top = max(res.sensor_at(42), res.sensor_at(84))
    assert res.sensor_at(42) > 0.3 * top and res.sensor_at(84) > 0.3 * top
    for order in (*range(37, 42), *range(43, 48), *range(80, 84), *range(85, 89)):
        if order % 3:
            assert res.sensor_at(order) < 0.03 * top, order


def test_sequential_planets_suppress_the_mesh_harmonic_and_shift_it_to_the_surviving_order(results):
    """Z_r = 41: the mesh line (order 41) and its neighbour 40 cancel; the surviving order 42 = f_m + f_c
    is the strongest near f_m, and 81 = 2 f_m - f_c near 2 f_m (McFadden & Smith: (k Z_r + q) = 0 mod 3)."""
    res = results["sequential"]
    assert res.sensor_at(42) > 10 * max(res.sensor_at(41), res.sensor_at(40), res.sensor_at(43))
    assert res.sensor_at(81) > 10 * max(res.sensor_at(82), res.sensor_at(80), res.sensor_at(83))


def test_parker_rule_rotational_when_l_zs_over_n_is_an_integer(results):
    """Parker's rule on the sun, each line against N times one planet's (the share: 1 when the planets add
    in phase, 0 when they cancel). In phase (Z_s = 12) every harmonic is rotational: the torque adds up, the
    net force cancels. Sequential (Z_s = 13): l = 1, 2 are translational (the torque cancels, the net force
    in the carrier frame remains), l = 3 rotational."""
    inp, seq = results["in phase"], results["sequential"]
    for harmonic in (1, 2, 3):
        assert inp.torque_share(harmonic) > 0.9 and inp.force_share(harmonic) < 1e-6, harmonic
    for harmonic in (1, 2):  # measured over one revolution: torque shares 0.09 and 0.02, forces 0.51, 0.52
        assert seq.torque_share(harmonic) < 0.2 < 0.4 < seq.force_share(harmonic), harmonic
    # l = 3 rotational: the torque adds up (1.26); its net force line (share 0.40 of a 1 N line) is not
    # the excitation but the mixing of the large l = 1, 2 translational motions with the mesh stiffness
    assert seq.torque_share(3) > 0.5
