"""What a hostile user finds (issue "Nothing a user types crashes, hangs or leaves a folder that contradicts
itself"): each finding refused in one line before anything runs (exit 2), or handled."""

from __future__ import annotations

import pytest

from gearbody.cli import main


@pytest.mark.parametrize(
    ("scene", "sets", "key"),
    [
        (  # allocated 2.24 GiB before any check had a bound
            "planetary",
            ["design.stages.1.sun.teeth=100000001", "design.stages.1.ring.teeth=100000075"],
            "design.stages.1.sun.teeth = 100000001: must be >= 6 and <= 2000",
        ),
        ("one-stage", ["design.pinion.teeth=5000"], "design.pinion.teeth = 5000: must be >= 6 and <= 2000"),
    ],
)
def test_counts_that_size_arrays_are_bounded(tmp_path, capsys, scene, sets, key):
    args = [a for s in sets for a in ("--set", s)]
    assert main(["run", scene, "--out", str(tmp_path / "run"), *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and key in err[0]
    assert not (tmp_path / "run").exists()
