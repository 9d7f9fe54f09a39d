"""Where the paper scripts write, and what a quick run may write: the checkout's validation/paper (the
record behind RESULTS.md) takes full runs only, a quick run elsewhere says it is one, a coarse sweep
gets no wider tolerance, and an installed package is never written into. No simulation runs here."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from gearbody_validation.paper import common, fig_12_calibration, figs_06_08, run_all


@pytest.fixture(autouse=True)
def _fresh_output(monkeypatch):
    """Each test resolves (or configures) the output folder itself."""
    monkeypatch.setattr(common, "_OUTPUT", {})


def _checkout(root: Path) -> Path:
    """A fake checkout: pyproject.toml and validation/paper/run_all.py (what marks the record)."""
    (root / "validation" / "paper").mkdir(parents=True)
    (root / "pyproject.toml").write_text("[project]\nname = 'gearbody'\n")
    (root / "validation" / "paper" / "run_all.py").write_text("")
    return root / "validation" / "paper"


def test_the_output_folder_is_out_else_the_checkout_run_in_else_the_current_directory(tmp_path):
    record = _checkout(tmp_path / "checkout")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    assert common.resolve_output_dir(tmp_path / "o", cwd=record.parents[1]) == tmp_path / "o"
    assert common.resolve_output_dir(cwd=record.parents[1]) == record
    assert common.resolve_output_dir(cwd=elsewhere) == elsewhere / common.DEFAULT_OUT
    assert common.is_record(record) and not common.is_record(elsewhere / common.DEFAULT_OUT)


def test_an_installed_package_is_never_the_output(tmp_path):
    """Run from a folder that is no checkout (an installed package's user): the output is under that
    folder, never next to the installed scripts, and not the record even if this package is a checkout."""
    package = Path(common.__file__).resolve().parent
    out = common.resolve_output_dir(cwd=tmp_path)
    assert out == tmp_path / common.DEFAULT_OUT
    assert package not in out.resolve().parents and out.resolve() != package
    site = tmp_path / "lib" / "python3" / "site-packages" / "gearbody_validation" / "paper"
    site.mkdir(parents=True)
    assert not common.is_record(site)  # an installed copy of the scripts is no record


def test_quick_into_the_record_is_refused_before_anything_runs(tmp_path, monkeypatch, capsys):
    record = _checkout(tmp_path)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exc:
        run_all.cli(["--quick"])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.startswith("run_all: --quick") and "--out DIR" in err
    assert not (record / "RESULTS.md").exists() and not (record / "results").exists()
    with pytest.raises(common.OutputRefused):  # also when a script's main is called from Python
        figs_06_08.main(quick=True)
    with pytest.raises(common.OutputRefused):
        common.write_results("x", "x", [], [], [], 0.0, quick=True)
    assert not (record / "results").exists()


def test_a_script_run_as_a_command_refuses_quick_in_a_checkout_with_one_line(tmp_path):
    _checkout(tmp_path)
    run = subprocess.run(
        [sys.executable, "-m", "gearbody_validation.paper.figs_06_08", "--quick"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 2, run.stderr
    assert run.stderr.strip().startswith("figs_06_08: --quick results are not the reproduction")
    assert len(run.stderr.strip().splitlines()) == 1


def _claims(passed: bool) -> list[common.Claim]:
    return [common.Claim("9", "a claim", "measured", passed)]


def test_quick_results_elsewhere_say_so_in_every_file_and_in_results_md(tmp_path, capsys):
    common.configure(tmp_path / "out", quick=True)
    common.write_results("figs_06_08", "Figs. 6-8", _claims(True), [], [], 1.0, quick=True)
    common.write_results("fig_09", "Fig. 9", _claims(False), [], [], 1.0)
    results = tmp_path / "out" / "results"
    assert json.loads((results / "figs_06_08.json").read_text())["quick"] is True
    assert json.loads((results / "fig_09.json").read_text())["quick"] is False
    md = (results / "figs_06_08.md").read_text()
    assert common.QUICK_LABEL in md and "| PASS (quick) |" in md
    text = run_all.collect()
    assert text.splitlines()[0].endswith(f"({common.QUICK_LABEL})")
    assert "| [figs_06_08](#figs_06_08) | 1 / 1 (QUICK run: not the reproduction) |" in text
    assert "| [fig_09](#fig_09) | 0 / 1 | 1 |" in text
    assert "[PASS (quick)] 9: a claim" in capsys.readouterr().out


def test_a_full_results_md_has_no_quick_label(tmp_path):
    common.configure(tmp_path / "out")
    common.write_results("fig_09", "Fig. 9", _claims(True), [], [], 1.0)
    assert "QUICK" not in run_all.collect()


def _sweep(fractions: np.ndarray, peak_hz: float, hz_per_fraction: float = 500.0) -> SimpleNamespace:
    f_z = fractions * hz_per_fraction
    kd = 1.0 + np.exp(-(((f_z - peak_hz) / 20.0) ** 2))
    return SimpleNamespace(speed_fraction=fractions, mesh_frequency_hz=f_z, kd_max=kd)


def test_a_coarse_sweep_gets_the_full_sweeps_tolerance():
    """Mesh mode 429 Hz, 500 Hz per speed fraction: the full sweep's step is 25 Hz, its tolerance 37.5 Hz.
    A quick sweep's grid point 52 Hz off would have passed 1.5 of its own 92 Hz steps; it fails."""
    quick = _sweep(figs_06_08.QUICK_SWEEP, peak_hz=377.0)
    f_peak = quick.mesh_frequency_hz[np.argmax(quick.kd_max)]
    assert abs(f_peak - 429.0) < 1.5 * np.diff(quick.mesh_frequency_hz).mean()  # the old, widened rule
    claim = figs_06_08.peak_claim(quick, 429.0)
    assert not claim.passed and "37 Hz" in claim.note
    full = _sweep(figs_06_08.SWEEP, peak_hz=410.0)
    assert figs_06_08.peak_claim(full, 429.0).passed
    assert not figs_06_08.peak_claim(_sweep(figs_06_08.SWEEP, peak_hz=370.0), 429.0).passed


def test_a_refitted_scene_goes_to_the_checkouts_scenes_or_the_output_folder(tmp_path):
    record = _checkout(tmp_path / "checkout")
    common.configure(record)
    assert fig_12_calibration.scene_folder() == record.parents[1] / "scenes"
    common.configure(tmp_path / "out")
    assert fig_12_calibration.scene_folder() == tmp_path / "out" / "scenes"
    assert fig_12_calibration.FITS["fig3"].record_dir == tmp_path / "out" / "results" / "fig_12_calibration"
