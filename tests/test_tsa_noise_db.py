"""Issue 29, deliverable 6: synchronous averaging over N_r revolutions lowers uncorrelated noise by
10 log10 N_r dB (noise power falls as 1 / N_r), while the synchronous part is kept."""

import numpy as np
import pytest

from gearbody.analysis import angle_resample, synchronous_average

FS_HZ, SHAFT_HZ, TEETH = 10_000.0, 20.0, 17


@pytest.mark.parametrize("n_revs", [16, 64, 256])
def test_noise_power_falls_by_10_log10_n_revolutions(n_revs):
    rng = np.random.default_rng(29 + n_revs)
    n = int(FS_HZ / SHAFT_HZ * (n_revs + 1))
    t = np.arange(n) / FS_HZ
    angle = 2 * np.pi * SHAFT_HZ * t * (1 + 0.02 * np.sin(2 * np.pi * 0.5 * t))  # a wandering speed
    gear = np.sin(TEETH * angle) + 0.3 * np.sin(2 * TEETH * angle + 0.4)
    noise = rng.normal(0.0, 1.0, n)
    pure = synchronous_average(gear, angle, teeth=TEETH)
    noisy = synchronous_average(gear + noise, angle, teeth=TEETH)
    noise_only = synchronous_average(noise, angle, points_per_rev=noisy.points_per_rev)
    # the noise of one revolution on the same angle grid (the resampling interpolates, so it is what
    # the average starts from), and what is left of it in the average, in dB
    one_rev = np.mean(angle_resample(noise, angle, noisy.points_per_rev).values ** 2)
    left_db = 10 * np.log10(np.mean((noisy.average - pure.average) ** 2) / one_rev)
    expected_db = -10 * np.log10(noisy.n_revs)
    assert abs(noisy.n_revs - n_revs) <= 3  # the wandering speed adds a revolution or three
    assert left_db == pytest.approx(expected_db, abs=1.0)  # chi-square scatter of the estimate: < 1 dB
    assert 10 * np.log10(np.mean(noise_only.average**2) / one_rev) == pytest.approx(expected_db, abs=1.0)
    # the synchronous part survives: the mesh order's amplitude within 1 %
    assert np.max(np.abs(pure.average - noisy.average)) < 6 / np.sqrt(n_revs)
