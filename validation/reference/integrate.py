"""The ONE segmented integrator of the reference (torsional one-mesh scenes, trains, lateral models).

The mesh stiffness, the per-tooth factors, the error branch, the friction arms (at the tooth change) and
the contact state (and in the lateral model the hertzian bearing state) change discontinuously with the
state; friction's direction has a kink.  So the integration runs segment by segment in *locked modes*:
between the located jumps the right-hand side
is smooth; ``solve_ivp`` stops exactly at the first mode boundary (terminal ``events``, plus a dense
sub-step scan for boundaries crossed and re-crossed inside one step), the mode is switched and the
integration restarts from the event state.  The time break points of the speed and load profiles are
segment ends too (the profiles are linear in between: :func:`_chunk`).

:func:`integrate` drives a *system* object; the systems live in :mod:`.models` (muller, two-wheel,
train) and :mod:`.lateral_model`.  A system provides

* ``n_dof``, ``meshes`` (one :class:`.mesh._Mesh` per mesh), ``speed_prof``, ``load_prof``, ``wsr``;
* ``start_chunk(ib, t, tb)``: the profile chunk on [t, tb] (the ib-th time interval);
  ``zero_chunk()``: the chunk used when only t = 0 is output;
* ``initial_modes(y, chunk)``: ``(modes, extra)``, ``modes[s] = [n, k, c, g]`` per mesh (phase period,
  phase interval, contact mode, friction's slide mode) and ``extra`` any further mode state (lateral:
  bearing modes);
* ``make_rhs(modes, extra, chunk)``: ``(rhs, mcs)``, the right-hand side locked in the modes and the
  per-mesh mode constants;
* ``make_events(modes, extra, mcs)``: ``(events, actions)``, terminal events leaving the modes, each
  action ``(kind, index, value)`` with kind "phase" (mesh index, +-1), "contact" (mesh index, new c),
  "slide" (mesh index, new g) or a kind of the system's own, applied by ``switch(extra, kind, index,
  value, y)``;
* ``deflection(s, n, k, t, y)``: d = delta + E of mesh s in phase mode (n, k) and its rate;
  ``sliding(s, mode, y)``: the sliding velocity v_sl (m/s) of mesh s in its locked mode (for
  re-classifying the slide mode after a tooth change);
* ``output_buffers(n_t)`` and ``outputs(ts, ys, modes, extra, mcs)``: the output arrays (time on the
  last axis, NaN-filled) and their values at the sample times ts of the current segment, evaluated
  from the dense-output states in the mode that was active when the sample time was reached.

Friction's slide modes: the direction sigma(v_sl / v_0) of docs/scenario.md is +-1 for |v_sl| >= v_0
and a quintic in between, with a jump of its third derivative at |v_sl| = v_0; left inside a step, that
kink costs DOP853 its order, so each mesh with friction has a slide mode g (+1, 0, -1) and the segments
end where |v_sl| crosses v_0 (figures: the package docstring, "Discontinuities").

Event hysteresis: 1e-10 of a mesh period on the phase, 1e-15 m on the deflection, 1e-10 of v_0 on the
sliding velocity (a state resting on a boundary cannot trigger an endless chain of zero-length
segments; more than 1000 in a row raise).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from .modes import _slide_mode
from .scenario import profile_value

_ETA_U = 1e-10  # event hysteresis in mesh periods
_ETA_D = 1e-15  # event hysteresis in metres of mesh deflection
_ETA_X = 1e-10  # event hysteresis of x = v_sl / v_0 (friction's slide modes)
_MAX_ZERO_SEGMENTS = 1000


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


def _chunk(model, ta: float, tb: float, theta_a: float) -> dict:
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


def phase_events(stage: int, n: int, k: int, mesh, ip: int) -> tuple[list, list]:
    """The two terminal events that end the locked phase mode (n, k) of mesh ``stage`` of a chain whose
    pinion angle is y[ip] (u = y[ip] z1 / 2 pi), with their mode changes (kind, stage, step)."""
    cz = mesh.cz
    lo = n + float(mesh.bA[k]) - _ETA_U
    hi = n + float(mesh.bB[k]) + _ETA_U

    def ev_up(t, y, ip=ip, cz=cz, hi=hi):
        return y[ip] * cz - hi

    def ev_down(t, y, ip=ip, cz=cz, lo=lo):
        return y[ip] * cz - lo

    ev_up.terminal, ev_up.direction = True, 1.0
    ev_down.terminal, ev_down.direction = True, -1.0
    return [ev_up, ev_down], [("phase", stage, +1), ("phase", stage, -1)]


def _contact_edges(lu: float, c: int) -> list[tuple[float, float, int]]:
    """Dead-zone edges to watch from contact state c (1 drive flank, -1 back flank, 0 in the gap):
    (offset of d, crossing direction, contact state after the crossing), with hysteresis _ETA_D."""
    if c == 1:
        return [(-(lu - _ETA_D), -1.0, 0)]
    if c == -1:
        return [(lu - _ETA_D, 1.0, 0)]
    return [(-(lu + _ETA_D), 1.0, 1), (lu + _ETA_D, -1.0, -1)]


def _slide_edges(g: int) -> list[tuple[float, float, int]]:
    """Edges of friction's slide mode g (+1: x = v_sl / v_0 >= 1, -1: x <= -1, 0: |x| < 1) as (level of
    x, crossing direction, slide mode after the crossing), with hysteresis _ETA_X."""
    if g == 1:
        return [(1.0 - _ETA_X, -1.0, 0)]
    if g == -1:
        return [(-1.0 + _ETA_X, 1.0, 0)]
    return [(1.0 + _ETA_X, 1.0, 1), (-1.0 - _ETA_X, -1.0, -1)]


def slide_events(index: int, g: int, inv_v0: float, v_sl) -> tuple[list, list]:
    """Terminal events leaving friction's slide mode g of mesh ``index``, whose sliding velocity in
    the current locked mode is ``v_sl(y)`` (y one state or states in columns), with their mode changes
    ("slide", index, new g)."""
    events, actions = [], []
    for level, direction, new_g in _slide_edges(g):

        def ev(t, y, level=level):
            return v_sl(y) * inv_v0 - level

        ev.terminal, ev.direction = True, direction
        events.append(ev)
        actions.append(("slide", index, new_g))
    return events, actions


def _segment(rhs, t: float, tb: float, y, events, method: str, rtol: float, atol, first):
    """Integrate one smooth segment from t towards tb, stopping at the first jump.

    Returns (result, t_end, y_end, indices of the events that fired there, 1 if the jump was found
    by the sub-step scan rather than by solve_ivp).
    """
    # A trial step that is too long for a stiff new mode can overflow inside its stages; the error norm
    # is then not finite and solve_ivp rejects the step and retries shorter (industrial-two-stage's
    # separation case did so 3 times). Those rejected stages are not results: silence their floating-
    # point warnings here and check instead that every accepted state is finite. A stage whose state has
    # already overflowed gets a non-finite slope without calling rhs (whose math.cos would raise on inf:
    # the conveyor's separation case with friction from the sliding velocity did).

    def guarded(t, y):
        if not np.all(np.isfinite(y)):
            return np.full_like(y, np.nan)
        return rhs(t, y)

    with np.errstate(over="ignore", invalid="ignore"):
        res = solve_ivp(
            guarded,
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
    if not np.all(np.isfinite(res.y)):
        raise RuntimeError(f"non-finite accepted state between t = {t} and {res.t[-1]}")
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


def _step_hint(res, h_prev):
    """First step for the next segment: the last full step size solve_ivp took."""
    ts_steps = res.sol.ts
    if ts_steps.size >= 3:
        return float(ts_steps[-2] - ts_steps[-3])
    if ts_steps.size == 2 and res.status == 0:
        return float(ts_steps[-1] - ts_steps[-2])
    return h_prev


def integrate(system, y: np.ndarray, t_eval: np.ndarray, rtol: float, atol, method: str) -> dict:
    """Segmented integration of ``system`` from the initial state ``y = [q, v]`` at t = 0 over the output
    times ``t_eval`` (see the module docstring).

    Returns Y (2 n_dof x n_t states), out (the system's output arrays), nfev, n_segments (restarts of
    solve_ivp) and n_missed (mode boundaries found inside a step by the dense scan).
    """
    t_stop = float(t_eval[-1])
    n_t = t_eval.size
    Y = np.full((2 * system.n_dof, n_t), np.nan)
    out = system.output_buffers(n_t)
    tbreaks = _time_breaks(system, t_stop)
    chunk = system.start_chunk(0, 0.0, tbreaks[0]) if t_stop > 0.0 else None
    modes, extra = system.initial_modes(y, chunk)

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
            for key, val in system.outputs(ts, ys, modes, extra, mcs).items():
                out[key][..., i_out:j] = val
            i_out = j

    if t_stop == 0.0:
        _, mcs = system.make_rhs(modes, extra, system.zero_chunk())
        fill_outputs(None, 0.0, mcs, True)

    for ib, tb in enumerate(tbreaks):
        if t >= tb:  # t_stop == 0
            break
        if ib > 0:
            chunk = system.start_chunk(ib, t, tb)
        last_chunk = ib == len(tbreaks) - 1
        while t < tb:
            rhs, mcs = system.make_rhs(modes, extra, chunk)
            events, actions = system.make_events(modes, extra, mcs)
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
                    raise RuntimeError(f"mode chattering at t={t_new} (modes {modes}, {extra})")
                phase_changed, contact_set, slide_set = set(), set(), set()
                for m in fired:
                    kind, s, val = actions[m]
                    if kind == "phase":
                        modes[s][0], modes[s][1] = system.meshes[s].step_phase(modes[s][0], modes[s][1], val)
                        phase_changed.add(s)
                    elif kind == "contact":
                        modes[s][2] = val
                        contact_set.add(s)
                    elif kind == "slide":
                        modes[s][3] = val
                        slide_set.add(s)
                    else:
                        system.switch(extra, kind, s, val, y_new)
                for s in sorted(phase_changed - slide_set):
                    mesh = system.meshes[s]
                    if mesh.mu != 0.0:
                        # the friction arms jump at a tooth change, and v_sl with them: re-classify
                        x = float(system.sliding(s, modes[s], y_new)) * mesh.inv_v0
                        modes[s][3] = _slide_mode(x, modes[s][3])
                for s in sorted(phase_changed - contact_set):
                    mesh = system.meshes[s]
                    if mesh.lu > 0.0:
                        # the error E can jump at a tooth change (a = 0 or 1): re-classify the contact
                        d_new, dd_new = system.deflection(s, modes[s][0], modes[s][1], t_new, y_new)
                        if abs(abs(d_new) - mesh.lu) > 10 * _ETA_D:
                            modes[s][2] = mesh.contact_mode(float(d_new), float(dd_new))
            t, y = t_new, y_new
    if i_out < n_t:
        raise RuntimeError("internal error: not all output times were filled")
    return {"Y": Y, "out": out, "nfev": nfev, "n_segments": n_segments, "n_missed": n_missed}
