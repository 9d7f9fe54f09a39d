"""Readers and writers of recordings (gearbody.recording.files): every writer's file reads back bit-exact
(samples, rate, start, tacho, units, sensitivity, location, direction, metadata), for a synthetic
recording and a simulated run's; every reader reads files written by other tools' conventions."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

from gearbody.recording import Channel, Recording, Tacho
from gearbody.recording.files import formats, read_recording, write_recording
from gearbody.recording.files._common import to_json

WRITTEN = [f"{name}{f.suffixes[0]}" for name, f in formats().items() if f.writes] + ["r.hdf5", "r.unv"]


def _suffix(item: str) -> str:
    return item[item.index(".") :]


def synthetic(pulses: bool = True) -> Recording:
    """Awkward on purpose: a rate of no finite decimal, a start of 13 digits, names with a space and a
    slash, a non-SI unit converted on the way in, a sensitivity, a location, direction, shaft and meta."""
    rng = np.random.default_rng(7)
    n = 3001
    chans = [
        Channel(
            "acc x", rng.standard_normal(n) * 3.3, "g", 0.0102, "input bearing housing", "-y", meta={"sn": 7}
        ),
        Channel("shaft/enc", np.cumsum(rng.random(n)) * 0.01, "rad", 1.0, shaft="input"),
        Channel("force", rng.standard_normal(n) * 1e5 + 1e-300, "N", 2.5e-6, direction="z"),
        Channel("tiny", rng.standard_normal(n) * 1e-30, "m", location="pinion"),
    ]
    tacho = (
        Tacho("input", 3, pulse_times_s=np.sort(rng.random(40)) * 0.1 + 0.2)
        if pulses
        else Tacho("input", 0, channel="shaft/enc")
    )
    meta = {"speed_rpm": 1487.25, "note": "Prüfstand ü", "nested": {"a": [1, 2.5, None]}, "flag": True}
    return Recording(51200.0 / 3.0, chans, t0_s=0.1234567891234, tacho=tacho, meta=meta)


def assert_same(back: Recording, rec: Recording) -> None:
    """Bit-exact: every channel's samples and description, rate, start, tacho, metadata."""
    assert back.names == rec.names
    for name in rec.names:
        a, b = back.channel(name), rec.channel(name)
        assert a.data.dtype == np.float64 and np.array_equal(a.data, b.data), name
        assert (a.unit, a.sensitivity, a.location, a.direction, a.shaft) == (
            b.unit, b.sensitivity, b.location, b.direction, b.shaft,
        ), name  # fmt: skip
        assert a.meta == b.meta, name
    assert back.sample_rate_hz == rec.sample_rate_hz
    assert back.t0_s == rec.t0_s
    assert back.meta == json.loads(to_json(rec.meta))
    assert (back.tacho is None) == (rec.tacho is None)
    if rec.tacho is not None:
        assert back.tacho.describe() == rec.tacho.describe()
        if rec.tacho.pulse_times_s is None:
            assert back.tacho.pulse_times_s is None
        else:
            assert np.array_equal(back.tacho.pulse_times_s, rec.tacho.pulse_times_s)


@pytest.mark.parametrize("item", WRITTEN)
@pytest.mark.parametrize("pulses", [True, False], ids=["pulse-tacho", "encoder-tacho"])
def test_every_writer_reads_back_bit_exact(tmp_path, item, pulses):
    rec = synthetic(pulses)
    path = write_recording(rec, tmp_path / f"r{_suffix(item)}")
    assert path.exists() and not list(tmp_path.glob(".*tmp*"))
    assert_same(read_recording(path), rec)


@pytest.mark.parametrize("item", WRITTEN)
def test_a_window_and_a_channel_choice_read_what_recording_window_gives(tmp_path, item):
    rec = synthetic()
    path = write_recording(rec, tmp_path / f"r{_suffix(item)}")
    back = read_recording(path, channels=["force"], start_s=0.15, end_s=0.2)
    want = rec.select(["force"]).window(0.15, 0.2)
    assert back.names == ["force"] and back.n_samples == want.n_samples > 100
    assert back.t0_s == want.t0_s and np.array_equal(back["force"], want["force"])


@pytest.fixture(scope="module")
def simulated():
    import gearbody as gb

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = gb.simulate(gb.load_scenario("lateral-8dof", ["operation.t_end_s=0.2"]))
    return result.to_recording(pulses_per_rev=64)  # the pinion turns 0.6 rev in 0.2 s of run-up: 40 pulses


@pytest.mark.parametrize("item", WRITTEN)
def test_a_simulated_runs_recording_reads_back_bit_exact(tmp_path, simulated, item):
    assert simulated.tacho.pulse_times_s is not None and len(simulated.channels) > 10
    assert_same(read_recording(write_recording(simulated, tmp_path / f"sim{_suffix(item)}")), simulated)


def test_scipy_reads_our_wav_and_skips_the_description_chunk(tmp_path):
    from scipy.io import wavfile

    rec = synthetic()
    path = write_recording(rec, tmp_path / "r.wav")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fs, data = wavfile.read(path)
    assert fs == round(rec.sample_rate_hz) and data.dtype == np.float64
    assert np.array_equal(data, np.column_stack([rec[n] for n in rec.names]))
    assert b"gbdy" in path.read_bytes()[-20000:]


def test_formats_lists_every_suffix_and_which_are_written():
    found = formats()
    suffixes = {s for f in found.values() for s in f.suffixes}
    assert suffixes == {".csv", ".parquet", ".wav", ".mat", ".h5", ".hdf5", ".uff", ".unv", ".tdms"}
    assert not found["tdms"].writes and all(f.writes for k, f in found.items() if k != "tdms")
    assert "calibration" in found["wav"].options and "calibration" not in found["csv"].options


# --- files written by other tools ---------------------------------------------------------------------
RNG = np.random.default_rng(3)
A, B = RNG.standard_normal(2000), RNG.standard_normal(2000)


def test_a_16_bit_wav_with_a_calibration_reads_to_its_quantisation(tmp_path):
    from scipy.io import wavfile

    volts = np.clip(np.column_stack([A, B]), -4, 4) * np.array([0.4, 0.1])  # within full scale
    counts = np.round(volts / np.array([2.0, 0.5]) * 32768).astype(np.int16)
    wavfile.write(tmp_path / "a.wav", 25600, counts)
    rec = read_recording(tmp_path / "a.wav", calibration=[2.0, 0.5], units={"ch1": "g", "ch2": "V"})
    assert rec.names == ["ch1", "ch2"] and rec.sample_rate_hz == 25600.0 and rec.t0_s == 0.0
    assert rec.channel("ch1").unit == "m/s^2" and rec.channel("ch2").unit == "V"
    quantum = np.array([2.0, 0.5]) / 32768
    assert np.max(np.abs(rec["ch1"] / 9.80665 - volts[:, 0])) <= quantum[0] * 0.5 * 1.0001
    assert np.max(np.abs(rec["ch2"] - volts[:, 1])) <= quantum[1] * 0.5 * 1.0001
    assert np.array_equal(rec["ch2"] * rec.channel("ch2").sensitivity, counts[:, 1].astype(float))


@pytest.mark.parametrize("dtype", [np.uint8, np.int32, np.float32])
def test_other_wav_sample_types_read_as_fractions_of_full_scale(tmp_path, dtype):
    from scipy.io import wavfile

    if dtype == np.uint8:
        raw = (np.clip(A, -1, 1) * 127 + 128).astype(np.uint8)
        want = (raw.astype(float) - 128) / 128
    elif dtype == np.int32:
        raw = (np.clip(A, -1, 1) * (2**31 - 1)).astype(np.int32)
        want = raw / 2.0**31
    else:
        raw = A.astype(np.float32)
        want = raw.astype(float)
    wavfile.write(tmp_path / "a.wav", 1000, raw)
    assert np.array_equal(read_recording(tmp_path / "a.wav")["ch1"], want)


def test_savemat_vectors_with_fs_and_a_data_matrix(tmp_path):
    from scipy.io import savemat

    savemat(tmp_path / "v.mat", {"acc": A, "vel": B, "Fs": 25600.0, "title": "rig 3"})
    rec = read_recording(tmp_path / "v.mat", units={"acc": "g", "vel": "mm/s"})
    assert rec.names == ["acc", "vel"] and rec.sample_rate_hz == 25600.0
    assert np.array_equal(rec["acc"], A * 9.80665) and rec.channel("vel").unit == "m/s"
    savemat(tmp_path / "m.mat", {"data": np.column_stack([A, B]), "fs": 1000})
    rec = read_recording(tmp_path / "m.mat", start_s=0.5)
    assert rec.names == ["ch1", "ch2"] and np.array_equal(rec["ch2"], B[500:]) and rec.t0_s == 0.5
    savemat(tmp_path / "t.mat", {"acc": A, "time": 3.0 + np.arange(A.size) / 500.0})
    rec = read_recording(tmp_path / "t.mat")
    assert rec.names == ["acc"] and rec.sample_rate_hz == pytest.approx(500.0, rel=1e-12) and rec.t0_s == 3.0


def _matlab_73(path, variables: dict) -> None:
    """A file as MATLAB -v7.3 saves it: HDF5 after a 512-byte header, arrays transposed, MATLAB_class."""
    import h5py

    with h5py.File(path, "w", userblock_size=512) as h5:
        for name, value in variables.items():
            if isinstance(value, str):
                ds = h5.create_dataset(name, data=np.array([[ord(c)] for c in value], dtype=np.uint16))
                ds.attrs["MATLAB_class"] = np.bytes_("char")
            else:
                value = np.asarray(value, dtype=np.float64)
                value = value.reshape(-1, 1) if value.ndim < 2 else value  # MATLAB: a column vector
                h5.create_dataset(name, data=value.T).attrs["MATLAB_class"] = np.bytes_("double")
    head = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan  1 00:00:00 2024 HDF5 schema 1.00 ."
    with open(path, "r+b") as fh:
        fh.write(head.ljust(116) + b"\0" * 8 + b"\x00\x02IM")


def test_a_matlab_v73_file_transposed_with_its_classes(tmp_path):
    pytest.importorskip("h5py")
    _matlab_73(tmp_path / "v.mat", {"acc": A, "mic": B, "fs": 2048.0, "operator": "ab"})
    rec = read_recording(tmp_path / "v.mat", end_s=0.5)
    assert rec.names == ["acc", "mic"] and rec.sample_rate_hz == 2048.0 and rec.n_samples == 1024
    assert np.array_equal(rec["mic"], B[:1024])
    _matlab_73(tmp_path / "m.mat", {"data": np.column_stack([A, B, -A]), "Fs": 100.0})
    rec = read_recording(tmp_path / "m.mat")
    assert rec.names == ["ch1", "ch2", "ch3"] and np.array_equal(rec["ch3"], -A)


def test_plain_h5py_datasets_with_a_rate_attribute_or_dataset(tmp_path):
    h5py = pytest.importorskip("h5py")
    with h5py.File(tmp_path / "a.h5", "w") as h5:
        group = h5.create_group("daq")
        group.attrs["sample_rate"] = 2048.0
        group.create_dataset("acc", data=A).attrs["unit"] = "g"
        group.create_dataset("mic", data=B.astype(np.float32)).attrs["units"] = "Pa"
    rec = read_recording(tmp_path / "a.h5", start_s=0.25)
    assert rec.names == ["daq/acc", "daq/mic"] and rec.sample_rate_hz == 2048.0 and rec.t0_s == 0.25
    assert np.array_equal(rec["daq/acc"], A[512:] * 9.80665)
    assert np.array_equal(rec["daq/mic"], B.astype(np.float32)[512:].astype(float))
    with h5py.File(tmp_path / "b.h5", "w") as h5:
        h5["x"], h5["y"], h5["fs"] = A, B, 500.0
    rec = read_recording(tmp_path / "b.h5")
    assert rec.names == ["x", "y"] and rec.sample_rate_hz == 500.0


def test_pyuff_written_records_in_its_own_dict_layout(tmp_path):
    pyuff = pytest.importorskip("pyuff")
    sets = [
        pyuff.prepare_58(
            binary=0, func_type=1, rsp_node=k, rsp_dir=k, ref_node=0, ref_dir=0, data=A * k,
            x=0.5 + np.arange(A.size) / 51200.0, id1=f"acc {k}", ordinate_axis_units_lab="g",
            abscissa_spacing=1, abscissa_spec_data_type=17, ordinate_spec_data_type=12,
            orddenom_spec_data_type=0,
        )
        for k in (1, 2)
    ]  # fmt: skip
    pyuff.UFF(str(tmp_path / "a.uff")).write_sets(sets, mode="add")
    rec = read_recording(tmp_path / "a.uff")
    assert rec.names == ["acc 1", "acc 2"] and rec.sample_rate_hz == 51200.0 and rec.t0_s == 0.5
    assert rec.channel("acc 2").unit == "m/s^2"
    assert np.max(np.abs(rec["acc 2"] / 9.80665 - 2 * A)) < 1e-10 * np.max(np.abs(A))  # ASCII: 12 digits


def test_a_loggers_csv_with_a_time_column_and_semicolons(tmp_path):
    t = 10.0 + np.arange(A.size) / 4096.0
    lines = ["# logger XYZ, channel setup 4", "Time [s];Acc (g);Speed [rpm];raw"]
    lines += [
        f"{float(ti)!r};{float(a)!r};{float(1500.0 + b)!r};{float(b)!r}"
        for ti, a, b in zip(t, A, B, strict=True)
    ]
    (tmp_path / "log.csv").write_text("\n".join(lines) + "\n")
    rec = read_recording(tmp_path / "log.csv", units={"raw": "V"})
    assert rec.names == ["Acc", "Speed", "raw"] and rec.t0_s == 10.0
    assert rec.sample_rate_hz == pytest.approx(4096.0, rel=1e-12)
    assert np.array_equal(rec["Acc"], A * 9.80665) and rec.channel("Speed").unit == "rad/s"
    assert rec.channel("raw").unit == "V" and np.array_equal(rec["raw"], B)
    tabbed = "\n".join("\t".join(f"{float(v)!r}" for v in row) for row in zip(A, B, strict=True))
    (tmp_path / "bare.csv").write_text(tabbed + "\n")
    rec = read_recording(tmp_path / "bare.csv", sample_rate_hz=100.0)
    assert rec.names == ["ch1", "ch2"] and np.array_equal(rec["ch2"], B)


def test_a_generic_parquet_with_a_time_column(tmp_path):
    pa = pytest.importorskip("pyarrow")
    pq = pytest.importorskip("pyarrow.parquet")
    table = pa.table({"t": np.arange(A.size) / 1000.0, "acc [g]": A, "n": np.arange(A.size)})
    pq.write_table(table, tmp_path / "a.parquet", row_group_size=300)
    rec = read_recording(tmp_path / "a.parquet", start_s=0.5)
    assert rec.names == ["acc", "n"] and rec.sample_rate_hz == pytest.approx(1000.0, rel=1e-12)
    assert np.array_equal(rec["acc"], A[500:] * 9.80665) and np.array_equal(rec["n"], np.arange(500, A.size))


def test_an_nptdms_written_file(tmp_path):
    nptdms = pytest.importorskip("nptdms")
    props = {"wf_increment": 1 / 25600, "wf_start_offset": 0.5}
    with nptdms.TdmsWriter(tmp_path / "a.tdms") as writer:
        writer.write_segment([
            nptdms.RootObject({"title": "rig"}), nptdms.GroupObject("daq"),
            nptdms.ChannelObject("daq", "acc", A[:700], properties={**props, "unit_string": "g"}),
            nptdms.ChannelObject("daq", "mic", B[:700], properties={**props, "unit_string": "Pa"}),
        ])  # fmt: skip
        writer.write_segment(
            [nptdms.ChannelObject("daq", "acc", A[700:]), nptdms.ChannelObject("daq", "mic", B[700:])]
        )
    rec = read_recording(tmp_path / "a.tdms", start_s=0.51)
    assert rec.names == ["acc", "mic"] and rec.sample_rate_hz == 25600.0 and rec.t0_s == 0.5 + 256 / 25600
    assert np.array_equal(rec["acc"], A[256:] * 9.80665) and np.array_equal(rec["mic"], B[256:])
    with nptdms.TdmsWriter(tmp_path / "t.tdms") as writer:
        writer.write_segment([
            nptdms.ChannelObject("g", "time", np.arange(A.size) / 100.0), nptdms.ChannelObject("g", "x", A)
        ])  # fmt: skip
    rec = read_recording(tmp_path / "t.tdms")
    assert rec.names == ["x"] and rec.sample_rate_hz == pytest.approx(100.0, rel=1e-12)


# --- the tacho on read -------------------------------------------------------------------------------
def test_a_pulse_train_or_an_encoder_channel_becomes_the_tacho(tmp_path):
    from scipy.io import savemat

    pulse = (np.sin(np.arange(A.size) * 0.3) > 0.9).astype(float) * 5.0
    angle_deg = np.arange(A.size) * 0.7
    savemat(tmp_path / "a.mat", {"acc": A, "key": pulse, "enc": angle_deg, "fs": 1000.0})
    rec = read_recording(tmp_path / "a.mat", tacho_channel="key", pulses_per_rev=2, tacho_shaft="output")
    assert rec.tacho.channel == "key" and rec.tacho.pulses_per_rev == 2 and rec.tacho.shaft == "output"
    assert "key" in rec.names
    rec = read_recording(tmp_path / "a.mat", channels=["acc"], tacho_channel="enc", units={"enc": "deg"})
    assert rec.names == ["acc", "enc"] and rec.tacho.is_encoder and rec.channel("enc").shaft == "input"
    assert np.allclose(rec["enc"], np.deg2rad(angle_deg), rtol=1e-15)
    rec2 = write_recording(rec, tmp_path / "b.h5")
    assert_same(read_recording(rec2), rec)
