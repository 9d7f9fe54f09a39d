"""The calibrated drives' predictions: the paper's claims not used in the fits of fig_12_calibration.py,
run on the scenes the fits wrote (`one-stage-calibrated`, the variant `one-stage-calibrated-rating`), and
the "Calibrated drive" results file.

Fitted claims (Fig. 12 (a), (d)) and predicted claims go to separate tables of
results/fig_12_calibration.md; results/fig_12_calibration.json holds the pre-registered fit's predicted
claims as `claims` (what run_all counts), its fitted ones as `fitted_claims`, the variant's as
`rating_claims` / `rating_fitted_claims`. The last section is a diagnostic (heavy gears, steady running)
of what the paper's numbers need; it calibrates nothing.
"""

from __future__ import annotations

import json
from dataclasses import asdict

import numpy as np

from gearbody.engine import scene_modes
from gearbody.model import load_scenario
from gearbody.plotting import new_figure, save_figure

from . import fig_09, figs_13_16
from .common import QUICK_LABEL, Claim, Timer, check_quick, results_dir
from .faults import tooth_run
from .fig_12 import CASES, RESOLVED_KD_CHANGE
from .fig_12_calibration import BOUND, FIT_CASES, FIT_SIGMA, FITS, Fit, case_overrides, run_batch

F_LABEL = "(f) E(0.1,20,0.3) C1=1000"
FURTHER_E_UM = (25.0, 30.0)  # (f): "if e is increased further, K_d does not change"
FURTHER_TOLERANCE = 0.10
NAME = "fig_12_calibration"


def fig_12_runs(scene: str) -> tuple[dict[str, float | None], dict[str, float | None]]:
    """K_d4 of the six Fig. 12 cases and of (f) at larger e on `scene` (None: the run was refused)."""
    jobs = [(scene, case_overrides(c), {}) for c in CASES]
    jobs += [(scene, case_overrides(F_LABEL, e), {}) for e in FURTHER_E_UM]
    kds = run_batch(jobs)
    cases = dict(zip(CASES, kds[: len(CASES)], strict=True))
    further = dict(zip((f"E(0.1,{e:g},0.3)" for e in FURTHER_E_UM), kds[len(CASES) :], strict=True))
    return cases, further


def _kd_claim(label: str, paper: str, v: float | None) -> Claim:
    if v is None:
        return Claim("12", f"{label}: {paper}", "run refused", False)
    if paper in ("unstable", "stable"):
        return Claim(
            "12",
            f"{label}: {paper}",
            f"K_d4 = {v:.2f}",
            (v > 2.0) == (paper == "unstable"),
            "K_d4 > 2" if paper == "unstable" else "K_d4 <= 2",
        )
    p = float(paper)
    return Claim("12", f"{label}: K_d4 = {paper}", f"K_d4 = {v:.2f}", abs(v - p) <= 0.25 * p, "within 25 %")


def fig_12_claims(k: dict[str, float], further: dict[str, float]) -> tuple[list[Claim], list[Claim]]:
    """(fitted, predicted) claims of Fig. 12 on the calibrated drive."""
    fitted, predicted = [], []
    for label, (*_, paper) in CASES.items():
        (fitted if label in FIT_CASES else predicted).append(_kd_claim(label, paper, k[label]))
    a, b, c, d, e, f = (k[label] if k[label] is not None else float("nan") for label in CASES)
    predicted += [
        Claim("12", "coupling damping C_1 = 1000 N m s lowers K_d (b -> c)", f"{b:.2f} -> {c:.2f}", c < b),
        Claim(
            "12",
            "a larger e raises K_d (a -> b, c -> d)",
            f"{a:.2f} -> {b:.2f}; {c:.2f} -> {d:.2f}",
            b > a and d > c,
        ),
        Claim(
            "12",
            "a smaller random scope r lowers K_d slightly (d -> e: 2.4 -> 2.3)",
            f"{d:.3f} -> {e:.3f}",
            e < d - RESOLVED_KD_CHANGE,
            f"by more than {RESOLVED_KD_CHANGE} (the seed scatter)",
        ),
        Claim(
            "12",
            "moving the error apex to a = 0.1 raises K_d strongly (d -> f: 2.4 -> 4.7)",
            f"{d:.2f} -> {f:.2f}",
            f > 1.5 * d,
        ),
    ]
    vals = [v for v in further.values() if v is not None]
    same = len(vals) == len(further) and all(abs(v - f) <= FURTHER_TOLERANCE * f for v in vals)
    predicted.append(
        Claim(
            "12",
            "(f): if e is increased further, K_d does not change",
            f"K_d4 {f:.2f} at e = 20 um; "
            + ", ".join(f"{n}: {'refused' if v is None else f'{v:.2f}'}" for n, v in further.items()),
            same,
            f"within {FURTHER_TOLERANCE:.0%} of (f)",
        )
    )
    return fitted, predicted


def fig_09_claims(scene: str, quick: bool) -> tuple[list[Claim], list[str]]:
    e_values = fig_09.e_grid(quick)
    curves = fig_09.curves_of(scene, e_values)
    claims, notes = fig_09.check(curves, e_values)
    for label, kd in curves.items():
        notes.append(f"Fig. 9 {label}: K_d max " + ", ".join(f"{v:.2f}" for v in kd))
    return claims, notes


def figs_13_16_claims(scene: str) -> list[Claim]:
    runs = {
        ("healthy" if f is None else f"{f:.1f} k_z"): (lambda f=f: tooth_run(f, figs_13_16.RECORD_S, scene))
        for f in figs_13_16.FACTORS
    }
    _, wideband, share, lines, failed = figs_13_16.run_series(runs)
    return figs_13_16._claims(f"factors ({scene})", wideband, share, lines, failed)


ZETA_RANGE = (0.03, 0.17)
"""The mesh damping ratios the C_z bound's reason states."""


def _damping_check(scene: str, zeta: float) -> tuple[float, dict[str, float | None]]:
    """The fit cases with C_z raised to the lowest stated damping ratio: (that C_z, K_d4 by case)."""
    c_z = load_scenario(scene).stages[0].mesh.damping_Ns_per_m * ZETA_RANGE[0] / zeta
    kds = run_batch([(scene, case_overrides(c), {"design.mesh.damping_Ns_per_m": c_z}) for c in FIT_CASES])
    return float(c_z), dict(zip(FIT_CASES, kds, strict=True))


SCATTER_SEEDS = (1, 2, 3, 4, 5)


def seed_scatter(scene: str) -> dict[str, tuple[float, float]]:
    """K_d4 of the fit cases over SCATTER_SEEDS (other random tooth depths): (mean, std) by case."""
    jobs = [(scene, [*case_overrides(c), f"meta.seed={s}"], {}) for s in SCATTER_SEEDS for c in FIT_CASES]
    k = np.array([np.nan if v is None else v for v in run_batch(jobs)]).reshape(len(SCATTER_SEEDS), -1)
    return {c: (float(np.mean(k[:, j])), float(np.std(k[:, j], ddof=1))) for j, c in enumerate(FIT_CASES)}


def _mesh_damping_ratio(scene: str) -> tuple[float, float, list[float]]:
    """(damping ratio of the mesh, reduced mass kg, natural frequencies Hz) of a scene with C_1 = 0."""
    sc = load_scenario(scene)
    st = sc.stages[0]
    m = 1.0 / (
        st.pinion.base_radius_m**2 / st.pinion.inertia_kg_m2
        + st.wheel.base_radius_m**2 / st.wheel.inertia_kg_m2
    )
    k = 0.5 * (st.mesh.stiffness_single_N_per_m + st.mesh.stiffness_double_N_per_m)
    zeta = st.mesh.damping_Ns_per_m / (2.0 * np.sqrt(k * m))
    return float(zeta), float(m), [float(f) for f in scene_modes(sc).frequencies_hz]


def _result(c: Claim, quick: bool) -> str:
    return ("PASS" if c.passed else "FAIL") + (" (quick)" if quick else "")


def _table(claims: list[Claim], quick: bool = False) -> list[str]:
    lines = ["| figure | claim | measured | result |", "|---|---|---|---|"]
    for c in claims:
        note = f" ({c.note})" if c.note else ""
        lines.append(f"| {c.figure} | {c.claim} | {c.measured} | {_result(c, quick)}{note} |")
    return lines


def _plot(kd: dict, further: dict, path, title: str):
    fig = new_figure((900, 450), 100)
    ax = fig.add_subplot(1, 1, 1)
    labels = list(kd) + list(further)
    paper = [CASES[c][4] for c in CASES] + ["4.7 (unchanged)"] * len(further)
    values = [kd[c] for c in CASES] + list(further.values())
    x = np.arange(len(labels))
    ax.bar(x, [np.nan if v is None else v for v in values], color="tab:blue", label="calibrated drive")
    for xi, p in zip(x, paper, strict=True):
        try:
            ax.plot(xi, float(p.split()[0]), "r_", ms=30, mew=2)
        except ValueError:
            ax.text(xi, 2.05, p, ha="center", fontsize=8, color="red")
    ax.axhline(2.0, color="red", lw=0.8, ls=":")
    ax.set_xticks(x, [label.split(" C1")[0] for label in labels], rotation=20, fontsize=7)
    ax.set_ylabel("K_d4 (max K_d, t >= 1.3 s)")
    ax.set_title(title)
    return save_figure(fig, path, 100)


def predict_fit(fit: Fit, record: dict, quick: bool = False) -> tuple[list, list[Claim], list[Claim], dict]:
    """Run the predictions on a fit's scene: (markdown lines, fitted claims, predicted claims, K_d4 by
    case)."""
    with Timer() as timer:
        kd, further = fig_12_runs(fit.scene)
        for label, v in {**kd, **further}.items():
            print(label, v)
        fitted, predicted = fig_12_claims(kd, further)
        c9, notes9 = fig_09_claims(fit.scene, quick)
        predicted += c9
        predicted += figs_13_16_claims(fit.scene)
    zeta, m_red, modes = _mesh_damping_ratio(fit.scene)
    damping_check = _damping_check(fit.scene, zeta) if zeta < ZETA_RANGE[0] else None
    scatter = seed_scatter(fit.scene)
    results_dir().mkdir(parents=True, exist_ok=True)
    fig = _plot(
        kd,
        further,
        results_dir() / f"{fit.name}_kd4.png",
        f"{fit.scene}: Fig. 12 cases (bars) and the paper's values (red)",
    )
    lines = _markdown(fit, record, fitted, predicted, notes9, zeta, m_red, modes, timer.s, fig, quick)
    at = lines.index("#### Fitted claims (used in the fit: not evidence)")
    lines[at:at] = [
        f"Seed scatter of the fit cases (error-mode seeds {', '.join(map(str, SCATTER_SEEDS))}, "
        f"{len(SCATTER_SEEDS) * len(FIT_CASES)} runs): K_d4 "
        + ", ".join(f"{c.split(' ')[0]} {m:.2f} +- {sd:.3f}" for c, (m, sd) in scatter.items())
        + f" (mean +- std); the fit's sigma {FIT_SIGMA} is the paper's read-off precision, not this.",
        "",
    ]
    if damping_check is not None:
        c_z, kd_fit = damping_check
        at = lines.index("#### Fitted claims (used in the fit: not evidence)")
        lines[at:at] = [
            f"The identified C_z lies inside its numeric bound, but its damping ratio {zeta:.3f} is below "
            f"the {ZETA_RANGE[0]} that the bound's reason states (the C_z bound was set for reduced masses "
            f"of 4-20 kg; it admits {zeta:.3f} at {m_red:.1f} kg). With C_z raised to the "
            f"ratio {ZETA_RANGE[0]} ({c_z:.0f} N s/m), the fit cases give K_d4 "
            + ", ".join(
                f"{k.split(' ')[0]} {v:.2f}" if v is not None else f"{k.split(' ')[0]} refused"
                for k, v in kd_fit.items()
            )
            + " (2 runs).",
            "",
        ]
    for c in fitted + predicted:
        print(f"[{_result(c, quick)}] {c.figure}: {c.claim} -- {c.measured}")
    return lines, fitted, predicted, {**kd, **further}


def predict(quick: bool = False) -> None:
    """Predictions of every fit with a record; writes results/fig_12_calibration.md/.json (the
    pre-registered fit's predicted claims are the `claims` that run_all counts); a quick run says so in
    the title, every result and ``"quick": true``."""
    check_quick(quick)
    data: dict = {"title": "Calibrated drive", "wall_s": 0.0, "quick": quick}
    bodies, summary, kds = [], [], {}
    for key, fit in FITS.items():
        path = fit.record_file()
        if path is None:
            continue
        record = json.loads(path.read_text())
        with Timer() as timer:
            lines, fitted, predicted, kds[key] = predict_fit(fit, record, quick)
        bodies += lines
        data["wall_s"] += timer.s + record["wall_s_total"]
        prefix = "" if key == "fig3" else f"{key}_"
        data[f"{prefix}claims"] = [asdict(c) for c in predicted]
        data[f"{prefix}fitted_claims"] = [asdict(c) for c in fitted]
        n12 = [c for c in predicted if c.figure == "12"]
        short = ", ".join(f"`{k.split('.')[-2] if '.' in k else k}`" for k in fit.fitted)
        summary.append(
            f"| `{fit.scene}` | {short} | "
            + " | ".join(
                f"{v:.2f} ({FIT_CASES[c]}, {r:+.1f} sigma)"
                for (c, v), r in zip(record["features"].items(), record["residuals"].values(), strict=True)
            )
            + f" | {record['cost']:.3g} | {sum(c.passed for c in predicted)} / {len(predicted)} | "
            f"{sum(c.passed for c in n12)} / {len(n12)} |"
        )
    parts = [
        "## Calibrated drive: Fig. 12 by calibration, the other claims as predictions"
        + (f" ({QUICK_LABEL})" if quick else ""),
        "",
        "| scene | fitted | (a) K_d4 fitted (paper) | (d) K_d4 fitted (paper) | chi^2/2 | predicted claims "
        "passed | of them Fig. 12 |",
        "|---|---|---|---|---|---|---|",
        *summary,
        "",
    ]
    need_lines, need_kd = needs()
    parts += [*_reading(kds, need_kd), "", *bodies, *need_lines]
    (results_dir() / f"{NAME}.md").write_text("\n".join(parts))
    (results_dir() / f"{NAME}.json").write_text(json.dumps(data, indent=2))


def _within(v: float | None, paper: str) -> bool:
    if v is None:
        return False
    if paper in ("unstable", "stable"):
        return (v > 2.0) == (paper == "unstable")
    return abs(v - float(paper)) <= 0.25 * float(paper)


def _reading(kds: dict[str, dict], need_kd: dict[str, float | None]) -> list[str]:
    """The summary's reading, its numbers (and its verbs) from the runs."""
    labels = list(CASES)
    out = []
    if "fig3" in kds:
        k = kds["fig3"]
        out.append(
            f"- Pre-registered fit (Fig. 3 structure, 75 kW): the search found no set inside the bounds that "
            f"reaches (d): the best leaves K_d4 (d) at {k[labels[3]]:.2f} against 2.4. C_1 "
            f"{'lowers' if k[labels[2]] < k[labels[1]] else 'does not lower'} K_d (b -> c "
            f"{k[labels[1]]:.2f} -> {k[labels[2]]:.2f}); (f) {k[labels[5]]:.2f} against 4.7."
        )
    if "rating" in kds:
        k = kds["rating"]
        out.append(
            f"- Variant (rating free): (a), (d) fitted to {k[labels[0]]:.2f}, {k[labels[3]]:.2f}; (f) "
            f"predicted at {k[labels[5]]:.2f} (paper 4.7); the rating ends at its lower bound and the wheel "
            f"inertia near its upper one (see its table: the data pull out of the plausible box); C_1 "
            f"{'lowers' if k[labels[2]] < k[labels[1]] else 'does not lower'} K_d (b -> c "
            f"{k[labels[1]]:.2f} -> {k[labels[2]]:.2f}); (b) K_d4 {k[labels[1]]:.2f}."
        )
    if kds:
        dr = {key: k[labels[4]] - k[labels[3]] for key, k in kds.items()}
        rs = ", ".join(f"{key}: {k[labels[3]]:.3f} -> {k[labels[4]]:.3f}" for key, k in kds.items())
        further = "; ".join(
            f"{key}: {k[labels[5]]:.2f} / " + " / ".join(f"{v:.2f}" for v in list(k.values())[len(labels) :])
            for key, k in kds.items()
        )
        out.append(
            f"- The r effect (d -> e): changes of {', '.join(f'{v:+.3f}' for v in dr.values())} "
            f"({rs}); a change below {RESOLVED_KD_CHANGE} (twice the seed scatter) is not "
            "evidence either way, so the claim needs a larger decrease."
        )
        out.append(
            f"- (f)'s 'if e is increased further, K_d does not change': K_d4 at e = 20 / 25 / 30 um: "
            f"{further}."
        )
    ok = [label.split(" ")[0] for label in labels if _within(need_kd.get(label), CASES[label][4])]
    out.append(
        f"- Diagnostic (last table): with the error imposed as mesh deflection (heavy gears) the "
        f"model gives {', '.join(ok) or 'none'} of the six cases within the claims' tolerances."
    )
    return out


def _own_sigma(fit, record: dict) -> str:
    """What gearbody's CalibrationResult says of the same Jacobian: each parameter's 1-sigma, or that it
    is not identified (a record written before the uncertainty reported unidentified parameters: no
    statement, its pseudo-inverse sigmas dropped directions)."""
    if "unidentified_directions" not in record:
        return ""
    sigma = record["sigma_parameters"]
    free = [k for k in fit.fitted if sigma.get(k) is None]
    if len(free) == len(fit.fitted):
        return f" (gearbody's CalibrationResult: none of the {len(free)} parameters is identified on its own)"
    return (
        " (gearbody's CalibrationResult: 1-sigma "
        + ", ".join(
            f"`{k}` {'not identified' if sigma.get(k) is None else format(sigma[k], '.2g')}"
            for k in fit.fitted
        )
        + ")"
    )


def _markdown(
    fit, record, fitted, predicted, notes9, zeta, m_red, modes, predict_s, fig, quick=False
) -> list[str]:
    n_pass = sum(c.passed for c in predicted)
    lines = [
        f"### {fit.scene}",
        "",
        f"{fit.statement} Scripts `validation/paper/fig_12_calibration.py` (the fit: `--calibrate --fit "
        f"{next(k for k, f in FITS.items() if f is fit)}`) and `fig_12_predictions.py`; scene "
        f"`scenes/{fit.scene}.toml`. Calibration: {record['evaluations']} parameter points x "
        f"{len(FIT_CASES)} cases = {record['simulations']} simulations of 2 s, "
        f"{record['wall_s_total']:.0f} s wall on {record['workers']} workers (nevergrad TwoPointsDE, "
        f"budget {record['budget']}, then least-squares polish); predictions {predict_s:.0f} s wall.",
        "",
        "| parameter | bounds | identified | conditional 1 sigma | reason for the bounds |",
        "|---|---|---|---|---|",
    ]
    for key, b in BOUND.items():
        if key in fit.fitted:
            v, sd = record["parameters"][key], record["conditional_sigma"][key]
            lines.append(f"| `{key}` | {b.lower:g} - {b.upper:g} | {v:.4g} | {sd:.2g} | {b.reason} |")
        else:
            lines.append(
                f"| `{key}` | {b.lower:g} - {b.upper:g} | not fitted (one-stage value) | - | {b.reason} |"
            )
    active = [
        k
        for k in fit.fitted
        if min(
            abs(np.log(record["parameters"][k] / BOUND[k].lower)),
            abs(np.log(BOUND[k].upper / record["parameters"][k])),
        )
        < 0.05
    ]
    lines += [
        "",
        f"Fit cost chi^2/2 = {record['cost']:.3g}; K_d4 fitted (target): "
        + ", ".join(f"{k.split(' ')[0]} {v:.2f} ({FIT_CASES[k]})" for k, v in record["features"].items())
        + "; residuals / sigma: "
        + ", ".join(f"{v:+.2f}" for v in record["residuals"].values())
        + f". {len(FIT_CASES)} targets identify {record['identified_directions']} directions of "
        f"{len(fit.fitted)} parameters (singular values in normalised coordinates "
        + ", ".join(f"{x:.3g}" for x in record["singular_values_unit"])
        + "): the values are one point of a family that fits as well; the conditional sigma holds the "
        "others at the optimum"
        + _own_sigma(fit, record)
        + "."
        + (f" At a bound: {', '.join(active)}." if active else ""),
        "",
        f"Mesh damping ratio at the optimum {zeta:.3f} of critical (reduced mass {m_red:.1f} kg); natural "
        "frequencies (C_1 = 0) " + ", ".join(f"{f:.1f}" for f in modes) + " Hz; mesh frequency 494 Hz.",
        "",
    ]
    lines += ["#### Fitted claims (used in the fit: not evidence)", "", *_table(fitted, quick), ""]
    lines += [f"#### Predicted claims: {n_pass} / {len(predicted)} pass", "", *_table(predicted, quick), ""]
    lines += [f"- {n}" for n in notes9]
    lines += [
        "- Figs. 6-8 are results of the two-wheel model of the paper's ref. [13] (Fig. 2, no motor or "
        "coupling): not one-stage claims, not rerun here (figs_06_08.py runs them on `two-wheel`).",
        "- Figs. 13-16 are rerun with the stiffness-factor series of figs_13_16.py on the calibrated scene "
        "(the geometry series is on `one-stage-geometry`, not calibrated).",
        "",
        f"![{fig.stem}](results/{fig.name})",
        "",
    ]
    return lines


# -- what the model would need --------------------------------------------------------------------------
NEEDS_INERTIA = {"design.pinion.inertia_kg_m2": 15.0, "design.wheel.inertia_kg_m2": 150.0}
"""Gear inertias ~70x the plausible ones: the pair's mesh mode (138 Hz) far below the mesh frequency, in
steady rated running (such a drive could not run up in 0.5 s): a diagnostic only."""
NEEDS_DAMPING_RATIO = 0.05
"""The mesh damping of the heavy pair: the damping ratio of `one-stage` (7000 N s/m on 3.99 kg)."""
NEEDS_SETTLE_S, NEEDS_RECORD_S = 0.5, 0.3


def imposed_error_kd(a_e_r: tuple[float, float, float], scene: str = "one-stage") -> float:
    """K_d of the error imposed as mesh deflection (mesh mode far below f_z): 1 + k_z (e_max - mean E) / F,
    mean E = mean(e_i) / 2 over the pinion's random tooth depths e_i (a triangle of height e_i per tooth)."""
    from gearbody.physics.error_mode import tooth_error_depths_m

    sc = load_scenario(scene)
    st = sc.stages[0]
    _, e_um, r = a_e_r
    depths = tooth_error_depths_m(e_um, r, st.pinion.teeth, sc.meta.seed)
    k = 0.5 * (st.mesh.stiffness_single_N_per_m + st.mesh.stiffness_double_N_per_m)
    f_rated = sc.design.machine.rated_torque_Nm / st.wheel.base_radius_m
    return float(1.0 + k * (depths.max() - depths.mean() / 2.0) / f_rated)


def _steady_kd(overrides: list[str]) -> float | None:
    from gearbody.engine import simulate
    from gearbody.errors import GearbodyError
    from gearbody.studies import steady_overrides

    try:
        res = simulate(
            load_scenario("one-stage", [*steady_overrides(1.0, NEEDS_SETTLE_S + NEEDS_RECORD_S), *overrides])
        )
    except GearbodyError as exc:
        print("refused:", str(exc).splitlines()[0][:160])
        return None
    return float(np.max(res.kd[res.time_s >= NEEDS_SETTLE_S]))


def needs() -> tuple[list[str], dict[str, float | None]]:
    """Runs showing what the paper's numbers need: the one-stage drive with the gear inertias far above
    the plausible ones (mesh mode far below the mesh frequency), beside the imposed-error estimate."""
    from concurrent.futures import ProcessPoolExecutor

    from gearbody.errors import GearbodyError

    labels = list(CASES)
    sc = load_scenario("one-stage")
    st = sc.stages[0]
    m_red = 1.0 / (
        st.pinion.base_radius_m**2 / NEEDS_INERTIA["design.pinion.inertia_kg_m2"]
        + st.wheel.base_radius_m**2 / NEEDS_INERTIA["design.wheel.inertia_kg_m2"]
    )
    k_mean = 0.5 * (st.mesh.stiffness_single_N_per_m + st.mesh.stiffness_double_N_per_m)
    c_z = NEEDS_DAMPING_RATIO * 2.0 * np.sqrt(k_mean * m_red)
    big = [f"{k}={v}" for k, v in NEEDS_INERTIA.items()] + [f"design.mesh.damping_Ns_per_m={c_z:.1f}"]
    with Timer() as timer, ProcessPoolExecutor(2) as pool:
        kds = list(pool.map(_steady_kd, [[*case_overrides(c), *big] for c in labels]))
    try:
        f_mesh = float(scene_modes(load_scenario("one-stage", big)).frequencies_hz[-1])
    except GearbodyError:
        f_mesh = float("nan")
    rows = ["| case | paper | imposed-error estimate | steady run, heavy gears |", "|---|---|---|---|"]
    for label, v in zip(labels, kds, strict=True):
        a, e, r, _, paper = CASES[label]
        rows.append(
            f"| {label} | {paper} | {imposed_error_kd((a, e, r)):.2f} | "
            f"{'refused' if v is None else f'{v:.2f}'} |"
        )
    return [
        "### What the paper's numbers need (diagnostic, not a calibration)",
        "",
        "If the error is imposed as mesh deflection (the gears cannot follow it: the mesh mode far below "
        "the mesh frequency), K_d = 1 + k_z (e_max - mean E) / F_rated (the estimate column: the one-stage "
        "k_z, F_rated and the scene's random tooth depths). In the Fig. 3 structure at this geometry that "
        "needs a reduced mass of the pair >> 130 kg (its mesh mode well below 494 Hz), gear inertias far "
        "outside their bounds. The run column: the one-stage drive with "
        f"{', '.join(f'{k} = {v:g}' for k, v in NEEDS_INERTIA.items())} (reduced mass {m_red:.0f} kg, mesh "
        f"mode {f_mesh:.0f} Hz) and C_z = {c_z:.3g} N s/m (damping ratio {NEEDS_DAMPING_RATIO}, as "
        "one-stage's) in "
        f"steady rated running (such a drive could not run up in 0.5 s), max K_d over {NEEDS_RECORD_S} s "
        f"after {NEEDS_SETTLE_S} s; {timer.s:.0f} s wall.",
        "",
        *rows,
        "",
    ], dict(zip(labels, kds, strict=True))
