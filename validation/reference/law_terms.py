"""The terms of the mesh law of ``docs/scenario.md``, each a literal transcription of one paragraph:
the random draw and the triangular error, run-out and pits, the smooth step of a transition width, the
stiffness profiles ("contact-ratio" / "iso-6336-b", "table", the "pairs" table of "potential-energy"),
the tooth factors, the friction law's regularised sign, envelope and transition speed, and the
reduced mass.  :mod:`.law` puts them together.

The ``scenario`` argument of these helpers is a mesh view (:func:`.scenario.stage_view`; a legacy
one-mesh scenario is its own view); ``mesh`` is a stage's ``mesh`` table.
"""

from __future__ import annotations

import math

import numpy as np

from .scenario import TWO_PI


def random_l(seed: int, z1: int, stage: int = 0) -> np.ndarray:
    """l = numpy.random.default_rng(seed).random(z1) for stage 0 (and every one-mesh scene),
    l = numpy.random.default_rng([seed, stage]).random(z1) for train stages >= 1."""
    if stage == 0:
        return np.random.default_rng(seed).random(z1)
    return np.random.default_rng([seed, stage]).random(z1)


def tooth_error_amplitudes(scenario: dict) -> np.ndarray:
    """e_i = [1 - r (1 - l[i])] e in metres, one per pinion tooth (train stage: meta.stage_index)."""
    em = scenario["production"]["error_mode"]
    z1 = int(scenario["design"]["pinion"]["teeth"])
    l_rand = random_l(int(scenario["meta"]["seed"]), z1, int(scenario["meta"].get("stage_index", 0)))
    return (1.0 - float(em["r"]) * (1.0 - l_rand)) * float(em["e_um"]) * 1e-6


def error_shape(p, a: float, e_i):
    """Triangular error E: e_i p / a for p < a, e_i (1 - p) / (1 - a) for p >= a."""
    p = np.asarray(p, dtype=float)
    e_i = np.asarray(e_i, dtype=float)
    rise = e_i * p / a if a > 0.0 else np.zeros(np.broadcast(p, e_i).shape)
    fall = e_i * (1.0 - p) / (1.0 - a) if a < 1.0 else np.zeros(np.broadcast(p, e_i).shape)
    return np.where(p < a, rise, fall)


def runout_terms(scenario: dict) -> list[tuple[float, float, int]]:
    """Run-out entries of the stage's eccentricity (mesh view: production.eccentricity; missing key:
    none) as (A, theta, z): A = amplitude_um * 1e-6, theta = radians(phase_deg) and z the teeth of that
    gear, so that each term is A sin(2 pi u / z + theta) (pinion: phi_p = 2 pi u / z1; wheel:
    phi_w* = 2 pi u / z2)."""
    teeth = {g: int(scenario["design"][g]["teeth"]) for g in ("pinion", "wheel")}
    out = []
    for entry in scenario.get("production", {}).get("eccentricity", []):
        if entry["gear"] not in teeth:
            raise ValueError(f"eccentricity: unknown gear {entry['gear']!r}")
        amp = float(entry["amplitude_um"]) * 1e-6
        out.append((amp, math.radians(float(entry["phase_deg"])), teeth[entry["gear"]]))
    return out


def runout_error(scenario: dict, u):
    """Run-out error + A_p sin(phi_p + theta_p) + A_w sin(phi_w* + theta_w) at the mesh coordinate u."""
    u = np.asarray(u, dtype=float)
    E = np.zeros(u.shape)
    for amp, theta, z in runout_terms(scenario):
        E = E + amp * np.sin(TWO_PI * u / z + theta)
    return E


def pitted_teeth(scenario: dict) -> list[tuple[str, int, float, float, float]]:
    """The stage's pitted_teeth (mesh view: condition.pitted_teeth; missing key: none) as
    (gear, tooth, depth in m, start_phase, end_phase)."""
    z = {g: int(scenario["design"][g]["teeth"]) for g in ("pinion", "wheel")}
    out = []
    for entry in scenario.get("condition", {}).get("pitted_teeth", []):
        gear, tooth = entry["gear"], int(entry["tooth"])
        lo, hi = float(entry["start_phase"]), float(entry["end_phase"])
        if gear not in z or not 0 <= tooth < z[gear]:
            raise ValueError(f"pitted tooth {tooth} of gear {gear!r} does not exist")
        if not 0.0 <= lo < hi <= 1.0:
            raise ValueError(f"pit phases need 0 <= start_phase < end_phase <= 1, got {lo}, {hi}")
        out.append((gear, tooth, float(entry["depth_um"]) * 1e-6, lo, hi))
    return out


def pit_error(scenario: dict, p, i, j):
    """Pitting error of the pair (pinion tooth i, wheel tooth j) at phase p: - depth while the pitted
    tooth is in mesh and start_phase <= p < end_phase; pits on both teeth of a pair add.

    With a transition width w > 0 the edges are smoothed, - depth [S((p - start)/w) - S((p - end)/w)]
    (p may then lie outside [0, 1): the pair's pit function at the phase it is evaluated at).
    """
    p = np.asarray(p, dtype=float)
    w = transition_width(scenario["design"]["mesh"])
    E = np.zeros(np.broadcast(p, i, j).shape)
    for gear, tooth, depth, lo, hi in pitted_teeth(scenario):
        in_mesh = (np.asarray(i) if gear == "pinion" else np.asarray(j)) == tooth
        if w > 0.0:
            E = E - np.where(in_mesh, depth * (smooth_step((p - lo) / w) - smooth_step((p - hi) / w)), 0.0)
        else:
            E = E - np.where(in_mesh & (lo <= p) & (p < hi), depth, 0.0)
    return E


def smooth_step(x):
    """C2 smooth step: S(x) = 0 for x <= -1/2, 1 for x >= 1/2, u^3 (10 - 15 u + 6 u^2), u = x + 1/2."""
    u = np.clip(np.asarray(x, dtype=float) + 0.5, 0.0, 1.0)
    return u * u * u * (10.0 - 15.0 * u + 6.0 * u * u)


def transition_width(mesh: dict) -> float:
    """design.mesh.transition_width (a stage's mesh in a train); absent key: 0 (the sharp law)."""
    w = float(mesh.get("transition_width", 0.0))
    if not 0.0 <= w <= 0.1:
        raise ValueError(f"transition_width must lie in [0, 0.1], got {w}")
    return w


def check_transition_width(scenario: dict) -> float:
    """The transition width w of a mesh view, with the limits of the spec checked:
    w <= min(2h, 1 - 2h) (every law but "table": the ramps at h and 1 - h), w/2 <= pitch_point_phase
    <= 1 - w/2 (unless 0 or 1), every pit at least w wide."""
    mesh = scenario["design"]["mesh"]
    w = transition_width(mesh)
    if w == 0.0:
        return w
    tol = 1e-12
    if mesh_law(mesh) != "table":
        h = half_double(mesh)
        if h > 0.0 and w > min(2.0 * h, 1.0 - 2.0 * h) + tol:
            raise ValueError(f"transition_width {w} exceeds min(2h, 1 - 2h) = {min(2 * h, 1 - 2 * h)}")
    ppp = float(mesh["pitch_point_phase"])
    if 0.0 < ppp < 1.0 and not w / 2 - tol <= ppp <= 1.0 - w / 2 + tol:
        raise ValueError(f"pitch_point_phase {ppp} must lie in [w/2, 1 - w/2] for transition_width {w}")
    for gear, tooth, _depth, lo, hi in pitted_teeth(scenario):
        if hi - lo < w - tol:
            raise ValueError(f"pit on {gear} tooth {tooth} is narrower than transition_width {w}")
    return w


def error_shape_ext(q, a: float, e_i):
    """Triangular shape extended by its straight lines outside [0, 1): the rising line e_i q / a where
    it applies (q < a; for a = 1 also above 1), the falling line e_i (1 - q) / (1 - a) otherwise (q >= a;
    for a = 0 also below 0).  Equal to :func:`error_shape` on [0, 1)."""
    q = np.asarray(q, dtype=float)
    e_i = np.asarray(e_i, dtype=float)
    shape = np.broadcast(q, e_i).shape
    rise = e_i * q / a if a > 0.0 else np.zeros(shape)
    fall = e_i * (1.0 - q) / (1.0 - a) if a < 1.0 else np.zeros(shape)
    use_rise = (q < a) & (a > 0.0) if a < 1.0 else np.ones(shape, dtype=bool)
    return np.where(use_rise, rise, fall)


FRICTION_TRANSITION_SPEED_M_S = 1e-3  # v_0 when condition.friction_transition_speed_m_s is absent
FRICTION_TRANSITION_SPEED_RANGE_M_S = (1e-6, 1.0)


def friction_transition_speed(scenario: dict) -> float:
    """v_0 = condition.friction_transition_speed_m_s (absent key: 1e-3 m/s, as gearbody), checked against
    1e-6 .. 1 m/s."""
    v0 = float(scenario["condition"].get("friction_transition_speed_m_s", FRICTION_TRANSITION_SPEED_M_S))
    lo, hi = FRICTION_TRANSITION_SPEED_RANGE_M_S
    if not lo <= v0 <= hi:
        raise ValueError(f"condition.friction_transition_speed_m_s = {v0} m/s: allowed {lo} to {hi} m/s")
    return v0


def friction_sigma(x):
    """Regularised sign of the friction direction, sigma(x) = 2 S(x / 2) - 1 (x = v_sl / v_0): -1 for
    x <= -1, +1 for x >= 1, odd, sigma(0) = 0, slope 1.875 at 0."""
    return 2.0 * smooth_step(0.5 * np.asarray(x, dtype=float)) - 1.0


def friction_envelope(p, w: float = 0.0):
    """Tooth-change envelope of the friction magnitude, e(p) = (2 S(p/w) - 1)(1 - 2 S((p - 1)/w)) on
    [0, 1) (0 at the tooth change, 1 from w/2 after it to w/2 before the next); 1 for w = 0."""
    p = np.asarray(p, dtype=float)
    if w <= 0.0:
        return np.ones(p.shape)
    return (2.0 * smooth_step(p / w) - 1.0) * (1.0 - 2.0 * smooth_step((p - 1.0) / w))


def mesh_law(mesh: dict) -> str:
    """The law behind design.mesh.stiffness_profile: "contact-ratio" (also "iso-6336-b": its resolved
    mesh carries stiffness_single / stiffness_double / contact_ratio, and the law is the same), "table",
    or "pairs" ("potential-energy": the sum of the pairs in contact, "Pair stiffness table")."""
    prof = mesh["stiffness_profile"]
    law = {"contact-ratio": "contact-ratio", "iso-6336-b": "contact-ratio", "table": "table"}.get(prof)
    if law is None and prof == "potential-energy":
        law = "pairs"
    if law is None:
        raise ValueError(f"unknown stiffness_profile {prof!r}")
    return law


def half_double(mesh: dict) -> float:
    """h = (contact_ratio - 1) / 2."""
    return (float(mesh["contact_ratio"]) - 1.0) / 2.0


def pair_table(mesh: dict) -> tuple[np.ndarray, np.ndarray, dict[tuple[str, int], np.ndarray]]:
    """design.mesh.pair_table of a "pairs" mesh as (grid q_m = -h + m (1 + 2h)/(N - 1), healthy pair
    stiffness K_m, {(gear, tooth): ratio R_m}); a tooth listed twice gets the product of its ratios."""
    tab = mesh.get("pair_table")
    if tab is None:
        raise ValueError(
            "a potential-energy mesh needs design.mesh.pair_table (see validation.compare.reference_input)"
        )
    K = np.asarray(tab["stiffness_N_per_m"], dtype=float).ravel()
    N = K.size
    if N < 2:
        raise ValueError("the pair stiffness table needs at least 2 points")
    h = half_double(mesh)
    grid = -h + np.arange(N) * ((1.0 + 2.0 * h) / (N - 1))
    ratios: dict[tuple[str, int], np.ndarray] = {}
    for entry in tab.get("ratios", []):
        gear, tooth = entry["gear"], int(entry["tooth"])
        if gear not in ("pinion", "wheel"):
            raise ValueError(f"pair_table ratio for unknown gear {gear!r}")
        R = np.asarray(entry["ratio"], dtype=float).ravel()
        if R.size != N:
            raise ValueError(f"ratio table of {gear} tooth {tooth} has {R.size} points, the pair table {N}")
        ratios[(gear, tooth)] = ratios[(gear, tooth)] * R if (gear, tooth) in ratios else R
    return grid, K, ratios


def contact_weight(q, h: float, w: float = 0.0):
    """Contact weight of a pair at its own phase q: 1 for -h <= q < 1 + h, else 0;
    with a transition width w > 0: S((q + h)/w) [1 - S((q - 1 - h)/w)]."""
    q = np.asarray(q, dtype=float)
    if w > 0.0:
        return smooth_step((q + h) / w) * (1.0 - smooth_step((q - 1.0 - h) / w))
    return np.where((-h <= q) & (q < 1.0 + h), 1.0, 0.0)


def base_stiffness(p, mesh: dict):
    """k_z(p) of healthy teeth: "contact-ratio" (and "iso-6336-b"), "table", or the "pairs" sum
    sum_o c(p - o) K(p - o) over o = -1, 0, +1."""
    p = np.asarray(p, dtype=float)
    law = mesh_law(mesh)
    if law == "contact-ratio":
        h = half_double(mesh)
        k_double = float(mesh["stiffness_double_N_per_m"])
        w = transition_width(mesh)
        if w > 0.0:  # k_s + (k_d - k_s) [1 - S((p - h)/w) + S((p - 1 + h)/w)]
            k_single = float(mesh["stiffness_single_N_per_m"])
            ramp = 1.0 - smooth_step((p - h) / w) + smooth_step((p - 1.0 + h) / w)
            return k_single + (k_double - k_single) * ramp
        double = (p < h) | (p >= 1.0 - h)
        return np.where(double, k_double, float(mesh["stiffness_single_N_per_m"]))
    if law == "pairs":
        grid, K, _ = pair_table(mesh)
        h, w = half_double(mesh), transition_width(mesh)
        return sum(contact_weight(p - o, h, w) * np.interp(p - o, grid, K) for o in (-1, 0, 1))
    ph = np.asarray(mesh["table_phase"], dtype=float)
    kk = np.asarray(mesh["table_stiffness_N_per_m"], dtype=float)
    if ph.size == 0 or ph.size != kk.size:
        raise ValueError("table stiffness profile needs equally long, non-empty tables")
    return np.interp(p, ph, kk, period=1.0)


def tooth_factors(scenario: dict) -> tuple[np.ndarray, np.ndarray]:
    """f (pinion, z1 values) and g (wheel, z2 values); 1 unless listed in the stage's damaged_teeth
    (mesh view: condition.damaged_teeth).

    A tooth listed more than once gets the product of its factors (assumption, see report).
    """
    z1 = int(scenario["design"]["pinion"]["teeth"])
    z2 = int(scenario["design"]["wheel"]["teeth"])
    f = np.ones(z1)
    g = np.ones(z2)
    for entry in scenario["condition"].get("damaged_teeth", []):
        arr = {"pinion": f, "wheel": g}[entry["gear"]]
        tooth = int(entry["tooth"])
        if not 0 <= tooth < arr.size:
            raise ValueError(f"damaged tooth index {tooth} out of range for the {entry['gear']}")
        arr[tooth] *= float(entry.get("stiffness_factor", 1.0))  # default 1 (crack keys alone)
    return f, g


def reduced_mass(scenario: dict) -> float:
    """m = 1 / (r1^2 / I_1p + r2^2 / I_2p)."""
    d = scenario["design"]
    r1, r2 = float(d["pinion"]["base_radius_m"]), float(d["wheel"]["base_radius_m"])
    i1, i2 = float(d["pinion"]["inertia_kg_m2"]), float(d["wheel"]["inertia_kg_m2"])
    return 1.0 / (r1 * r1 / i1 + r2 * r2 / i2)
