"""Shared fixtures, and the ``slow`` marker: ``pytest -m "not slow"`` is the fast loop (every unit test:
1309 tests in 2 min 56 s on two idle cores, ``time pytest -m "not slow"`` on a clean clone, 2026-12-02);
plain ``pytest`` (CI) runs everything, the simulation-heavy comparisons with the independent reference
and the docs' examples included; both spread over the cores (pytest-xdist, pyproject's addopts)."""

from __future__ import annotations

import os
import subprocess
import tempfile

import pytest

from gearbody.model import Scenario, load_scenario

# `gearbody validate` keeps the reference's outputs in a cache; the tests run it afresh in a folder of
# their own (never the user's ~/.cache), so every test process starts with an empty one.
os.environ["GEARBODY_REFERENCE_CACHE"] = tempfile.mkdtemp(prefix="gearbody-test-reference-cache-")

STEADY_OVERRIDES = (
    'operation.initial_state="steady"',
    "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
)
"""Steady rated running from the steady operating point (no run-up)."""


@pytest.fixture
def steady_overrides() -> list[str]:
    """The overrides of steady rated running (a fresh list per test)."""
    return list(STEADY_OVERRIDES)


@pytest.fixture
def steady_scenario():
    """``steady_scenario(scene, *overrides, t_end=0.05)``: a scene in steady rated running."""

    def make(scene: str, *extra: str, t_end: float = 0.05) -> Scenario:
        return load_scenario(scene, [*STEADY_OVERRIDES, f"operation.t_end_s={t_end}", *extra])

    return make


@pytest.fixture(scope="session")
def two_stage() -> Scenario:
    """The two-stage scene as shipped (immutable, so shared by the session)."""
    return load_scenario("two-stage")


@pytest.fixture
def small_disk(tmp_path):
    """A 1 MiB tmpfs mounted in tmp_path (root only; skipped with the reason elsewhere), and a function
    that fills it to ``pages`` free: ``(disk, fill, filler)``."""
    disk = tmp_path / "disk"
    disk.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", str(disk)], capture_output=True)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a small filesystem here: {done.stderr.decode().strip()[:100]}")
    filler = disk / "filler"

    def fill(pages: int) -> None:
        st = os.statvfs(disk)
        filler.write_bytes(b"\0" * max(0, (st.f_bavail - pages) * st.f_bsize))

    try:
        yield disk, fill, filler
    finally:
        subprocess.run(["umount", "-l", str(disk)], check=False)
