"""Wall time of computed order tracking on one long channel (not a test).

3e6 samples at 50 kHz (60 s), a run-up 10 -> 40 rev/s with a mesh order 20 plus noise, after a warm run
on a short piece (imports, FFT plans). Cases: the defaults (max_order 500, 8192 points per revolution:
~1.2e7 output points, 4x the input, because the 4:1 speed range widens the grid) and max_order=100
(1024 points per revolution, ~1.5e6 output points). Best of ``--repeat`` runs, and the peak of Python
allocations (tracemalloc) of one run.

    PYTHONPATH=. python benchmarks/bench_order_track.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import time
import tracemalloc

import numpy as np

from gearbody.analysis.orders import order_track

FS_HZ = 50_000.0
N_SAMPLES = 3_000_000


def _record() -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(N_SAMPLES) / FS_HZ
    speed_hz = 10.0 + 30.0 * t / t[-1]
    angle = 2 * np.pi * np.cumsum(speed_hz) / FS_HZ
    x = np.cos(20 * angle) + 0.1 * np.random.default_rng(0).normal(size=N_SAMPLES)
    return x, angle


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    x, angle = _record()
    order_track(x[:20_000], FS_HZ, angle[:20_000])  # warm
    for kwargs in ({}, {"max_order": 100.0}):
        best = float("inf")
        for _ in range(args.repeat):
            start = time.perf_counter()
            tracked = order_track(x, FS_HZ, angle, **kwargs)
            best = min(best, time.perf_counter() - start)
        tracemalloc.start()
        order_track(x, FS_HZ, angle, **kwargs)
        peak_mb = tracemalloc.get_traced_memory()[1] / 1e6
        tracemalloc.stop()
        print(
            f"order_track {kwargs or 'defaults'}: {best:.2f} s (best of {args.repeat}), "
            f"samples_per_rev {tracked.samples_per_rev}, max_order {tracked.max_order:.4g}, "
            f"{tracked.values.size} points, peak allocations {peak_mb:.0f} MB"
        )


if __name__ == "__main__":
    main()
