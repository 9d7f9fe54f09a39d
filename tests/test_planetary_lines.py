"""Kinematic lines of a planetary stage, the ring-fixed sensor, McFadden and Smith's rule and Parker's
planet-phasing rule, checked against hand-computed numbers and independent sums. Engine-free, fast."""

import math
from fractions import Fraction

import numpy as np
import pytest

from gearbody.analysis.labels import label_peaks, peaks_table
from gearbody.analysis.planet_pass import (
    HannPassWindow,
    phasing_excitation,
    ring_sensor_signal,
    surviving_lines,
    wrap_angle_rad,
)
from gearbody.analysis.planetary_lines import SYMBOLS, PlanetaryLine, PlanetarySources, planetary_lines
from gearbody.analysis.spectrum import amplitude_spectrum

# --- the stated example: Z_s = 21, Z_p = 30, Z_r = 81, N = 3, ring fixed, sun at 25 Hz -------------------
# Assembly: (21 + 81)/3 = 34, an integer, and Z_r = Z_s + 2 Z_p = 81 (standard gears).
# By hand (Willis with the ring fixed): f_c = f_s Z_s/(Z_s + Z_r) = 25 * 21/102 = 175/34 Hz = 5.1470588 Hz;
# f_m = Z_r f_c = 81 * 175/34 = 14175/34 Hz = 416.91176 Hz (= Z_s (f_s - f_c) = 21 * 675/34, the same);
# planet relative to the carrier: f_p - f_c = -f_m/Z_p = -14175/1020 = -13.897059 Hz, so
# f_p = 175/34 - 14175/1020 = -8.75 Hz exactly; f_pp = 3 f_c = 525/34 = 15.441176 Hz;
# f_sf = 3 (25 - 175/34) = 2025/34 = 59.558824 Hz; f_pf = 13.897059 Hz (27.794118 Hz on both flanks);
# f_rf = 3 f_c = 15.441176 Hz.

F_C = Fraction(25) * 21 / 102
F_M = 81 * F_C
F_P = F_C - F_M / 30


def example() -> PlanetarySources:
    return PlanetarySources(21, 30, 81, 3, carrier_hz=float(F_C), sun_hz=25.0, ring_hz=0.0, planet_hz=-8.75)


def test_hand_computed_example_numbers():
    assert F_C == Fraction(175, 34) and F_P == Fraction(-35, 4)  # -8.75 Hz, as computed above
    s = example()
    assert s.carrier_relative_hz == pytest.approx(175 / 34, rel=1e-14)
    assert s.mesh_hz == pytest.approx(14175 / 34, rel=1e-14)
    assert s.mesh_hz == pytest.approx(21 * (25 - 175 / 34), rel=1e-14)  # Z_s |f_s - f_c|
    assert s.mesh_hz == pytest.approx(30 * abs(-8.75 - 175 / 34), rel=1e-14)  # Z_p |f_p - f_c|
    assert s.planet_pass_hz == pytest.approx(525 / 34, rel=1e-14)
    assert s.sun_fault_hz == pytest.approx(2025 / 34, rel=1e-14)
    assert s.planet_fault_hz == pytest.approx(14175 / 1020, rel=1e-14)
    assert s.ring_fault_hz == pytest.approx(525 / 34, rel=1e-14)
    assert s.sun_relative_hz == 25.0


def test_fault_frequencies_are_mesh_frequency_over_teeth():
    """A second route: a member turns f_m / Z relative to the carrier, so f_sf = N f_m / Z_s,
    f_pf = f_m / Z_p, f_rf = N f_m / Z_r, for the example and for a stage with a turning ring."""
    turning_ring = PlanetarySources(
        20, 31, 82, 4, carrier_hz=3.0, sun_hz=3.0 + 82 * 4.5 / 20, ring_hz=-1.5, planet_hz=3.0 - 82 * 4.5 / 31
    )
    for s in (example(), turning_ring):
        f_m = s.mesh_hz
        assert s.sun_fault_hz == pytest.approx(s.n_planets * f_m / s.z_sun, rel=1e-13)
        assert s.planet_fault_hz == pytest.approx(f_m / s.z_planet, rel=1e-13)
        assert s.ring_fault_hz == pytest.approx(s.n_planets * f_m / s.z_ring, rel=1e-13)
    assert turning_ring.mesh_hz == pytest.approx(82 * 4.5) and turning_ring.planet_pass_hz == pytest.approx(
        18.0
    )


def test_catalogue_names_the_example_lines():
    lines = planetary_lines(example(), f_max_hz=900.0, harmonics=2, sidebands=6, fault_orders=2)
    assert all(isinstance(line, PlanetaryLine) for line in lines)
    by_label = {line.label: line for line in lines}
    expected_hz = {
        "1x carrier": 175 / 34,
        "1x sun": 25.0,
        "1 f_pp": 525 / 34,
        "1 f_m": 14175 / 34,
        "2 f_m": 2 * 14175 / 34,
        "f_m + 3 f_c": (81 + 3) * 175 / 34,
        "f_m - 6 f_c": (81 - 6) * 175 / 34,
        "2 f_m - f_c": (162 - 1) * 175 / 34,
        "1 f_sf": 2025 / 34,
        "1 f_pf": 14175 / 1020,
        "2 f_pf": 2 * 14175 / 1020,
        "1 f_rf": 525 / 34,
    }
    for label, f_hz in expected_hz.items():
        assert by_label[label].frequency_hz == pytest.approx(f_hz, rel=1e-12), label
    assert by_label["1 f_m"].family == "mesh" and by_label["1 f_sf"].family == "fault"
    assert by_label["f_m + 3 f_c"].orders == (("f_m", 1), ("f_c", 3))
    assert [line.frequency_hz for line in lines] == sorted(line.frequency_hz for line in lines)
    assert max(line.frequency_hz for line in lines) <= 900.0
    # every symbol of every label is in the legend
    assert {s for line in lines for s, _ in line.orders} <= set(SYMBOLS)


def test_catalogue_marks_the_lines_equal_spacing_lets_through():
    """Z_r = 81 = 27 * 3: the mesh harmonics survive with sidebands at multiples of N f_c = 3 f_c only."""
    lines = planetary_lines(example(), f_max_hz=900.0, harmonics=2, sidebands=6)
    sidebands = [line for line in lines if line.family == "sideband"]
    assert sidebands
    for line in sidebands:
        q = dict(line.orders)["f_c"]
        assert line.survives_equal_spacing == (q % 3 == 0), line.label
    assert all(line.survives_equal_spacing for line in lines if line.family in ("mesh", "planet_pass"))
    carrier = {line.label: line.survives_equal_spacing for line in lines if "carrier" in line.label}
    assert carrier == {"1x carrier": False, "2x carrier": False, "3x carrier": True}
    assert all(line.survives_equal_spacing is None for line in lines if line.family == "fault")


def test_ring_as_the_turning_member_gives_lines_in_the_rings_frame():
    """Carrier held (a star stage), ring turning: the planets pass a ring point at N |f_c - f_r|."""
    f_r = -2.0
    f_s = -81 * f_r / 21  # Z_s f_s = -Z_r f_r with f_c = 0
    s = PlanetarySources(21, 30, 81, 3, carrier_hz=0.0, sun_hz=f_s, ring_hz=f_r, planet_hz=81 * f_r / 30)
    assert s.mesh_hz == pytest.approx(162.0) and s.planet_pass_hz == pytest.approx(6.0)
    assert s.sun_fault_hz == pytest.approx(3 * 81 * 2 / 21) and s.planet_fault_hz == pytest.approx(5.4)


def test_fault_sidebands_sit_around_the_mesh_harmonics():
    s = example()
    lines = planetary_lines(s, 1000.0, harmonics=1, fault_sidebands=1)
    found = {line.label: line.frequency_hz for line in lines if line.family == "fault_sideband"}
    assert found["f_m + f_sf"] == pytest.approx(s.mesh_hz + s.sun_fault_hz)
    assert found["f_m - f_pf"] == pytest.approx(s.mesh_hz - s.planet_fault_hz)
    assert len(found) == 6


# --- the synthetic ring-sensor signal ------------------------------------------------------------------

SAMPLES_PER_REV = 1920  # a multiple of N = 3, 4, 5, 6: equally spaced planets sit whole samples apart, so
REVOLUTIONS = 4  # the sampled sum cancels as exactly as the continuous one (aliased orders included)
WIDE_RAD = 2 * np.pi / 2.3  # a Hann width whose Fourier coefficients W_q vanish at no q below 10


def sensor_spectrum(z_ring, n_planets, window, positions_rad=None, sensor_angle_rad=0.3):
    """Planets with identical unit cosine mesh forces, phase Z_r psi_n, carrier at 1 Hz; the spectrum of
    the sum by numpy's FFT over an integer number of revolutions (every line on a bin, no leakage),
    returned as single-sided amplitude per carrier order."""
    n_samples = SAMPLES_PER_REV * REVOLUTIONS
    t = np.arange(n_samples) / SAMPLES_PER_REV  # f_c = 1 Hz: t in carrier revolutions
    if positions_rad is None:
        positions_rad = 2 * np.pi * np.arange(n_planets) / n_planets
    psi = 2 * np.pi * t[None, :] + np.asarray(positions_rad)[:, None]
    forces = np.cos(z_ring * psi)  # a mesh period per ring tooth passed: phase Z_r psi_n
    y = ring_sensor_signal(t, psi, forces, sensor_angle_rad, window).signal_N
    amplitude = 2 * np.abs(np.fft.rfft(y)) / n_samples
    return amplitude[::REVOLUTIONS]  # bins at integer carrier orders


def window_coefficients(window, sensor_angle_rad=0.3):
    """W_q e^(-i q theta_s): the Fourier coefficients of phi -> w(phi - theta_s) over one revolution,
    computed from the window's samples alone (independent of the planet sum)."""
    phi = 2 * np.pi * np.arange(SAMPLES_PER_REV) / SAMPLES_PER_REV
    return np.fft.fft(window(phi - sensor_angle_rad)) / SAMPLES_PER_REV


def test_full_width_hann_window_spectra_worked_by_hand():
    """w = (1 + cos phi)/2 has W_0 = 1/2, W_+-1 = 1/4 only. Three planets, unit forces:
    Z_r = 81 (in phase): only q = 0 survives, a single line at 81 f_c of amplitude N/2 = 1.5;
    Z_r = 80 (sequential): only q = +1 (81 = 0 mod 3), a single line at 81 f_c of N/4 = 0.75,
    and nothing at the mesh frequency 80 f_c."""
    window = HannPassWindow(2 * np.pi)
    in_phase = sensor_spectrum(81, 3, window)
    assert in_phase[81] == pytest.approx(1.5, rel=1e-12)
    assert np.delete(in_phase, 81).max() < 1e-12
    sequential = sensor_spectrum(80, 3, window)
    assert sequential[81] == pytest.approx(0.75, rel=1e-12)
    assert sequential[80] < 1e-12
    assert np.delete(sequential, 81).max() < 1e-12


@pytest.mark.parametrize("width_rad", [np.pi / 2, np.pi, 1.5 * np.pi])
def test_in_phase_planets_keep_the_mesh_harmonic_with_sidebands_at_multiples_of_n_fc(width_rad):
    window = HannPassWindow(width_rad)
    a = sensor_spectrum(81, 3, window)
    band = {q: a[81 + q] for q in range(-12, 13)}
    assert max(band, key=band.get) == 0  # the mesh harmonic is the strongest line of its band
    for q, value in band.items():
        if q % 3:
            assert value < 1e-12, q
    assert band[3] > 1e-3 and band[-3] > 1e-3
    # the surviving lines have the amplitude the window's own coefficients predict: N |W_q| (the
    # negative-frequency branch adds W_(q + 2 Z_r), included)
    c = window_coefficients(window)
    for q in (-6, -3, 0, 3, 6):
        predicted = 3 * abs(c[q] + c[(q + 2 * 81) % SAMPLES_PER_REV])
        assert band[q] == pytest.approx(predicted, rel=1e-9, abs=1e-14), q


@pytest.mark.parametrize(("z_ring", "n_planets"), [(80, 3), (82, 3), (81, 4), (83, 5), (97, 4), (100, 6)])
def test_sequential_phasing_suppresses_the_mesh_harmonic_and_the_rule_places_the_lines(z_ring, n_planets):
    window = HannPassWindow(WIDE_RAD)
    a = sensor_spectrum(z_ring, n_planets, window)
    q_range = 2 * n_planets
    (rule,) = surviving_lines(z_ring, n_planets, [1], q_range)
    assert not rule.mesh_present
    band = {q: a[z_ring + q] for q in range(-q_range, q_range + 1)}
    peak = max(band.values())
    assert band[0] < 1e-12 * peak  # the mesh harmonic is suppressed
    c = window_coefficients(window)
    for q, value in band.items():
        if q in rule.q:  # a line where the rule puts one, of the amplitude N |W_q| (+ the far branch)
            predicted = n_planets * abs(c[q] + c[(q + 2 * z_ring) % SAMPLES_PER_REV])
            assert predicted > 1e-6 * peak and value == pytest.approx(predicted, rel=1e-9), q
        else:
            assert value < 1e-12 * peak, q
    strongest = [q for q, value in band.items() if value > peak * (1 - 1e-9)]
    assert tuple(strongest) == rule.nearest_q


def test_sequential_phasing_makes_the_sidebands_asymmetric():
    """Z_r = 80, N = 3: f_m + f_c survives and f_m - f_c does not; f_m - 2 f_c survives, f_m + 2 f_c not."""
    a = sensor_spectrum(80, 3, HannPassWindow(WIDE_RAD))
    assert a[81] > 0.1 and a[79] < 1e-12
    assert a[78] > 0.01 and a[82] < 1e-12
    assert a[81] > a[78]  # |W_1| > |W_2| for this window


def test_three_mesh_harmonics_follow_the_rule_each():
    """Forces with harmonics 1, 2, 3 (Z_r = 80, N = 3): harmonics 1 and 2 suppressed with their strongest
    lines at q = +1 and q = -1, harmonic 3 (240 = 0 mod 3) present; nothing outside the rule's lines."""
    n_samples = SAMPLES_PER_REV * REVOLUTIONS
    t = np.arange(n_samples) / SAMPLES_PER_REV
    psi = 2 * np.pi * t[None, :] + 2 * np.pi * np.arange(3)[:, None] / 3
    forces = np.cos(80 * psi) + 0.5 * np.cos(160 * psi + 0.3) + 0.25 * np.cos(240 * psi - 1.0)
    y = ring_sensor_signal(t, psi, forces, 0.3, HannPassWindow(WIDE_RAD)).signal_N
    a = (2 * np.abs(np.fft.rfft(y)) / n_samples)[::REVOLUTIONS]
    allowed = set()
    for rule in surviving_lines(80, 3, 3, 40):  # bands of +-40 orders cover 74 .. 246
        centre = 80 * rule.harmonic
        band = {q: a[centre + q] for q in range(-6, 7)}
        assert (band[0] > 1e-3) == rule.mesh_present
        assert max(band, key=band.get) in rule.nearest_q
        allowed |= {centre + q for q in rule.q}
    outside = [a[order] for order in range(74, 247) if order not in allowed]
    assert max(outside) < 1e-12


def test_unequally_spaced_planets_break_the_cancellation():
    """The rule is a property of equal spacing: planets at 0, 110 and 250 degrees show every line."""
    a = sensor_spectrum(80, 3, HannPassWindow(np.pi), positions_rad=np.radians([0.0, 110.0, 250.0]))
    assert a[80] > 1e-3 and a[79] > 1e-3 and a[82] > 1e-3


def test_labelled_peaks_of_the_sensor_signal_name_the_planetary_lines():
    """The planetary catalogue works with label_peaks and peaks_table as it is."""
    s = PlanetarySources(
        22, 29, 80, 3, carrier_hz=1.0, sun_hz=1 + 80 / 22, ring_hz=0.0, planet_hz=1 - 80 / 29
    )
    n_samples = SAMPLES_PER_REV * REVOLUTIONS
    t = np.arange(n_samples) / SAMPLES_PER_REV
    psi = 2 * np.pi * t[None, :] + 2 * np.pi * np.arange(3)[:, None] / 3
    y = ring_sensor_signal(t, psi, np.cos(80 * psi), 0.0, HannPassWindow(np.pi)).signal_N
    spectrum = amplitude_spectrum(y, SAMPLES_PER_REV, window="boxcar")
    peaks = label_peaks(spectrum, planetary_lines(s, 200.0, harmonics=1), min_prominence_db=20.0)
    labels = {round(p.frequency_hz): p.label for p in peaks}
    assert labels[81] == "f_m + f_c" and labels[78] == "f_m - 2 f_c"
    assert 80 not in labels  # the suppressed mesh frequency is no peak
    assert "f_m + f_c" in peaks_table(peaks)


def test_example_stage_sensor_spectrum_labelled_in_hertz():
    """The stated example at its own speeds (f_c = 175/34 Hz, f_m = 416.9 Hz), planets in phase
    (Z_r = 81 = 27 * 3): the peaks are the mesh harmonic and its sidebands at +-3 f_c, +-6 f_c, all
    lines the catalogue marks as surviving equal spacing."""
    s = example()
    n_samples = SAMPLES_PER_REV * REVOLUTIONS
    fs_hz = SAMPLES_PER_REV * s.carrier_hz
    t = np.arange(n_samples) / fs_hz
    psi = 2 * np.pi * s.carrier_hz * t[None, :] + 2 * np.pi * np.arange(3)[:, None] / 3
    forces = 100.0 * np.cos(2 * np.pi * s.mesh_hz * t[None, :] + 81 * (psi - psi[:1]))  # phase Z_r psi_n
    y = ring_sensor_signal(t, psi, forces, 0.3, HannPassWindow(WIDE_RAD)).signal_N
    spectrum = amplitude_spectrum(y, fs_hz, window="boxcar")
    lines = planetary_lines(s, 500.0, harmonics=1)
    peaks = label_peaks(spectrum, lines, min_prominence_db=40.0, f_max_hz=500.0)
    top = max(p.amplitude for p in peaks)
    peaks = [p for p in peaks if p.amplitude > 1e-4 * top]  # not the far branch's 1e-16 N lines
    labels = [p.label for p in peaks]
    assert {"1 f_m", "f_m + 3 f_c", "f_m - 3 f_c", "f_m + 6 f_c", "f_m - 6 f_c"} <= set(labels)
    by_label = {line.label: line for line in lines}
    for p in peaks:
        assert all(by_label[label].survives_equal_spacing for label in p.labels), p.label
    assert max(peaks, key=lambda p: p.amplitude).label == "1 f_m"
    assert max(peaks, key=lambda p: p.amplitude).frequency_hz == pytest.approx(14175 / 34, rel=1e-12)


# --- the window and the sensor's sum, by hand ----------------------------------------------------------


def test_hann_window_values_by_hand():
    w = HannPassWindow(np.pi)
    values = w(np.array([0.0, np.pi / 4, -np.pi / 4, np.pi / 2, 0.6 * np.pi, 2 * np.pi + 0.1]))
    expected = [1.0, 0.5, 0.5, 0.0, 0.0, math.cos(0.1) ** 2]
    np.testing.assert_allclose(values, expected, atol=1e-15)
    full = HannPassWindow(2 * np.pi)
    phi = np.linspace(-3, 3, 7)
    np.testing.assert_allclose(full(phi), (1 + np.cos(phi)) / 2, atol=1e-15)
    np.testing.assert_allclose(wrap_angle_rad([3 * np.pi, -np.pi, 0.5]), [-np.pi, -np.pi, 0.5])


def test_ring_sensor_sum_and_projection_by_hand():
    """Two planets at 0 and pi/2, sensor at pi/4, Hann width pi: each weight cos^2(pi/4) = 1/2.
    Forces 10 N and 4 N: y = 5 + 2 = 7 N. With the force at delta = pi/2 from the planet angle:
    planet 0 projects cos(0 + pi/2 - pi/4) = cos(pi/4), planet 1 cos(pi/2 + pi/2 - pi/4) = -cos(pi/4):
    y = (5 - 2) / sqrt(2) N."""
    t = np.array([0.0, 1.0])
    psi = np.array([[0.0, 0.0], [np.pi / 2, np.pi / 2]])
    forces = np.array([[10.0, 10.0], [4.0, 4.0]])
    plain = ring_sensor_signal(t, psi, forces, np.pi / 4, HannPassWindow(np.pi))
    np.testing.assert_allclose(plain.signal_N, [7.0, 7.0])
    np.testing.assert_allclose(plain.weights, 0.5)
    projected = ring_sensor_signal(t, psi, forces, np.pi / 4, HannPassWindow(np.pi), np.pi / 2)
    np.testing.assert_allclose(projected.signal_N, [3 / math.sqrt(2)] * 2)
    # a custom window sees the angles wrapped to [-pi, pi): planets 10 turns on give the same signal
    seen = []
    window = HannPassWindow(np.pi)
    custom = ring_sensor_signal(
        t, psi + 20 * np.pi, forces, np.pi / 4, lambda phi: seen.append(phi) or window(phi)
    )
    np.testing.assert_allclose(custom.signal_N, plain.signal_N)
    np.testing.assert_allclose(seen[0], [[-np.pi / 4] * 2, [np.pi / 4] * 2])


# --- McFadden and Smith's rule and Parker's rule -------------------------------------------------------


def test_surviving_lines_by_hand():
    """Z_r = 80, N = 3: 80 = 2 mod 3, so k = 1 keeps q = 1 (81), -2 (78), 4 (84), -5 (75);
    k = 2: 160 = 1 mod 3 keeps q = -1 (159), 2 (162), ...; k = 3: 240 = 0 mod 3, the mesh harmonic."""
    k1, k2, k3 = surviving_lines(80, 3, 3, 5)
    assert (k1.mesh_present, k1.q, k1.nearest_q, k1.carrier_orders) == (
        False,
        (-5, -2, 1, 4),
        (1,),
        (75, 78, 81, 84),
    )
    assert (k2.mesh_present, k2.q, k2.nearest_q) == (False, (-4, -1, 2, 5), (-1,))
    assert (k3.mesh_present, k3.q, k3.nearest_q) == (True, (-3, 0, 3), (0,))
    np.testing.assert_allclose(k1.frequencies_hz(175 / 34), np.array([75, 78, 81, 84]) * 175 / 34)
    # N = 4, Z_r = 82: 82 = 2 mod 4, q = -2 and +2 tie
    (tie,) = surviving_lines(82, 4, [1], 2)
    assert tie.q == (-2, 2) and tie.nearest_q == (-2, 2)


def test_surviving_lines_agree_with_the_sum_over_planets():
    """Independent: sum_n exp(i (k Z_r + q) 2 pi n / N) is N or 0."""
    for z_ring, n in [(80, 3), (81, 3), (97, 5), (100, 6), (71, 4)]:
        for rule in surviving_lines(z_ring, n, 4, 9):
            for q in range(-9, 10):
                total = abs(np.sum(np.exp(1j * (rule.harmonic * z_ring + q) * 2 * np.pi * np.arange(n) / n)))
                assert (total > 1e-9) == (q in rule.q)
            assert rule.mesh_present == ((rule.harmonic * z_ring) % n == 0)


# Parker (2000), as stated in docs/references.md: rotational if l Z_s / N is an integer, translational if
# (l Z_s +- 1)/N is, planet modes otherwise. By hand:
PARKER_CASES = [
    (21, 3, 1, "rotational"),  # 21/3 = 7
    (22, 3, 1, "translational"),  # (22 - 1)/3 = 7
    (20, 3, 1, "translational"),  # (20 + 1)/3 = 7
    (22, 4, 1, "planet"),  # 22/4, 21/4, 23/4: none an integer
    (22, 4, 2, "rotational"),  # 44/4 = 11
    (23, 5, 1, "planet"),  # 23 = 3 mod 5
    (23, 5, 2, "translational"),  # (46 - 1)/5 = 9
    (23, 5, 5, "rotational"),  # 115/5 = 23
    (31, 6, 1, "translational"),  # (31 - 1)/6 = 5
    (32, 6, 1, "planet"),  # 32 = 2 mod 6
    (33, 6, 2, "rotational"),  # 66/6 = 11
    (25, 2, 1, "translational"),  # (25 + 1)/2 = 13
]


@pytest.mark.parametrize(("z_sun", "n_planets", "harmonic", "expected"), PARKER_CASES)
def test_parker_planet_phasing_rule_cases(z_sun, n_planets, harmonic, expected):
    assert phasing_excitation(z_sun, n_planets, harmonic) == expected


@pytest.mark.parametrize(("z_sun", "n_planets", "harmonic", "expected"), PARKER_CASES)
def test_parker_rule_from_the_net_mesh_load_on_the_sun(z_sun, n_planets, harmonic, expected):
    """Independent: the l-th harmonic of planet n's sun-mesh force has phase l Z_s psi_n and acts along
    a direction turning with psi_n. Its net moment on the sun ~ sum_n exp(i l Z_s psi_n) (rotational
    modes), its net force x + i y ~ sum_n exp(i psi_n (1 +- l Z_s)) (translational modes); with
    neither, only planet modes are loaded."""
    psi = 2 * np.pi * np.arange(n_planets) / n_planets
    lz = harmonic * z_sun
    moment = abs(np.sum(np.exp(1j * lz * psi)))
    force = max(abs(np.sum(np.exp(1j * psi * (1 + lz)))), abs(np.sum(np.exp(1j * psi * (1 - lz)))))
    computed = "rotational" if moment > 1e-9 else "translational" if force > 1e-9 else "planet"
    assert moment < 1e-9 or force < 1e-9  # the classes exclude each other
    assert computed == expected


def test_parker_rule_over_a_range_of_stages_matches_the_net_load():
    for n in range(2, 8):
        psi = 2 * np.pi * np.arange(n) / n
        for z_sun in range(12, 40):
            for harmonic in range(1, 6):
                lz = harmonic * z_sun
                moment = abs(np.sum(np.exp(1j * lz * psi))) > 1e-9
                force = max(abs(np.sum(np.exp(1j * psi * (1 + s * lz)))) for s in (1, -1)) > 1e-9
                computed = "rotational" if moment else "translational" if force else "planet"
                assert phasing_excitation(z_sun, n, harmonic) == computed, (z_sun, n, harmonic)


def test_three_planets_never_excite_planet_modes():
    """Lin & Parker: N = 3 has no planet modes (multiplicity N - 3 = 0), so no harmonic may excite them."""
    assert {phasing_excitation(z, 3, k) for z in range(12, 60) for k in range(1, 6)} == {
        "rotational",
        "translational",
    }


# --- bad input, named ----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"planet_hz": -8.0}, r"planet_hz must be -8\.75 Hz by the Willis equation.*got -8\.0"),
        ({"sun_hz": 26.0}, r"sun_hz must be 25 Hz by the Willis equation.*got 26\.0"),
        ({"carrier_hz": 0.0, "sun_hz": 0.0, "planet_hz": 0.0}, r"carrier_hz = 0\.0 equals ring_hz = 0\.0"),
        ({"z_ring": 25}, r"z_ring must exceed z_sun = 21 and z_planet = 30.*got 25"),
        ({"n_planets": 0}, r"n_planets must be an integer >= 1, got 0"),
        ({"z_sun": 2.5}, r"z_sun must be an integer >= 3, got 2\.5"),
        ({"ring_hz": float("nan")}, r"ring_hz must be a finite signed speed \[Hz\], got nan"),
        ({"rtol": 0.0}, r"rtol must be a number in \(0, 1\), got 0\.0"),
    ],
)
def test_bad_stage_input_is_named(kwargs, match):
    args = {
        "z_sun": 21,
        "z_planet": 30,
        "z_ring": 81,
        "n_planets": 3,
        "carrier_hz": float(F_C),
        "sun_hz": 25.0,
        "ring_hz": 0.0,
        "planet_hz": -8.75,
    }
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        PlanetarySources(**args)


def test_willis_tolerance_admits_a_small_speed_error():
    s = PlanetarySources(21, 30, 81, 3, float(F_C), 25.0, 0.0, -8.75 * (1 + 1e-4), rtol=1e-3)
    assert s.planet_fault_hz == pytest.approx(13.897059 + 8.75e-4, rel=1e-6)


def test_bad_arguments_of_the_catalogue_and_the_rules_are_named():
    with pytest.raises(ValueError, match=r"sources must be a PlanetarySources, got dict"):
        planetary_lines({}, 100.0)
    with pytest.raises(ValueError, match=r"f_max_hz must be a positive frequency \[Hz\], got -1"):
        planetary_lines(example(), -1)
    with pytest.raises(ValueError, match=r"sidebands must be an integer >= 0, got -2"):
        planetary_lines(example(), 100.0, sidebands=-2)
    with pytest.raises(ValueError, match=r"width_rad must be in \(0, 2 pi\].*got 7\.0"):
        HannPassWindow(7.0)
    with pytest.raises(ValueError, match=r"n_planets must be an integer >= 2, got 1"):
        phasing_excitation(21, 1, 1)
    with pytest.raises(ValueError, match=r"harmonic must be an integer >= 1, got 0"):
        phasing_excitation(21, 3, 0)
    with pytest.raises(ValueError, match=r"q_range must be an integer >= 0, got -1"):
        surviving_lines(80, 3, 2, -1)
    with pytest.raises(ValueError, match=r"harmonics\[1\] must be an integer >= 1, got 0"):
        surviving_lines(80, 3, [1, 0], 3)
    with pytest.raises(ValueError, match=r"carrier_hz must be a positive frequency"):
        surviving_lines(80, 3, 1, 3)[0].frequencies_hz(0.0)


def test_bad_sensor_input_is_named():
    t = np.arange(4.0)
    psi = np.zeros((3, 4))
    window = HannPassWindow(np.pi)
    with pytest.raises(ValueError, match=r"planet_mesh_forces_N must have the shape of planet_angles_rad"):
        ring_sensor_signal(t, psi, np.zeros((2, 4)), 0.0, window)
    with pytest.raises(ValueError, match=r"planet_angles_rad must have shape \(n_planets, 4\)"):
        ring_sensor_signal(t, np.zeros((3, 5)), np.zeros((3, 5)), 0.0, window)
    with pytest.raises(ValueError, match=r"time_s must hold at least 2 increasing samples"):
        ring_sensor_signal(t[::-1], psi, psi, 0.0, window)
    with pytest.raises(ValueError, match=r"planet_angles_rad must be 2-D, got shape \(4,\)"):
        ring_sensor_signal(t, t, t, 0.0, window)
    with pytest.raises(ValueError, match=r"planet_mesh_forces_N must be finite"):
        ring_sensor_signal(t, psi, np.full((3, 4), np.nan), 0.0, window)
    with pytest.raises(ValueError, match=r"sensor_angle_rad must be a finite angle"):
        ring_sensor_signal(t, psi, psi, math.inf, window)
    with pytest.raises(ValueError, match=r"window must be callable"):
        ring_sensor_signal(t, psi, psi, 0.0, 3.0)
    with pytest.raises(ValueError, match=r"window must return finite weights of shape \(3, 4\)"):
        ring_sensor_signal(t, psi, psi, 0.0, lambda phi: np.ones(4))
    with pytest.raises(ValueError, match=r"force_direction_offset_rad must be a finite angle"):
        ring_sensor_signal(t, psi, psi, 0.0, window, math.nan)


def test_the_docs_quote_the_numbers_the_code_computes():
    """docs/planetary-lines.md gives the example's lines and the two phasing spectra; they must stay what
    the code computes."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "planetary-lines.md").read_text()
    s = example()
    for line in planetary_lines(s, 450.0, harmonics=1, sidebands=6, member_orders=1, fault_orders=2):
        if line.label in text:
            assert f"| {line.label} | {line.family} | {line.frequency_hz:.4f} |" in text, line.label
    in_phase = sensor_spectrum(81, 3, HannPassWindow(WIDE_RAD))
    sequential = sensor_spectrum(80, 3, HannPassWindow(WIDE_RAD))
    for value in (in_phase[81], in_phase[84], in_phase[87], sequential[81], sequential[78], sequential[84]):
        assert f"{value:.4f}" in text
    f_c = 25 * 22 / 102  # the sequential stage, sun at 25 Hz, ring fixed
    assert f"f_c = {f_c:.4f} Hz, f_m = {80 * f_c:.4f} Hz" in text and f"{81 * f_c:.4f} Hz" in text
