"""Fig. 12: the four-period run (run-up, no load, load ramp, rated load) for six error modes and
coupling dampings, K_d in period 4 against the paper's values.

System: the shipped `one-stage` scene as it is (its operation section is the four periods: run-up
0-0.5 s, no load to 0.8 s, load ramp to 1.2 s, rated load to 2.0 s); only the error mode and the
coupling damping C_1 change per case, as in the paper.

    python -m gearbody_validation.paper.fig_12 [--out DIR [--quick]]
"""

from __future__ import annotations

import numpy as np

from gearbody.engine import simulate
from gearbody.model import load_scenario
from gearbody.plotting import new_figure, save_figure

from .common import Claim, Timer, check_quick, parser, results_dir, start, write_results

# label: (a, e_um, r, C_1 N m s, the paper's K_d in period 4 or its verdict)
CASES = {
    "(a) E(0.5,12,0.3) C1=0": (0.5, 12.0, 0.3, 0.0, "1.8"),
    "(b) E(0.5,15,0.3) C1=0": (0.5, 15.0, 0.3, 0.0, "unstable"),
    "(c) E(0.5,15,0.3) C1=1000": (0.5, 15.0, 0.3, 1000.0, "stable"),
    "(d) E(0.5,20,0.3) C1=1000": (0.5, 20.0, 0.3, 1000.0, "2.4"),
    "(e) E(0.5,20,0.15) C1=1000": (0.5, 20.0, 0.15, 1000.0, "2.3"),
    "(f) E(0.1,20,0.3) C1=1000": (0.1, 20.0, 0.3, 1000.0, "4.7"),
}
PERIOD_4_S = 1.3  # rated load from 1.2 s; 0.1 s to settle
RESOLVED_KD_CHANGE = 0.03
"""Smallest change of K_d4 counted as an effect: twice the seed-to-seed spread of K_d4 (std 0.013-0.016
over error-mode seeds 1-5 on the calibrated drive's fit cases, fig_12_predictions.seed_scatter)."""


def run(a, e, r, c1, t_end):
    sc = load_scenario(
        "one-stage",
        [
            f"production.error_mode={{a={a},e_um={e},r={r}}}",
            f"design.coupling.damping_Nms_per_rad={c1}",
            f"operation.t_end_s={t_end}",
        ],
    )
    return simulate(sc)


def main(quick: bool = False) -> None:
    check_quick(quick)
    t_end = 1.6 if quick else 2.0
    kd4, traces = {}, {}
    with Timer() as timer:
        for label, (a, e, r, c1, _) in CASES.items():
            res = run(a, e, r, c1, t_end)
            kd4[label] = float(np.max(res.kd[res.time_s >= PERIOD_4_S]))
            traces[label] = (res.time_s[::10], res.kd[::10])
            print(label, round(kd4[label], 3))
    fig = new_figure((1000, 900), 100)
    for n, (label, (t, kd)) in enumerate(traces.items()):
        ax = fig.add_subplot(3, 2, n + 1)
        ax.plot(t, kd, lw=0.5)
        ax.axhline(2.0, color="red", lw=0.8, ls=":")
        for edge in (0.5, 0.8, 1.2):
            ax.axvline(edge, color="grey", lw=0.6, ls="--")
        ax.set_title(f"{label}: K_d4 = {kd4[label]:.2f} (paper {CASES[label][4]})", fontsize=9)
        ax.set_xlabel("t [s]", fontsize=8)
        ax.set_ylabel("K_d", fontsize=8)
    results_dir().mkdir(parents=True, exist_ok=True)
    figs = [save_figure(fig, results_dir() / "fig_12_runs.png", 100)]
    k = list(kd4.values())
    claims = []
    for label, (*_, paper) in CASES.items():
        v = kd4[label]
        if paper in ("unstable", "stable"):
            agree = (v > 2.0) == (paper == "unstable")
            claims.append(
                Claim(
                    "12",
                    f"{label}: {paper}",
                    f"K_d4 = {v:.2f}",
                    agree,
                    "K_d4 > 2" if paper == "unstable" else "K_d4 <= 2",
                )
            )
        else:
            p = float(paper)
            agree = abs(v - p) <= 0.25 * p
            claims.append(Claim("12", f"{label}: K_d4 = {paper}", f"K_d4 = {v:.2f}", agree, "within 25 %"))
    claims += [
        Claim(
            "12",
            "coupling damping C_1 = 1000 N m s lowers K_d (b -> c)",
            f"{k[1]:.2f} -> {k[2]:.2f}",
            k[2] < k[1],
        ),
        Claim(
            "12",
            "a larger e raises K_d (a -> b, c -> d)",
            f"{k[0]:.2f} -> {k[1]:.2f}; {k[2]:.2f} -> {k[3]:.2f}",
            k[1] > k[0] and k[3] > k[2],
        ),
        Claim(
            "12",
            "a smaller random scope r lowers K_d slightly (d -> e: 2.4 -> 2.3)",
            f"{k[3]:.3f} -> {k[4]:.3f}",
            k[4] < k[3] - RESOLVED_KD_CHANGE,
            f"by more than {RESOLVED_KD_CHANGE} (the seed scatter)",
        ),
        Claim(
            "12",
            "moving the error apex to a = 0.1 raises K_d strongly (d -> f: 2.4 -> 4.7)",
            f"{k[3]:.2f} -> {k[5]:.2f}",
            k[5] > 1.5 * k[3],
        ),
    ]
    notes = [
        f"one-stage scene as shipped, four periods, t_end {t_end} s; K_d4 = max K_d for t >= {PERIOD_4_S} s.",
        "The paper's parameter set is not published; ours puts the mesh mode (2844 Hz) far above the "
        "rated mesh frequency (494 Hz), so absolute K_d values are lower than the paper's. Nothing tuned.",
    ]
    title = "Fig. 12: four-period runs, K_d in period 4"
    write_results("fig_12", title, claims, notes, figs, timer.s, quick)


if __name__ == "__main__":
    args = parser(__doc__, "period 4 shortened to 0.4 s").parse_args()
    start("fig_12", args)
    main(args.quick)
