"""Independent reference model for the gearbody scenes ``muller``, ``two-wheel``, ``one-stage`` and
``train`` (a chain of N >= 1 stages, section "Gear trains" of ``docs/scenario.md``).

Written directly from ``docs/scenario.md`` (the contract) as a first-order ODE system and integrated
with :func:`scipy.integrate.solve_ivp`.  It deliberately shares no code with ``gearbody``.

Discontinuities
---------------
The mesh stiffness, the per-tooth factors, the error branch, the friction sign and (with backlash)
the contact state all change discontinuously with the pinion angle / mesh deflection.  Plain
adaptive stepping across such jumps is first order and slow, so the integration is done segment by
segment in *locked modes*:

* phase mode ``(n, k)``: the pinion mesh coordinate ``u = phi_p z1 / (2 pi)`` lies in
  ``[n + b_k, n + b_{k+1})`` where ``b`` are all phase break points in one mesh period (0, h, 1-h,
  pitch_point_phase, error apex ``a``, table points, pair-table grid points, pit edges).  Inside such
  an interval every mesh quantity is a polynomial function of ``p = u - n`` (at most linear, except
  the "pairs" stiffness, a product of linear pieces, and the smooth steps of a transition width), plus
  the smooth run-out term, and is evaluated from that formula, so the right-hand side is smooth, also
  a little beyond the interval ends during trial steps;
* contact mode ``c`` in {+1 flank contact, 0 separated, -1 back-flank contact}; only used when the
  backlash ``l_u > 0`` (with ``l_u = 0`` the spring law ``k d`` is linear and damping is on for all
  ``d != 0``, so there is nothing to switch).

``solve_ivp`` stops exactly at each mode boundary (terminal ``events``), the mode is switched and
the integration restarts from the event state.  The event functions carry a tiny hysteresis (1e-10
of a mesh period, 1e-15 m of deflection) so that a state resting exactly on a boundary (e.g. a gear
at standstill at u = 0) cannot trigger an endless chain of zero-length segments.  The time break
points of the speed and load profiles are also segment boundaries.

Fault errors
------------
The run-out ``A_p sin(phi_p + theta_p) + A_w sin(2 pi u / z2 + theta_w)`` (production.eccentricity) and
the pits ``- depth`` (condition.pitted_teeth, while the pitted tooth is in mesh and
``start_phase <= p < end_phase``) are added to the error E, which enters ``d = delta + E`` only (contact
events, elastic force, initial deflection), never the damping rate ``delta_dot``.  The pit edges are
phase break points, so within a locked mode the pit depth is a constant of the mode
(:class:`_ModeConsts`); the run-out is smooth in ``u`` and is evaluated as ``sin(2 pi (n + p) / z +
theta)`` by :func:`_mode_error`, the one place where a locked mode forms E (right-hand sides, contact
events, outputs, contact re-classification).  The literal helpers :func:`runout_error`,
:func:`pit_error` and :func:`total_error` transcribe the same paragraph for the self-checks and the
initial states.  Missing keys (older resolved scenarios) mean no fault.

Transition width
----------------
With ``design.mesh.transition_width = w > 0`` (a stage's own mesh in a train; missing key: 0) every
jump of the law at fixed deflection is spread over ``|p - p_jump| < w/2`` with the C2 smooth step
``S`` (:func:`smooth_step`): contact-ratio stiffness ramps at h and 1 - h, the tooth factor and the
whole error blended with the outgoing pair (at phase p + 1) for p < w/2 and with the incoming pair (at
p - 1) for p > 1 - w/2 (the triangle extended by its straight lines, :func:`error_shape_ext`), smoothed
pit edges and a smoothed friction sign (:func:`friction_sign`); the damping uses the blended factor
("pairs": the contact weights of the outgoing and incoming pairs ramp at h and 1 - h instead of k_z, the
factor is not blended, each pair carries its own, and the damping keeps k / k_healthy).
The literal transcription is :func:`blended_law` / :func:`mesh_force_literal` /
:func:`friction_moments`.  For the segmented integration the break points become the ramp ends
``p_jump -+ w/2`` (modulo 1), plus the kinks (p = 0 where the friction arms jump, the apex a, table
and pair-table grid points); inside each interval every smooth step is then 0, 1 or its quintic, and
the locked mode carries that polynomial form (:class:`_SmoothMode`, :class:`_PairMode`), so the
right-hand side is again smooth within a segment.  With w = 0 nothing of this is used: the sharp code
path is unchanged.

The mesh force at the output times is evaluated from the (dense-output) states at those times with
the very same function (``_mesh_force``) that the right-hand side uses, in the mode that was active
when the sample time was reached.

Stiffness profiles
------------------
"contact-ratio" and "table" as in the contract; "iso-6336-b" is the "contact-ratio" law (its resolved
mesh carries stiffness_single / stiffness_double / contact_ratio) everywhere, limits included
(:func:`mesh_law`).  "potential-energy" is the "pairs" law (docs/scenario.md, "Pair stiffness table"):
the pair table ``design.mesh.pair_table`` (added to the resolved dict by
``validation.compare.reference_input``; :func:`pair_table`) holds the healthy pair stiffness K_m and the
damaged teeth's ratios R_m on the grid ``q_m = -h + m (1 + 2h)/(N - 1)``, and
``k = sum_{o=-1,0,1} c(p - o) K f_io g_jo R_pinion,io R_wheel,jo`` (tables at the pair's own phase
``q = p - o``, teeth ``(i + o, j + o)``), so a factor or a ratio acts on its tooth's pair over the whole
contact; the damping is ``C_z k / k_healthy``; error, friction and their blending are unchanged.  Literal
transcription: :func:`contact_weight`, :func:`pair_stiffness`, :func:`effective_stiffness`.  For the
segmented integration every grid point is a break point (``p = q_m + o`` modulo 1, ~N per period), so
each pair's tables are linear pieces in a mode (:class:`_PairMode`).  Why (measured on
one-stage-geometry, N = 81, the short validation cases steady / separation / run-up, errors against the
same model at rtol 1e-12): leaving the grid kinks inside the segments (tables interpolated in the
right-hand side) takes 1.8 / 4.4 / 6.5 s but DOP853's error estimate does not see the kinks: 3.6e-3 /
4.0e-2 / 6.7e-4 % of F_rated (RK45's does: 1e-4 / 2.4e-3 / 9e-5 % at rtol 1e-10, 9e-5 % in the separation
case only at rtol 1e-12, 7.5 s); with the break points 1e-4 / 1.2e-5 / 4.6e-4 % in 3.8 / 17 / 5.8 s.  The
price is one segment per grid interval: at the separation case's mesh frequency (2.8 kHz) 9x the time
of the same gears with the "iso-6336-b" law (5 break points), 2-4x at rated speed.

Gear trains
-----------
Each stage's mesh is a :class:`_Mesh` built from the one-stage-shaped :func:`stage_view` of that
stage (its own pinion/wheel, stiffness profile, damping, backlash, error mode with its own random
draw, damaged teeth, run-out and pits, and the rated torque referred to its wheel), so the helpers
above serve trains unchanged.  Every mesh has its own locked mode ``(n_s, k_s, c_s)``; a segment of
the integration is locked in all of them at once and ends at the first boundary event of *any* mesh
(the events of all meshes are passed to ``solve_ivp`` together, and the sub-step scan covers all of
them).  For N = 1 the train right-hand side performs the same floating-point operations as the
one-stage scene.
"""

from __future__ import annotations

import math
from typing import NamedTuple

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover
    import tomli as tomllib

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

__all__ = [
    "load_scenario",
    "simulate_reference",
    "F_rated",
    "profile_value",
    "profile_integral",
    "kloss_torque",
    "steady_slip",
    "random_l",
    "tooth_error_amplitudes",
    "error_shape",
    "runout_terms",
    "runout_error",
    "pitted_teeth",
    "pit_error",
    "total_error",
    "smooth_step",
    "transition_width",
    "check_transition_width",
    "error_shape_ext",
    "pair_law",
    "blended_law",
    "friction_sign",
    "base_stiffness",
    "mesh_law",
    "half_double",
    "pair_table",
    "contact_weight",
    "pair_stiffness",
    "effective_stiffness",
    "tooth_factors",
    "reduced_mass",
    "mesh_force_literal",
    "friction_moments",
    "initial_state",
    "phase_breakpoints",
    "is_train",
    "train_stages",
    "stage_F_rated",
    "stage_view",
]

TWO_PI = 2.0 * math.pi
_ETA_U = 1e-10  # event hysteresis in mesh periods
_ETA_D = 1e-15  # event hysteresis in metres of mesh deflection
_MAX_ZERO_SEGMENTS = 1000


# ----------------------------------------------------------------------------------------------
# Scenario helpers (each is a literal transcription of one sentence of docs/scenario.md)
# ----------------------------------------------------------------------------------------------
def load_scenario(path) -> dict:
    """Read a (resolved) scenario TOML file."""
    with open(path, "rb") as fh:
        return tomllib.load(fh)


def F_rated(scenario: dict) -> float:
    """F_rated = machine.rated_torque_Nm / r2 (train: F_rated,0 of the first stage)."""
    if is_train(scenario):
        return float(stage_F_rated(scenario)[0])
    d = scenario["design"]
    return float(d["machine"]["rated_torque_Nm"]) / float(d["wheel"]["base_radius_m"])


# ----------------------------------------------------------------------------------------------
# Gear trains (scene "train")
# ----------------------------------------------------------------------------------------------
def is_train(scenario: dict) -> bool:
    return scenario["meta"]["scene"] == "train"


def train_stages(scenario: dict) -> list[dict]:
    """design.stages of a train, checked: N >= 1 stages and exactly N + 1 shafts."""
    stages = list(scenario["design"]["stages"])
    n_shafts = len(scenario["design"]["shafts"])
    if len(stages) < 1:
        raise ValueError("a train needs at least one stage")
    if n_shafts != len(stages) + 1:
        raise ValueError(f"a train of {len(stages)} stages needs {len(stages) + 1} shafts, got {n_shafts}")
    return stages


def stage_F_rated(scenario: dict) -> np.ndarray:
    """Rated force per stage (s = 0 .. N-1 here): the rated machine torque passed upstream through the
    base radii, F_rated,N = rated_torque_Nm / r_wN, F_rated,s = F_rated,s+1 r_p,s+1 / r_ws.

    Any other scene: the single F_rated in an array of length 1.
    """
    if not is_train(scenario):
        return np.array([F_rated(scenario)])
    stages = train_stages(scenario)
    r_p = [float(st["pinion"]["base_radius_m"]) for st in stages]
    r_w = [float(st["wheel"]["base_radius_m"]) for st in stages]
    N = len(stages)
    out = np.empty(N)
    out[N - 1] = float(scenario["design"]["machine"]["rated_torque_Nm"]) / r_w[N - 1]
    for s in range(N - 2, -1, -1):
        out[s] = out[s + 1] * r_p[s + 1] / r_w[s]
    return out


def stage_view(scenario: dict, s: int) -> dict:
    """Stage s of a train as a one-stage-shaped scenario dict for the mesh helpers
    (tooth_factors, tooth_error_amplitudes, mesh_force_literal, friction_moments, F_rated, ...).

    meta.scene becomes "train-stage" and meta.stage_index = s selects the random draw;
    production.error_mode / eccentricity and condition.damaged_teeth / pitted_teeth are the stage's own
    (missing keys: none), condition.friction_coefficient the common one; machine.rated_torque_Nm is the
    rated torque on this stage's wheel, F_rated,s r_ws, so that F_rated(view) = F_rated,s (to round-off).
    """
    st = train_stages(scenario)[s]
    m_wheel = float(stage_F_rated(scenario)[s]) * float(st["wheel"]["base_radius_m"])
    return {
        "meta": {**scenario["meta"], "scene": "train-stage", "stage_index": s},
        "design": {
            "pinion": st["pinion"],
            "wheel": st["wheel"],
            "mesh": st["mesh"],
            "machine": {"rated_torque_Nm": m_wheel},
        },
        "production": {"error_mode": st["error_mode"], "eccentricity": st.get("eccentricity", [])},
        "condition": {
            "friction_coefficient": scenario["condition"]["friction_coefficient"],
            "damaged_teeth": st.get("damaged_teeth", []),
            "pitted_teeth": st.get("pitted_teeth", []),
        },
    }


def _profile_arrays(profile: dict) -> tuple[np.ndarray, np.ndarray]:
    times = np.asarray(profile["time_s"], dtype=float).ravel()
    fr = np.asarray(profile["fraction"], dtype=float).ravel()
    if times.size == 0 or times.size != fr.size:
        raise ValueError("profile needs equally long, non-empty time_s and fraction")
    if np.any(np.diff(times) < 0):
        raise ValueError("profile time_s must be non-decreasing")
    return times, fr


def profile_value(t, profile: dict):
    """Piecewise linear through the points, held constant before the first / after the last."""
    times, fr = _profile_arrays(profile)
    return np.interp(t, times, fr)


def profile_integral(t, profile: dict):
    """Exact integral of the profile from 0 to t (t >= 0)."""
    times, fr = _profile_arrays(profile)
    tt = np.atleast_1d(np.asarray(t, dtype=float))
    out = np.empty_like(tt)
    for m, tm in enumerate(tt):
        if tm < 0:
            raise ValueError("profile_integral needs t >= 0")
        pts = np.unique(np.concatenate(([0.0, tm], times[(times > 0.0) & (times < tm)])))
        vals = np.interp(pts, times, fr)
        out[m] = float(np.sum(0.5 * (vals[1:] + vals[:-1]) * np.diff(pts)))
    return out if np.ndim(t) else float(out[0])


def kloss_torque(w, ws_t: float, motor: dict):
    """Kloss torque M_s = 2 M_b s s_b / (s^2 + s_b^2), s = (w_s(t) - w) / synchronous_speed_rad_s."""
    wsr = float(motor["synchronous_speed_rad_s"])
    mb = float(motor["breakdown_torque_Nm"])
    sb = float(motor["breakdown_slip"])
    s = (ws_t - np.asarray(w, dtype=float)) / wsr
    return 2.0 * mb * s * sb / (s * s + sb * sb)


def steady_slip(m_p: float, motor: dict) -> float:
    """Stable-branch slip with M_s = m_p: s = s_b (M_b - sqrt(M_b^2 - M_p^2)) / M_p, 0 for M_p = 0."""
    mb = float(motor["breakdown_torque_Nm"])
    sb = float(motor["breakdown_slip"])
    if m_p == 0.0:
        return 0.0
    if abs(m_p) > mb:
        raise ValueError(f"pinion torque {m_p} exceeds the breakdown torque {mb}: no steady state")
    return sb * (mb - math.sqrt(mb * mb - m_p * m_p)) / m_p


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
    """Run-out entries of production.eccentricity (missing key: none) as (A, theta, z): A = amplitude_um
    * 1e-6, theta = radians(phase_deg) and z the teeth of that gear, so that each term is
    A sin(2 pi u / z + theta) (pinion: phi_p = 2 pi u / z1; wheel: phi_w* = 2 pi u / z2)."""
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
    """condition.pitted_teeth (missing key: none) as (gear, tooth, depth in m, start_phase, end_phase)."""
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


def total_error(scenario: dict, u):
    """The whole error E at the mesh coordinate u: triangular shape (eq. 6) + run-out + pits
    (with w > 0 blended with the outgoing / incoming pair near the tooth change, :func:`blended_law`)."""
    if transition_width(scenario["design"]["mesh"]) > 0.0:
        return blended_law(scenario, u)[1]
    u = np.asarray(u, dtype=float)
    n = np.floor(u).astype(np.int64)
    p = u - n
    i = np.mod(n, int(scenario["design"]["pinion"]["teeth"]))
    j = np.mod(n, int(scenario["design"]["wheel"]["teeth"]))
    a = float(scenario["production"]["error_mode"]["a"])
    E = error_shape(p, a, tooth_error_amplitudes(scenario)[i])
    return E + runout_error(scenario, u) + pit_error(scenario, p, i, j)


# ----------------------------------------------------------------------------------------------
# Transition width (docs/scenario.md, "Transition width"): literal transcription
# ----------------------------------------------------------------------------------------------
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
    """The transition width w of a one-stage-shaped scenario, with the limits of the spec checked:
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


def pair_law(scenario: dict, m, q):
    """Tooth factor f_i g_j and error (triangle + pits, no run-out) of the pair of mesh period m
    (i = m mod z1, j = m mod z2) evaluated at phase q (possibly outside [0, 1))."""
    z1 = int(scenario["design"]["pinion"]["teeth"])
    z2 = int(scenario["design"]["wheel"]["teeth"])
    m = np.asarray(m, dtype=np.int64)
    i, j = np.mod(m, z1), np.mod(m, z2)
    f, g = tooth_factors(scenario)
    a = float(scenario["production"]["error_mode"]["a"])
    E = error_shape_ext(q, a, tooth_error_amplitudes(scenario)[i]) + pit_error(scenario, q, i, j)
    return f[i] * g[j], E


def blended_law(scenario: dict, u) -> tuple[np.ndarray, np.ndarray]:
    """Tooth factor f g and whole error E at the mesh coordinate u, blended at the tooth change:
    p < w/2: X = X_out + S(p/w) (X_in - X_out), outgoing pair (i - 1, j - 1) at phase p + 1;
    p > 1 - w/2: X = X_in + S((p - 1)/w) (X_next - X_in), incoming pair (i + 1, j + 1) at p - 1.
    The run-out (a function of u only) is the same for all pairs and is added once.
    With w = 0: f_i g_j and the sharp E."""
    u = np.asarray(u, dtype=float)
    n = np.floor(u).astype(np.int64)
    p = u - n
    w = transition_width(scenario["design"]["mesh"])
    fg_in, E_in = pair_law(scenario, n, p)
    if w > 0.0:
        fg_out, E_out = pair_law(scenario, n - 1, p + 1.0)
        fg_nx, E_nx = pair_law(scenario, n + 1, p - 1.0)
        s0, s1 = smooth_step(p / w), smooth_step((p - 1.0) / w)
        low, high = p < w / 2, p > 1.0 - w / 2
        fg_hi = np.where(high, fg_in + s1 * (fg_nx - fg_in), fg_in)
        fg = np.where(low, fg_out + s0 * (fg_in - fg_out), fg_hi)
        E = np.where(low, E_out + s0 * (E_in - E_out), np.where(high, E_in + s1 * (E_nx - E_in), E_in))
    else:
        fg, E = fg_in, E_in
    return fg, E + runout_error(scenario, u)


def friction_sign(p, pitch_point_phase: float, w: float = 0.0):
    """s = +1 for p < pitch, -1 otherwise (w = 0); with w > 0 and 0 < pitch < 1:
    s = 2 [S(p/w) - S((p - pitch)/w) + S((p - 1)/w)] - 1; pitch 0 or 1: constant sign."""
    p = np.asarray(p, dtype=float)
    ppp = float(pitch_point_phase)
    if w > 0.0 and 0.0 < ppp < 1.0:
        return 2.0 * (smooth_step(p / w) - smooth_step((p - ppp) / w) + smooth_step((p - 1.0) / w)) - 1.0
    return np.where(p < ppp, 1.0, -1.0)


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


def pair_stiffness(scenario: dict, u, healthy: bool = False):
    """The "pairs" law at the mesh coordinate u (literal): with p, n from u and the period's teeth
    (i, j) = (n mod z1, n mod z2), k = sum over o = -1, 0, +1 of c(q) K(q) f_io g_jo R_pinion,io(q)
    R_wheel,jo(q), q = p - o, (io, jo) = (i + o, j + o) (modulo z1, z2); K and R linear between the
    grid points and held at their end values outside.  healthy: all f, g, R = 1 (:func:`base_stiffness`)."""
    mesh = scenario["design"]["mesh"]
    u = np.asarray(u, dtype=float)
    n = np.floor(u).astype(np.int64)
    p = u - n
    if healthy:
        return base_stiffness(p, mesh)
    z1 = int(scenario["design"]["pinion"]["teeth"])
    z2 = int(scenario["design"]["wheel"]["teeth"])
    grid, K, ratios = pair_table(mesh)
    h, w = half_double(mesh), transition_width(mesh)
    f, g = tooth_factors(scenario)
    k = np.zeros(u.shape)
    for o in (-1, 0, 1):
        q = p - o
        io, jo = np.mod(n + o, z1), np.mod(n + o, z2)
        term = contact_weight(q, h, w) * np.interp(q, grid, K) * f[io] * g[jo]
        for (gear, tooth), R in ratios.items():
            on = (io if gear == "pinion" else jo) == tooth
            term = term * np.where(on, np.interp(q, grid, R), 1.0)
        k = k + term
    return k


def effective_stiffness(scenario: dict, u) -> tuple[np.ndarray, np.ndarray]:
    """Stiffness k of the law at the mesh coordinate u and the factor of its damping: k_z(p) f_i g_j and
    f_i g_j (w > 0: the blended factor); "pairs": the pair sum and k / k_healthy."""
    mesh = scenario["design"]["mesh"]
    u = np.asarray(u, dtype=float)
    if mesh_law(mesh) == "pairs":
        k = pair_stiffness(scenario, u)
        return k, k / pair_stiffness(scenario, u, healthy=True)
    n = np.floor(u).astype(np.int64)
    p = u - n
    if transition_width(mesh) > 0.0:  # factor blended with the outgoing / incoming pair
        fg = blended_law(scenario, u)[0]
    else:
        f, g = tooth_factors(scenario)
        fg = f[np.mod(n, int(scenario["design"]["pinion"]["teeth"]))]
        fg = fg * g[np.mod(n, int(scenario["design"]["wheel"]["teeth"]))]
    return base_stiffness(p, mesh) * fg, fg


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
    """f (pinion, z1 values) and g (wheel, z2 values); 1 unless listed in condition.damaged_teeth.

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


def mesh_force_literal(scenario: dict, u, delta, delta_dot) -> dict:
    """Vectorised, literal transcription of the mesh-force paragraph (used by the self-checks).

    u: pinion mesh coordinate phi_p z1 / (2 pi); delta = r1 phi_p - r2 phi_w; delta_dot its rate.
    E is the total error (triangular shape, run-out, pits); it enters d only, never the damping.
    """
    d_ = scenario["design"]
    mesh = d_["mesh"]
    z1, z2 = int(d_["pinion"]["teeth"]), int(d_["wheel"]["teeth"])
    u = np.asarray(u, dtype=float)
    n = np.floor(u).astype(np.int64)
    p = u - n
    i = np.mod(n, z1)
    j = np.mod(n, z2)
    # k = k_z(p) f_i g_j and the damping factor f_i g_j (w > 0: blended at the tooth change);
    # "pairs": the sum over the pairs in contact and k / k_healthy
    k, fg = effective_stiffness(scenario, u)
    Cf = float(mesh["damping_Ns_per_m"]) * fg
    if transition_width(mesh) > 0.0:  # error blended near the tooth change
        E = blended_law(scenario, u)[1]
    else:
        e_i = tooth_error_amplitudes(scenario)[i]
        E = error_shape(p, float(scenario["production"]["error_mode"]["a"]), e_i)
        E = E + runout_error(scenario, u) + pit_error(scenario, p, i, j)  # fault errors: in d only
    d = np.asarray(delta, dtype=float) + E
    lu = float(mesh["backlash_um"]) * 1e-6
    F_el = k * np.maximum(d - lu, np.minimum(d + lu, 0.0))
    contact = np.abs(d) > lu
    F_t = np.where(contact, Cf * np.asarray(delta_dot, float), 0.0)
    return {
        "F": F_el + F_t,
        "F_el": F_el,
        "F_t": F_t,
        "p": p,
        "i": i,
        "j": j,
        "k": k,
        "E": E,
        "d": d,
        "fg": fg,
    }


def friction_moments(scenario: dict, p, F) -> dict:
    """T = mu |F| s and the moments M_zt1 = T rho_1, M_zt2 = T rho_2 (literal)."""
    d_ = scenario["design"]
    mesh = d_["mesh"]
    r1, r2 = float(d_["pinion"]["base_radius_m"]), float(d_["wheel"]["base_radius_m"])
    z1 = int(d_["pinion"]["teeth"])
    ppp = float(mesh["pitch_point_phase"])
    tan_a = math.tan(math.radians(float(mesh["pressure_angle_deg"])))
    pb = TWO_PI * r1 / z1
    p = np.asarray(p, dtype=float)
    s = friction_sign(p, ppp, transition_width(mesh))
    T = float(scenario["condition"]["friction_coefficient"]) * np.abs(np.asarray(F, dtype=float)) * s
    rho1 = r1 * tan_a + (p - ppp) * pb
    rho2 = r2 * tan_a - (p - ppp) * pb
    return {"T": T, "rho1": rho1, "rho2": rho2, "M_zt1": T * rho1, "M_zt2": T * rho2}


def initial_state(scenario: dict) -> tuple[np.ndarray, np.ndarray]:
    """Initial coordinates and velocities for initial_state "rest" | "steady"."""
    scene = scenario["meta"]["scene"]
    if scene == "train":
        return _train_initial_state(scenario)
    n_dof = {"muller": 1, "two-wheel": 2, "one-stage": 4}[scene]
    kind = scenario["operation"]["initial_state"]
    q0 = np.zeros(n_dof)
    v0 = np.zeros(n_dof)
    if kind == "rest":
        return q0, v0
    if kind != "steady":
        raise ValueError(f"unknown initial_state {kind!r}")
    d_ = scenario["design"]
    r1, r2 = float(d_["pinion"]["base_radius_m"]), float(d_["wheel"]["base_radius_m"])
    mesh = d_["mesh"]
    lu = float(mesh["backlash_um"]) * 1e-6
    load0 = float(profile_value(0.0, scenario["operation"]["load_profile"]))
    M_L = float(d_["machine"]["rated_torque_Nm"]) * load0
    F0 = M_L / r2
    M_p = F0 * r1
    k0 = float(effective_stiffness(scenario, 0.0)[0])  # w > 0: factor blended with the outgoing pair
    E0 = float(total_error(scenario, 0.0))  # total error at p = 0, tooth 0 (fault errors included)
    delta0 = F0 / k0 + lu - E0 if F0 != 0.0 else 0.0
    if scene == "muller":
        q0[0] = delta0
        return q0, v0
    motor = d_["motor"]
    wsr = float(motor["synchronous_speed_rad_s"])
    ws0 = wsr * float(profile_value(0.0, scenario["operation"]["speed_profile"]))
    w = ws0 - steady_slip(M_p, motor) * wsr
    if scene == "two-wheel":
        q0[:] = [0.0, -delta0 / r2]
        v0[:] = [w, w * r1 / r2]
        return q0, v0
    k1 = float(d_["coupling"]["stiffness_Nm_per_rad"])
    k2 = float(d_["output_shaft"]["stiffness_Nm_per_rad"])
    phi3 = -delta0 / r2
    q0[:] = [M_p / k1, 0.0, phi3, phi3 - M_L / k2]
    v0[:] = [w, w, w * r1 / r2, w * r1 / r2]
    return q0, v0


def _train_initial_state(scenario: dict) -> tuple[np.ndarray, np.ndarray]:
    """Initial state of a train (section "Gear trains" of docs/scenario.md), stage by stage."""
    stages = train_stages(scenario)
    N = len(stages)
    q0 = np.zeros(2 * N + 2)
    v0 = np.zeros(2 * N + 2)
    kind = scenario["operation"]["initial_state"]
    if kind == "rest":
        return q0, v0
    if kind != "steady":
        raise ValueError(f"unknown initial_state {kind!r}")
    d_ = scenario["design"]
    shaft_k = [float(sh["stiffness_Nm_per_rad"]) for sh in d_["shafts"]]
    load0 = float(profile_value(0.0, scenario["operation"]["load_profile"]))
    M_L = float(d_["machine"]["rated_torque_Nm"]) * load0
    r_p = [float(st["pinion"]["base_radius_m"]) for st in stages]
    r_w = [float(st["wheel"]["base_radius_m"]) for st in stages]
    z_p = [int(st["pinion"]["teeth"]) for st in stages]
    F = [load0 * Fr for Fr in stage_F_rated(scenario)]  # F_s = f F_rated,s
    pinion_torque = [F[s] * r_p[s] for s in range(N)]
    # speeds: motor = pinion 1 from the Kloss stable branch, wheel = pinion r_p / r_w, next pinion = wheel
    motor = d_["motor"]
    wsr = float(motor["synchronous_speed_rad_s"])
    ws0 = wsr * float(profile_value(0.0, scenario["operation"]["speed_profile"]))
    w = ws0 - steady_slip(pinion_torque[0], motor) * wsr
    v0[0] = w
    for s in range(N):
        v0[1 + 2 * s] = w
        w = w * r_p[s] / r_w[s]
        v0[2 + 2 * s] = w
    v0[2 * N + 1] = w
    # angles: pinion 1 = 0, then stage by stage in power-flow order
    pinion = 0.0
    for s in range(N):
        view = stage_view(scenario, s)
        mesh = view["design"]["mesh"]
        u = pinion * z_p[s] / TWO_PI
        k = float(effective_stiffness(view, u)[0])  # w > 0: factor blended near the tooth change
        E = float(total_error(view, u))  # fault errors included
        lu = float(mesh["backlash_um"]) * 1e-6
        if F[s] == 0.0:
            delta = 0.0
        elif k == 0.0:
            raise ValueError(f"steady start: stage {s} meshes with zero stiffness at its initial angle")
        else:
            delta = F[s] / k + lu - E
        q0[1 + 2 * s] = pinion
        wheel = (r_p[s] * pinion - delta) / r_w[s]
        q0[2 + 2 * s] = wheel
        if s + 1 < N:
            pinion = wheel - pinion_torque[s + 1] / shaft_k[s + 1]
    q0[0] = q0[1] + pinion_torque[0] / shaft_k[0]
    q0[2 * N + 1] = q0[2 * N] - M_L / shaft_k[N]
    return q0, v0


def phase_breakpoints(scenario: dict) -> np.ndarray:
    """All phases in [0, 1) at which some mesh quantity jumps or kinks (0 always included)."""
    mesh = scenario["design"]["mesh"]
    w = check_transition_width(scenario)
    if w > 0.0:
        return _phase_breakpoints_smooth(scenario, w)
    pts = [0.0]
    law = mesh_law(mesh)
    if law == "table":
        pts += [float(x) % 1.0 for x in mesh["table_phase"]]
    else:  # contact-ratio: k_z jumps; pairs: a pair leaves at h and one enters at 1 - h
        h = half_double(mesh)
        pts += [h, 1.0 - h]
    if law == "pairs":  # kinks of the pair tables: the grid points q_m, at p = q_m + o (mod 1)
        pts += [float(x) % 1.0 for x in pair_table(mesh)[0]]
    pts.append(float(scenario["production"]["error_mode"]["a"]))
    if scenario["meta"]["scene"] != "muller" and float(scenario["condition"]["friction_coefficient"]) != 0.0:
        pts.append(float(mesh["pitch_point_phase"]))
    for _gear, _tooth, _depth, lo, hi in pitted_teeth(scenario):  # pit edges
        pts += [lo, hi % 1.0]
    pts = np.unique([x for x in pts if 0.0 <= x < 1.0])
    # merge points closer than 1e-9 (e.g. a pit edge 0.3 and h = 0.30000000000000004): no degenerate
    # intervals narrower than the event hysteresis
    keep = [pts[0]]
    for x in pts[1:]:
        if x - keep[-1] > 1e-9 and 1.0 - x > 1e-9:
            keep.append(x)
    return np.array(keep)


def _phase_breakpoints_smooth(scenario: dict, w: float) -> np.ndarray:
    """Break points with a transition width w > 0: each smoothed jump at p_c becomes a C2 ramp on
    [p_c - w/2, p_c + w/2] whose ends (where the third derivative jumps) are break points, taken
    modulo 1 (the ramps of the tooth change, 0 -+ w/2, and of anything near it straddle a period
    end).  Kinks stay break points: p = 0 (the friction arms jump there while s passes 0), the error
    apex a and the table points.  The centres of the ramps are not needed (the law is a polynomial
    across them), so that inside every interval each smooth step is locked at 0, 1 or its polynomial.
    """
    mesh = scenario["design"]["mesh"]
    centres = [0.0]  # tooth change
    kinks = [0.0, float(scenario["production"]["error_mode"]["a"]) % 1.0]
    law = mesh_law(mesh)
    if law == "table":
        kinks += [float(x) % 1.0 for x in mesh["table_phase"]]
    else:  # contact-ratio ramps; pairs: contact weights of the outgoing / incoming pair
        h = half_double(mesh)
        centres += [h, 1.0 - h]
    if law == "pairs":
        kinks += [float(x) % 1.0 for x in pair_table(mesh)[0]]
    ppp = float(mesh["pitch_point_phase"])
    if scenario["meta"]["scene"] != "muller" and float(scenario["condition"]["friction_coefficient"]) != 0.0:
        if 0.0 < ppp < 1.0:
            centres.append(ppp)
    for _gear, _tooth, _depth, lo, hi in pitted_teeth(scenario):
        centres += [lo, hi]
    pts = kinks + [(c + sgn * 0.5 * w) % 1.0 for c in centres for sgn in (-1.0, 1.0)]
    pts = np.unique([x for x in pts if 0.0 <= x < 1.0])
    keep = [pts[0]]
    for x in pts[1:]:
        if x - keep[-1] > 1e-9 and 1.0 - x > 1e-9:
            keep.append(x)
    return np.array(keep)


# ----------------------------------------------------------------------------------------------
# Locked-mode mesh law (used by the right-hand side AND for the outputs)
# ----------------------------------------------------------------------------------------------
class _ModeConsts(NamedTuple):
    """Constants of one mesh in a locked mode (phase interval k of mesh period n, contact mode c)."""

    fg: float  # tooth factors f_i g_j
    kA: float  # base stiffness k_z = kA + kS (p - bA) on the interval
    kS: float
    bA: float
    e_i: float  # triangular error e_i (Ea + Eb p) on the interval
    Ea: float
    Eb: float
    c: int  # contact mode: 1 drive flank, 0 separated, -1 back flank
    lu: float  # half backlash
    Cf: float  # damping C_z f_i g_j
    pit: float  # depth of the pits active on this interval (constant there: pit edges are breakpoints)
    nf: float  # n, so that u = n + p
    runout: tuple  # (A, 2 pi / z, theta) per run-out term: A sin(2 pi u / z + theta)
    tw: _SmoothMode | None = None  # transition width w > 0: the smoothed law of this mode (else None)
    pk: _PairMode | None = None  # "pairs" law: the pairs in contact in this mode (else None)


def _mode_error(mc: _ModeConsts, p):
    """Total error E in a locked mode at p = u - n (float or array): triangle - pit + run-out."""
    if mc.tw is not None:
        E = _smooth_error(mc.tw, p)
    else:
        E = mc.e_i * (mc.Ea + mc.Eb * p) - mc.pit
    if mc.runout:
        u = mc.nf + p
        sin = math.sin if isinstance(u, float) else np.sin
        for amp, w, theta in mc.runout:
            E = E + amp * sin(w * u + theta)
    return E


def _mesh_force(mc: _ModeConsts, p, delta, delta_dot):
    """Mesh force F = F_el + F_t in a locked mode; works on floats and on numpy arrays.

    d = delta + E with the total error E of :func:`_mode_error`; the damping uses delta_dot only.
    """
    if mc.c == 0:
        return 0.0 * (p + delta + delta_dot)
    d = delta + _mode_error(mc, p)
    if mc.pk is not None:  # "pairs": k from the pairs in contact, damping C_z k / k_healthy
        k, k_healthy = _pairs_eval(mc.pk, p)
        return k * (d - mc.c * mc.lu) + mc.Cf * (k / k_healthy) * delta_dot
    tw = mc.tw
    if tw is not None:  # blended factor (also in the damping) and smoothed stiffness
        fg = _smooth_factor(tw, p)
        return fg * (_poly_eval(tw.kz, p) * (d - mc.c * mc.lu) + tw.Cz * delta_dot)
    return mc.fg * (mc.kA + mc.kS * (p - mc.bA)) * (d - mc.c * mc.lu) + mc.Cf * delta_dot


def _mode_mu_sign(mesh: _Mesh, k: int, mc: _ModeConsts, p):
    """mu s in a locked mode at p (float or array): the interval's constant with w = 0, the smoothed
    friction sign of :func:`friction_sign` with w > 0."""
    if mc.tw is None:
        return mesh.mu * mesh.iv[k][4] + 0.0 * p
    return _poly_eval(mc.tw.mus, p)


# ----------------------------------------------------------------------------------------------
# Locked-mode form of the smoothed law (transition width w > 0)
# ----------------------------------------------------------------------------------------------
# Inside one phase interval every smooth step S((q - c)/w) is either 0, 1 or its quintic (all ramp
# ends are break points), so each smoothed quantity is  A + B p + sum coef * P((p - c) / w + 1/2)
# with P(x) = x^3 (10 - 15 x + 6 x^2): stored as (A, B, ((coef, c, 1/w), ...)).  Evaluated with
# the quintic also slightly beyond the interval ends (trial steps), so the right-hand side is smooth.
class _SmoothMode(NamedTuple):
    kz: tuple  # k_z(p) (tables: the linear piece)
    mus: tuple  # mu s(p)
    beta: tuple | None  # blend weight S(p/w) or S((p - 1)/w); None: a single pair (no blending)
    fgA: float  # factor of pair A (outgoing / in mesh)
    fgB: float  # factor of pair B (in mesh / incoming); X = X_A + beta (X_B - X_A)
    EA: tuple  # error of pair A (triangle + pits; run-out is added by _mode_error)
    EB: tuple
    Cz: float  # mesh damping C_z (times the blended factor)


def _poly_eval(L: tuple, p):
    A, B, terms = L
    v = A + B * p
    for coef, c, iw in terms:
        x = (p - c) * iw + 0.5
        v = v + coef * (x * x * x * (10.0 - 15.0 * x + 6.0 * x * x))
    return v


def _smooth_factor(tw: _SmoothMode, p):
    if tw.beta is None:
        return tw.fgA + 0.0 * p
    return tw.fgA + _poly_eval(tw.beta, p) * (tw.fgB - tw.fgA)


def _smooth_error(tw: _SmoothMode, p):
    EA = _poly_eval(tw.EA, p)
    if tw.beta is None:
        return EA
    return EA + _poly_eval(tw.beta, p) * (_poly_eval(tw.EB, p) - EA)


class _PolyBuilder:
    """Accumulates A + B p + sum coef S((p - c)/w) on one phase interval (midpoint ``mid``)."""

    def __init__(self, w: float, mid: float, A: float = 0.0, B: float = 0.0):
        self.w, self.mid, self.A, self.B, self.terms = w, mid, A, B, []

    def step(self, coef: float, c: float) -> None:
        """Add coef S((p - c)/w), locked on the interval: 0, coef, or the quintic."""
        x = (self.mid - c) / self.w
        if x >= 0.5:
            self.A += coef
        elif x > -0.5:
            self.terms.append((coef, c, 1.0 / self.w))

    def done(self) -> tuple:
        return (self.A, self.B, tuple(self.terms))


# ----------------------------------------------------------------------------------------------
# Locked-mode form of the "pairs" law
# ----------------------------------------------------------------------------------------------
# In phase interval k of mesh period n the pairs o = -1, 0, +1 whose contact weight is not 0 there are
# listed with their teeth's factor f g and the tables to multiply (K, then the ratio table of a damaged
# pinion / wheel tooth of that pair), each as its linear piece on the interval, (v0, slope, p0):
# v0 + slope (p - p0) (all grid points q_m are break points at p = q_m + o mod 1, so a pair's own phase
# q = p - o stays between two grid points).  The contact weight is 1 (w = 0: h and 1 - h are break
# points) or a locked smooth step (w > 0).  So k is a polynomial in p on the interval (evaluated also a
# little beyond its ends during trial steps), and the damping factor k / k_healthy a smooth quotient.
class _PairMode(NamedTuple):
    terms: tuple  # per pair in contact: (weight poly | None, f g, ((v0, slope, p0) per table))


def _pairs_eval(pm: _PairMode, p):
    """k = sum over the pairs of c f g K R_p R_w and k_healthy = sum c K at p (float or array)."""
    k = k_healthy = 0.0
    for weight, fg, tables in pm.terms:
        v0, slope, p0 = tables[0]
        kq = v0 + slope * (p - p0)
        if weight is not None:
            kq = kq * _poly_eval(weight, p)
        k_healthy = k_healthy + kq
        for v0, slope, p0 in tables[1:]:
            kq = kq * (v0 + slope * (p - p0))
        k = k + fg * kq
    return k, k_healthy


class _Mesh:
    """Constants of one gear mesh, plus its per-mode constants.

    ``sc`` is a one-stage-shaped scenario dict: a whole ``muller`` / ``two-wheel`` / ``one-stage``
    scenario or the :func:`stage_view` of one stage of a train (then ``Frated`` = F_rated,s exactly).
    """

    def __init__(self, sc: dict, Frated: float | None = None):
        d_ = sc["design"]
        self.z1 = int(d_["pinion"]["teeth"])
        self.z2 = int(d_["wheel"]["teeth"])
        self.r1 = float(d_["pinion"]["base_radius_m"])
        self.r2 = float(d_["wheel"]["base_radius_m"])
        self.cz = self.z1 / TWO_PI
        mesh = d_["mesh"]
        self.lu = float(mesh["backlash_um"]) * 1e-6
        self.Cz = float(mesh["damping_Ns_per_m"])
        self.ppp = float(mesh["pitch_point_phase"])
        self.tan_a = math.tan(math.radians(float(mesh["pressure_angle_deg"])))
        self.pb = TWO_PI * self.r1 / self.z1
        muller = sc["meta"]["scene"] == "muller"
        self.mu = float(sc["condition"]["friction_coefficient"]) if not muller else 0.0
        self.a = float(sc["production"]["error_mode"]["a"])
        self.f, self.g = tooth_factors(sc)
        self.e_amp = tooth_error_amplitudes(sc)
        self.runout = tuple((amp, TWO_PI / z, theta) for amp, theta, z in runout_terms(sc))
        self.pits = pitted_teeth(sc)
        self.Frated = F_rated(sc) if Frated is None else float(Frated)
        self.w = check_transition_width(sc)
        self.mesh = mesh
        self.law = mesh_law(mesh)
        if self.law == "pairs":
            grid, K, ratios = pair_table(mesh)
            for gear, tooth in ratios:
                if not 0 <= tooth < (self.z1 if gear == "pinion" else self.z2):
                    raise ValueError(f"pair_table ratio for {gear} tooth {tooth}, which does not exist")
            self.h = half_double(mesh)
            self.grid = grid
            self.Ktab = K.tolist()
            self.ratios = {key: R.tolist() for key, R in ratios.items()}
            self.inv_dq = (K.size - 1) / (1.0 + 2.0 * self.h)
        # phase intervals
        b = phase_breakpoints(sc)
        self.bA = b
        self.bB = np.append(b[1:], 1.0)
        self.K = b.size
        self.iv = []  # per interval: (kA, kS, Ea, Eb, s)
        for k in range(self.K):
            lo, hi = float(self.bA[k]), float(self.bB[k])
            mid = 0.5 * (lo + hi)
            if self.law != "table":  # pairs: not used (the mode's _PairMode)
                kA, kS = float(base_stiffness(mid, mesh)), 0.0
            else:
                kA = float(base_stiffness(lo, mesh))
                kS = (float(base_stiffness(hi % 1.0, mesh)) - kA) / (hi - lo)
            if mid < self.a:
                Ea, Eb = 0.0, 1.0 / self.a
            else:
                Ea, Eb = 1.0 / (1.0 - self.a), -1.0 / (1.0 - self.a)
            s = 1.0 if mid < self.ppp else -1.0
            self.iv.append((kA, kS, Ea, Eb, s))
        # scales for the default absolute tolerance
        self.m_red = reduced_mass(sc)
        kmax = max(float(np.max(base_stiffness(np.linspace(0, 1, 201), mesh))), 1.0)
        self.defl_scale = max(self.Frated / kmax, 1e-7)
        self.omega_n = math.sqrt(kmax / self.m_red)

    # -- mode constants ---------------------------------------------------------------------
    def smooth_mode(self, n: int, k: int) -> _SmoothMode:
        """The smoothed law (w > 0) on phase interval k of mesh period n, in locked form."""
        w = self.w
        lo, hi = float(self.bA[k]), float(self.bB[k])
        mid = 0.5 * (lo + hi)
        mesh = self.mesh
        # stiffness k_z = k_s + (k_d - k_s) [1 - S((p - h)/w) + S((p - 1 + h)/w)]; tables unchanged
        if self.law == "contact-ratio":
            h = half_double(mesh)
            ks, kd = float(mesh["stiffness_single_N_per_m"]), float(mesh["stiffness_double_N_per_m"])
            kz = _PolyBuilder(w, mid, A=kd)
            kz.step(-(kd - ks), h)
            kz.step(kd - ks, 1.0 - h)
        else:  # table (pairs: not used)
            kA, kS = self.iv[k][0], self.iv[k][1]
            kz = _PolyBuilder(w, mid, A=kA - kS * lo, B=kS)
        # friction: mu s, s = 2 [S(p/w) - S((p - pitch)/w) + S((p - 1)/w)] - 1 (0 < pitch < 1)
        if 0.0 < self.ppp < 1.0:
            mus = _PolyBuilder(w, mid, A=-self.mu)
            mus.step(2.0 * self.mu, 0.0)
            mus.step(-2.0 * self.mu, self.ppp)
            mus.step(2.0 * self.mu, 1.0)
        else:
            mus = _PolyBuilder(w, mid, A=self.mu * (1.0 if mid < self.ppp else -1.0))
        # pairs near the tooth change: (period, phase shift q - p)
        if mid < 0.5 * w:
            pairs, beta = [(n - 1, 1.0), (n, 0.0)], _PolyBuilder(w, mid)
            beta.step(1.0, 0.0)
        elif mid > 1.0 - 0.5 * w:
            pairs, beta = [(n, 0.0), (n + 1, -1.0)], _PolyBuilder(w, mid)
            beta.step(1.0, 1.0)
        else:
            pairs, beta = [(n, 0.0)], None
        fgs, Es = [], []
        a = self.a
        for m, shift in pairs:
            i, j = m % self.z1, m % self.z2
            fgs.append(self.f[i] * self.g[j])
            e_i = float(self.e_amp[i])
            qmid = mid + shift
            # triangle extended by its straight lines, as a function of p (q = p + shift)
            if a >= 1.0 or (a > 0.0 and qmid < a):
                E = _PolyBuilder(w, qmid, A=e_i * shift / a, B=e_i / a)
            else:
                E = _PolyBuilder(w, qmid, A=e_i * (1.0 - shift) / (1.0 - a), B=-e_i / (1.0 - a))
            for gear, tooth, depth, plo, phi in self.pits:  # - depth [S((q - start)/w) - S((q - end)/w)]
                if tooth == (i if gear == "pinion" else j):
                    E.step(-depth, plo)
                    E.step(depth, phi)
            # centres in q -> centres in p
            Es.append((E.A, E.B, tuple((cf, c - shift, iw) for cf, c, iw in E.terms)))
        return _SmoothMode(
            kz=kz.done(),
            mus=mus.done(),
            beta=beta.done() if beta is not None else None,
            fgA=fgs[0],
            fgB=fgs[-1],
            EA=Es[0],
            EB=Es[-1],
            Cz=self.Cz,
        )

    def pair_mode(self, n: int, k: int) -> _PairMode:
        """The "pairs" law on phase interval k of mesh period n, in locked form (see _PairMode)."""
        lo, hi = float(self.bA[k]), float(self.bB[k])
        mid = 0.5 * (lo + hi)
        h, w = self.h, self.w
        terms = []
        for o in (-1, 0, 1):
            shift = -float(o)  # own phase q = p - o
            qmid = mid + shift
            weight = None
            if w > 0.0:  # c = S((q + h)/w) [1 - S((q - 1 - h)/w)], as a function of p
                enter = _PolyBuilder(w, mid)
                enter.step(1.0, o - h)
                leave = _PolyBuilder(w, mid, A=1.0)
                leave.step(-1.0, o + 1.0 + h)
                parts = [b.done() for b in (enter, leave)]
                if any(A == 0.0 and not terms_ for A, _B, terms_ in parts):
                    continue  # out of contact on the whole interval
                ramps = [P for P in parts if P[2]]
                if len(ramps) > 1:
                    raise ValueError("transition width too wide for the contact ratio")
                weight = ramps[0] if ramps else None
            elif not -h <= qmid < 1.0 + h:
                continue
            io, jo = (n + o) % self.z1, (n + o) % self.z2
            tables = [self.Ktab]
            for key in (("pinion", io), ("wheel", jo)):
                if key in self.ratios:
                    tables.append(self.ratios[key])
            pieces = tuple(self._linear_piece(T, qmid, shift) for T in tables)
            terms.append((weight, float(self.f[io] * self.g[jo]), pieces))
        return _PairMode(tuple(terms))

    def _linear_piece(self, T: list, qmid: float, shift: float) -> tuple[float, float, float]:
        """The piece of table T through own phase qmid as (v0, slope, p0): v0 + slope (p - p0)."""
        x = (qmid + self.h) * self.inv_dq
        if x <= 0.0:
            return T[0], 0.0, 0.0
        m = int(x)
        if m >= len(T) - 1:
            return T[-1], 0.0, 0.0
        return T[m], (T[m + 1] - T[m]) * self.inv_dq, float(self.grid[m]) - shift

    def mode_consts(self, n: int, k: int, c: int) -> _ModeConsts:
        kA, kS, Ea, Eb, _s = self.iv[k]
        i, j = n % self.z1, n % self.z2
        fg = self.f[i] * self.g[j]
        pk = None
        if self.law == "pairs":  # the damping factor k / k_healthy is formed by _mesh_force
            pk, fg = self.pair_mode(n, k), 1.0
        mid = 0.5 * (float(self.bA[k]) + float(self.bB[k]))
        pit = 0.0
        for gear, tooth, depth, lo, hi in self.pits:
            if tooth == (i if gear == "pinion" else j) and lo <= mid < hi:
                pit += depth
        return _ModeConsts(
            fg=fg,
            kA=kA,
            kS=kS,
            bA=float(self.bA[k]),
            e_i=self.e_amp[i],
            Ea=Ea,
            Eb=Eb,
            c=c,
            lu=self.lu,
            Cf=self.Cz * fg,
            pit=pit,
            nf=float(n),
            runout=self.runout,
            tw=self.smooth_mode(n, k) if self.w > 0.0 else None,
            pk=pk,
        )

    def phase_mode(self, u: float, u_dot: float) -> tuple[int, int]:
        n = math.floor(u)
        p = u - n
        k = int(np.searchsorted(self.bA, p, side="right")) - 1
        if p == self.bA[k] and u_dot < 0.0:  # sitting on a boundary and moving down
            k -= 1
            if k < 0:
                k, n = self.K - 1, n - 1
        return n, k

    def contact_mode(self, d: float, d_dot: float) -> int:
        lu = self.lu
        if lu == 0.0:
            return 1
        if d > lu or (d == lu and d_dot > 0):
            return 1
        if d < -lu or (d == -lu and d_dot < 0):
            return -1
        return 0

    def step_phase(self, n: int, k: int, step: int) -> tuple[int, int]:
        """Phase mode after crossing one interval boundary upwards (+1) or downwards (-1)."""
        k += step
        if k >= self.K:
            k, n = 0, n + 1
        elif k < 0:
            k, n = self.K - 1, n - 1
        return n, k


class _Model(_Mesh):
    """Constants of one resolved single-mesh scenario (muller, two-wheel, one-stage)."""

    def __init__(self, sc: dict):
        self.sc = sc
        self.scene = sc["meta"]["scene"]
        if self.scene not in ("muller", "two-wheel", "one-stage"):
            raise ValueError(f"unknown scene {self.scene!r}")
        super().__init__(sc)
        d_ = sc["design"]
        # motor / shafts / inertias
        mot = d_["motor"]
        self.wsr = float(mot["synchronous_speed_rad_s"])
        self.Mb = float(mot["breakdown_torque_Nm"])
        self.sb = float(mot["breakdown_slip"])
        self.Is = float(mot["inertia_kg_m2"])
        self.I1 = float(d_["pinion"]["inertia_kg_m2"])
        self.I2 = float(d_["wheel"]["inertia_kg_m2"])
        self.Im = float(d_["machine"]["inertia_kg_m2"])
        self.Mrated = float(d_["machine"]["rated_torque_Nm"])
        # shafts exist only in the one-stage system (two-wheel: rigid shafts, keys absent)
        coupling, shaft = d_.get("coupling", {}), d_.get("output_shaft", {})
        self.k1 = float(coupling.get("stiffness_Nm_per_rad", 0.0))
        self.C1 = float(coupling.get("damping_Nms_per_rad", 0.0))
        self.k2 = float(shaft.get("stiffness_Nm_per_rad", 0.0))
        self.C2 = float(shaft.get("damping_Nms_per_rad", 0.0))
        op = sc["operation"]
        self.speed_prof = op["speed_profile"]
        self.load_prof = op["load_profile"]
        self.n_dof = {"muller": 1, "two-wheel": 2, "one-stage": 4}[self.scene]

    # -- kinematics of the mesh per scene (u, delta, delta_dot) ------------------------------
    def kin(self, t, y, theta):
        """theta: callable t -> prescribed pinion angle (muller) or None."""
        if self.scene == "muller":
            return theta(t) * self.cz, y[0], y[1]
        ip, iw = (1, 2) if self.scene == "one-stage" else (0, 1)
        nd = self.n_dof
        return (
            y[ip] * self.cz,
            self.r1 * y[ip] - self.r2 * y[iw],
            self.r1 * y[nd + ip] - self.r2 * y[nd + iw],
        )

    def u_dot(self, t, y, chunk) -> float:
        if self.scene == "muller":
            return chunk["ws"](t) * self.cz
        ip = 1 if self.scene == "one-stage" else 0
        return y[self.n_dof + ip] * self.cz

    # -- right-hand sides ----------------------------------------------------------------------
    def make_rhs(self, n: int, k: int, c: int, chunk: dict):
        mc = self.mode_consts(n, k, c)
        s = self.iv[k][4]
        mus = self.mu * s
        ta, sa, ss, la, ls = chunk["ta"], chunk["sa"], chunk["ss"], chunk["la"], chunk["ls"]
        wsr, Mb, sb = self.wsr, self.Mb, self.sb
        sbsq = sb * sb
        Mrated = self.Mrated
        r1, r2, cz = self.r1, self.r2, self.cz
        ppp, pb = self.ppp, self.pb
        r1tan, r2tan = r1 * self.tan_a, r2 * self.tan_a
        mesh = _mesh_force
        nf = float(n)
        array = np.array
        mus_poly = mc.tw.mus if mc.tw is not None else None  # w > 0: mu s(p)
        peval = _poly_eval

        if self.scene == "muller":
            m = self.m_red
            Fr = self.Frated
            th_a = chunk["theta_a"]

            def rhs(t, y):
                x, v = y.tolist()
                tau = t - ta
                u = (th_a + wsr * (sa * tau + 0.5 * ss * tau * tau)) * cz
                F = mesh(mc, u - nf, x, v)
                return array([v, (Fr * (la + ls * tau) - F) / m])

            return rhs, mc

        if self.scene == "two-wheel":
            J1 = self.Is + self.I1
            J2 = self.I2 + self.Im

            def rhs(t, y):
                p1, p2, w1, w2 = y.tolist()
                tau = t - ta
                p = p1 * cz - nf
                F = mesh(mc, p, r1 * p1 - r2 * p2, r1 * w1 - r2 * w2)
                T = (mus if mus_poly is None else peval(mus_poly, p)) * abs(F)
                q = (p - ppp) * pb
                slip = (wsr * (sa + ss * tau) - w1) / wsr
                Ms = 2.0 * Mb * sb * slip / (slip * slip + sbsq)
                Mr = Mrated * (la + ls * tau)
                return array(
                    [w1, w2, (Ms - r1 * F + T * (r1tan + q)) / J1, (r2 * F - T * (r2tan - q) - Mr) / J2]
                )

            return rhs, mc

        Is, I1, I2, Im = self.Is, self.I1, self.I2, self.Im
        k1, C1, k2, C2 = self.k1, self.C1, self.k2, self.C2

        def rhs(t, y):
            p1, p2, p3, p4, w1, w2, w3, w4 = y.tolist()
            tau = t - ta
            p = p2 * cz - nf
            F = mesh(mc, p, r1 * p2 - r2 * p3, r1 * w2 - r2 * w3)
            T = (mus if mus_poly is None else peval(mus_poly, p)) * abs(F)
            q = (p - ppp) * pb
            slip = (wsr * (sa + ss * tau) - w1) / wsr
            Ms = 2.0 * Mb * sb * slip / (slip * slip + sbsq)
            M1 = k1 * (p1 - p2) + C1 * (w1 - w2)
            M2 = k2 * (p3 - p4) + C2 * (w3 - w4)
            Mr = Mrated * (la + ls * tau)
            return array(
                [
                    w1,
                    w2,
                    w3,
                    w4,
                    (Ms - M1) / Is,
                    (M1 - r1 * F + T * (r1tan + q)) / I1,
                    (r2 * F - T * (r2tan - q) - M2) / I2,
                    (M2 - Mr) / Im,
                ]
            )

        return rhs, mc

    # -- events --------------------------------------------------------------------------------
    def make_events(self, n: int, k: int, c: int, mc: tuple, theta):
        """Terminal events leaving the locked mode; each carries the resulting mode change."""
        lo = n + float(self.bA[k]) - _ETA_U
        hi = n + float(self.bB[k]) + _ETA_U
        kin = self.kin
        nf = float(n)

        def ev_up(t, y):
            return kin(t, y, theta)[0] - hi

        def ev_down(t, y):
            return kin(t, y, theta)[0] - lo

        ev_up.terminal, ev_up.direction = True, 1.0
        ev_down.terminal, ev_down.direction = True, -1.0
        events = [ev_up, ev_down]
        actions = [("phase", +1), ("phase", -1)]
        if self.lu > 0.0:

            def dfun(t, y):
                u, delta, _ = kin(t, y, theta)
                return delta + _mode_error(mc, u - nf)

            for offset, direction, new_c in _contact_edges(self.lu, c):

                def ev(t, y, offset=offset):
                    return dfun(t, y) + offset

                ev.terminal, ev.direction = True, direction
                events.append(ev)
                actions.append(("contact", new_c))
        return events, actions

    def deflection(self, n, k, t, y, theta) -> tuple[float, float]:
        """d = delta + E in mode (n, k) and its rate (for re-classifying the contact mode)."""
        u, delta, ddot = self.kin(t, y, theta)
        return delta + _mode_error(self.mode_consts(n, k, 0), u - n), ddot

    def default_atol(self, rtol: float) -> np.ndarray:
        if self.scene == "muller":
            return np.array([1.0, self.omega_n]) * rtol * self.defl_scale
        ang = rtol * self.defl_scale / max(self.r1, self.r2)
        return np.concatenate((np.full(self.n_dof, ang), np.full(self.n_dof, ang * self.omega_n)))


def _chunk(model: _Model, ta: float, tb: float, theta_a: float) -> dict:
    """Linear pieces of the speed and load profiles on [ta, tb] (no profile break point inside)."""

    def lin(profile):
        # evaluated inside the chunk, so that a step (repeated time) at either end is taken correctly
        q1, q3 = ta + 0.25 * (tb - ta), ta + 0.75 * (tb - ta)
        v1, v3 = float(profile_value(q1, profile)), float(profile_value(q3, profile))
        slope = (v3 - v1) / (q3 - q1)
        return v1 - slope * (q1 - ta), slope

    sa, ss = lin(model.speed_prof)
    la, ls = lin(model.load_prof)
    wsr = model.wsr

    def ws(t):
        return wsr * (sa + ss * (t - ta))

    return {"ta": ta, "tb": tb, "sa": sa, "ss": ss, "la": la, "ls": ls, "theta_a": theta_a, "ws": ws}


def _scan_missed_events(sol, events: list, t0: float, t1: float, n_sub: int = 16):
    """Look for mode boundaries crossed *inside* a step (crossed and re-crossed, or crossed before
    a step end at which solve_ivp saw no sign change).  solve_ivp only compares the event functions
    at step ends, which misses e.g. a short dip of the deflection into the backlash.  The dense
    output of every step is sampled at n_sub points; the earliest crossing is located with brentq.

    Returns (event index, root time) or None.
    """
    ts = np.asarray(sol.ts)
    if ts.size < 2:
        return None
    frac = np.arange(1, n_sub) / n_sub
    tt = (ts[:-1, None] + np.diff(ts)[:, None] * frac[None, :]).ravel()
    tt = tt[(tt > t0) & (tt < t1)]
    if tt.size == 0:
        return None
    yy = sol(tt)
    first = {}
    for m, ev in enumerate(events):
        g = np.asarray(ev(tt, yy))
        bad = g > 0.0 if ev.direction > 0 else g < 0.0
        if bad.any():
            first[m] = int(np.argmax(bad))
    if not first:
        return None
    q = min(first.values())
    t_lo = tt[q - 1] if q > 0 else t0
    best = None
    for m, qm in first.items():
        if qm != q:
            continue
        ev = events[m]

        def gfun(s, ev=ev):
            return float(ev(s, sol(s)))

        g_lo = gfun(t_lo)
        ok_lo = g_lo <= 0.0 if ev.direction > 0 else g_lo >= 0.0
        eps4 = 4 * np.finfo(float).eps
        root = brentq(gfun, t_lo, tt[q], xtol=eps4, rtol=eps4) if ok_lo else t_lo
        if best is None or root < best[1]:
            best = (m, root)
    return best


class _Train:
    """Constants of a resolved train scenario (N stages, 2N + 2 torsional coordinates).

    Coordinates ``[motor, pinion_1, wheel_1, ..., pinion_N, wheel_N, machine]``: stage s (0-based
    here) has its pinion at index 1 + 2s and its wheel at 2 + 2s, and shaft j joins the coordinates
    2j and 2j + 1 (shaft 0: motor - pinion_1, shaft s: wheel_s - pinion_(s+1), shaft N: wheel_N -
    machine).  Each mesh is a :class:`_Mesh` built from its :func:`stage_view`.
    """

    def __init__(self, sc: dict):
        self.sc = sc
        stages = train_stages(sc)
        self.N = len(stages)
        self.n_dof = 2 * self.N + 2
        self.meshes = [_Mesh(stage_view(sc, s), Fr) for s, Fr in enumerate(stage_F_rated(sc))]
        self.ip = [1 + 2 * s for s in range(self.N)]
        self.iw = [2 + 2 * s for s in range(self.N)]
        d_ = sc["design"]
        self.shaft_k = [float(sh["stiffness_Nm_per_rad"]) for sh in d_["shafts"]]
        self.shaft_C = [float(sh["damping_Nms_per_rad"]) for sh in d_["shafts"]]
        mot = d_["motor"]
        self.wsr = float(mot["synchronous_speed_rad_s"])
        self.Mb = float(mot["breakdown_torque_Nm"])
        self.sb = float(mot["breakdown_slip"])
        inertia = [float(mot["inertia_kg_m2"])]
        for st in stages:
            inertia += [float(st["pinion"]["inertia_kg_m2"]), float(st["wheel"]["inertia_kg_m2"])]
        inertia.append(float(d_["machine"]["inertia_kg_m2"]))
        self.inertia = inertia
        self.Mrated = float(d_["machine"]["rated_torque_Nm"])
        self.Frated = np.array([m.Frated for m in self.meshes])
        op = sc["operation"]
        self.speed_prof = op["speed_profile"]
        self.load_prof = op["load_profile"]

    # -- per-mesh kinematics (u, delta, delta_dot); y may be one state or states in columns -----
    def kin(self, s: int, y):
        m, ip, iw, nd = self.meshes[s], self.ip[s], self.iw[s], self.n_dof
        return y[ip] * m.cz, m.r1 * y[ip] - m.r2 * y[iw], m.r1 * y[nd + ip] - m.r2 * y[nd + iw]

    def deflection(self, s: int, n: int, k: int, y) -> tuple[float, float]:
        """d = delta + E of stage s in phase mode (n, k), and its rate."""
        u, delta, ddot = self.kin(s, y)
        return delta + _mode_error(self.meshes[s].mode_consts(n, k, 0), u - n), ddot

    def initial_modes(self, y) -> list[list[int]]:
        modes = []
        for s, m in enumerate(self.meshes):
            u, _, _ = self.kin(s, y)
            n, k = m.phase_mode(float(u), float(y[self.n_dof + self.ip[s]]) * m.cz)
            d, dd = self.deflection(s, n, k, y)
            modes.append([n, k, m.contact_mode(float(d), float(dd))])
        return modes

    # -- right-hand side in locked modes -------------------------------------------------------
    def make_rhs(self, modes: list, chunk: dict):
        """First-order right-hand side with every mesh locked in its mode; also returns the per-mesh
        mode constants (for the outputs)."""
        mcs = []
        stage_data = []
        for s, (n, k, c) in enumerate(modes):
            m = self.meshes[s]
            mc = m.mode_consts(n, k, c)
            mcs.append(mc)
            stage_data.append(
                (
                    self.ip[s],
                    self.iw[s],
                    m.r1,
                    m.r2,
                    m.cz,
                    float(n),
                    mc,
                    m.mu * m.iv[k][4] if mc.tw is None else mc.tw.mus,
                    m.ppp,
                    m.pb,
                    m.r1 * m.tan_a,
                    m.r2 * m.tan_a,
                )
            )
        shafts = [(2 * j, 2 * j + 1, self.shaft_k[j], self.shaft_C[j]) for j in range(self.N + 1)]
        ta, sa, ss, la, ls = chunk["ta"], chunk["sa"], chunk["ss"], chunk["la"], chunk["ls"]
        wsr, Mb, sb = self.wsr, self.Mb, self.sb
        sbsq = sb * sb
        Mrated = self.Mrated
        nd = self.n_dof
        Is, Im = self.inertia[0], self.inertia[-1]
        Ip = self.inertia[1:-1:2]
        Iw = self.inertia[2:-1:2]
        mesh = _mesh_force
        peval = _poly_eval
        array = np.array

        def rhs(t, y):
            yl = y.tolist()
            q, v = yl[:nd], yl[nd:]
            tau = t - ta
            # shaft moments S_j = k_j (q_a - q_b) + C_j (v_a - v_b), j = 0 .. N
            S = [kj * (q[a] - q[b]) + Cj * (v[a] - v[b]) for a, b, kj, Cj in shafts]
            slip = (wsr * (sa + ss * tau) - v[0]) / wsr
            Ms = 2.0 * Mb * sb * slip / (slip * slip + sbsq)
            Mr = Mrated * (la + ls * tau)
            acc = [(Ms - S[0]) / Is]  # motor: I_s phi_m'' = M_s - S_0
            for s, (ip, iw, r1, r2, cz, nf, mc, mus, ppp, pb, r1tan, r2tan) in enumerate(stage_data):
                p = q[ip] * cz - nf
                F = mesh(mc, p, r1 * q[ip] - r2 * q[iw], r1 * v[ip] - r2 * v[iw])
                T = (mus if mc.tw is None else peval(mus, p)) * abs(F)
                qq = (p - ppp) * pb
                # I_ps phi_ps'' = S_{s-1} - r_ps F_s + M_zt1,s;  I_ws phi_ws'' = r_ws F_s - M_zt2,s - S_s
                acc.append((S[s] - r1 * F + T * (r1tan + qq)) / Ip[s])
                acc.append((r2 * F - T * (r2tan - qq) - S[s + 1]) / Iw[s])
            acc.append((S[-1] - Mr) / Im)  # machine: I_m phi_M'' = S_N - M_r
            return array(v + acc)

        return rhs, mcs

    # -- events --------------------------------------------------------------------------------
    def make_events(self, modes: list, mcs: list):
        """Terminal events leaving the locked modes of all meshes; actions[m] = (stage, kind, value)."""
        events, actions = [], []
        for s, (n, k, c) in enumerate(modes):
            m = self.meshes[s]
            ip, iw, cz, r1, r2 = self.ip[s], self.iw[s], m.cz, m.r1, m.r2
            lo = n + float(m.bA[k]) - _ETA_U
            hi = n + float(m.bB[k]) + _ETA_U

            def ev_up(t, y, ip=ip, cz=cz, hi=hi):
                return y[ip] * cz - hi

            def ev_down(t, y, ip=ip, cz=cz, lo=lo):
                return y[ip] * cz - lo

            ev_up.terminal, ev_up.direction = True, 1.0
            ev_down.terminal, ev_down.direction = True, -1.0
            events += [ev_up, ev_down]
            actions += [(s, "phase", +1), (s, "phase", -1)]
            if m.lu > 0.0:
                for offset, direction, new_c in _contact_edges(m.lu, c):

                    def ev(t, y, offset=offset, c_=(ip, iw, cz, r1, r2, mcs[s])):
                        ip, iw, cz, r1, r2, mc = c_
                        return r1 * y[ip] - r2 * y[iw] + _mode_error(mc, y[ip] * cz - mc.nf) + offset

                    ev.terminal, ev.direction = True, direction
                    events.append(ev)
                    actions.append((s, "contact", new_c))
        return events, actions

    def default_atol(self, rtol: float) -> np.ndarray:
        """Same rule as one-stage, with the smallest angle scale and the fastest mesh of all stages."""
        ang = min(rtol * m.defl_scale / max(m.r1, m.r2) for m in self.meshes)
        om = max(m.omega_n for m in self.meshes)
        return np.concatenate((np.full(self.n_dof, ang), np.full(self.n_dof, ang * om)))


def _simulate_train(scenario: dict, t_eval, rtol: float, atol, method: str) -> dict[str, np.ndarray]:
    """Segmented integration of a train: a segment ends at the first jump of ANY mesh."""
    model = _Train(scenario)
    t_eval = _output_times(scenario, t_eval)
    t_stop = float(t_eval[-1])
    if atol is None:
        atol = model.default_atol(rtol)
    nd, N = model.n_dof, model.N
    q0, v0 = initial_state(scenario)
    y = np.concatenate((q0, v0))
    n_t = t_eval.size
    Y = np.full((2 * nd, n_t), np.nan)
    F_out = np.full((N, n_t), np.nan)
    tbreaks = _time_breaks(model, t_stop)
    modes = model.initial_modes(y)

    t = 0.0
    nfev = n_segments = n_missed = zero_segments = 0
    i_out = 0
    h_prev = None

    def fill_outputs(sol, t_hi, mcs, include_end):
        nonlocal i_out
        j = i_out
        while j < n_t and (t_eval[j] < t_hi or (include_end and t_eval[j] <= t_hi)):
            j += 1
        if j > i_out:
            ts = t_eval[i_out:j]
            ys = sol(ts) if sol is not None else np.repeat(y[:, None], ts.size, axis=1)
            Y[:, i_out:j] = ys
            for s in range(N):
                u, delta, ddot = model.kin(s, ys)
                F_out[s, i_out:j] = _mesh_force(mcs[s], u - modes[s][0], delta, ddot)
            i_out = j

    if t_stop == 0.0:
        _, mcs = model.make_rhs(modes, _chunk(model, 0.0, 1.0, 0.0))
        fill_outputs(None, 0.0, mcs, True)

    for ib, tb in enumerate(tbreaks):
        if t >= tb:  # t_stop == 0
            break
        chunk = _chunk(model, t, tb, 0.0)
        last_chunk = ib == len(tbreaks) - 1
        while t < tb:
            rhs, mcs = model.make_rhs(modes, chunk)
            events, actions = model.make_events(modes, mcs)
            first = min(h_prev, tb - t) if h_prev else None
            res, t_new, y_new, fired, was_missed = _segment(rhs, t, tb, y, events, method, rtol, atol, first)
            nfev += int(res.nfev)
            n_segments += 1
            n_missed += was_missed
            h_prev = _step_hint(res, h_prev)
            fill_outputs(res.sol, t_new, mcs, last_chunk and not fired)
            if fired:
                zero_segments = zero_segments + 1 if t_new == t else 0
                if zero_segments > _MAX_ZERO_SEGMENTS:
                    raise RuntimeError(f"mode chattering at t={t_new} (modes {modes})")
                phase_changed, contact_set = set(), set()
                for m in fired:
                    s, kind, val = actions[m]
                    if kind == "phase":
                        modes[s][0], modes[s][1] = model.meshes[s].step_phase(modes[s][0], modes[s][1], val)
                        phase_changed.add(s)
                    else:
                        modes[s][2] = val
                        contact_set.add(s)
                for s in phase_changed - contact_set:
                    mesh = model.meshes[s]
                    if mesh.lu > 0.0:
                        # the error E can jump at a tooth change (a = 0 or 1): re-classify the contact
                        d_new, dd_new = model.deflection(s, modes[s][0], modes[s][1], y_new)
                        if abs(abs(d_new) - mesh.lu) > 10 * _ETA_D:
                            modes[s][2] = mesh.contact_mode(float(d_new), float(dd_new))
            t, y = t_new, y_new
    if i_out < n_t:
        raise RuntimeError("internal error: not all output times were filled")
    stage_kd = F_out / model.Frated[:, None]
    return {
        "time": t_eval,
        "coordinates": Y[:nd],
        "velocities": Y[nd:],
        "mesh_force_N": F_out[0].copy(),
        "kd": stage_kd[0].copy(),
        "stage_mesh_force_N": F_out,
        "stage_kd": stage_kd,
        "nfev": np.array(nfev),
        "n_segments": np.array(n_segments),
        "n_missed_events": np.array(n_missed),
    }


def _output_times(scenario: dict, t_eval) -> np.ndarray:
    """t_eval, or the spec's grid t = k / output_rate_hz, k = 0 .. floor(t_end * rate)."""
    if t_eval is None:
        rate = float(scenario["solver"]["output_rate_hz"])
        n_out = math.floor(float(scenario["operation"]["t_end_s"]) * rate)
        t_eval = np.arange(n_out + 1) / rate
    t_eval = np.asarray(t_eval, dtype=float).ravel()
    if t_eval.size == 0 or t_eval[0] < 0.0 or np.any(np.diff(t_eval) < 0.0):
        raise ValueError("t_eval must be non-empty, non-negative and non-decreasing")
    return t_eval


def _time_breaks(model, t_stop: float) -> list[float]:
    """Segment ends in time: the break points of the speed and load profiles, and t_stop."""
    tbreaks = {t_stop}
    for prof in (model.speed_prof, model.load_prof):
        tbreaks.update(float(x) for x in prof["time_s"] if 0.0 < float(x) < t_stop)
    return sorted(tbreaks)


def _contact_edges(lu: float, c: int) -> list[tuple[float, float, int]]:
    """Dead-zone edges to watch from contact state c (1 drive flank, -1 back flank, 0 in the gap):
    (offset of d, crossing direction, contact state after the crossing), with hysteresis _ETA_D."""
    if c == 1:
        return [(-(lu - _ETA_D), -1.0, 0)]
    if c == -1:
        return [(lu - _ETA_D, 1.0, 0)]
    return [(-(lu + _ETA_D), 1.0, 1), (lu + _ETA_D, -1.0, -1)]


def _segment(rhs, t: float, tb: float, y, events, method: str, rtol: float, atol, first):
    """Integrate one smooth segment from t towards tb, stopping at the first jump.

    Returns (result, t_end, y_end, indices of the events that fired there, 1 if the jump was found
    by the sub-step scan rather than by solve_ivp).
    """
    res = solve_ivp(
        rhs,
        (t, tb),
        y,
        method=method,
        rtol=rtol,
        atol=atol,
        events=events,
        dense_output=True,
        first_step=first,
    )
    if res.status < 0:
        raise RuntimeError(f"solve_ivp failed at t={t}: {res.message}")
    t_new = float(res.t[-1])
    y_new = res.y[:, -1].copy()
    fired = []
    if res.status == 1:
        fired = [m for m, te in enumerate(res.t_events) if te.size and te[0] == t_new]
    missed = _scan_missed_events(res.sol, events, t, t_new)
    if missed is None:
        return res, t_new, y_new, fired, 0
    t_new = float(missed[1])
    return res, t_new, res.sol(t_new), [missed[0]], 1


def _step_hint(res, h_prev):
    """First step for the next segment: the last full step size solve_ivp took."""
    ts_steps = res.sol.ts
    if ts_steps.size >= 3:
        return float(ts_steps[-2] - ts_steps[-3])
    if ts_steps.size == 2 and res.status == 0:
        return float(ts_steps[-1] - ts_steps[-2])
    return h_prev


def simulate_reference(
    scenario: dict,
    t_eval: np.ndarray | None = None,
    *,
    rtol: float = 1e-10,
    atol: float | np.ndarray | None = None,
    method: str = "DOP853",
) -> dict[str, np.ndarray]:
    """Integrate a resolved scenario; see the module docstring.

    Returns time, coordinates and velocities (n_dof x n_t), mesh_force_N (F = F_el + F_t),
    kd = F / F_rated, stage_mesh_force_N and stage_kd (n_stages x n_t; one row for the one-mesh
    scenes) and nfev (0-d array); for diagnostics also n_segments (restarts of solve_ivp) and
    n_missed_events (mode boundaries found inside a step by the dense scan).

    Train (N stages): coordinates [motor, pinion_1, wheel_1, ..., pinion_N, wheel_N, machine]
    (n_dof = 2N + 2); mesh_force_N / kd are those of the first stage, stage_kd[s] = F_s / F_rated,s.
    """
    if is_train(scenario):
        return _simulate_train(scenario, t_eval, rtol, atol, method)
    model = _Model(scenario)
    t_eval = _output_times(scenario, t_eval)
    t_stop = float(t_eval[-1])
    if atol is None:
        atol = model.default_atol(rtol)
    nd = model.n_dof
    q0, v0 = initial_state(scenario)
    y = np.concatenate((q0, v0))
    n_t = t_eval.size
    Y = np.full((2 * nd, n_t), np.nan)
    F_out = np.full(n_t, np.nan)

    tbreaks = _time_breaks(model, t_stop)

    # initial modes
    t = 0.0
    theta_a = 0.0
    chunk = _chunk(model, 0.0, tbreaks[0], theta_a) if t_stop > 0 else None

    def make_theta(ch):
        wsr, ta, sa, ss, tha = model.wsr, ch["ta"], ch["sa"], ch["ss"], ch["theta_a"]

        def theta(tt):
            tau = tt - ta
            return tha + wsr * (sa * tau + 0.5 * ss * tau * tau)

        return theta

    theta = make_theta(chunk) if chunk is not None else (lambda tt: 0.0)
    u0, _, _ = model.kin(0.0, y, theta)
    n, k = model.phase_mode(u0, model.u_dot(0.0, y, chunk) if chunk else 0.0)
    d0, dd0 = model.deflection(n, k, 0.0, y, theta)
    c = model.contact_mode(d0, dd0)

    nfev = 0
    i_out = 0
    h_prev = None
    zero_segments = 0
    n_segments = 0
    n_missed = 0

    def fill_outputs(sol, t_lo, t_hi, mc, include_end):
        nonlocal i_out
        j = i_out
        while j < n_t and (t_eval[j] < t_hi or (include_end and t_eval[j] <= t_hi)):
            j += 1
        if j > i_out:
            ts = t_eval[i_out:j]
            ys = sol(ts) if sol is not None else np.repeat(y[:, None], ts.size, axis=1)
            Y[:, i_out:j] = ys
            u, delta, ddot = model.kin(ts, ys, theta)
            F_out[i_out:j] = _mesh_force(mc, u - n, delta, ddot)
            i_out = j

    if t_stop == 0.0:
        _, mc = model.make_rhs(n, k, c, _chunk(model, 0.0, 1.0, 0.0))
        theta = lambda tt: 0.0  # noqa: E731
        fill_outputs(None, 0.0, 0.0, mc, True)

    for ib, tb in enumerate(tbreaks):
        if ib > 0:
            theta_a = theta(t)
            chunk = _chunk(model, t, tb, theta_a)
            theta = make_theta(chunk)
        last_chunk = ib == len(tbreaks) - 1
        while t < tb:
            rhs, mc = model.make_rhs(n, k, c, chunk)
            events, actions = model.make_events(n, k, c, mc, theta)
            first = min(h_prev, tb - t) if h_prev else None
            res, t_new, y_new, fired, was_missed = _segment(rhs, t, tb, y, events, method, rtol, atol, first)
            nfev += int(res.nfev)
            n_segments += 1
            n_missed += was_missed
            h_prev = _step_hint(res, h_prev)
            fill_outputs(res.sol, t, t_new, mc, last_chunk and not fired)
            if fired:
                zero_segments = zero_segments + 1 if t_new == t else 0
                if zero_segments > _MAX_ZERO_SEGMENTS:
                    raise RuntimeError(f"mode chattering at t={t_new} (n={n}, k={k}, c={c})")
                phase_changed = False
                for m in fired:
                    kind, val = actions[m]
                    if kind == "phase":
                        n, k = model.step_phase(n, k, val)
                        phase_changed = True
                    else:
                        c = val
                if phase_changed and model.lu > 0.0 and not any(actions[m][0] == "contact" for m in fired):
                    # the error E can jump at a tooth change (a = 0 or 1): re-classify the contact
                    d_new, dd_new = model.deflection(n, k, t_new, y_new, theta)
                    if abs(abs(d_new) - model.lu) > 10 * _ETA_D:
                        c = model.contact_mode(d_new, dd_new)
            t, y = t_new, y_new
    if i_out < n_t:
        raise RuntimeError("internal error: not all output times were filled")
    return {
        "time": t_eval,
        "coordinates": Y[:nd],
        "velocities": Y[nd:],
        "mesh_force_N": F_out,
        "kd": F_out / model.Frated,
        "stage_mesh_force_N": F_out[None, :].copy(),
        "stage_kd": (F_out / model.Frated)[None, :],
        "nfev": np.array(nfev),
        "n_segments": np.array(n_segments),
        "n_missed_events": np.array(n_missed),
    }
