"""Issue 29: a recording analysed as a run is (``gearbody analyze``), and a run beside a recording
(``gearbody compare``), on synthetic recordings whose content is known and on simulated runs."""

import json

import numpy as np
import pytest

import gearbody as gb
from gearbody.cli import main
from gearbody.diagnosis import DriveKinematics, analyze_recording
from gearbody.recording import Channel, Recording, Tacho
from gearbody.recording.files import write_recording

FS = 20_000.0


def _synthetic(seconds=4.0, seed=3, bpfo_amplitude=3.0, tacho=True):
    """lateral-8dof-ball's drive at ~17 rev/s: mesh order 29 (1 m/s^2), a once-per-revolution tooth
    fault of the pinion, impacts at the pinion bearing's BPFO ringing a 4 kHz mode, noise."""
    drive = DriveKinematics.from_scenario(gb.load_scenario("lateral-8dof-ball"))
    rng = np.random.default_rng(seed)
    t = np.arange(int(seconds * FS)) / FS
    f_in = 17.0 * (1 + 0.01 * np.sin(2 * np.pi * 0.4 * t))
    angle = 2 * np.pi * np.cumsum(f_in) / FS
    x = np.sin(29 * angle) + 0.5 * np.exp(-((np.mod(angle, 2 * np.pi) - 3.0) ** 2) / 0.002)
    bpfo = next(line.frequency_hz for line in drive.lines(17.0, 1000) if line.label == "BPFO pinion bearing")
    impacts = np.zeros(t.size)
    impacts[(np.arange(int(seconds * bpfo)) / bpfo * FS).astype(int)] = bpfo_amplitude
    ring = np.exp(-np.arange(200) / FS * 1500) * np.sin(2 * np.pi * 4000 * np.arange(200) / FS)
    x = x + np.convolve(impacts, ring)[: t.size] + rng.normal(0, 0.2, t.size)
    channels = [Channel("acc", x, "m/s^2", location="pinion bearing housing", direction="y")]
    pulses = None
    if tacho:
        k = np.arange(1, int(angle[-1] / (2 * np.pi)))
        pulses = np.interp(2 * np.pi * k, angle, t)
    rec = Recording(FS, channels, tacho=Tacho("pinion", 1, pulse_times_s=pulses) if tacho else None)
    return rec, drive, bpfo


def test_drive_kinematics_of_the_scenes():
    one = DriveKinematics.from_scenario(gb.load_scenario("one-stage"))
    # the scene's base radii 0.068128 / 0.206732 m set the simulated ratio: 29 / 88 to 6e-6
    assert one.ratio("wheel", "pinion") == pytest.approx(29 / 88, rel=1e-5)
    assert one.resolve_body("output") == "machine" and one.resolve_body("input") == "pinion"
    two = DriveKinematics.from_scenario(gb.load_scenario("two-stage"))
    assert [g.body for g in two.gears] == ["pinion", "wheel", "pinion_2", "wheel_2"]
    planetary = DriveKinematics.from_scenario(gb.load_scenario("planetary"))
    assert planetary.input_body == "sun" and planetary.speed_ratios["ring"] == 0
    labels = {line.label for line in planetary.lines(10.0, 2000.0)}
    assert "1 f_m" in labels and "1 f_pp" in labels
    with pytest.raises(gb.InputError, match="not a rotating body"):
        one.resolve_body("spindle")


def test_synthetic_recording_gives_its_mesh_order_fault_and_bearing_line():
    rec, drive, bpfo = _synthetic()
    diag = analyze_recording(rec, drive)
    ch = diag.channels["acc"]
    assert diag.mean_input_hz == pytest.approx(17.0, rel=0.01)
    mesh = next(b for b in ch.bands if b.label == "1 f_z1")  # the order spectrum's mesh band
    assert mesh.peak_amplitude == pytest.approx(1.0, rel=0.05)
    # the local tooth fault of the pinion: a spiky difference signal over pinion revolutions only
    assert ch.indicators["pinion"]["fm4"] > 2 * ch.indicators["wheel"]["fm4"]
    lo, hi = ch.kurtogram.band_hz
    assert lo < 4000 < hi  # the kurtogram finds the ringing mode
    top = max(ch.envelope_peaks, key=lambda p: p.amplitude)
    assert top.frequency_hz == pytest.approx(bpfo, rel=0.02) and "BPFO pinion bearing" in top.label
    features = diag.features()
    assert features["acc/envelope_peak:BPFO pinion bearing"] > 0
    assert features["input_speed_hz"] == pytest.approx(17.0, rel=0.01)


def test_tacholess_analysis_finds_the_speed_from_the_mesh_harmonic():
    rec, drive, _ = _synthetic(tacho=False)
    diag = analyze_recording(rec, drive, envelope=False)  # searched near the scene's nominal 17.29 rev/s
    assert "nominal input speed 17.29" in diag.notes[0]
    assert diag.mean_input_hz == pytest.approx(17.0, rel=2e-3)
    rec.meta["input_speed_hz"] = 16.5  # a guess within 3 %
    diag = analyze_recording(rec, drive, envelope=False)
    assert diag.angles.source == "tacholess"
    assert diag.mean_input_hz == pytest.approx(17.0, rel=2e-3)


def test_analyze_command_on_a_logger_file(tmp_path, capsys):
    rec, _, _ = _synthetic()
    path = write_recording(rec, tmp_path / "logger.h5")
    assert main(["analyze", str(path), "--scene", "lateral-8dof-ball", "--out", str(tmp_path / "a")]) == 0
    out = capsys.readouterr().out
    assert "acc / pinion: FM0" in out
    written = {p.name for p in (tmp_path / "a").iterdir()}
    for name in (
        "report.html",
        "features.json",
        "spectrum_acc.png",
        "orders_acc.png",
        "tsa_acc_pinion.png",
        "kurtogram_acc.png",
        "envelope_acc.png",
    ):
        assert name in written
    page = (tmp_path / "a" / "report.html").read_text()
    assert "BPFO pinion bearing" in page and "Synchronous averages" in page
    features = json.loads((tmp_path / "a" / "features.json").read_text())
    assert features["acc/fm4:pinion"] > 5
    # the same command again on the same folder is the same analysis: written again
    assert main(["analyze", str(path), "--scene", "lateral-8dof-ball", "--out", str(tmp_path / "a")]) == 0


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["analyze", "nofile.wav", "--scene", "one-stage"], "no such file"),
        (["analyze", "{h5}"], "needs --scene"),
        (["analyze", "{h5}", "--scene", "one-stage", "--channel", "nope"], "no channel 'nope'"),
        (["analyze", "{h5}", "--scene", "one-stage", "--start", "2", "--end", "1"], "--end 1 must be after"),
        (["analyze", "{h5}", "--scene", "one-stage", "--unit", "acc"], "expected NAME=UNIT"),
        (["analyze", "{h5}", "--scene", "one-stage", "--calibration", "x"], "--calibration x"),
        (
            ["analyze", "{h5}", "--scene", "one-stage", "--tacho-shaft", "wheel"],
            "describe the tacho of --tacho",
        ),
        (["analyze", "{h5}", "--scene", "one-stage", "--pulses-per-rev", "-1"], "--pulses-per-rev"),
    ],
)
def test_analyze_refuses_bad_input_with_exit_2(tmp_path, capsys, argv, message):
    rec, _, _ = _synthetic(seconds=1.0)
    h5 = write_recording(rec, tmp_path / "r.h5")
    argv = [str(h5) if a == "{h5}" else a for a in argv]
    assert main([*argv, "--out", str(tmp_path / "o")]) == 2
    assert message in capsys.readouterr().err


@pytest.fixture(scope="module")
def run_folder(tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    assert main(["run", "lateral-8dof", "--t-end", "2", "--out", str(out), "--quiet", "--no-plots"]) == 0
    return out


def test_analyze_a_run_matches_its_own_report_indicators(run_folder, tmp_path):
    """The run's report averages over its exact pinion angle; analyze reads it as a recording with a
    once-per-revolution virtual tacho: the indicators agree to a few per cent."""
    from gearbody.reports.html import report_sections

    result = gb.Result.load_npz(run_folder / "result.npz")
    own = report_sections(result)["indicators"]
    assert main(["analyze", str(run_folder), "--out", str(tmp_path / "a")]) == 0
    features = json.loads((tmp_path / "a" / "features.json").read_text())
    signal = result.vibration_signal_name
    for name in ("rms", "fm0", "energy_ratio"):
        assert features[f"{signal}/{name}:pinion"] == pytest.approx(own[name], rel=0.03)


def test_compare_a_run_with_its_own_export_gives_ratios_of_one(run_folder, tmp_path, capsys):
    result = gb.Result.load_npz(run_folder / "result.npz")
    rec = result.to_recording([result.vibration_signal_name], pulses_per_rev=1)
    rec = rec.window(float(result.time_s[result.final_window()][0]))
    path = write_recording(rec, tmp_path / "export.parquet")
    assert main(["compare", str(run_folder), str(path), "--out", str(tmp_path / "c")]) == 0
    data = json.loads((tmp_path / "c" / "comparison.json").read_text())
    ratios = [row["ratio"] for row in data["features"] if np.isfinite(row["ratio"])]
    assert len(ratios) > 20 and np.allclose(ratios, 1.0, rtol=1e-9)
    assert (tmp_path / "c" / "overlay_orders.png").stat().st_size > 10_000
    assert "ratio" in capsys.readouterr().out


def test_recording_feature_on_a_run_and_calibrate_target_from(run_folder, tmp_path):
    from gearbody.diagnosis.features import target_from_features

    result = gb.Result.load_npz(run_folder / "result.npz")
    value = result.features(["recording:feature=fm0:pinion"])["recording:feature=fm0:pinion"]
    assert np.isfinite(value) and value > 0
    misfit = result.features([f"recording:feature=fm0:pinion,target={value},sigma=0.1"])
    assert abs(next(iter(misfit.values()))) < 1e-12
    (tmp_path / "features.json").write_text(json.dumps({"acc/fm0:pinion": 1.5}))
    assert target_from_features(tmp_path, "fm0:pinion") == ("fm0:pinion", 1.5)
    with pytest.raises(gb.InputError, match="no feature 'fm9'"):
        target_from_features(tmp_path, "fm9")


def test_a_noise_tacho_and_a_dead_channel_are_refused_or_said():
    rec, drive, _ = _synthetic(seconds=2.0)
    n = rec.n_samples
    noise = np.random.default_rng(0).normal(size=n)
    noisy = Recording(
        FS, [rec.channel("acc"), Channel("tacho", noise, "V")], tacho=Tacho("pinion", 1, channel="tacho")
    )
    with pytest.raises(gb.InputError, match="not a shaft's pulses"):
        analyze_recording(noisy, drive)
    fast = Tacho("pinion", 1, pulse_times_s=np.arange(1, 2000) * 1e-3)  # 1000 rev/s: 58 x nominal
    with pytest.raises(gb.InputError, match="nominal 17.29 rev/s"):
        analyze_recording(Recording(FS, [rec.channel("acc")], tacho=fast), drive)
    dead = rec.with_channels(Channel("dead", np.zeros(n), "m/s^2"))
    diag = analyze_recording(dead, drive, ["acc", "dead"], envelope=False)
    assert list(diag.channels) == ["acc"] and "channel 'dead' is constant" in diag.notes[-1]
    with pytest.raises(gb.InputError, match="every channel asked for is constant"):
        analyze_recording(dead, drive, ["dead"])


@pytest.mark.slow
def test_sensitivity_ranks_keys_by_the_misfit_to_a_recordings_feature(run_folder, tmp_path):
    """--target-from: the output is the misfit (value - target) / sigma of a recording's feature,
    computed on every run by the same analysis."""
    assert main(["analyze", str(run_folder), "--out", str(tmp_path / "a")]) == 0
    args = ["sensitivity", "lateral-8dof", "--key", "condition.friction_coefficient=0.0:0.1",
            "--target-from", str(tmp_path / "a"), "fm0:pinion", "0.1", "--samples", "2", "--t-end", "0.8",
            "--set", 'operation.initial_state="steady"',
            "--set", "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
            "--set", "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
            "--workers", "1", "--quiet", "--out", str(tmp_path / "s")]  # fmt: skip
    assert main(args) == 0
    indices = (tmp_path / "s" / "indices.csv").read_text()
    assert "recording:feature=fm0:pinion" in indices and "target=" in indices
