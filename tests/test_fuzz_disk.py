"""A full disk, for every command that writes (issue 26): each writer runs on a small filesystem the test
mounts in its own sandbox (a 1 MiB tmpfs; root only, else skipped with the reason), filled to a drawn
number of free pages. The command ends with exit 0 (it fitted), exit 1 with one line naming the file
that could not be written, or exit 2 with one line (the output folder cannot even be made); it leaves
no temporary file and records nothing half-written as done (a run's record says incomplete, a study
keeps only whole cases). Once there is room, the same command completes.
"""

from __future__ import annotations

import json
import os
import shutil

import pytest
from fuzzing import Report, fuzz_settings, reproduce, runner_fixture
from hypothesis import given
from hypothesis import strategies as st

from gearbody.folders import MANIFEST

pytestmark = pytest.mark.slow

KEY = "condition.friction_coefficient"
STUDY = ["--t-end", "0.003", "--workers", "1", "--quiet"]
WRITERS = {
    "run": ["run", "SCENE", "--t-end", "0.003", "--no-plots", "--quiet"],
    "run with plots": ["run", "SCENE", "--t-end", "0.01", "--report", "--quiet"],
    "new": ["new", "SCENE", "--overwrite"],  # (run again once it fitted: replaces its own file)
    "mesh": ["mesh", "SCENE"],
    "render": ["render", "SCENE", "--kinematic", "--frames", "2", "--width", "64", "--height", "48"]
    + ["--quiet"],
    "sweep": ["sweep", "SCENE", "--vary", f"{KEY}=0.0,0.05", *STUDY],
    "sensitivity": ["sensitivity", "SCENE", "--key", f"{KEY}=0.0:0.05", "--feature", "kd_max"]
    + ["--samples", "2", *STUDY],
    "calibrate": ["calibrate", "SCENE", "--param", f"{KEY}=0.0:0.05", "--target", "kd_max", "1.5", "0.5"]
    + ["--budget", "2", "--polish-evaluations", "0", *STUDY],
}
SCENES = ("two-wheel", "one-stage", "lateral-8dof", "planetary")
REPORT = Report("full disk")


runner = runner_fixture("fuzz-disk", REPORT)


def _temporary(folder) -> list:
    return [p for p in folder.rglob(".*.tmp*") if p.is_file()]


@fuzz_settings(8, shrink=False)
@given(
    writer=st.sampled_from(sorted(WRITERS)),
    scene=st.sampled_from(SCENES),
    pages=st.sampled_from([0, 1, 2, 3, 5, 8, 13, 21, 34, 55, 89]),
)
def test_a_full_disk_is_one_line_leaves_nothing_half_written_and_the_rerun_completes(
    small_disk, runner, writer, scene, pages
):
    disk, fill, filler = small_disk
    for old in disk.iterdir():
        shutil.rmtree(old) if old.is_dir() else old.unlink()
    out = disk / "out"
    target = ["--out", str(out) + (".toml" if writer == "new" else "")]
    argv = [scene if a == "SCENE" else a for a in WRITERS[writer]] + target
    fill(pages)
    where = reproduce(argv, None, f"the disk {disk} filled to {pages} free pages of 4 KiB")
    first = runner.run(argv, runner.folder())
    kind = first.kind()
    REPORT.add(writer, f"{kind} (exit {first.code})")
    assert kind in ("ok", "failed", "refused"), first.describe(where)
    lines = first.lines()
    if kind == "failed":
        assert lines[-1].startswith(f"gearbody: failed: cannot write {out}"), first.describe(where)
        assert "No space left on device" in lines[-1], first.describe(where)
    if kind == "refused":
        assert str(out) in lines[-1] and "No space left on device" in lines[-1], first.describe(where)
    assert not _temporary(disk), f"{where}: temporary files left {_temporary(disk)}"
    manifest = out / MANIFEST
    if kind != "ok" and manifest.exists():
        assert not json.loads(manifest.read_text())["complete"], f"{where}: recorded complete"
    if kind != "ok" and writer == "sweep":
        for case in out.glob("cases/*/summary.json"):  # a recorded case is a whole one
            assert (case.parent / "scenario.toml").exists(), f"{where}: {case} without its scenario"
    filler.unlink()  # room again: the same command completes
    again = runner.run(argv, runner.folder())
    assert again.kind() == "ok", again.describe(where + "; then again with room")
    if manifest.exists():
        assert json.loads(manifest.read_text())["complete"], where
    assert not _temporary(disk)
    os.sync()
