"""Time-synchronous averaging in the angle domain on synthetic signals with known answers."""

import numpy as np
import pytest

from gearbody.analysis.tsa import (
    AngleDomainSignal,
    SynchronousAverage,
    angle_resample,
    default_points_per_rev,
    synchronous_average,
)

TEETH = 20
FS_HZ = 25_000.0
SHAFT_HZ = 25.0  # 1000 samples per revolution at constant speed


def _gear(angle_rad):
    """Synchronous gear signal: mesh order 20 and two harmonics."""
    a = np.asarray(angle_rad)
    return np.sin(20 * a) + 0.5 * np.sin(40 * a + 0.3) + 0.25 * np.sin(60 * a + 1.0)


def _constant_speed(n_revs: int, angle0_rad: float = 0.7):
    n = int(round(FS_HZ / SHAFT_HZ * (n_revs + 1)))
    t = np.arange(n) / FS_HZ
    return angle0_rad + 2 * np.pi * SHAFT_HZ * t


# --- (a) noise reduction at constant speed --------------------------------------------------------------


def test_tsa_recovers_synchronous_part_and_noise_falls_by_sqrt_n():
    rng = np.random.default_rng(12345)
    noise_rms = {}
    for n_revs in (16, 64):
        angle = _constant_speed(n_revs)
        noise = rng.normal(0.0, 1.0, angle.size)
        sa = synchronous_average(_gear(angle) + noise, angle, teeth=TEETH)
        assert sa.n_revs == n_revs
        assert sa.points_per_rev == 4096  # next power of two >= 4 x ~1000 samples per revolution
        # noise-free: the TSA is the synchronous signal itself (spline error only)
        clean = synchronous_average(_gear(angle), angle, teeth=TEETH)
        np.testing.assert_allclose(clean.average, _gear(clean.angle_rad), atol=1e-4)
        # with noise: what is left is noise, sqrt(n_revs) below that of one resampled revolution
        left = sa.average - clean.average
        single = angle_resample(noise, angle, sa.points_per_rev).values
        per_rev_rms = float(np.sqrt(np.mean(single**2)))
        noise_rms[n_revs] = float(np.sqrt(np.mean(left**2)))
        assert noise_rms[n_revs] == pytest.approx(per_rev_rms / np.sqrt(n_revs), rel=0.15)
        # the synchronous part is recovered down to that noise level
        assert np.sqrt(np.mean((sa.average - _gear(sa.angle_rad)) ** 2)) < 1.2 * per_rev_rms / np.sqrt(n_revs)
    assert noise_rms[16] / noise_rms[64] == pytest.approx(2.0, rel=0.15)


def test_angle_grid_starts_at_first_whole_revolution():
    angle = _constant_speed(5, angle0_rad=0.7)
    resampled = angle_resample(np.sin(angle), angle, 64)
    assert isinstance(resampled, AngleDomainSignal)
    assert resampled.start_rad == pytest.approx(2 * np.pi)
    assert resampled.values.shape == (resampled.n_revs, 64)
    # 0.7 .. 0.7 + 6 revolutions (less one sample) -> whole revolutions from 2 pi to 2 pi * 6
    assert resampled.n_revs == 5
    np.testing.assert_allclose(resampled.angle_rad, np.arange(64) * 2 * np.pi / 64)
    np.testing.assert_allclose(resampled.values, np.tile(np.sin(resampled.angle_rad), (5, 1)), atol=1e-9)
    # starting exactly on a whole revolution keeps it; the sixth lacks its last sample
    exact = angle_resample(np.sin(angle - 0.7), angle - 0.7, 64)
    assert exact.start_rad == 0.0 and exact.n_revs == 5
    closed = np.append(angle - 0.7, 12 * np.pi)
    assert angle_resample(np.sin(closed), closed, 64).n_revs == 6


# --- (b) varying speed ----------------------------------------------------------------------------------


def _varying_speed(kind: str, n_revs_nominal: int = 40):
    """Shaft angle [rad] at FS_HZ with the speed ramping or fluctuating by +-20 % around SHAFT_HZ."""
    duration_s = n_revs_nominal / SHAFT_HZ
    t = np.arange(int(duration_s * FS_HZ)) / FS_HZ
    w0 = 2 * np.pi * SHAFT_HZ
    if kind == "ramp":  # 0.8 w0 -> 1.2 w0 linearly
        return 0.3 + w0 * (0.8 * t + 0.2 * t**2 / duration_s)
    fm_hz = SHAFT_HZ / 3.7  # incommensurate with the shaft
    return 0.3 + w0 * t - 0.2 * w0 / (2 * np.pi * fm_hz) * np.cos(2 * np.pi * fm_hz * t)


@pytest.mark.parametrize("kind", ["ramp", "fluctuation"])
def test_varying_speed_angle_domain_tsa_is_exact_time_domain_smears(kind):
    angle = _varying_speed(kind)
    signal = np.sin(TEETH * angle)
    sa = synchronous_average(signal, angle, teeth=TEETH)
    assert np.max(np.abs(sa.average - np.sin(TEETH * sa.angle_rad))) < 1e-3
    assert sa.order_amplitude[TEETH] == pytest.approx(1.0, abs=1e-3)

    # naive time-domain average over the nominal period (1000 samples): the mesh order smears out
    per_rev = int(round(FS_HZ / SHAFT_HZ))
    blocks = signal[: signal.size // per_rev * per_rev].reshape(-1, per_rev)
    naive = blocks.mean(axis=0)
    naive_amplitude = 2 * np.abs(np.fft.rfft(naive))[TEETH] / per_rev
    assert naive_amplitude < 0.3


# --- (c) local fault: difference, regular and residual signals ------------------------------------------

BUMP_RAD = 2.0
BUMP_WIDTH_RAD = 0.03


def _with_bump(angle_rad, bump_amplitude: float = 1.0, sideband_amplitude: float = 0.0):
    wrapped = np.mod(angle_rad - BUMP_RAD + np.pi, 2 * np.pi) - np.pi  # angle from the bump, -pi .. pi
    bump = bump_amplitude * np.exp(-0.5 * (wrapped / BUMP_WIDTH_RAD) ** 2)
    return 3.0 + _gear(angle_rad) + bump + sideband_amplitude * np.cos(21 * angle_rad)


def test_local_bump_shows_in_difference_signal_regular_holds_mesh_harmonics():
    angle = _constant_speed(8)
    sa = synchronous_average(_with_bump(angle), angle, teeth=TEETH)
    regular, difference, residual = sa.regular(), sa.difference(), sa.residual()
    # exact split: average = mean + regular + difference
    np.testing.assert_allclose(sa.average, sa.average.mean() + regular + difference, atol=1e-12)
    # the bump stands out in the difference signal at its angle
    peak = int(np.argmax(difference))
    assert sa.angle_rad[peak] == pytest.approx(BUMP_RAD, abs=0.01)
    assert difference[peak] > 0.75  # 0.83: the removed orders take a little of the bump
    assert abs(np.argmax(residual) - peak) <= 2
    # the regular signal holds the mesh harmonics (plus the bump's small share at those orders,
    # 2 * 0.03 / sqrt(2 pi) ~ 0.024 per order)
    assert np.sqrt(np.mean((regular - _gear(sa.angle_rad)) ** 2)) < 0.06
    # without the bump the regular signal is the gear signal and the difference vanishes
    smooth = synchronous_average(_with_bump(angle, bump_amplitude=0.0), angle, teeth=TEETH)
    np.testing.assert_allclose(smooth.regular(), _gear(smooth.angle_rad), atol=1e-4)
    assert np.max(np.abs(smooth.difference())) < 1e-4


def test_first_sidebands_are_regular_not_difference_but_stay_in_residual():
    angle = _constant_speed(8)
    sa = synchronous_average(_with_bump(angle, 0.0, sideband_amplitude=0.4), angle, teeth=TEETH)
    sideband = 0.4 * np.cos(21 * sa.angle_rad)
    np.testing.assert_allclose(sa.regular(), _gear(sa.angle_rad) + sideband, atol=1e-4)
    np.testing.assert_allclose(sa.difference(), 0.0, atol=1e-4)
    np.testing.assert_allclose(sa.residual(), sideband, atol=1e-4)


def test_shaft_orders_are_regular_and_removed_from_residual():
    angle = _constant_speed(4)
    shaft = 0.7 * np.sin(angle) + 0.2 * np.cos(2 * angle)
    third = 0.1 * np.sin(3 * angle)
    sa = synchronous_average(_gear(angle) + shaft + third, angle, teeth=TEETH)
    grid = sa.angle_rad
    np.testing.assert_allclose(sa.residual(), 0.1 * np.sin(3 * grid), atol=1e-4)
    np.testing.assert_allclose(sa.difference(), 0.1 * np.sin(3 * grid), atol=1e-4)
    np.testing.assert_allclose(
        sa.regular(shaft_orders=3),
        _gear(grid) + 0.7 * np.sin(grid) + 0.2 * np.cos(2 * grid) + 0.1 * np.sin(3 * grid),
        atol=1e-4,
    )
    # shaft_orders=0 keeps orders 1 and 2 in the residual; order 1 = 20 - 19 is no sideband
    np.testing.assert_allclose(
        sa.residual(shaft_orders=0),
        0.7 * np.sin(grid) + 0.2 * np.cos(2 * grid) + 0.1 * np.sin(3 * grid),
        atol=1e-4,
    )


def test_default_points_per_rev():
    assert default_points_per_rev(1000, 1.0) == 4096
    assert default_points_per_rev(10, 1.0) == 64
    assert default_points_per_rev(10, 1.0, teeth=37) == 512  # 8 * 37 = 296 -> 512
    assert default_points_per_rev(10**9, 1.0) == 2**16
    assert default_points_per_rev(2, 1.0) == 8


# --- (d) bad inputs -------------------------------------------------------------------------------------


def test_bad_inputs_raise_naming_the_parameter():
    angle = _constant_speed(3)
    x = np.sin(angle)
    bent = angle.copy()
    bent[500] = bent[499]
    with pytest.raises(ValueError, match=r"shaft_angle_rad.*sample 500"):
        angle_resample(x, bent, 64)
    with pytest.raises(ValueError, match=r"shaft_angle_rad.*sample 500"):
        synchronous_average(x, bent)
    with pytest.raises(ValueError, match="at least 1 complete revolution"):
        synchronous_average(x[:900], angle[:900])  # 0.7 .. ~6.35 rad: not up to 4 pi
    with pytest.raises(ValueError, match="points_per_rev must be >= 8, got 4"):
        angle_resample(x, angle, 4)
    with pytest.raises(ValueError, match="points_per_rev must be an integer"):
        synchronous_average(x, angle, points_per_rev=64.5)
    with pytest.raises(ValueError, match="equal lengths"):
        angle_resample(x[:-1], angle, 64)
    with pytest.raises(ValueError, match="signal must be 1-D"):
        angle_resample(np.ones((2, angle.size)), angle, 64)
    nan = x.copy()
    nan[7] = np.nan
    with pytest.raises(ValueError, match="signal must be finite, sample 7"):
        angle_resample(nan, angle, 64)
    with pytest.raises(ValueError, match="teeth must be a positive integer"):
        synchronous_average(x, angle, teeth=0)
    with pytest.raises(ValueError, match=r"points_per_rev must be >= 2 \(teeth \+ 1\) = 42"):
        synchronous_average(x, angle, points_per_rev=32, teeth=TEETH)
    no_teeth = synchronous_average(x, angle, points_per_rev=64)
    assert isinstance(no_teeth, SynchronousAverage) and no_teeth.teeth is None
    for derived in (no_teeth.regular, no_teeth.difference, no_teeth.residual):
        with pytest.raises(ValueError, match="teeth is required"):
            derived()
    with_teeth = synchronous_average(x, angle, points_per_rev=64, teeth=TEETH)
    with pytest.raises(ValueError, match="shaft_orders must be a non-negative integer, got -1"):
        with_teeth.regular(shaft_orders=-1)
