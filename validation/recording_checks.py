"""Issue 29's checks against ground truth, measured and printed as one table (the tests assert them):

    python -m gearbody_validation.recording_checks

Each row: what is known, what the analysis gives, the error. The cases are those of
tests/test_orders.py, test_envelope.py, test_bearing_lines.py, test_kurtogram.py, test_tsa_noise_db.py,
test_recording_runup.py and test_recording_files.py.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np


def _matlab_ordertrack() -> list[tuple[str, str, str, float]]:
    """MATLAB's ordertrack example: 600 Hz, 5 s, 10 -> 40 rev/s, orders 0.5, 1, 4, 6 (0.5, 1, sqrt 2, 2)."""
    from gearbody.analysis import order_spectrum, order_track

    fs = 600.0
    t = np.arange(0, 5 + 0.5 / fs, 1 / fs)
    rpm = 60 * np.linspace(10, 40, t.size)
    phase = 2 * np.pi * np.concatenate(([0.0], np.cumsum((rpm[1:] + rpm[:-1]) / 2 / 60) / fs))
    orders, amplitudes = (0.5, 1.0, 4.0, 6.0), (0.5, 1.0, np.sqrt(2), 2.0)
    x = sum(a * np.cos(o * phase) for o, a in zip(orders, amplitudes, strict=True))
    spec = order_spectrum(order_track(x, fs, phase), revolutions=4)
    rows = []
    for o, a in zip(orders, amplitudes, strict=True):
        got = float(spec.amplitude[np.argmin(np.abs(spec.order - o))])
        rows.append((f"ordertrack example: order {o:g}", f"{a:.6f}", f"{got:.6f}", abs(got - a) / a))
    return rows


def _am_tone() -> list[tuple[str, str, str, float]]:
    from gearbody.analysis import envelope_spectrum

    fs, n, fc, fm, m = 10_000.0, 10_000, 1000.0, 50.0, 0.5
    t = np.arange(n) / fs
    x = (1 + m * np.cos(2 * np.pi * fm * t)) * np.cos(2 * np.pi * fc * t)
    rows = []
    for convention, lines in (
        ("squared", ((0, 1.125), (fm, 1.0), (2 * fm, 0.125))),
        ("envelope", ((fm, 0.5),)),
    ):
        env = envelope_spectrum(x, fs, convention=convention, window="boxcar")
        for f, want in lines:
            got = float(env.amplitude[np.argmin(np.abs(env.frequency_hz - f))])
            rows.append(
                (
                    f"AM tone m=0.5, {convention} envelope at {f:g} Hz",
                    f"{want:g}",
                    f"{got:.9f}",
                    abs(got - want) / want,
                )
            )
    return rows


def _cwru() -> list[tuple[str, str, str, float]]:
    from gearbody.analysis import BearingGeometry, bearing_frequencies

    g = BearingGeometry(9, 0.3126 * 0.0254, 1.537 * 0.0254, 0.0)
    f = bearing_frequencies(g, 1.0)
    return [(f"CWRU 6205 {name} [x shaft]", f"{want}", f"{got:.5f}", abs(got - want) / want)
            for name, want, got in (("BPFO", 3.5848, f.bpfo_hz), ("BPFI", 5.4152, f.bpfi_hz),
                                    ("FTF", 0.3983, f.ftf_hz))]  # fmt: skip


def _kurtogram() -> list[tuple[str, str, str, float]]:
    from gearbody.analysis import fast_kurtogram

    fs, rng = 20_000.0, np.random.default_rng(0)
    n = int(2 * fs)
    impacts = np.zeros(n)
    impacts[(np.arange(int(2 * 97)) / 97 * fs).astype(int)] = 1.0
    ring = np.exp(-np.arange(400) / fs * 600) * np.sin(2 * np.pi * 3500 * np.arange(400) / fs)
    x = (
        np.convolve(impacts, ring)[:n]
        + rng.normal(0, 0.3, n)
        + 5 * np.sin(2 * np.pi * 30 * np.arange(n) / fs)
    )
    k = fast_kurtogram(x, fs)
    lo, hi = k.band_hz
    return [
        (
            "kurtogram band holds the 3.5 kHz resonance",
            "3500 in band",
            f"{lo:.0f}..{hi:.0f} Hz",
            0.0 if lo <= 3500 <= hi else 1.0,
        )
    ]


def _tsa_noise() -> list[tuple[str, str, str, float]]:
    from gearbody.analysis import angle_resample, synchronous_average

    rows = []
    for n_revs in (16, 64, 256):
        rng = np.random.default_rng(29 + n_revs)
        fs, f = 10_000.0, 20.0
        t = np.arange(int(fs / f * (n_revs + 1))) / fs
        angle = 2 * np.pi * f * t
        noise = rng.normal(0, 1, t.size)
        avg = synchronous_average(noise, angle, points_per_rev=1024)
        one = np.mean(angle_resample(noise, angle, 1024).values ** 2)
        got = 10 * np.log10(np.mean(avg.average**2) / one)
        want = -10 * np.log10(avg.n_revs)
        rows.append(
            (f"TSA noise over {avg.n_revs} revolutions [dB]", f"{want:.2f}", f"{got:.2f}", abs(got - want))
        )
    return rows


def _runup() -> list[tuple[str, str, str, float]]:
    import gearbody as gb
    from gearbody.analysis import shaft_angle_from_pulses

    run = gb.simulate(gb.load_scenario("one-stage", ["operation.t_end_s=0.6"]))
    rows = []
    for ppr in (60, 360):
        rec = run.to_recording(["pinion_accel_rad_s2"], pulses_per_rev=ppr)
        p = rec.tacho.pulse_times_s
        inside = (rec.time_s >= p[1]) & (rec.time_s <= p[-2])
        step = 2 * np.pi / ppr
        k0 = np.round(np.interp(p[0], rec.time_s, run["pinion_angle_rad"]) / step)
        err = np.abs(shaft_angle_from_pulses(p, ppr, rec.time_s) + k0 * step - run["pinion_angle_rad"])[
            inside
        ]
        rows.append(
            (
                f"run-up angle from a {ppr}-pulse tacho vs simulated [rad]",
                "0",
                f"{err.max():.2e}",
                float(err.max()),
            )
        )
    return rows


def _round_trips() -> list[tuple[str, str, str, float]]:
    from gearbody.recording import Channel, Recording, Tacho
    from gearbody.recording.files import read_recording, write_recording

    rng = np.random.default_rng(1)
    rec = Recording(
        12_345.678, [Channel("acc", rng.normal(size=5000), "m/s^2", 0.01, "housing", "y"),
                     Channel("force", rng.normal(size=5000), "N")],
        t0_s=0.125, tacho=Tacho("pinion", 4, pulse_times_s=np.cumsum(rng.uniform(0.01, 0.02, 20))),
        meta={"load": "rated"},
    )  # fmt: skip
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for suffix in (".csv", ".parquet", ".wav", ".mat", ".h5", ".uff"):
            back = read_recording(write_recording(rec, Path(tmp) / f"r{suffix}"))
            same = all(np.array_equal(back[n], rec[n]) for n in rec.names)
            same &= np.array_equal(back.tacho.pulse_times_s, rec.tacho.pulse_times_s)
            same &= back.sample_rate_hz == rec.sample_rate_hz and back.t0_s == rec.t0_s
            rows.append(
                (
                    f"write and read back {suffix}",
                    "bit-exact",
                    "bit-exact" if same else "DIFFERS",
                    0.0 if same else 1.0,
                )
            )
    return rows


def main() -> None:
    rows = [*_matlab_ordertrack(), *_am_tone(), *_cwru(), *_kurtogram(), *_tsa_noise(), *_runup(),
            *_round_trips()]  # fmt: skip
    width = max(len(r[0]) for r in rows)
    print(f"{'check':{width}s}  {'expected':>14s}  {'measured':>16s}  error")
    for name, want, got, err in rows:
        print(f"{name:{width}s}  {want:>14s}  {got:>16s}  {err:.2e}")


if __name__ == "__main__":
    main()
