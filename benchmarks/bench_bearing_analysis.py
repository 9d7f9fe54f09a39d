"""Wall time of the bearing-fault analysis on a long record (not a test): envelope_spectrum,
fast_kurtogram (max_level 7), spectral_kurtosis, real_cepstrum, cepstrum_prewhiten and lifter_family on
3e6 samples of white Gaussian noise at 50 kHz (60 s); the first (cold) call and the best of ``--repeat``.

    python benchmarks/bench_bearing_analysis.py [--samples 3000000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from gearbody.analysis.cepstrum import cepstrum_prewhiten, lifter_family, real_cepstrum
from gearbody.analysis.envelope import envelope_spectrum
from gearbody.analysis.kurtogram import fast_kurtogram, spectral_kurtosis

FS_HZ = 50_000.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=3_000_000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    x = np.random.default_rng(0).normal(size=args.samples)
    jobs = {
        "envelope_spectrum (whole band)": lambda: envelope_spectrum(x, FS_HZ),
        "envelope_spectrum (band 2-8 kHz)": lambda: envelope_spectrum(x, FS_HZ, band_hz=(2e3, 8e3)),
        "fast_kurtogram (max_level 7)": lambda: fast_kurtogram(x, FS_HZ, 7),
        "spectral_kurtosis (nperseg 256)": lambda: spectral_kurtosis(x, FS_HZ, 256),
        "real_cepstrum": lambda: real_cepstrum(x, FS_HZ),
        "cepstrum_prewhiten": lambda: cepstrum_prewhiten(x),
        "lifter_family (29.95 Hz)": lambda: lifter_family(x, FS_HZ, 29.95),
    }
    print(f"{args.samples} samples at {FS_HZ:g} Hz; seconds: cold, best of {args.repeat}")
    for name, job in jobs.items():
        times = []
        for _ in range(1 + args.repeat):
            start = time.perf_counter()
            job()
            times.append(time.perf_counter() - start)
        print(f"  {name:36s} {times[0]:6.3f} {min(times[1:]):6.3f}")


if __name__ == "__main__":
    main()
