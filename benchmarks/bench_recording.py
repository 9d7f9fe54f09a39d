"""Issue 29's benchmark: a 60 s, 50 kHz, 4-channel recording from a data logger analysed end to end by
``gearbody analyze`` (read, tacho, order tracking, spectra, synchronous averages, indicators, kurtogram,
envelope, report and figures) in <= 20 s and <= 1 GiB on the 2-core machine.

The recording is synthetic and logger-like: a 16-bit WAV of three accelerometers (the one-stage drive's
mesh order 29 with harmonics, shaft-rate modulation, a local tooth fault once per pinion revolution,
outer-race impacts ringing a 6 kHz housing mode, Gaussian noise; the speed wandering +-3 % about
17 rev/s) and a 1-pulse-per-revolution TTL tacho on the fourth channel. The command runs in a child
process; its wall time and peak resident memory (``ru_maxrss`` of the child) are what is measured.

    python benchmarks/bench_recording.py [--seconds 60] [--rate 50000] [--write]
"""

from __future__ import annotations

import argparse
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def make_wav(path: Path, seconds: float, rate_hz: float, seed: int = 29) -> None:
    from scipy.io import wavfile

    rng = np.random.default_rng(seed)
    n = int(seconds * rate_hz)
    t = np.arange(n) / rate_hz
    f_shaft = 17.0 * (1 + 0.03 * np.sin(2 * np.pi * 0.05 * t))
    angle = 2 * np.pi * np.cumsum(f_shaft) / rate_hz
    mesh = np.sin(29 * angle) + 0.4 * np.sin(58 * angle + 0.3) + 0.15 * np.sin(87 * angle + 1.1)
    mesh *= 1 + 0.2 * np.cos(angle) + 0.5 * np.exp(-((np.mod(angle, 2 * np.pi) - 2.0) ** 2) / 0.01)
    bpfo_hz = 3.5848 * 17.0  # a 6205-like bearing on the pinion shaft
    impacts = np.zeros(n)
    k = (np.arange(int(seconds * bpfo_hz)) / bpfo_hz * rate_hz).astype(int)
    impacts[k[k < n]] = 1.0
    ring = np.exp(-np.arange(400) / rate_hz * 800) * np.sin(2 * np.pi * 6000 * np.arange(400) / rate_hz)
    bearing = np.convolve(impacts, ring)[:n] * 2.0
    channels = []
    for gain in (1.0, 0.7, 0.4):
        channels.append(gain * (mesh + bearing) + rng.normal(0, 0.3, n))
    tacho = np.where(np.mod(angle, 2 * np.pi) < 0.3, 1.0, 0.0)  # 1 pulse per revolution
    full_scale = 8.0  # accelerometers: 8 g full scale
    data = np.stack([*(c / full_scale for c in channels), 0.5 * tacho], axis=1)
    wavfile.write(path, int(rate_hz), np.round(np.clip(data, -1, 1) * 32767).astype(np.int16))


def run(seconds: float, rate_hz: float) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        wav = Path(tmp) / "logger.wav"
        t0 = time.perf_counter()
        make_wav(wav, seconds, rate_hz)
        made_s = time.perf_counter() - t0
        command = [
            sys.executable,
            "-m",
            "gearbody.cli",
            "analyze",
            str(wav),
            "--scene",
            "one-stage",
            "--tacho",
            "ch4",
            "--unit",
            "ch1=g",
            "--unit",
            "ch2=g",
            "--unit",
            "ch3=g",
            "--unit",
            "ch4=V",
            "--calibration",
            "8,8,8,1",
            "--out",
            str(Path(tmp) / "out"),
        ]
        before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
        t0 = time.perf_counter()
        done = subprocess.run(command, capture_output=True, text=True, cwd=ROOT)
        wall_s = time.perf_counter() - t0
        peak_kib = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
        if done.returncode != 0:
            raise SystemExit(f"gearbody analyze failed:\n{done.stdout}\n{done.stderr}")
        return {
            "seconds": seconds,
            "rate_hz": rate_hz,
            "file_mib": wav.stat().st_size / 2**20,
            "made_s": made_s,
            "wall_s": wall_s,
            "peak_mib": max(peak_kib, before) / 1024,
            "output": done.stdout.strip(),
        }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seconds", type=float, default=60.0)
    p.add_argument("--rate", type=float, default=50_000.0)
    p.add_argument("--write", action="store_true", help="append the result to benchmarks/RESULTS.md")
    args = p.parse_args()
    r = run(args.seconds, args.rate)
    line = (
        f"| {r['seconds']:g} s x {r['rate_hz'] / 1e3:g} kHz x 4 ch int16 WAV ({r['file_mib']:.0f} MiB) | "
        f"{r['wall_s']:.1f} s (target <= 20) | {r['peak_mib']:.0f} MiB (target <= 1024) |"
    )
    print(r["output"])
    print(line)
    if args.write:
        with open(ROOT / "benchmarks" / "RESULTS.md", "a") as fh:
            fh.write(
                f"\n## Recording analysed end to end (issue 29), {time.strftime('%Y-%m-%d')}\n\n"
                "`python benchmarks/bench_recording.py --write`: `gearbody analyze` of a logger's WAV (3 "
                "accelerometers, 1 tacho), in a child process: wall time and peak resident memory.\n\n"
                "| recording | wall time | peak memory |\n|---|---|---|\n" + line + "\n"
            )


if __name__ == "__main__":
    main()
