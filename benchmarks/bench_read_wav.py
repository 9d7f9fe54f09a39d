"""Reading a long WAV recording: wall time and peak memory of gearbody.recording.files.read_recording.

Not a test. Writes a WAV of --seconds at --rate Hz with --channels channels of --dtype (int16 or
float32) in a temporary folder, then reads it (calibration 1) in a fresh process and prints the wall
time, the peak of Python's traced allocations (tracemalloc) against the float64 result's size, and the
process's peak resident memory (ru_maxrss) before and after the read (the file's mapped pages count in it).

    python benchmarks/bench_read_wav.py [--seconds 60] [--rate 50000] [--channels 4] [--dtype int16]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

MEASURE = """
import resource, sys, time, tracemalloc
from gearbody.recording.files import read_recording
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
tracemalloc.start()
start = time.perf_counter()
rec = read_recording(sys.argv[1], calibration=1.0)
wall = time.perf_counter() - start
peak = tracemalloc.get_traced_memory()[1]
tracemalloc.stop()
rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(wall, peak, before * 1024, rss, rec.n_samples * len(rec.channels) * 8)
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--rate", type=int, default=50_000)
    parser.add_argument("--channels", type=int, default=4)
    parser.add_argument("--dtype", choices=["int16", "float32"], default="int16")
    args = parser.parse_args()
    from scipy.io import wavfile

    n = int(args.seconds * args.rate)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "long.wav"
        rng = np.random.default_rng(0)
        raw = (rng.standard_normal((n, args.channels)) * 3000).astype(args.dtype)
        wavfile.write(path, args.rate, raw)
        del raw
        size = path.stat().st_size
        start = time.perf_counter()
        out = subprocess.run(
            [sys.executable, "-c", MEASURE, str(path)], capture_output=True, text=True, check=True
        )
        total = time.perf_counter() - start
        wall, peak, before, rss, result = (float(v) for v in out.stdout.split())
    print(
        f"{args.seconds:g} s x {args.rate} Hz x {args.channels} ch {args.dtype} WAV "
        f"({size / 1e6:.0f} MB): "
        f"read in {wall:.3f} s (process {total:.1f} s with imports); float64 result {result / 1e6:.1f} MB; "
        f"tracemalloc peak {peak / 1e6:.1f} MB ({peak / result:.2f}x); "
        f"process peak RSS {before / 1e6:.0f} MB after imports, {rss / 1e6:.0f} MB after the read"
    )


if __name__ == "__main__":
    main()
