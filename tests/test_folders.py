"""A results folder is one run (issue 26): a command writes into a folder only if it is empty, holds
the same run, or ``--overwrite`` replaces it (the old outputs removed first); two commands on one
folder are serialised by a lock, which a killed command never leaves blocking; a full disk is one line
naming the file (exit 1), with nothing half-written recorded as done.

Full disk: where this process may mount (root), a small tmpfs made by the test itself, filled to a few
pages; everywhere, ENOSPC simulated by :func:`_disk_full_at` (``os.replace`` of the named file fails
with ENOSPC after its temporary file is written) or, for the appended calibration record, by a write
that stops half-way through a line."""

from __future__ import annotations

import builtins
import errno
import json
import os
import signal
import subprocess
import sys
import time
from contextlib import contextmanager
from fnmatch import fnmatch
from pathlib import Path

import pytest

from gearbody.cli import main
from gearbody.errors import FolderInUse, InputError, OutputError
from gearbody.folders import LOCK, MANIFEST, FolderLock, atomic_write, claim, inspect

RUN = ["--t-end", "0.02", "--quiet"]
STEADY = ["--set", 'operation.initial_state="steady"']
SMALL_RENDER = ["--frames", "2", "--width", "80", "--height", "60", "--quiet"]


def _one_line(err: str) -> str:
    """The single line of an error output (no traceback)."""
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err.strip()


def _listing(folder: Path) -> dict[str, int]:
    """``{name: mtime_ns}`` of every entry in ``folder``."""
    return {p.name: p.stat().st_mtime_ns for p in folder.iterdir()}


def _temporary(folder: Path) -> list[Path]:
    return [p for p in folder.rglob(".*.tmp*")]


@contextmanager
def _disk_full_at(monkeypatch, pattern: str, nth: int = 1):
    """ENOSPC when the ``nth`` file whose name matches ``pattern`` is put in place (its temporary file
    written, then the rename fails as a full disk would have failed the write)."""
    real = os.replace
    seen = []

    def replace(src, dst, *args, **kwargs):
        if fnmatch(Path(dst).name, pattern):
            seen.append(dst)
            if len(seen) == nth:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(src))
        return real(src, dst, *args, **kwargs)

    with monkeypatch.context() as m:
        m.setattr(os, "replace", replace)
        yield seen


# -- the rules, without simulations ---------------------------------------------------------------------


def test_atomic_write_on_a_full_disk_names_the_file_and_leaves_it_as_it_was(tmp_path):
    target = tmp_path / "summary.json"
    target.write_text("old")

    def half_then_full(tmp: Path) -> None:
        tmp.write_text('{"half": ')
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    with pytest.raises(OutputError) as caught:
        atomic_write(target, half_then_full)
    assert str(caught.value) == f"cannot write {target}: No space left on device (the disk is full)"
    assert isinstance(caught.value, OSError) and caught.value.errno == errno.ENOSPC
    assert target.read_text() == "old" and sorted(p.name for p in tmp_path.iterdir()) == ["summary.json"]


def test_claim_rules_empty_same_other_foreign_and_overwrite(tmp_path):
    run = {"scenario": {"meta": {"name": "one-stage"}, "operation": {"t_end_s": 0.02}}}
    folder = tmp_path / "out"
    (folder / "render").mkdir(parents=True)  # a subfolder (runs/SCENE/render) leaves it empty
    (folder / ".DS_Store").write_text("")  # and so does a hidden file
    with claim(folder, "run", run) as c:
        assert c.mode == "new" and (folder / LOCK).is_file()
        c.begin()
        for name in ("result.npz", "summary.json", "report.html", "bearing_forces.png"):
            (folder / name).write_text(name)
        c.finish()
    assert not (folder / LOCK).exists()  # removed when released
    assert json.loads((folder / MANIFEST).read_text())["complete"] is True
    with claim(folder, "run", run) as c:  # the same run: written again, the old outputs go first
        assert c.mode == "same"
        c.begin()
        assert sorted(p.name for p in folder.iterdir()) == [".DS_Store", MANIFEST, LOCK, "render"]
        (folder / "result.npz").write_text("new")
        c.finish()
    other = {"scenario": {"meta": {"name": "two-stage"}, "operation": {"t_end_s": 0.02}}}
    with pytest.raises(InputError) as refused:
        claim(folder, "run", other)
    assert str(refused.value) == (
        f"--out {folder} holds another run (meta.name: 'one-stage' there, 'two-stage' now); give "
        "--overwrite to replace it, or choose another --out"
    )
    with pytest.raises(InputError, match=r"holds a 'gearbody run' result \(result.npz\); give --overwrite"):
        claim(folder, "sweep")
    (folder / "notes.txt").write_text("mine")
    with claim(folder, "sweep", overwrite=True) as c:  # replaced: gearbody's outputs go, notes.txt stays
        assert c.mode == "replace"
        c.begin()
    assert sorted(p.name for p in folder.iterdir()) == [".DS_Store", "notes.txt", "render"]
    with pytest.raises(
        InputError, match=r"is not empty: it holds files gearbody did not write \(notes.txt\)"
    ):
        claim(folder, "run", run)
    assert not (folder / LOCK).exists()  # a refusal leaves no lock behind


def test_inspect_tells_a_folder_written_without_a_manifest_by_its_files(tmp_path):
    for files, kind in (
        (["study.json"], "sweep"),
        (["sensitivity.json"], "sensitivity"),
        (["evaluations.jsonl"], "calibrate"),
        (["frame_0000.png", "result.npz"], "render"),
        (["mesh_stage1.png"], "mesh"),
        (["result.npz", "kd_time.png", "a.txt"], "run"),
        # an earlier gearbody rendered into a run folder: the run's files are gearbody outputs too
        (["frame_0000.png", "summary.json", "kd_time.png", "result.npz"], "render-into-run"),
    ):
        folder = tmp_path / kind
        folder.mkdir()
        for name in files:
            (folder / name).write_text("")
        state = inspect(folder)
        assert state.kind == kind.split("-")[0], kind
        assert {p.name for p in state.outputs} == set(files) - {"a.txt"}, kind
    assert inspect(tmp_path / "run").foreign == ("a.txt",)


LOCK_HOLDER = """
import os, sys, time
from pathlib import Path
from gearbody.folders import FolderLock
FolderLock(Path(sys.argv[1]), "sweep").acquire()
if len(sys.argv) > 2 and os.fork() == 0:  # a child (a pool worker) outlives its parent
    time.sleep(60)
    os._exit(0)
print("locked", flush=True)
time.sleep(60)
"""


def _hold_lock(folder: Path, fork: bool = False) -> subprocess.Popen:
    proc = subprocess.Popen(
        [sys.executable, "-c", LOCK_HOLDER, str(folder), *(["fork"] if fork else [])],
        stdout=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    assert proc.stdout.readline().strip() == "locked"
    return proc


def test_a_locked_folder_is_refused_naming_the_holder_and_a_killed_holder_never_blocks(tmp_path):
    holder = _hold_lock(tmp_path)
    try:
        with pytest.raises(FolderInUse) as busy:
            FolderLock(tmp_path, "run").acquire()
        assert str(busy.value) == (
            f"--out {tmp_path}: another gearbody sweep (pid {holder.pid}) is writing in it; wait for it to "
            "end, or choose another --out"
        )
    finally:
        os.killpg(holder.pid, signal.SIGKILL)
        holder.wait()
    assert (tmp_path / LOCK).exists()  # left by the killed holder, and not in the way
    with FolderLock(tmp_path, "run") as lock:
        assert lock.fd is not None
    assert not (tmp_path / LOCK).exists()


def test_a_forked_child_does_not_keep_the_lock_of_its_killed_parent(tmp_path):
    """A pool worker is a forked copy of the study's process: the lock must die with the study even if
    a worker lives on."""
    holder = _hold_lock(tmp_path, fork=True)
    try:
        os.kill(holder.pid, signal.SIGKILL)  # the parent only: its child sleeps on
        holder.wait()
        with FolderLock(tmp_path, "sweep"):
            pass
    finally:
        os.killpg(holder.pid, signal.SIGKILL)


# -- run, render, mesh ------------------------------------------------------------------------------------


def test_run_of_another_scene_into_a_run_folder_is_refused_and_overwrite_replaces_it(tmp_path, capsys):
    """Issue 26: the old scene's report.html and bearing_forces.png stayed beside the new result."""
    out = tmp_path / "run"
    assert main(["run", "lateral-6dof", *RUN, "--report", "--out", str(out)]) == 0
    assert {"report.html", "bearing_forces.png", "summary.json"} <= set(os.listdir(out))
    before = _listing(out)
    capsys.readouterr()
    assert main(["run", "one-stage", *RUN, "--out", str(out)]) == 2
    line = _one_line(capsys.readouterr().err)
    assert line.startswith(f"gearbody: invalid input: --out {out} holds another run (meta.name: ")
    assert line.endswith("give --overwrite to replace it, or choose another --out")
    assert _listing(out) == before  # nothing touched
    assert main(["run", "one-stage", *RUN, "--overwrite", "--out", str(out)]) == 0
    names = set(os.listdir(out))
    assert "report.html" not in names and "bearing_forces.png" not in names
    assert names == {MANIFEST, "result.npz", "scenario.toml", "summary.json"} | {
        "kd_time.png",
        "kd_folded.png",
        "spectrum.png",
    }
    assert json.loads((out / "summary.json").read_text())["scene"] == "one-stage"
    # the same run again (no --overwrite needed): the folder is what this command writes
    assert main(["run", "one-stage", *RUN, "--no-plots", "--out", str(out)]) == 0
    assert set(os.listdir(out)) == {MANIFEST, "result.npz", "scenario.toml", "summary.json"}
    assert json.loads((out / MANIFEST).read_text())["complete"] is True


def test_render_simulating_into_a_run_folder_is_refused_and_overwrite_leaves_no_run_files(tmp_path, capsys):
    """Issue 26: render replaced result.npz and scenario.toml but kept the run's summary.json and plots."""
    out = tmp_path / "run"
    assert main(["run", "one-stage", *RUN, "--out", str(out)]) == 0
    before = _listing(out)
    capsys.readouterr()
    assert main(["render", "one-stage", "--t-end", "0.03", *SMALL_RENDER, "--out", str(out)]) == 2
    assert _one_line(capsys.readouterr().err) == (
        f"gearbody: invalid input: --out {out} holds a 'gearbody run' result (kd_folded.png, kd_time.png, "
        "result.npz and 3 more); give --overwrite to replace it, or choose another --out"
    )
    assert _listing(out) == before
    render = ["render", "one-stage", "--t-end", "0.03", *SMALL_RENDER, "--overwrite", "--out", str(out)]
    assert main(render) == 0
    assert set(os.listdir(out)) == {
        MANIFEST,
        "result.npz",
        "scenario.toml",
        "frame_0000.png",
        "frame_0001.png",
        "animation.gif",
    }
    assert "t_end_s = 0.03" in (out / "scenario.toml").read_text()  # the render's run, not the old one


def test_render_refuses_to_overwrite_the_result_it_reads(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", "one-stage", *RUN, "--no-plots", "--out", str(out)]) == 0
    capsys.readouterr()
    argv = ["render", "one-stage", "--result", str(out), *SMALL_RENDER, "--out", str(out), "--overwrite"]
    assert main(argv) == 2
    assert "which holds another run (--overwrite would remove it)" in _one_line(capsys.readouterr().err)
    assert (out / "result.npz").is_file() and (out / "summary.json").is_file()


def test_a_full_disk_in_render_names_the_frame_and_leaves_the_render_incomplete(
    tmp_path, monkeypatch, capsys
):
    out = tmp_path / "render"
    with _disk_full_at(monkeypatch, "frame_0001.png"):
        assert main(["render", "one-stage", "--kinematic", *SMALL_RENDER, "--out", str(out)]) == 1
    assert _one_line(capsys.readouterr().err) == (
        f"gearbody: failed: cannot write {out}/frame_0001.png: No space left on device (the disk is full)"
    )
    assert not _temporary(out) and not (out / "animation.gif").exists()
    assert json.loads((out / MANIFEST).read_text())["complete"] is False
    assert main(["render", "one-stage", "--kinematic", *SMALL_RENDER, "--out", str(out)]) == 0  # same run
    assert json.loads((out / MANIFEST).read_text())["complete"] is True and (out / "animation.gif").is_file()


def test_a_full_disk_in_run_names_the_file_and_a_rerun_completes(tmp_path, monkeypatch, capsys):
    out = tmp_path / "run"
    with _disk_full_at(monkeypatch, "summary.json"):
        assert main(["run", "one-stage", *RUN, "--no-plots", "--out", str(out)]) == 1
    assert _one_line(capsys.readouterr().err) == (
        f"gearbody: failed: cannot write {out}/summary.json: No space left on device (the disk is full)"
    )
    assert not (out / "summary.json").exists() and not _temporary(out)
    assert json.loads((out / MANIFEST).read_text())["complete"] is False
    assert main(["run", "one-stage", *RUN, "--no-plots", "--out", str(out)]) == 0
    assert (out / "summary.json").is_file() and json.loads((out / MANIFEST).read_text())["complete"]


def test_mesh_into_another_scenes_plots_is_refused_and_overwrite_leaves_no_stale_stage(tmp_path, capsys):
    out = tmp_path / "mesh"
    assert main(["mesh", "two-stage", "--out", str(out)]) == 0
    capsys.readouterr()
    assert main(["mesh", "one-stage", "--out", str(out)]) == 2
    assert "holds another mesh (meta.name: 'two-stage' there, 'one-stage' now" in capsys.readouterr().err
    assert main(["mesh", "one-stage", "--overwrite", "--out", str(out)]) == 0
    assert sorted(os.listdir(out)) == [MANIFEST, "mesh_stage1.png"]  # no stage 2 of the other scene


# -- studies ------------------------------------------------------------------------------------------------

SWEEP = [
    "sweep",
    "one-stage",
    "--vary",
    "production.error_mode.e_um=0,10",
    "--t-end",
    "0.02",
    "--workers",
    "1",
]


def test_a_study_refuses_a_run_folder_and_a_run_refuses_a_study_folder(tmp_path, capsys):
    run, study = tmp_path / "run", tmp_path / "study"
    assert main(["run", "one-stage", *RUN, "--no-plots", "--out", str(run)]) == 0
    capsys.readouterr()
    assert main([*SWEEP, "--quiet", "--out", str(run)]) == 2
    assert (
        "holds a 'gearbody run' result (result.npz, scenario.toml, summary.json)" in capsys.readouterr().err
    )
    assert main([*SWEEP, "--quiet", "--out", str(study)]) == 0
    capsys.readouterr()
    calibrate = ["calibrate", "one-stage", "--param", "design.mesh.damping_Ns_per_m=3000:12000"]
    for argv in (["run", "one-stage", *RUN], [*calibrate, "--target", "kd_max", "1", "0.1", "--quiet"]):
        assert main([*argv, "--out", str(study)]) == 2
        assert f"--out {study} holds a 'gearbody sweep' study (cases, " in _one_line(capsys.readouterr().err)


def test_two_sweeps_on_one_folder_the_second_is_refused_and_the_first_completes(tmp_path, capsys):
    """Issue 26: one of two sweeps on one --out died with FileNotFoundError (each deleted the other's live
    temporary files as stale). Now the second is refused in one line while the first runs."""
    out = tmp_path / "sweep"
    argv = [*SWEEP[:3], "production.error_mode.e_um=0:20:6", "--t-end", "0.3", "--workers", "1"]
    first = subprocess.Popen(
        [sys.executable, "-m", "gearbody.cli", *argv, "--quiet", "--out", str(out)],
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 120
        while not (out / "cases" / "case-0000" / "summary.json").exists():  # mid-study, lock held
            assert first.poll() is None and time.monotonic() < deadline
            time.sleep(0.05)
        assert main([*argv, "--quiet", "--out", str(out)]) == 2
        assert first.poll() is None  # still running: the refusal happened while it held the folder
    finally:
        _, err = first.communicate(timeout=300)
    assert _one_line(capsys.readouterr().err) == (
        f"gearbody: invalid input: --out {out}: another gearbody sweep (pid {first.pid}) is writing in it; "
        "wait for it to end, or choose another --out"
    )
    assert first.returncode == 0 and err == ""
    summaries = sorted((out / "cases").glob("*/summary.json"))
    assert len(summaries) == 6 and not (out / LOCK).exists() and not _temporary(out)


def test_a_sweep_killed_with_sigkill_leaves_no_lock_in_the_way_of_its_resume(tmp_path, capsys):
    out = tmp_path / "sweep"
    argv = [*SWEEP[:3], "production.error_mode.e_um=0:20:6", "--t-end", "0.3", "--workers", "1"]
    first = subprocess.Popen([sys.executable, "-m", "gearbody.cli", *argv, "--quiet", "--out", str(out)])
    deadline = time.monotonic() + 120
    while not (out / "cases" / "case-0000" / "summary.json").exists():
        assert first.poll() is None and time.monotonic() < deadline
        time.sleep(0.05)
    first.kill()
    first.wait()
    assert (out / LOCK).exists()  # the killed process could not remove it; the kernel released it
    assert main([*argv, "--out", str(out)]) == 0
    assert "cases already done" in capsys.readouterr().err
    assert len(list((out / "cases").glob("*/summary.json"))) == 6


def test_a_full_disk_in_a_sweep_keeps_the_cases_recorded_and_the_resume_completes(
    tmp_path, monkeypatch, capsys
):
    out = tmp_path / "sweep"
    with _disk_full_at(monkeypatch, "summary.json", nth=2):  # the second case's record
        assert main([*SWEEP, "--quiet", "--out", str(out)]) == 1
    case = out / "cases" / "case-0001"
    assert _one_line(capsys.readouterr().err) == (
        f"gearbody: failed: cannot write {case}/summary.json: No space left on device (the disk is full); "
        "1 of 2 cases recorded: make room and rerun the same command to resume"
    )
    assert (out / "cases" / "case-0000" / "summary.json").is_file()
    assert (case / "result.npz").is_file() and not (case / "summary.json").exists()  # not done
    assert not _temporary(out) and not (out / "summary.csv").exists()
    assert main([*SWEEP, "--out", str(out)]) == 0
    assert "resuming" in capsys.readouterr().err and (case / "summary.json").is_file()


SENSITIVITY = [
    "sensitivity",
    "one-stage",
    "--key",
    "design.mesh.damping_Ns_per_m=3000:12000",
    "--feature",
    "kd_max",
    "--samples",
    "2",
    "--t-end",
    "0.02",
    "--workers",
    "1",
]


def test_a_full_disk_in_a_sensitivity_analysis_keeps_the_rows_recorded(tmp_path, monkeypatch, capsys):
    out = tmp_path / "sens"
    with _disk_full_at(monkeypatch, "row-*.json", nth=3):
        assert main([*SENSITIVITY, "--quiet", "--out", str(out)]) == 1
    line = _one_line(capsys.readouterr().err)
    assert line.startswith(f"gearbody: failed: cannot write {out}/evaluations/row-000002.json: No space left")
    assert line.endswith(
        "2 of the 4 runs of this call recorded: make room and rerun the same command to resume"
    )
    assert sorted(p.name for p in (out / "evaluations").iterdir()) == ["row-000000.json", "row-000001.json"]
    assert main([*SENSITIVITY, "--out", str(out)]) == 0
    assert "2 of 4 rows already recorded" in capsys.readouterr().err


def test_a_sensitivity_analysis_refuses_another_one_and_overwrite_replaces_it(tmp_path, capsys):
    out = tmp_path / "sens"
    assert main([*SENSITIVITY, "--quiet", "--out", str(out)]) == 0
    other = [*SENSITIVITY[:3], "design.mesh.damping_Ns_per_m=4000:12000", *SENSITIVITY[4:]]
    capsys.readouterr()
    assert main([*other, "--quiet", "--out", str(out)]) == 2
    assert "holds a different sensitivity analysis" in _one_line(capsys.readouterr().err)
    assert main([*other, "--quiet", "--overwrite", "--out", str(out)]) == 0
    spec = json.loads((out / "sensitivity.json").read_text())["spec"]
    assert spec["bounds"] == [[4000.0, 12000.0]]


CALIBRATE = [
    "calibrate",
    "one-stage",
    "--t-end",
    "0.02",
    "--target",
    "kd_max",
    "1.5",
    "0.1",
    "--budget",
    "2",
    "--polish-evaluations",
    "0",
    "--workers",
    "1",
    "--quiet",
]
DAMPING = ["--param", "design.mesh.damping_Ns_per_m=3000:12000"]


def test_calibrate_into_another_calibration_and_a_damaged_record_are_one_line(tmp_path, capsys):
    """Issue 26: another calibration's folder was a CalibrationError traceback (exit 1), a corrupt
    evaluations.jsonl a JSONDecodeError."""
    out = tmp_path / "cal"
    assert main([*CALIBRATE, *DAMPING, "--out", str(out)]) == 0
    record = out / "evaluations.jsonl"
    lines = record.read_text().splitlines()
    capsys.readouterr()
    stiffness = ["--param", "design.mesh.stiffness_single_N_per_m=1e9:2e9"]
    assert main([*CALIBRATE, *stiffness, "--out", str(out)]) == 2
    assert _one_line(capsys.readouterr().err) == (
        f"gearbody calibrate: --out {out} holds a record that is not this calibration's: {record}: records "
        "another calibration (a different scene, parameters, targets or settings); rerun with the same "
        "arguments to resume, give --overwrite to replace it, or choose another --out"
    )
    assert record.read_text().splitlines() == lines
    # lines that are no whole evaluation are dropped (those points evaluated again), not a traceback
    record.write_text("\n".join([lines[0], "[1, 2]", lines[1], '{"point": 3}', "{not json", lines[2][:20]]))
    assert main([*CALIBRATE, *DAMPING, "--out", str(out)]) == 0
    assert json.loads((out / "calibration.json").read_text())["replayed"] >= 1
    kept = record.read_text().splitlines()
    assert kept[:2] == lines[:2] and all(json.loads(x)["point"] for x in kept[1:])
    record.write_text("{not a record\n" + "\n".join(lines[1:]) + "\n")
    capsys.readouterr()
    assert main([*CALIBRATE, *DAMPING, "--out", str(out)]) == 2
    assert _one_line(capsys.readouterr().err).endswith(
        "its first line is not a gearbody calibration record; give --overwrite to replace it, or choose "
        "another --out"
    )
    assert main([*CALIBRATE, *stiffness, "--overwrite", "--out", str(out)]) == 0
    assert (
        json.loads(record.read_text().splitlines()[0])["fingerprint"] != json.loads(lines[0])["fingerprint"]
    )


def test_a_full_disk_in_a_calibration_cuts_no_recorded_evaluation(tmp_path, monkeypatch, capsys):
    """ENOSPC half-way through the second evaluation's line: one line naming the record; the resume
    drops the cut line, replays the whole one and ends as an uninterrupted calibration."""
    out = tmp_path / "cal"
    from gearbody.studies import calibration

    appended = []

    def full_open(path, mode="r", *args, **kwargs):
        f = builtins.open(path, mode, *args, **kwargs)
        if mode != "a":
            return f
        appended.append(path)
        if len(appended) < 2:
            return f

        class Full:
            def __enter__(self):
                return self

            def __exit__(self, *exc):
                f.close()

            def write(self, text):
                f.write(text[: len(text) // 2])
                f.flush()
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

        return Full()

    with monkeypatch.context() as m:
        m.setattr(calibration, "open", full_open, raising=False)
        assert main([*CALIBRATE, *DAMPING, "--out", str(out)]) == 1
    record = out / "evaluations.jsonl"
    assert _one_line(capsys.readouterr().err) == (
        f"gearbody: failed: cannot write {record}: No space left on device (the disk is full); the "
        f"evaluations recorded in {record} stay: make room and rerun the same command to resume"
    )
    assert not record.read_text().endswith("\n") and not (out / "calibration.json").exists()
    assert main([*CALIBRATE, *DAMPING, "--out", str(out)]) == 0
    resumed = json.loads((out / "calibration.json").read_text())
    clean = tmp_path / "clean"
    assert main([*CALIBRATE, *DAMPING, "--out", str(clean)]) == 0
    uninterrupted = json.loads((clean / "calibration.json").read_text())
    assert resumed["replayed"] == 1 and resumed["parameters"] == uninterrupted["parameters"]


# -- a real full disk: a small filesystem the test mounts ---------------------------------------------------


# small_disk: tests/conftest.py (the fuzzers of a full disk use it too)


def test_a_real_full_disk_in_run_and_in_a_sweep_is_one_line_and_resumable(small_disk, capsys):
    disk, fill, filler = small_disk
    run, sweep = disk / "run", disk / "sweep"
    fill(pages=4)
    assert main(["run", "one-stage", *RUN, "--out", str(run)]) == 1
    line = _one_line(capsys.readouterr().err)
    assert line.startswith(f"gearbody: failed: cannot write {run}/") and line.endswith(
        ": No space left on device (the disk is full)"
    )
    assert not _temporary(run) and not (run / "summary.json").exists()
    assert not json.loads((run / MANIFEST).read_text())["complete"]
    assert main([*SWEEP, "--quiet", "--out", str(sweep)]) == 1
    line = _one_line(capsys.readouterr().err)
    assert line.startswith(f"gearbody: failed: cannot write {sweep}/cases/case-0000/")
    assert line.endswith("0 of 2 cases recorded: make room and rerun the same command to resume")
    assert not list(sweep.glob("cases/*/summary.json")) and not _temporary(sweep)
    filler.unlink()  # room again: both resume
    assert main(["run", "one-stage", *RUN, "--out", str(run)]) == 0
    assert json.loads((run / MANIFEST).read_text())["complete"]
    assert main([*SWEEP, "--quiet", "--out", str(sweep)]) == 0
    assert len(list(sweep.glob("cases/*/summary.json"))) == 2


def test_an_oserror_no_writer_names_is_one_line_exit_1(monkeypatch, capsys):
    from gearbody.cli import listing

    def broken(args):
        raise OSError(errno.EIO, os.strerror(errno.EIO), "/data/scenes.toml")

    monkeypatch.setattr(listing, "execute", broken)
    assert main(["list"]) == 1
    assert _one_line(capsys.readouterr().err) == "gearbody: failed: /data/scenes.toml: Input/output error"
