"""The labelled spectrum's peak finding without scipy.signal/ndimage (their import cost a second of every
`gearbody run`): the same peaks as scipy.signal.find_peaks and the same floor as
scipy.ndimage.median_filter(mode="reflect"), plateaus and short arrays included."""

from __future__ import annotations

import numpy as np
from fuzzing import fuzz_settings
from hypothesis import given
from hypothesis import strategies as st
from scipy.ndimage import median_filter
from scipy.signal import find_peaks

from gearbody.analysis.peaks import local_maxima, running_median

samples = st.lists(st.integers(0, 5), min_size=0, max_size=300).map(lambda v: np.array(v, dtype=float))
reals = st.lists(st.floats(-1e3, 1e3), min_size=0, max_size=300).map(np.array)


@fuzz_settings(200)
@given(st.one_of(samples, reals))
def test_local_maxima_are_scipys(x):
    assert np.array_equal(local_maxima(x), find_peaks(x)[0] if x.size else np.zeros(0, dtype=np.intp))


@fuzz_settings(200)
@given(st.one_of(samples, reals), st.sampled_from([1, 3, 5, 65]))
def test_the_running_median_is_ndimages(x, size):
    if x.size < size:  # ndimage returns garbage there (median_filter([0, 1], 65) -> [1.6e-322, 1])
        x = np.resize(x, size) if x.size else np.zeros(size)
    assert np.array_equal(running_median(x, size, chunk=7), median_filter(x, size=size, mode="reflect"))


def test_a_window_longer_than_the_spectrum_reflects_it():
    # [0, 1] reflected: ... 1 0 | 0 1 | 1 0 ...: every window of 65 holds 32 or 33 of each
    assert np.array_equal(running_median(np.array([0.0, 1.0]), 65), [0.0, 1.0])
