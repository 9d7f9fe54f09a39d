"""Fig. 9: K_d against the error e for E(0.1, e, 0), E(0.5, e, 0), E(0.5, -e, 0), C_1 = 0.

System: the shipped `one-stage` scene (Fig. 3: motor, coupling with C_1 = 0, pinion, wheel, output
shaft, machine), rated speed and load, steady running, friction as in the scene. The paper: K_d
grows linearly with e up to a threshold e that depends on a; above it the running is unstable
(tooth separation, K_d > 2).

    python -m gearbody_validation.paper.fig_09 [--out DIR [--quick]]
"""

from __future__ import annotations

import numpy as np

from gearbody.engine import simulate
from gearbody.model import load_scenario
from gearbody.plotting import new_figure, save_figure
from gearbody.studies import steady_overrides

from .common import Claim, Timer, check_quick, parser, results_dir, start, write_results

SETTLE_S, RECORD_S = 0.1, 0.1
MODES = {"a: E(0.1, e, 0)": (0.1, 1.0), "b: E(0.5, e, 0)": (0.5, 1.0), "c: E(0.5, -e, 0)": (0.5, -1.0)}


def kd_max(a: float, e_um: float, scene: str = "one-stage") -> float:
    sc = load_scenario(
        scene,
        [
            *steady_overrides(1.0, SETTLE_S + RECORD_S),
            f"production.error_mode={{a={a},e_um={e_um},r=0.0}}",
            "design.coupling.damping_Nms_per_rad=0.0",
        ],
    )
    res = simulate(sc)
    return float(np.max(res.kd[res.time_s >= SETTLE_S]))


def threshold(e: np.ndarray, kd: np.ndarray, level: float = 2.0) -> float:
    """Smallest e at which K_d reaches `level` (linear interpolation), NaN if never."""
    above = np.flatnonzero(kd > level)
    if above.size == 0:
        return float("nan")
    k = above[0]
    if k == 0:
        return float(e[0])
    return float(e[k - 1] + (level - kd[k - 1]) * (e[k] - e[k - 1]) / (kd[k] - kd[k - 1]))


def e_grid(quick: bool = False) -> np.ndarray:
    return np.array([0, 10, 20, 40, 60] if quick else [0, 5, 10, 15, 20, 25, 30, 40, 50, 60, 80], float)


def curves_of(scene: str, e_values: np.ndarray) -> dict[str, np.ndarray]:
    """K_d max against e for every error mode of MODES on a scene."""
    curves = {}
    for label, (a, sign) in MODES.items():
        curves[label] = np.array([kd_max(a, sign * e, scene) for e in e_values])
        print(label, np.round(curves[label], 3))
    return curves


def main(quick: bool = False) -> None:
    check_quick(quick)
    e_values = e_grid(quick)
    with Timer() as timer:
        curves = curves_of("one-stage", e_values)
    fig = new_figure((900, 500), 100)
    ax = fig.add_subplot(1, 1, 1)
    claims, notes = check(curves, e_values, ax)
    ax.axhline(2.0, color="red", lw=0.8, ls=":", label="K_d = 2")
    ax.set_xlabel("error e [um]")
    ax.set_ylabel("K_d max (steady rated running)")
    ax.set_title("one-stage, C_1 = 0, r = 0: K_d against the error e")
    ax.grid(alpha=0.3)
    ax.legend()
    results_dir().mkdir(parents=True, exist_ok=True)
    figs = [save_figure(fig, results_dir() / "fig_09_kd_vs_e.png", 100)]
    e_list = ", ".join(f"{e:.0f}" for e in e_values)
    notes.append(f"e values {e_list} um; settle {SETTLE_S} s, record {RECORD_S} s.")
    title = "Fig. 9: K_d against the error e"
    write_results("fig_09", title, claims, notes, figs, timer.s, quick)


def check(curves: dict[str, np.ndarray], e_values: np.ndarray, ax=None) -> tuple[list[Claim], list[str]]:
    """The paper's Fig. 9 claims on K_d-against-e curves (plotted on `ax` when given)."""
    claims, notes = [], []
    thresholds = {}
    for label, kd in curves.items():
        if ax is not None:
            ax.plot(e_values, kd, "o-", label=label)
        thresholds[label] = threshold(e_values, kd)
        stable = kd <= 2.0
        if np.count_nonzero(stable) >= 3:
            slope, intercept = np.polyfit(e_values[stable], kd[stable], 1)
            fit = slope * e_values[stable] + intercept
            ss_res = float(np.sum((kd[stable] - fit) ** 2))
            ss_tot = float(np.sum((kd[stable] - kd[stable].mean()) ** 2)) or 1e-30
            r2 = 1 - ss_res / ss_tot
            notes.append(
                f"{label}: stable-range fit K_d = {intercept:.3f} + {slope:.4f} e[um], R^2 = {r2:.4f} "
                f"(e <= {e_values[stable].max():.0f} um); threshold e (K_d = 2): {thresholds[label]:.1f} um"
            )
            claims.append(
                Claim(
                    "9",
                    f"{label}: K_d grows linearly with e below the threshold",
                    f"R^2 = {r2:.4f}, slope {slope:.4f} /um",
                    r2 > 0.98 and slope > 0,
                )
            )
        claims.append(
            Claim(
                "9",
                f"{label}: above a threshold e the running is unstable (K_d > 2)",
                f"threshold {thresholds[label]:.1f} um (largest e {e_values.max():.0f} um)",
                np.isfinite(thresholds[label]),
            )
        )
    ta, tb = thresholds["a: E(0.1, e, 0)"], thresholds["b: E(0.5, e, 0)"]
    e_top = float(e_values.max())

    def shown(x):
        return f"{x:.1f} um" if np.isfinite(x) else f"> {e_top:.0f} um"

    # a threshold beyond the sweep is still a threshold that differs from one inside it
    differs = (np.isfinite(ta) != np.isfinite(tb)) or (
        np.isfinite(ta) and np.isfinite(tb) and abs(ta - tb) > 0.1 * max(ta, tb)
    )
    claims.append(
        Claim("9", "the threshold e depends on a (a = 0.1 vs 0.5)", f"{shown(ta)} vs {shown(tb)}", differs)
    )
    return claims, notes


if __name__ == "__main__":
    args = parser(__doc__, "fewer e values").parse_args()
    start("fig_09", args)
    main(args.quick)
