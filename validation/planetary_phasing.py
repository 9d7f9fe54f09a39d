"""Planet phasing in the forced response of a simulated planetary drive (issue 19, deliverable 4).

Two variants of the planetary scene (three equally spaced planets, ring fixed), run steadily at rated
load through gearbody (Exudyn):

- in phase, z 12/15/42 (Z_r = 42 a multiple of N = 3, and Z_s = 12 too): every planet meshes alike;
- sequential, z 13/14/41 (Z_r = 41, Z_s = 13 not multiples of 3): planet n lags by n/3 of a mesh period.

Measured on the ring-fixed sensor (``ring_sensor_N``: the planets' ring-mesh forces through the Hann
planet-pass window) in carrier orders (the signal resampled over whole carrier revolutions relative to
the ring, so a line at (k Z_r + q) f_c falls on order k Z_r + q exactly): McFadden & Smith's rule, lines
only at orders k Z_r + q = 0 mod N. On the sun: Parker's planet-phasing rule, mesh harmonic l excites
rotational modes (the sun's torque sum_n F_sn r_bs fluctuates, the net force on it does not) when l Z_s / N
is an integer, translational ones (the net force in the carrier frame fluctuates, the torque does not)
when (l Z_s +- 1) / N is. ``python -m validation.planetary_phasing`` prints both tables (about 1 min).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

VARIANTS = {"in phase": (12, 15, 42), "sequential": (13, 14, 41)}
STEADY = [
    'operation.initial_state="steady"',
    "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
    "design.stages.1.sun_error_mode={a=0.5,e_um=0.0,r=0.0}",
    "design.stages.1.ring_error_mode={a=0.5,e_um=0.0,r=0.0}",
]
SETTLE_S = 0.04
"""Start-up transient left out before the carrier revolutions are analysed."""


def variant_scenario(teeth: tuple[int, int, int], revolutions: int = 2):
    """The planetary scene with other teeth (module 3 mm, pressure angle 24.6 deg: the radii change),
    no tooth errors (the lines come from the stiffness variation alone), long enough for ``revolutions``
    carrier revolutions after SETTLE_S."""
    from gearbody.model import load_scenario

    zs, _, zr = teeth
    members = [
        f"design.stages.1.{m}.teeth={z}" for m, z in zip(("sun", "planet", "ring"), teeth, strict=True)
    ]
    w_sun = load_scenario("planetary", members).design.motor.synchronous_speed_rad_s * 0.985  # ~steady slip
    f_c = w_sun * zs / (zs + zr) / (2 * math.pi)
    t_end = SETTLE_S + (revolutions + 0.3) / f_c
    return load_scenario("planetary", [*STEADY, *members, f"operation.t_end_s={t_end:.4f}"])


@dataclass
class PhasingResult:
    teeth: tuple[int, int, int]
    carrier_orders: np.ndarray  # orders of the ring-sensor spectrum (per carrier revolution)
    sensor_amplitude_N: np.ndarray
    mesh_frequency_hz: float
    carrier_hz: float
    torque_lines_Nm: dict[int, float]  # mesh harmonic l -> amplitude of the sun torque at l f_m
    force_lines_N: dict[int, float]  # l -> amplitude of the net force on the sun (carrier frame) at l f_m
    planet_lines_N: dict[int, float]  # l -> amplitude of one planet's sun-mesh force at l f_m
    sun_base_radius_m: float

    def torque_share(self, harmonic: int) -> float:
        """Sun torque at l f_m over N r_bs times one planet's line: 1 when the planets add in phase."""
        return self.torque_lines_Nm[harmonic] / (3 * self.sun_base_radius_m * self.planet_lines_N[harmonic])

    def force_share(self, harmonic: int) -> float:
        """Net sun force at l f_m over N times one planet's line (0 when the planets' forces cancel)."""
        return self.force_lines_N[harmonic] / (3 * self.planet_lines_N[harmonic])

    def sensor_at(self, order: int) -> float:
        return float(self.sensor_amplitude_N[int(np.argmin(np.abs(self.carrier_orders - order)))])


def _order_spectrum(signal: np.ndarray, angle_rad: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Amplitude spectrum over whole revolutions of ``angle_rad`` (orders per revolution)."""
    from gearbody.analysis.tsa import angle_resample

    a = angle_resample(signal, angle_rad, 2048)
    y = a.values.ravel()
    amp = np.abs(np.fft.rfft(y)) * 2.0 / y.size
    return np.arange(amp.size) / a.n_revs, amp


def run_variant(teeth: tuple[int, int, int], revolutions: int = 2) -> PhasingResult:
    """Simulate one variant and measure its ring-sensor order spectrum and the sun's Parker lines."""
    from gearbody import simulate

    sc = variant_scenario(teeth, revolutions)
    r = simulate(sc)
    keep = r.time_s >= SETTLE_S
    carrier = r["carrier_angle_rad"][keep] - r["ring_angle_rad"][keep]
    carrier = carrier - carrier[0]  # whole revolutions from the first analysed sample
    orders, amp = _order_spectrum(r["ring_sensor_N"][keep], carrier)
    st = sc.stages[0]
    g = st.geometry
    N = st.planets
    # the sun's torque and the net mesh force on it in the carrier frame, over mesh periods: resample on
    # the sun's angle relative to the carrier (Z_s mesh periods per relative revolution)
    rel = r["sun_angle_rad"][keep] - r["carrier_angle_rad"][keep]
    rel = rel - rel[0]
    torque = sum(r[f"planet_{n + 1}_sun_mesh_force_N"][keep] for n in range(N)) * g.sun_base_radius_m
    # net force on the sun from its planets = -(its bearing force on the housing) - m a; the bearing's
    # elastic force dominates at mesh frequencies below the sun's translational modes: use the sun's
    # displacement (x, y) turned into the carrier frame
    th = r["carrier_angle_rad"][keep]
    x, y = r["sun_x_m"][keep], r["sun_y_m"][keep]
    u = np.cos(th) * x + np.sin(th) * y
    orders_s, torque_amp = _order_spectrum(torque, rel)
    _, force_amp = _order_spectrum(u * st.sun.bearing_stiffness_N_per_m, rel)
    _, planet_amp = _order_spectrum(r["planet_1_sun_mesh_force_N"][keep], rel)
    lines = {}
    for l_ in (1, 2, 3):
        i = int(np.argmin(np.abs(orders_s - l_ * g.z_sun)))
        lines[l_] = (float(torque_amp[i]), float(force_amp[i]), float(planet_amp[i]))
    w = r["carrier_speed_rad_s"][keep].mean() / (2 * math.pi)
    return PhasingResult(
        teeth,
        orders,
        amp,
        float(np.mean(r["mesh_frequency_hz"][keep])),
        float(w),
        {k: v[0] for k, v in lines.items()},
        {k: v[1] for k, v in lines.items()},
        {k: v[2] for k, v in lines.items()},
        g.sun_base_radius_m,
    )


def line_table(res: PhasingResult, harmonics: int = 2, span: int = 4) -> str:
    """Markdown rows: ring-sensor amplitude at orders k Z_r + q, q = -span..span, and whether the
    McFadden-Smith rule lets each survive ((k Z_r + q) mod N == 0)."""
    zr, n = res.teeth[2], 3
    peak = max(res.sensor_at(k * zr + q) for k in range(1, harmonics + 1) for q in range(-span, span + 1))
    rows = [
        "| line k f_m + q f_c | order k Z_r + q | amplitude [N] | relative | rule |",
        "|---|---|---|---|---|",
    ]
    for k in range(1, harmonics + 1):
        for q in range(-span, span + 1):
            order = k * zr + q
            a = res.sensor_at(order)
            name = f"k = {k}, q = {q:+d}"  # the line k f_m + q f_c
            rule = "survives" if order % n == 0 else "cancelled"
            rows.append(f"| {name} | {order} | {a:.4g} | {a / peak:.3g} | {rule} |")
    return "\n".join(rows)


def parker_table(res: PhasingResult) -> str:
    zs, n = res.teeth[0], 3
    rows = [
        "| harmonic l | l Z_s mod N | rule | one planet's F_sn at l f_m [N] | sun torque [N m] (share) "
        "| net sun force, carrier frame [N] (share) |",
        "|---|---|---|---|---|---|",
    ]
    for l_ in sorted(res.torque_lines_Nm):
        m = l_ * zs % n
        rule = "rotational" if m == 0 else ("translational" if m in (1, n - 1) else "planet")
        rows.append(
            f"| {l_} | {m} | {rule} | {res.planet_lines_N[l_]:.4g} | {res.torque_lines_Nm[l_]:.4g} "
            f"({res.torque_share(l_):.3g}) | {res.force_lines_N[l_]:.4g} ({res.force_share(l_):.3g}) |"
        )
    return "\n".join(rows)


def main() -> None:
    for name, teeth in VARIANTS.items():
        res = run_variant(teeth)
        print(
            f"## {name}: z_s/z_p/z_r = {'/'.join(map(str, teeth))}, N = 3, "
            f"f_m = {res.mesh_frequency_hz:.1f} Hz, f_c = {res.carrier_hz:.3f} Hz\n"
        )
        print("Ring sensor (carrier orders):\n")
        print(line_table(res))
        print("\nSun (Parker's rule):\n")
        print(parker_table(res))
        print()


if __name__ == "__main__":
    main()
