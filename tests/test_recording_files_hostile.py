"""Readers of recordings on hostile files and options: every failure is one InputError naming the file and
the problem (never a traceback of a library, never a memory blow-up); options a format cannot use are
refused; reading a WAV allocates little more than its float64 result."""

from __future__ import annotations

import struct
import tracemalloc

import numpy as np
import pytest
from test_recording_files import synthetic

from gearbody.errors import InputError
from gearbody.recording.files import formats, read_recording, write_recording

SUFFIXES = sorted({s for f in formats().values() for s in f.suffixes})
WRITTEN = [f.suffixes[0] for f in formats().values() if f.writes]


def _fails(path, *fragments, **options) -> str:
    with pytest.raises(InputError) as err:
        read_recording(path, **options)
    text = str(err.value)
    assert str(path) in text and "Traceback" not in text
    for fragment in fragments:
        assert fragment in text, text
    return text


@pytest.mark.parametrize("suffix", SUFFIXES)
def test_an_empty_file(tmp_path, suffix):
    (tmp_path / f"e{suffix}").write_bytes(b"")
    _fails(tmp_path / f"e{suffix}", "empty")


@pytest.mark.parametrize("suffix", SUFFIXES)
def test_a_file_of_garbage(tmp_path, suffix):
    (tmp_path / f"g{suffix}").write_bytes(bytes(range(256)) * 8)
    _fails(tmp_path / f"g{suffix}")


@pytest.mark.parametrize("suffix", WRITTEN)
def test_a_truncated_file_of_ours(tmp_path, suffix):
    path = write_recording(synthetic(), tmp_path / f"r{suffix}")
    data = path.read_bytes()
    path.write_bytes(data[: len(data) * 2 // 3])
    _fails(path)


def test_a_truncated_csv_and_wav_say_so(tmp_path):
    path = write_recording(synthetic(), tmp_path / "r.csv")
    lines = path.read_text().splitlines()
    path.write_text("\n".join(lines[:-100]) + "\n")
    _fails(path, "rows", "truncated")
    path = write_recording(synthetic(), tmp_path / "r.wav")
    path.write_bytes(path.read_bytes()[:5000])
    _fails(path, "truncated")


def test_nan_samples(tmp_path):
    (tmp_path / "n.csv").write_text("time,acc\n0,1\n0.001,nan\n0.002,3\n")
    _fails(tmp_path / "n.csv", "'acc'", "sample 1", "nan")
    from scipy.io import wavfile

    wavfile.write(tmp_path / "n.wav", 100, np.array([0.1, 0.2, np.inf, 0.3], dtype=np.float32))
    _fails(tmp_path / "n.wav", "'ch1'", "sample 2", "inf")


def test_a_recording_with_nan_is_not_written(tmp_path):
    from gearbody.recording import Channel, Recording

    rec = Recording(100.0, [Channel("a", np.array([0.0, np.nan, 1.0]))])
    with pytest.raises(InputError, match="'a'.*sample 1"):
        write_recording(rec, tmp_path / "a.h5")
    assert not list(tmp_path.iterdir())


def test_a_non_uniform_time_column(tmp_path):
    t = np.arange(100) / 1000.0
    t[50:] += 0.0003
    (tmp_path / "t.csv").write_text("t,acc\n" + "".join(f"{float(x)!r},1\n" for x in t))
    _fails(tmp_path / "t.csv", "not uniform", "sample_rate_hz=")
    rec = read_recording(tmp_path / "t.csv", sample_rate_hz=1000.0)  # within half a step of its grid
    assert rec.sample_rate_hz == 1000.0


@pytest.mark.parametrize("step", [1e-12, 0.0, -1.0])
def test_absurd_sample_rates_from_a_time_column(tmp_path, step):
    (tmp_path / "t.csv").write_text("time_s,acc\n" + "".join(f"{k * step!r},1\n" for k in range(10)))
    _fails(tmp_path / "t.csv", "time")


def test_absurd_sample_rates_given_or_in_the_file(tmp_path):
    from scipy.io import savemat

    savemat(tmp_path / "a.mat", {"acc": np.ones(10), "fs": 1e15})
    _fails(tmp_path / "a.mat", "'fs'", "sample rate")
    savemat(tmp_path / "b.mat", {"acc": np.ones(10)})
    _fails(tmp_path / "b.mat", "sample_rate_hz", sample_rate_hz=-5.0)
    _fails(tmp_path / "b.mat", "no sample rate", "sample_rate_hz=")
    from scipy.io import wavfile

    wavfile.write(tmp_path / "z.wav", 8000, np.zeros(10, np.int16))
    data = bytearray((tmp_path / "z.wav").read_bytes())
    data[24:32] = struct.pack("<II", 0, 0)  # the fmt chunk's sample rate and byte rate
    (tmp_path / "z.wav").write_bytes(bytes(data))
    _fails(tmp_path / "z.wav", "sample rate")


def test_channels_of_different_lengths(tmp_path):
    from scipy.io import savemat

    savemat(tmp_path / "a.mat", {"acc": np.ones(10), "vel": np.ones(12), "fs": 100.0})
    _fails(tmp_path / "a.mat", "different lengths", "acc: 10", "vel: 12")
    h5py = pytest.importorskip("h5py")
    with h5py.File(tmp_path / "a.h5", "w") as h5:
        h5["x"], h5["y"] = np.ones(10), np.ones(11)
        h5.attrs["fs"] = 10.0
    _fails(tmp_path / "a.h5", "different lengths")
    (tmp_path / "r.csv").write_text("time,a,b\n0,1,2\n0.1,1\n0.2,1,2\n")
    _fails(tmp_path / "r.csv", "3 numbers")


def test_wrong_shapes(tmp_path):
    from scipy.io import savemat

    savemat(tmp_path / "m.mat", {"data": np.ones((3, 500)), "fs": 100.0})
    _fails(tmp_path / "m.mat", "3 x 500", "transpose")
    (tmp_path / "w.csv").write_text("time,a\n0,1,2\n0.1,1,2\n")
    _fails(tmp_path / "w.csv", "2 columns")
    (tmp_path / "one.csv").write_text("time,a\n0,1\n")
    _fails(tmp_path / "one.csv")


def test_a_header_claiming_more_than_memory_is_refused_before_reading(tmp_path):
    h5py = pytest.importorskip("h5py")
    with h5py.File(tmp_path / "huge.h5", "w") as h5:  # 2**42 samples declared, a few kB on disk
        h5.create_dataset("x", shape=(2**42,), chunks=(1024,), dtype="f8")
        h5.attrs["fs"] = 1e6
    assert (tmp_path / "huge.h5").stat().st_size < 100_000
    _fails(tmp_path / "huge.h5", "GiB", "start_s=/end_s=")
    part = read_recording(tmp_path / "huge.h5", end_s=0.001)
    assert part.n_samples == 1000


def test_options_a_format_cannot_use_are_refused(tmp_path):
    path = write_recording(synthetic(), tmp_path / "r.csv")
    _fails(path, "calibration=", "'csv'", "sample_rate_hz=, units=", calibration=2.0)
    wav = write_recording(synthetic(), tmp_path / "r.wav")
    _fails(wav, "sample_rate_hz=", "'wav'", sample_rate_hz=100.0)
    uff = write_recording(synthetic(), tmp_path / "r.uff")
    _fails(uff, "sample_rate_hz=", "'uff'", sample_rate_hz=100.0)
    for own in (path, wav, uff):  # our files hold their rate, units, calibration
        _fails(own, "units=", "gearbody recording", units={"force": "kN"})
    _fails(path, "pulses_per_rev", "tacho_channel", pulses_per_rev=4)
    _fails(path, "'nope'", "acc x", channels=["nope"])
    _fails(path, "'nope'", tacho_channel="nope")
    _fails(path, "start_s", "0 samples", start_s=100.0)
    _fails(wav, "calibration", calibration=[1.0, 2.0])


def test_foreign_option_values_are_checked(tmp_path):
    from scipy.io import wavfile

    wavfile.write(tmp_path / "a.wav", 100, np.zeros((10, 2), np.int16))
    _fails(tmp_path / "a.wav", "calibration", "2 (one per channel)", calibration=[1.0, 2.0, 3.0])
    _fails(tmp_path / "a.wav", "calibration", "> 0", calibration=-1.0)
    _fails(tmp_path / "a.wav", "'furlong'", "units=", units={"ch1": "furlong"})
    _fails(tmp_path / "a.wav", "units=", "'ch9'", units={"ch9": "g"})
    _fails(tmp_path / "a.wav", "encoder", tacho_channel="ch1", pulses_per_rev=0)


def test_unknown_suffixes_and_formats_name_the_choices(tmp_path):
    (tmp_path / "a.xyz").write_text("1")
    with pytest.raises(InputError, match=r"'\.xyz'.*\.csv.*\.tdms"):
        read_recording(tmp_path / "a.xyz")
    with pytest.raises(InputError, match="format = 'excel'.*csv, parquet"):
        read_recording(tmp_path / "a.xyz", format="excel")
    with pytest.raises(InputError, match="does not write it"):
        write_recording(synthetic(), tmp_path / "a.tdms")
    with pytest.raises(InputError, match="no such file"):
        read_recording(tmp_path / "missing.csv")


def test_a_missing_library_names_the_extra_to_install(tmp_path, monkeypatch):
    import importlib

    real = importlib.import_module

    def no_h5py(name, *args):
        if name.split(".")[0] in ("h5py", "nptdms"):
            raise ImportError(name)
        return real(name, *args)

    monkeypatch.setattr(importlib, "import_module", no_h5py)
    with pytest.raises(InputError, match=r'h5py.*pip install "gearbody\[files\]"'):
        write_recording(synthetic(), tmp_path / "a.h5")
    (tmp_path / "a.tdms").write_bytes(b"TDSm" + bytes(100))
    _fails(tmp_path / "a.tdms", "nptdms", 'pip install "gearbody[tdms]"')


@pytest.mark.parametrize("dtype", [np.int16, np.float32])
def test_reading_a_wav_allocates_about_its_float64_result(tmp_path, dtype):
    """60 s x 50 kHz x 4 channels would be 96 MB of float64; 2 s here (3.2 MB), the same blocks."""
    from scipy.io import wavfile

    n, nch = 100_000, 4
    raw = (np.random.default_rng(0).standard_normal((n, nch)) * 3000).astype(dtype)
    wavfile.write(tmp_path / "big.wav", 50_000, raw)
    del raw
    tracemalloc.start()
    try:
        rec = read_recording(tmp_path / "big.wav", calibration=1.0)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    result = 8 * n * nch
    assert rec.n_samples == n and len(rec.channels) == nch
    assert peak < 1.3 * result, f"peak {peak / 1e6:.1f} MB for a {result / 1e6:.1f} MB result"
