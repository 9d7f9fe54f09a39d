"""The ring sensor's analysis window (gearbody.analysis.carrier_window): whole carrier revolutions
relative to the ring at the end of the steady part, the order-tracked spectrum over them, the note of a
run too short for the carrier sidebands; and the marking of the lines the phasing rule cancels."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearbody.analysis import label_peaks
from gearbody.analysis.carrier_window import (
    MIN_CARRIER_REVOLUTIONS,
    CarrierWindow,
    carrier_order_spectrum,
    carrier_window,
)
from gearbody.analysis.planetary_lines import (
    CANCELLED_MARK,
    PlanetarySources,
    is_cancelled_label,
    mark_cancelled,
    planetary_lines,
)

FS_HZ = 5000.0
F_C_HZ = 5.4  # carrier relative to the ring
Z_R = 80  # sequential for N = 3: f_m cancelled, f_m + f_c survives


def carrier_angle(t_s: np.ndarray, wobble: float = 0.02) -> np.ndarray:
    """A carrier turning at F_C_HZ with a 3 Hz speed fluctuation (wobble: its angle amplitude, rad)."""
    return 2 * np.pi * F_C_HZ * t_s + wobble * np.sin(2 * np.pi * 3.0 * t_s + 0.4)


def run(t_end_s: float, wobble: float = 0.02) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(0.0, t_end_s, 1.0 / FS_HZ)
    return t, carrier_angle(t, wobble)


def test_the_window_is_every_whole_revolution_of_the_steady_half():
    t, phi = run(2.0)
    w = carrier_window(t, phi)
    assert w.steady_from_s == pytest.approx(1.0, abs=1e-3)  # the second half of a run steady from 0
    revs_in_half = (phi[-1] - np.interp(1.0, t, phi)) / (2 * np.pi)
    assert w.revolutions == math.floor(revs_in_half) == 5
    # it ends at the last sample and starts at the last sample before exactly 5 revolutions back
    assert w.stop == t.size
    assert phi[-1] - phi[w.start] >= 5 * 2 * np.pi > phi[-1] - phi[w.start + 1]
    # mean speed and duration of exactly 5 revolutions, the wobble notwithstanding
    assert w.carrier_hz == pytest.approx(F_C_HZ, rel=2e-3)
    assert w.duration_s * w.carrier_hz == pytest.approx(5.0, rel=1e-12)
    assert w.resolution_hz == pytest.approx(w.carrier_hz / 5)
    assert w.resolves_sidebands and w.note() == ""
    assert w.mask(t.size).sum() == t.size - w.start


def test_a_later_change_of_speed_or_load_moves_the_steady_part():
    t, phi = run(2.0)
    w = carrier_window(t, phi, change_s=1.2)
    assert w.steady_from_s == pytest.approx(1.6, abs=1e-3)
    assert w.revolutions == 2 and not w.resolves_sidebands
    # the carrier turning backwards relative to the ring is the same window
    assert carrier_window(t, -phi, change_s=1.2) == w


def test_whole_revolutions_put_every_carrier_order_on_a_bin():
    """Lines at carrier orders Z_r - 1, Z_r, Z_r + 1 under a fluctuating speed: exact amplitudes on the
    bins n (Z_r + q), and three separate local maxima (n = 4: a free bin between neighbours)."""
    t, phi = run(1.6)
    w = carrier_window(t, phi)
    assert w.revolutions == MIN_CARRIER_REVOLUTIONS == 4
    amplitudes = {-1: 0.2, 0: 1.0, 1: 0.5}
    y = sum(a * np.cos((Z_R + q) * phi + q) for q, a in amplitudes.items())
    spec = carrier_order_spectrum(y, phi, w, FS_HZ)
    assert spec.resolution_hz == pytest.approx(w.carrier_hz / 4, rel=1e-9)
    for q, a in amplitudes.items():
        j = 4 * (Z_R + q)
        assert spec.frequency_hz[j] == pytest.approx((Z_R + q) * w.carrier_hz, rel=1e-12)
        assert spec.amplitude[j] == pytest.approx(a, rel=1e-3)
        assert spec.amplitude[j] > spec.amplitude[j - 1] and spec.amplitude[j] > spec.amplitude[j + 1]
        assert spec.amplitude[j + 2] < 1e-3 * a  # nothing synchronous between neighbouring orders
    # the same signal over the time window (no order tracking): the wobble smears the orders
    plain = carrier_order_spectrum(y, phi, _time_only(w), FS_HZ)
    assert np.max(plain.amplitude) < 0.8


def _time_only(w: CarrierWindow) -> CarrierWindow:
    from dataclasses import replace

    return replace(w, revolutions=0)


def test_a_run_too_short_says_so_and_the_time_it_names_is_enough():
    t, phi = run(0.5)
    w = carrier_window(t, phi)
    assert w.revolutions == 1 and not w.resolves_sidebands
    note = w.note()
    assert "does not resolve the carrier sidebands" in note
    assert f"{w.resolution_hz:.3g} Hz resolution" in note
    assert f"--t-end {w.needed_t_end_s:g}" in note
    longer_t, longer_phi = run(w.needed_t_end_s + 1e-6)  # the named simulated time, from the same start
    assert carrier_window(longer_t, longer_phi).resolves_sidebands
    shorter_t, shorter_phi = run(w.needed_t_end_s - 0.15)
    assert not carrier_window(shorter_t, shorter_phi).resolves_sidebands
    # under one revolution: the steady part in time, still with its resolution and the time needed
    t, phi = run(0.2)
    w = carrier_window(t, phi)
    assert w.revolutions == 0 and w.start == np.searchsorted(t, 0.1)
    assert w.resolution_hz == pytest.approx(1 / w.duration_s)
    assert w.available_revolutions == pytest.approx(0.1 * F_C_HZ, abs=0.02)
    assert f"{w.available_revolutions:.2f} carrier revolutions" in w.note() and "--t-end 1.5" in w.note()
    spec = carrier_order_spectrum(np.cos(Z_R * phi), phi, w, FS_HZ)
    assert spec.n_samples == t.size - w.start


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"settle_factor": 0.5}, "settle_factor must be >= 1, got 0.5"),
        ({"min_revolutions": 0}, "min_revolutions"),
        ({"change_s": float("nan")}, "change_s must be a finite number"),
    ],
)
def test_bad_window_arguments_are_refused_by_name(kwargs, message):
    t, phi = run(0.5)
    with pytest.raises(ValueError, match=message):
        carrier_window(t, phi, **kwargs)
    with pytest.raises(ValueError, match="time_s and carrier_angle_rad must be 1-D"):
        carrier_window(t, phi[:-1])
    with pytest.raises(ValueError, match="window must be a CarrierWindow"):
        carrier_order_spectrum(phi, phi, None, FS_HZ)


# --- cancelled lines ------------------------------------------------------------------------------------


def sequential_stage() -> PlanetarySources:
    return PlanetarySources(
        22, 29, Z_R, 3, carrier_hz=1.0, sun_hz=1 + Z_R / 22, ring_hz=0.0, planet_hz=1 - Z_R / 29
    )


def test_mark_cancelled_marks_exactly_the_lines_the_rule_cancels():
    lines = planetary_lines(sequential_stage(), 300.0, harmonics=3)
    marked = mark_cancelled(lines)
    assert [m.frequency_hz for m in marked] == [line.frequency_hz for line in lines]
    for line, m in zip(lines, marked, strict=True):
        assert is_cancelled_label(m.label) == (line.survives_equal_spacing is False), line.label
        assert m.label == (
            f"{line.label} {CANCELLED_MARK}" if line.survives_equal_spacing is False else line.label
        )
    labels = {m.label for m in marked}
    assert "1 f_m (cancelled)" in labels and "f_m + f_c" in labels and "3 f_m" in labels
    with pytest.raises(ValueError, match=r"lines\[0\] must be a PlanetaryLine"):
        mark_cancelled(["f_m"])


def test_labelled_peaks_of_a_sensor_carry_the_cancelled_mark():
    """A ring-fixed sensor of a sequential stage whose planets are not quite identical (planet 2's mesh
    force 30 % larger): the cancelled lines show weakly and are labelled as cancelled, the surviving
    ones not."""
    from gearbody.analysis.planet_pass import HannPassWindow, ring_sensor_signal

    t, _ = run(1.6, wobble=0.0)
    psi = 2 * np.pi * F_C_HZ * t[None, :] + 2 * np.pi * np.arange(3)[:, None] / 3
    forces = np.cos(Z_R * psi) * np.array([[1.0], [1.3], [1.0]])
    y = ring_sensor_signal(t, psi, forces, 0.0, HannPassWindow(2 * np.pi / 2.3)).signal_N
    phi = 2 * np.pi * F_C_HZ * t
    w = carrier_window(t, phi)
    spec = carrier_order_spectrum(y, phi, w, FS_HZ)
    s = sequential_stage()
    s = PlanetarySources(
        22,
        29,
        Z_R,
        3,
        carrier_hz=w.carrier_hz,
        sun_hz=w.carrier_hz * (1 + Z_R / 22),
        ring_hz=0.0,
        planet_hz=w.carrier_hz * (1 - Z_R / 29),
    )
    lines = planetary_lines(s, 600.0, harmonics=1, sidebands=6)
    peaks = label_peaks(
        spec, mark_cancelled(lines), tolerance_hz=0.5 * spec.resolution_hz, min_prominence_db=20
    )
    by_label = {p.label: p for p in peaks}
    assert {"f_m + f_c", "f_m - 2 f_c", "1 f_m (cancelled)", "f_m - f_c (cancelled)"} <= set(by_label)
    assert by_label["1 f_m (cancelled)"].amplitude < by_label["f_m + f_c"].amplitude
    survives = {line.label: line.survives_equal_spacing for line in lines}
    for p in peaks:
        for label in p.labels:
            plain = label.removesuffix(f" {CANCELLED_MARK}")
            assert is_cancelled_label(label) == (survives[plain] is False), label
