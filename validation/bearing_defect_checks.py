"""Issue 30's checks of simulated bearing defects against theory, measured and printed as one table (the
tests in tests/test_bearing_defect_theory.py assert them):

    python -m gearbody_validation.bearing_defect_checks

lateral-8dof-ball on ball-by-ball bearings (:data:`validation.compare.BEARING_DEFECT`'s parameters),
steady at rated load for 1 s, a 20 um defect in the pinion's bearing (SKF 6308 geometry: 8 balls,
d/D = 0.232), seen by a housing accelerometer with one mode (5 kHz, 2 % damping) on the pinion's
bearing forces and 0.3 m/s^2 of seeded noise (it buries the impacts where the mode does not amplify
them); the first 0.1 s left out. Each row: the line theory predicts from the run's mean pinion speed,
the largest bin of the squared-envelope spectrum (in the kurtogram's band) within the slip band round
it, its distance and its height over the spectrum's median.
"""

from __future__ import annotations

import functools

import numpy as np

SLIP = 0.015  # the cage slip of BEARING_DEFECT's bearings
MODE_HZ, ZETA = 5000.0, 0.02
NOISE_M_S2 = 0.3  # rms: above the mode's mass line, where the impacts would pass unamplified
SETTLE_S = 0.1  # the start, before the run is steady, is left out
T_END_S = 1.0
DEFECTS = {
    "outer": '[{race="outer",depth_m=%g,width_deg=6.0,angle_deg=90.0}]',
    "inner": '[{race="inner",depth_m=%g,width_deg=6.0,angle_deg=0.0}]',
    "ball": '[{race="ball",depth_m=%g,width_deg=20.0,angle_deg=0.0,ball=0}]',
}


def overrides(kind: str | None, depth_m: float = 20e-6, seed: int = 7, t_end_s: float = T_END_S) -> list[str]:
    """lateral-8dof-ball's overrides: ball-by-ball bearings, steady rated, a pinion bearing defect."""
    from .compare import BEARING_DEFECT

    keep = [
        o
        for o in BEARING_DEFECT["lateral-8dof-ball"]
        if ".defects=" not in o and "pinion.bearing.param" not in o
    ]
    out = [
        *keep,
        "design.stages.1.pinion.bearing.parameters={ball_stiffness_N_per_m_n=5.5e10,radial_clearance_m=5e-6,"
        f"damping_Ns_per_m=2000.0,cage_slip={SLIP},slip_seed={seed}}}",
        'operation.initial_state="steady"',
        "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
        "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
        f"operation.t_end_s={t_end_s}",
    ]
    if kind:
        out.append(f"design.stages.1.pinion.bearing.defects={DEFECTS[kind] % depth_m}")
    return out


@functools.cache
def run(kind: str | None, depth_m: float = 20e-6, seed: int = 7, t_end_s: float = T_END_S):
    """The simulated run (cached: the tests and the table share it)."""
    from gearbody.engine import simulate
    from gearbody.model import load_scenario

    return simulate(load_scenario("lateral-8dof-ball", overrides(kind, depth_m, seed, t_end_s)))


def recording(result, mode_hz: float = MODE_HZ, seed: int = 1):
    """The housing accelerometer ``pinion_housing`` and a 1-pulse tacho on the pinion."""
    from gearbody.recording.instruments import Accelerometer, HousingMode, virtual_instruments

    forces = {"pinion_bearing_force_y_N": 1e-3, "pinion_bearing_force_x_N": 5e-4}
    acc = Accelerometer("pinion_housing", [HousingMode(mode_hz, ZETA, forces)], noise_rms_m_s2=NOISE_M_S2)
    return virtual_instruments(result, [acc], tacho_shaft="pinion", pulses_per_rev=1, seed=seed)


def envelope(kind: str | None, depth_m: float = 20e-6, mode_hz: float = MODE_HZ):
    """(kurtogram, squared-envelope spectrum up to 400 Hz in its band) of the accelerometer."""
    from gearbody.analysis.envelope import envelope_spectrum
    from gearbody.analysis.kurtogram import fast_kurtogram

    rec = recording(run(kind, depth_m), mode_hz)
    fs = rec.sample_rate_hz
    x = rec["pinion_housing"][int(SETTLE_S * fs) :]
    kurt = fast_kurtogram(x, fs, max_level=6)
    return kurt, envelope_spectrum(x, fs, band_hz=kurt.band_hz, max_frequency_hz=400.0)


def lines(result):
    """BPFO, BPFI, BSF, FTF of the pinion's bearing at the run's mean pinion speed."""
    from gearbody.analysis.bearing_lines import BearingGeometry, bearing_frequencies

    f_r = float(np.mean(result["pinion_speed_rad_s"])) / (2 * np.pi)
    return bearing_frequencies(BearingGeometry(8, 0.015081, 0.065, 0.0), f_r)


def peak(env, f_hz: float, half_width_hz: float) -> tuple[float, float]:
    """(frequency, amplitude) of the envelope's largest bin within f +- half width."""
    sel = np.flatnonzero(np.abs(env.frequency_hz - f_hz) <= half_width_hz)
    i = sel[np.argmax(env.amplitude[sel])]
    return float(env.frequency_hz[i]), float(env.amplitude[i])


def within_slip(env, f_hz: float) -> tuple[float, float]:
    """Peak within the slip band f (1 +- slip), widened by one bin either side."""
    return peak(env, f_hz, SLIP * f_hz + env.resolution_hz)


def floor(env, f_max_hz: float = 400.0) -> float:
    """Median amplitude of the envelope spectrum up to f_max (its noise floor)."""
    return float(np.median(env.amplitude[(env.frequency_hz > 2.0) & (env.frequency_hz < f_max_hz)]))


def rows() -> list[tuple[str, float, float, float, float]]:
    """(line, theory Hz, measured Hz, |difference| Hz, height over the floor)."""
    out = []
    for kind, wanted in (
        ("outer", lambda L: [(f"{k} x BPFO", k * L.bpfo_hz) for k in (1, 2, 3, 4)]),
        (
            "inner",
            lambda L: [
                ("BPFI", L.bpfi_hz),
                ("BPFI - f_r", L.bpfi_hz - L.shaft_hz),
                ("BPFI + f_r", L.bpfi_hz + L.shaft_hz),
                ("f_r", L.shaft_hz),
            ],
        ),
        (
            "ball",
            lambda L: [
                ("2 x BSF", 2 * L.bsf_hz),
                ("2 BSF - FTF", 2 * L.bsf_hz - L.ftf_hz),
                ("2 BSF + FTF", 2 * L.bsf_hz + L.ftf_hz),
                ("FTF", L.ftf_hz),
            ],
        ),
    ):
        _, env = envelope(kind)
        base = floor(env)
        for name, f in wanted(lines(run(kind))):
            got, a = within_slip(env, f)
            out.append(
                (
                    f"{kind}-race defect: {name}" if kind != "ball" else f"ball defect: {name}",
                    f,
                    got,
                    abs(got - f),
                    a / base,
                )
            )
    return out


def main() -> None:
    print(f"{'line':38s} {'theory Hz':>10s} {'measured Hz':>12s} {'|diff| Hz':>10s} {'x floor':>8s}")
    for name, f, got, diff, height in rows():
        print(f"{name:38s} {f:10.3f} {got:12.3f} {diff:10.3f} {height:8.1f}")
    _, env = envelope("outer")
    print(f"(bins {env.resolution_hz:.3f} Hz apart; slip band +-{100 * SLIP:g} %)")
    for mode in (MODE_HZ, 6500.0):
        kurt, _ = envelope("outer", mode_hz=mode)
        lo, hi = kurt.band_hz
        print(
            f"kurtogram band with a {mode:g} Hz housing mode: {lo:.0f} .. {hi:.0f} Hz "
            f"(kurtosis {kurt.max_kurtosis:.1f})"
        )


if __name__ == "__main__":
    main()
