"""Figs. 13-16: spectra for one tooth at 0.8, 0.6, 0.2 and 0.0 k_z.

System: the shipped `one-stage` scene, steady rated running, E(0.5, 10, 0) (r = 0, so that the healthy
gear excites only the mesh harmonics), pinion tooth 5 with its stiffness factor lowered. Signal: the
pinion's angular acceleration (band-limited like a measured signal), 1 s record, Hann window.
Claims (paper, p. 12): the wideband content grows with the severity of the fracture, and its lines are
spaced at the shaft frequency.

Second series (issue 7): the same cases stated as tooth damage on `one-stage-geometry` (potential-energy
mesh stiffness, the damaged tooth's pair weakened over its whole contact): a 6 mm root crack in place of
0.8 k_z, 40 % / 80 % of the face width broken off for 0.6 / 0.2, the whole tooth broken off for 0.0
(validation/paper/faults.py, GEOMETRIC_DAMAGE).

    python -m gearbody_validation.paper.figs_13_16
"""

from __future__ import annotations

import numpy as np

from gearbody.analysis import amplitude_spectrum
from gearbody.engine import SimulationError
from gearbody.plotting import new_figure, save_figure

from .common import Claim, Timer, parser, results_dir, start, write_results
from .faults import GEOMETRIC_DAMAGE, damaged_tooth_run, tooth_run

FACTORS = (None, 0.8, 0.6, 0.2, 0.0)
RECORD_S = 1.0
SIGNAL = "pinion_accel_rad_s2"


def non_mesh_rms(spectrum, f_z: float, f_max: float, half_width_hz: float = 3.0) -> float:
    """RMS of the spectrum's lines away from the mesh harmonics k f_z (|f - k f_z| > half_width_hz)."""
    f, a = spectrum.frequency_hz, spectrum.amplitude
    k = np.round(f / f_z)
    keep = (np.abs(f - k * f_z) > half_width_hz) & (f > 5.0) & (f < f_max)
    return float(np.sqrt(0.5 * np.sum(a[keep] ** 2) / 1.5))  # Hann: sum over bins / ENBW 1.5


def shaft_order_share(spectrum, f_shaft: float, f_z: float, f_max: float, top: int = 40) -> float:
    """Share of the `top` strongest non-mesh peaks that sit within one bin of a multiple of f_shaft."""
    f, a = spectrum.frequency_hz, spectrum.amplitude
    df = spectrum.resolution_hz
    is_peak = (a[1:-1] > a[:-2]) & (a[1:-1] >= a[2:])
    idx = np.flatnonzero(is_peak) + 1
    idx = idx[(f[idx] > 5.0) & (f[idx] < f_max) & (np.abs(f[idx] - np.round(f[idx] / f_z) * f_z) > 3.0)]
    idx = idx[np.argsort(a[idx])[::-1][:top]]
    off = np.abs(f[idx] - np.round(f[idx] / f_shaft) * f_shaft)
    return float(np.mean(off <= 1.01 * df)) if idx.size else 0.0


def run_series(runs: dict) -> tuple[dict, dict, dict, dict, dict]:
    """Spectra, wideband RMS, shaft-order share, (f_z, f_pinion) and failures of labelled runs."""
    spectra, wideband, share, lines, failed = {}, {}, {}, {}, {}
    for label, run in runs.items():
        try:
            res, window = run()
        except SimulationError as exc:
            failed[label] = str(exc)
            print(label, "failed:", exc)
            continue
        sp = amplitude_spectrum(res[SIGNAL][window], res.sample_rate_hz, window="hann")
        f_z = float(np.mean(res["mesh_frequency_hz"][window]))
        f_p = float(np.mean(res["pinion_speed_rad_s"][window])) / (2 * np.pi)
        f_max = 4.5 * f_z
        spectra[label] = sp
        wideband[label] = non_mesh_rms(sp, f_z, f_max)
        share[label] = shaft_order_share(sp, f_p, f_z, f_max)
        lines[label] = (f_z, f_p)
        print(label, f"wideband {wideband[label]:.3g} rad/s^2, shaft-order share {share[label]:.2f}")
    return spectra, wideband, share, lines, failed


def _plot(spectra: dict, wideband: dict, lines: dict, path):
    fig = new_figure((1000, 1100), 100)
    for n, (label, sp) in enumerate(spectra.items()):
        ax = fig.add_subplot(len(spectra), 1, n + 1)
        keep = sp.frequency_hz <= 4.5 * lines[label][0]
        ax.semilogy(sp.frequency_hz[keep], sp.amplitude[keep], lw=0.6)
        ax.set_title(f"tooth: {label}: wideband RMS {wideband[label]:.3g} rad/s^2", fontsize=9)
        ax.set_ylabel("rad/s^2", fontsize=8)
        ax.set_ylim(bottom=1e-2)
    ax.set_xlabel("frequency [Hz]")
    return save_figure(fig, path, 100)


def _claims(series: str, wideband: dict, share: dict, lines: dict, failed: dict) -> list:
    damaged = [k for k in wideband if k != "healthy"]
    values = [wideband[k] for k in damaged]
    f_z, f_p = lines[damaged[-1]]
    claims = [
        Claim(
            "13-16",
            f"{series}: wideband content grows with the tooth fracture " + " -> ".join(damaged),
            " / ".join(f"{v:.3g}" for v in values) + f" rad/s^2 (healthy {wideband['healthy']:.3g})",
            all(b > a for a, b in zip(values, values[1:], strict=False)) and values[0] > wideband["healthy"],
        ),
        Claim(
            "13-16",
            f"{series}: its lines are spaced at the shaft frequency (pinion, the damaged gear)",
            "share of the 40 strongest non-mesh peaks on multiples of f_pinion = "
            + " / ".join(f"{share[k]:.2f}" for k in damaged)
            + f" (f_pinion {f_p:.2f} Hz)",
            min(share[k] for k in damaged) >= 0.9,
        ),
    ]
    for label, message in failed.items():
        claims.append(
            Claim(
                "13-16",
                f"{series}: the {label} case runs",
                "simulation failed: " + message,
                False,
                "the pinion chatters across the edge of the missing tooth",
            )
        )
    return claims


def main() -> None:
    with Timer() as timer:
        factor_runs = {
            ("healthy" if f is None else f"{f:.1f} k_z"): (lambda f=f: tooth_run(f, RECORD_S))
            for f in FACTORS
        }
        geometry_runs = {"healthy": lambda: damaged_tooth_run(None, RECORD_S)}
        for label, damage in GEOMETRIC_DAMAGE.items():
            geometry_runs[label] = lambda d=damage: damaged_tooth_run(d, RECORD_S)
        spectra, wideband, share, lines, failed = run_series(factor_runs)
        g_spectra, g_wideband, g_share, g_lines, g_failed = run_series(geometry_runs)
    results_dir().mkdir(parents=True, exist_ok=True)
    figs = [
        _plot(spectra, wideband, lines, results_dir() / "figs_13_16_spectra.png"),
        _plot(g_spectra, g_wideband, g_lines, results_dir() / "figs_13_16_geometry_spectra.png"),
    ]
    claims = _claims("factors (one-stage)", wideband, share, lines, failed)
    claims += _claims("damage by geometry (one-stage-geometry)", g_wideband, g_share, g_lines, g_failed)
    f_z = lines["healthy"][0]
    notes = [
        f"Signal {SIGNAL}, {RECORD_S} s after 0.1 s settling, Hann window "
        f"({spectra['healthy'].resolution_hz:.2f} Hz bins), band 5 Hz - 4.5 f_z; mesh harmonics "
        f"excluded +-3 Hz. f_z = {f_z:.1f} Hz.",
        "Wideband RMS: sqrt(sum of a^2 / 2 / 1.5) over the non-mesh bins (1.5: Hann noise bandwidth).",
        "Factors: the period's total k_z times the factor while the tooth is the period's tooth (the "
        "paper's lumped model). Geometry: the damaged tooth's pair stiffness over its whole contact "
        "(eps_alpha = 1.742 mesh periods), from the potential-energy method; the mean pair stiffness "
        "ratios are 0.77 (6 mm crack), 0.6, 0.2 and 0.",
    ]
    write_results("figs_13_16", "Figs. 13-16: spectra with one tooth weakened", claims, notes, figs, timer.s)


if __name__ == "__main__":
    start("figs_13_16", parser(__doc__).parse_args())
    main()
