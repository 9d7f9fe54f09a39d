"""The reference's cache (validation/compare.py, cached_reference): a repeated case reads the reference's
output back bit-exact, anything that changes what the reference computes runs it again."""

from __future__ import annotations

import numpy as np
import pytest
from gearbody_validation import compare


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv(compare.CACHE_ENV, str(tmp_path / "cache"))
    return tmp_path / "cache"


def counting_reference():
    calls = []

    def reference(data, t_eval):
        calls.append(1)
        return {
            "mesh_force_N": np.sin(t_eval) * data["k"],
            "stage_mesh_force_N": np.vstack([t_eval, -t_eval]),
        }

    return reference, calls


def test_a_repeated_case_comes_from_the_cache_bit_exact(cache):
    reference, calls = counting_reference()
    t = np.linspace(0.0, 1.0, 101)
    first, was = compare.cached_reference(reference, {"k": 2.0}, t)
    again, now = compare.cached_reference(reference, {"k": 2.0}, t)
    assert (was, now, len(calls)) == (False, True, 1)
    for key in first:
        assert np.array_equal(first[key], again[key]) and first[key].dtype == again[key].dtype
    assert len(list(cache.glob("*.npz"))) == 1


@pytest.mark.parametrize("change", ["data", "times", "off"])
def test_what_changes_the_reference_runs_it_again(cache, change):
    reference, calls = counting_reference()
    t = np.linspace(0.0, 1.0, 101)
    compare.cached_reference(reference, {"k": 2.0}, t)
    data = {"k": 2.5} if change == "data" else {"k": 2.0}
    times = t * 1.0000001 if change == "times" else t
    _, cached = compare.cached_reference(reference, data, times, use_cache=change != "off")
    assert not cached and len(calls) == 2


def test_an_unreadable_cache_entry_is_run_again(cache):
    reference, calls = counting_reference()
    t = np.linspace(0.0, 1.0, 11)
    compare.cached_reference(reference, {"k": 1.0}, t)
    for path in cache.glob("*.npz"):
        path.write_bytes(b"not an npz")
    out, cached = compare.cached_reference(reference, {"k": 1.0}, t)
    assert not cached and len(calls) == 2 and np.array_equal(out["mesh_force_N"], np.sin(t))


def test_the_digest_covers_the_reference_source():
    digest = compare.reference_digest()
    assert len(digest) == 64 and digest == compare.reference_digest()


def test_the_table_says_which_reference_came_from_the_cache(cache):
    rows = []
    compare._echo_row(
        rows.append, compare.CaseResult("s", "c", 0.1, 0.01, float("nan"), 1.2, 0.0, 1.0, 0.01, True)
    )
    compare._echo_row(
        rows.append,
        compare.CaseResult("s", "c", 0.1, 0.01, float("nan"), 1.2, 0.0, 1.0, 0.01, True, "", True),
    )
    assert "cached" not in rows[0] and "0.01" in rows[0]
    assert rows[1].split()[-2] == "cached"
