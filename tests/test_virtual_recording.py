"""Issue 30: the route from a scenario's [instruments] to an analysis: ``gearbody run`` writes the virtual
recording (instruments.mat) beside the result, ``gearbody analyze RUN`` analyses it like a logger's file
(``--run-signals``: the run's own signals), ``gearbody compare`` keeps the run's signals on its RUN side;
and ``gearbody.virtual_recording`` from Python."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

import gearbody as gb
from gearbody.cli import main
from gearbody.model.scenes import scene_path
from gearbody.recording.frf import MeasuredFRF, write_frf
from gearbody.recording.instruments import HousingMode

TABLE = """
[instruments]
sample_rate_hz = 10000.0

[[instruments.accelerometers]]
name = "acc_pinion"
location = "pinion bearing housing, top"
direction = "+y"
noise_rms_g = 0.001
[[instruments.accelerometers.modes]]
frequency_hz = 3000.0
damping_ratio = 0.03
participation = { pinion_bearing_force_y_N = 0.033, wheel_bearing_force_y_N = 0.0167 }

[[instruments.accelerometers]]
name = "acc_wheel"
direction = "+x"
frf_file = "wheel.csv"

[instruments.tacho]
shaft = "wheel"
pulses_per_rev = 2
"""


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    folder = tmp_path_factory.mktemp("scene")
    mode = HousingMode(2000.0, 0.05, {"wheel_bearing_force_x_N": 0.02})
    write_frf(MeasuredFRF.from_modes([mode], np.arange(0.0, 10_001.0, 2.0)), folder / "wheel.csv")
    path = folder / "ball.toml"
    path.write_text(scene_path("lateral-8dof-ball").read_text() + TABLE)
    return path


@pytest.fixture(scope="module")
def run_folder(scene, tmp_path_factory):
    out = tmp_path_factory.mktemp("run") / "ball"
    assert main(["run", str(scene), "--t-end", "1", "--out", str(out), "--quiet", "--no-plots"]) == 0
    return out


def test_run_writes_the_virtual_recording_the_table_describes(run_folder, scene):
    rec = gb.read_recording(run_folder / "instruments.mat")
    assert rec.names == ["acc_pinion", "acc_wheel"] and rec.sample_rate_hz == 10_000.0
    assert rec.n_samples == 10_001  # 1 s at 10 kHz, from the run's 20 kHz
    ch = rec.channel("acc_pinion")
    assert (ch.unit, ch.location, ch.direction) == ("m/s^2", "pinion bearing housing, top", "+y")
    assert ch.sensitivity == pytest.approx(0.1 / 9.80665)
    assert rec.tacho.shaft == "wheel" and rec.tacho.pulses_per_rev == 2
    result = gb.Result.load_npz(run_folder / "result.npz")
    wheel_hz = np.mean(result["wheel_speed_rad_s"][result.final_window()]) / (2 * np.pi)
    pulses = rec.tacho.pulse_times_s
    assert 1 / np.median(np.diff(pulses[pulses > 0.75])) == pytest.approx(2 * wheel_hz, rel=1e-3)
    assert rec.meta["source"] == "virtual instruments" and rec.meta["seed"] == 1  # meta.seed
    assert rec.meta["scenario"]["instruments"]["accelerometers"][1]["frf_file"] == str(
        scene.parent / "wheel.csv"
    )
    # the same recording from Python, bit for bit (the seed and the anti-alias filter are the run's)
    again = gb.virtual_recording(result)
    assert all(np.array_equal(again[n], rec[n]) for n in rec.names)
    steady = rec.window(0.75)
    rms = {n: float(np.sqrt(np.mean(steady[n] ** 2))) for n in rec.names}
    assert 1.0 < rms["acc_pinion"] < 100.0 and 0.1 < rms["acc_wheel"] < 100.0, rms


def test_analyze_a_run_folder_reads_its_virtual_instruments(run_folder, tmp_path, capsys):
    assert main(["analyze", str(run_folder), "--out", str(tmp_path / "a")]) == 0
    out = capsys.readouterr().out
    assert "the run's virtual instruments (instruments.mat; --run-signals" in out
    assert f"analysed acc_pinion, acc_wheel of {run_folder}" in out
    features = json.loads((tmp_path / "a" / "features.json").read_text())
    assert "acc_pinion/fm0:pinion" in features and "acc_wheel/rms" in features
    page = (tmp_path / "a" / "report.html").read_text()
    assert "Channel <code>acc_wheel</code>" in page
    assert main(["analyze", str(run_folder), "--run-signals", "--out", str(tmp_path / "b")]) == 0
    assert "analysed pinion_housing_accel_y_m_s2 of" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--tacho-shaft", "pinion"], "--tacho-shaft: the run's virtual instruments"),
        (["--unit", "acc_pinion=g"], "--unit: the run's virtual instruments"),
        (["--pulses-per-rev", "0"], "--pulses-per-rev: the run's virtual instruments"),
    ],
)
def test_options_for_a_loggers_file_are_refused_on_the_virtual_recording(
    run_folder, tmp_path, capsys, argv, message
):
    assert main(["analyze", str(run_folder), *argv, "--out", str(tmp_path / "a")]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "a").exists()


def test_run_signals_on_a_file_is_refused(run_folder, tmp_path, capsys):
    argv = ["analyze", str(run_folder / "instruments.mat"), "--run-signals", "--out", str(tmp_path / "a")]
    assert main(argv) == 2
    assert "--run-signals: RECORDING" in capsys.readouterr().err


def test_compare_keeps_the_runs_signals_and_takes_a_virtual_recording(run_folder, tmp_path, capsys):
    argv = ["compare", str(run_folder), str(run_folder), "--out", str(tmp_path / "c")]
    assert main(argv) == 0
    assert (
        "run pinion_housing_accel_y_m_s2 [m/s^2] beside recording acc_pinion [m/s^2]"
        in capsys.readouterr().out
    )


def test_a_refused_instruments_table_stops_the_run_before_anything_is_written(scene, tmp_path, capsys):
    out = tmp_path / "r"
    bad = "--set=instruments.accelerometers.1.modes.1.participation={pinion_force_N=1.0}"
    assert main(["run", str(scene), "--t-end", "0.01", bad, "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "instruments.accelerometers.1.modes.1.participation.pinion_force_N: not a force signal" in err
    assert not out.exists()


def test_the_frf_file_is_read_before_the_run(scene, tmp_path, capsys):
    copy = tmp_path / "ball.toml"
    shutil.copy(scene, copy)  # its wheel.csv is not beside it
    assert main(["run", str(copy), "--t-end", "0.01", "--out", str(tmp_path / "r"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert (
        f"instruments.accelerometers.2.frf_file = '{tmp_path / 'wheel.csv'}'" in err and "no such FRF" in err
    )


def test_a_result_without_scenario_or_table_is_refused():
    result = gb.Result(np.arange(10) / 10.0, {"pinion_angle_rad": np.arange(10.0)}, {})
    with pytest.raises(gb.InputError, match="carries no scenario"):
        gb.virtual_recording(result)
    with pytest.raises(gb.InputError, match="has no \\[instruments\\] table"):
        gb.virtual_recording(result, gb.load_scenario("one-stage"))


def test_a_run_too_short_for_the_tacho_is_recorded_tacholess_and_says_so(scene, tmp_path, capsys):
    out = tmp_path / "r"
    assert main(["run", str(scene), "--t-end", "0.004", "--no-plots", "--quiet", "--out", str(out)]) == 0
    err = capsys.readouterr().err  # 4 ms of a wheel at 5.6 rev/s, 2 pulses per revolution: one pulse
    assert "the tacho on wheel gave 1 pulses in the run (a tacho needs 3): the recording has no tacho" in err
    rec = gb.read_recording(out / "instruments.mat")
    assert rec.tacho is None and rec.n_samples == 41 and "tacho_note" in rec.meta


def test_an_acquisition_of_fewer_than_two_samples_is_refused_before_the_run(scene, tmp_path, capsys):
    out = tmp_path / "r"
    argv = ["run", str(scene), "--t-end", "0.0002", "--set", "instruments.sample_rate_hz=100.0"]
    assert main([*argv, "--no-plots", "--quiet", "--out", str(out)]) == 2
    assert (
        "instruments.sample_rate_hz = 100: 1 sample(s) over operation.t_end_s = 0.0002"
        in capsys.readouterr().err
    )
    assert not out.exists()
