"""Self-convergence of the reference: default tolerance vs a 10x tighter run.

    python -m validation.accuracy_check [scenario.toml ...]

Prints, per scenario, max |dF| / F_rated over the output grid, wall times and function evaluations.
Without arguments it runs every file in validation/scenarios/.
"""

from __future__ import annotations

import pathlib
import sys
import time

import numpy as np

from .reference import F_rated, load_scenario, simulate_reference


def compare(sc: dict, rtol: float = 1e-10, factor: float = 10.0) -> dict:
    t0 = time.perf_counter()
    a = simulate_reference(sc, rtol=rtol)
    t1 = time.perf_counter()
    b = simulate_reference(sc, rtol=rtol / factor)
    t2 = time.perf_counter()
    dF = np.abs(a["mesh_force_N"] - b["mesh_force_N"]) / F_rated(sc)
    return {
        "max_dF_rel": float(dF.max()),
        "argmax_t": float(a["time"][int(dF.argmax())]),
        "max_dq": float(np.abs(a["coordinates"] - b["coordinates"]).max()),
        "wall_default_s": t1 - t0,
        "wall_tight_s": t2 - t1,
        "nfev_default": int(a["nfev"]),
        "nfev_tight": int(b["nfev"]),
        "segments": int(a["n_segments"]),
        "kd_min": float(a["kd"].min()),
        "kd_max": float(a["kd"].max()),
    }


def main(argv: list[str]) -> None:
    default = sorted((pathlib.Path(__file__).parent / "scenarios").glob("*.toml"))
    paths = [pathlib.Path(p) for p in argv] or default
    for path in paths:
        r = compare(load_scenario(path))
        print(
            f"{path.name:32s} max|dF|/F_rated = {100 * r['max_dF_rel']:.2e} % (t = {r['argmax_t']:.5f} s)  "
            f"K_d in [{r['kd_min']:.3f}, {r['kd_max']:.3f}]  wall {r['wall_default_s']:.1f} s "
            f"(tight {r['wall_tight_s']:.1f} s)  nfev {r['nfev_default']}  segments {r['segments']}"
        )


if __name__ == "__main__":
    main(sys.argv[1:])
