"""Simulated bearing defects against what theory says they show (issue 30, deliverable 4); the cases,
and the table of measured lines, are validation/bearing_defect_checks.py's.

lateral-8dof-ball on ball-by-ball bearings, steady at rated load, 1 s; a defect in the pinion's bearing
(SKF 6308 geometry: 8 balls, d/D = 0.232); a housing accelerometer with one mode (5 kHz, 2 % damping) on
the pinion's bearing forces and seeded noise. The pinion turns at f_r = 17.03 Hz, so BPFO = 52.3 Hz,
BPFI = 83.9 Hz, BSF = 34.7 Hz, FTF = 6.54 Hz; the envelope spectrum's bins are 1.1 Hz apart.
"""

from __future__ import annotations

import numpy as np
import pytest
from gearbody_validation.bearing_defect_checks import (
    SETTLE_S,
    SLIP,
    ZETA,
    envelope,
    floor,
    lines,
    overrides,
    recording,
    run,
    within_slip,
)

from gearbody.analysis.kurtogram import fast_kurtogram
from gearbody.diagnosis import DriveKinematics, analyze_recording
from gearbody.model import load_scenario

pytestmark = pytest.mark.slow


def test_an_outer_race_defect_shows_bpfo_and_its_harmonics_within_the_slip_band():
    _, env = envelope("outer")
    bpfo = lines(run("outer")).bpfo_hz
    base = floor(env)
    for k in (1, 2, 3, 4):
        f, a = within_slip(env, k * bpfo)
        assert abs(f - k * bpfo) <= SLIP * k * bpfo + env.resolution_hz
        assert a > 5 * base, (k, a, base)
    _, healthy = envelope(None)  # the healthy bearing's envelope has no such line
    assert within_slip(env, bpfo)[1] > 20 * within_slip(healthy, bpfo)[1]


def test_an_inner_race_defect_shows_bpfi_with_shaft_rate_sidebands():
    _, env = envelope("inner")
    L = lines(run("inner"))
    base = floor(env)
    _, a = within_slip(env, L.bpfi_hz)
    assert a > 5 * base
    for side in (-1, 1):  # the spall passes through the load zone once per shaft turn
        assert within_slip(env, L.bpfi_hz + side * L.shaft_hz)[1] > 5 * base, side
    assert within_slip(env, L.shaft_hz)[1] > 5 * base
    _, healthy = envelope(None)
    assert a > 20 * within_slip(healthy, L.bpfi_hz)[1]


def test_a_rolling_element_defect_shows_twice_bsf_with_cage_rate_sidebands():
    _, env = envelope("ball")
    L = lines(run("ball"))
    base = floor(env)
    f, a = within_slip(env, 2 * L.bsf_hz)
    assert abs(f - 2 * L.bsf_hz) <= SLIP * 2 * L.bsf_hz + env.resolution_hz
    assert a > 4 * base
    for side in (-1, 1):  # the ball carries load only in the load zone: once per cage turn
        assert within_slip(env, 2 * L.bsf_hz + side * L.ftf_hz)[1] > 4 * base, side
    assert within_slip(env, L.ftf_hz)[1] > 4 * base


@pytest.mark.parametrize("mode_hz", [5000.0, 6500.0])
def test_the_kurtogram_picks_the_housing_modes_band(mode_hz):
    kurt, _ = envelope("outer", mode_hz=mode_hz)
    lo, hi = kurt.band_hz
    assert lo < mode_hz * (1 + ZETA) and hi > mode_hz * (1 - ZETA), (lo, hi)


def test_a_larger_outer_race_defect_raises_the_envelope_line_monotonically():
    drive = DriveKinematics.from_scenario(load_scenario("lateral-8dof-ball", overrides("outer")))
    values = []
    for depth in (5e-6, 10e-6, 20e-6):
        rec = recording(run("outer", depth)).window(SETTLE_S)
        features = analyze_recording(rec, drive, ["pinion_housing"]).features()
        key = next(k for k in features if k.startswith("pinion_housing/envelope_peak:") and "BPFO" in k)
        values.append(features[key])
    assert values[0] < values[1] < values[2], values


def test_the_same_seeds_give_bit_identical_signals_and_other_seeds_do_not():
    a = recording(run("outer", seed=7, t_end_s=0.2))["pinion_housing"]
    run.cache_clear()  # simulate again, not the cached run
    assert np.array_equal(a, recording(run("outer", seed=7, t_end_s=0.2))["pinion_housing"])
    assert not np.array_equal(a, recording(run("outer", seed=8, t_end_s=0.2))["pinion_housing"])  # cage slip
    other_noise = recording(run("outer", seed=7, t_end_s=0.2), seed=2)["pinion_housing"]
    assert not np.array_equal(a, other_noise)


def test_the_kurtogram_of_the_healthy_bearing_finds_nothing_as_impulsive():
    kurt, _ = envelope("outer")
    rec = recording(run(None))
    x = rec["pinion_housing"][int(SETTLE_S * rec.sample_rate_hz) :]
    assert kurt.max_kurtosis > 3 * fast_kurtogram(x, rec.sample_rate_hz, max_level=6).max_kurtosis
