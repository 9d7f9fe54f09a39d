"""A whole drive of planetary and parallel stages (docs/planetary.md "The stage in a drive", with
docs/scenario.md "Gear trains"): motor -> shaft 0 -> stage 1 -> shaft 1 -> ... -> machine.

Coordinates: ``[motor, stage 1, ..., stage N, machine]``; a parallel stage is ``[pinion, wheel]``
(torsional, as in "Gear trains"), a planetary stage its ``3 (N_p + 3)`` member coordinates
(:mod:`.planetary_model`).  Shafts join chain angles: the motor, a pinion / wheel, ``s_in theta_in`` /
``s_out theta_out`` of a planetary stage; the input member receives ``s_in S_in``, the output
``-s_out S_out`` (the contract's turning-sense rule).  Friction ``condition.friction_coefficient`` in
every mesh, its direction opposing the sliding velocity (``condition.friction_transition_speed_m_s``
v_0): a parallel stage's moments ``-r1 F + T rho_1``, ``r2 F - T rho_2`` (docs/scenario.md), the
planetary meshes' forces at the contact point (docs/planetary.md, "Friction"); the steady start
ignores it (parallel-only trains: :func:`.simulate_reference`).
"""

from __future__ import annotations

import numpy as np

from .integrate import _contact_edges, _output_times, integrate, phase_events, slide_events
from .law import effective_stiffness, total_error
from .mesh import _Mesh
from .modes import _mesh_force, _mode_error, _mode_friction, _slide_mode
from .planetary import _Chain, _PlanetaryBlock, planetary_signals
from .planetary_model import PlanetaryStage
from .scenario import design_shafts, friction_speed, profile_value, steady_slip


class _ParallelBlock:
    """A parallel stage ``[pinion, wheel]`` in the chain (torsional; friction T = -mu e(p) |F| sigma(v_sl /
    v_0) with the arms rho_1 = r1 tan(alpha) + (p - pitch) p_b, rho_2 = r2 tan(alpha) - (p - pitch) p_b
    and v_sl = rho_1 w_p - rho_2 w_w, :func:`.modes._mode_friction`)."""

    def __init__(self, law: _Mesh, view: dict, off: int, m0: int, inertia: tuple[float, float]):
        self.law, self.view, self.off, self.m0 = law, view, off, m0
        self.n_dof = 2
        self.meshes = [law]
        self.i_in, self.sg_in, self.i_out, self.sg_out = off, 1.0, off + 1, 1.0
        self.sl = slice(off, off + 2)
        self.inertia = np.array(inertia)

    def mass(self) -> np.ndarray:
        return self.inertia

    def _kin(self, q, v):
        m = self.law
        return q[0] * m.cz, m.r1 * q[0] - m.r2 * q[1], m.r1 * v[0] - m.r2 * v[1]

    def forces(self, q, v, modes, mcs) -> np.ndarray:
        m = self.law
        u, delta, ddot = self._kin(q, v)
        p = u - modes[0][0]
        F = _mesh_force(mcs[0], p, delta, ddot)
        if not m.mu:
            return np.array([-m.r1 * F, m.r2 * F])
        T, rho1, rho2, _ = _mode_friction(m, mcs[0], modes[0][3], p, F, v[0], v[1])
        return np.array([-m.r1 * F + T * rho1, m.r2 * F - T * rho2])

    def frictions(self, qs, vs, modes, mcs, F_rows) -> list:
        """Friction force T (N) at states in columns."""
        u = self._kin(qs, vs)[0]
        return [_mode_friction(self.law, mcs[0], modes[0][3], u - modes[0][0], F_rows[0], vs[0], vs[1])[0]]

    def initial_modes(self, q, v) -> list:
        m = self.law
        u, delta, ddot = self._kin(q, v)
        n, k = m.phase_mode(float(u), float(v[0]) * m.cz)
        d = delta + _mode_error(m.mode_consts(n, k, 0), u - n)
        g = _slide_mode(self.sliding(0, [n, k, 0, 0], q, v) * m.inv_v0) if m.mu else 0
        return [[n, k, m.contact_mode(float(d), float(ddot)), g]]

    def deflection(self, j: int, n: int, k: int, q, v):
        u, delta, ddot = self._kin(q, v)
        return delta + _mode_error(self.law.mode_consts(n, k, 0), u - n), ddot

    def sliding(self, j: int, mode: list, q, v):
        """v_sl = rho_1 w_p - rho_2 w_w in the locked phase mode (q, v: the block's coordinates)."""
        m = self.law
        qq = (q[0] * m.cz - mode[0] - m.ppp) * m.pb
        return (m.r1tan + qq) * v[0] - (m.r2tan - qq) * v[1]

    def events(self, modes, mcs, nd: int):
        m, (n, k, c, g) = self.law, modes[0]
        events, actions = phase_events(self.m0, n, k, m, self.off)
        if m.lu > 0.0:
            ip, iw = self.off, self.off + 1
            for offset, direction, new_c in _contact_edges(m.lu, c):

                def ev(t, y, offset=offset, mc=mcs[0]):
                    return m.r1 * y[ip] - m.r2 * y[iw] + _mode_error(mc, y[ip] * m.cz - mc.nf) + offset

                ev.terminal, ev.direction = True, direction
                events.append(ev)
                actions.append(("contact", self.m0, new_c))
        if m.mu:
            sl, mode = self.sl, [n, k, c, g]
            ev, ac = slide_events(self.m0, g, m.inv_v0, lambda y: self.sliding(0, mode, y[sl], y[nd:][sl]))
            events += ev
            actions += ac
        return events, actions

    def outputs(self, qs, vs, modes, mcs) -> list:
        u, delta, ddot = self._kin(qs, vs)
        return [_mesh_force(mcs[0], u - modes[0][0], delta, ddot)]


def _parallel_view(scenario: dict, st: dict, s: int, F_rated: float) -> dict:
    """The one-stage-shaped mesh view of parallel stage s (its random draw: meta.stage_index = s)."""
    return {
        "meta": {**scenario["meta"], "scene": "train-stage", "stage_index": s},
        "design": {
            "pinion": st["pinion"],
            "wheel": st["wheel"],
            "mesh": st["mesh"],
            "machine": {"rated_torque_Nm": F_rated * float(st["wheel"]["base_radius_m"])},
        },
        "production": {"error_mode": st["error_mode"], "eccentricity": st.get("eccentricity", [])},
        "condition": {
            "friction_coefficient": float(scenario["condition"].get("friction_coefficient", 0.0)),
            **friction_speed(scenario),
            "damaged_teeth": st.get("damaged_teeth", []),
            "pitted_teeth": st.get("pitted_teeth", []),
        },
    }


def _arms(stage: dict, s: int, seed: int) -> tuple[float, float]:
    """(r_in, r_out) of stage s: base radii (parallel) or the torque arms r_eq (planetary)."""
    if stage.get("type", "parallel") == "planetary":
        st = PlanetaryStage(stage, seed=seed, stage_index=s)
        return st.r_eq_in, st.r_eq_out
    return float(stage["pinion"]["base_radius_m"]), float(stage["wheel"]["base_radius_m"])


def drive_F_rated(scenario: dict) -> np.ndarray:
    """Rated force per stage: F_rated,N = M_rated / r_out,N, F_rated,s = F_rated,s+1 r_in,s+1 / r_out,s
    (planetary: per planet and mesh, with r = r_eq)."""
    stages = scenario["design"]["stages"]
    seed = int(scenario["meta"]["seed"])
    arms = [_arms(st, s, seed) for s, st in enumerate(stages)]
    F = np.empty(len(stages))
    F[-1] = float(scenario["design"]["machine"]["rated_torque_Nm"]) / arms[-1][1]
    for s in range(len(stages) - 2, -1, -1):
        F[s] = F[s + 1] * arms[s + 1][0] / arms[s][1]
    return F


def build_drive(scenario: dict):
    """(system, blocks, F_rated per stage) of a resolved drive scenario."""
    d = scenario["design"]
    stages = d["stages"]
    shafts = design_shafts(scenario)
    if len(stages) < 1 or len(shafts) != len(stages) + 1:
        raise ValueError(f"a drive of {len(stages)} stages needs {len(stages) + 1} shafts, got {len(shafts)}")
    seed = int(scenario["meta"]["seed"])
    mu = float(scenario["condition"].get("friction_coefficient", 0.0))
    v0 = scenario["condition"].get("friction_transition_speed_m_s")  # None: the contract's default
    Fr = drive_F_rated(scenario)
    blocks, mass = [], [float(d["motor"]["inertia_kg_m2"])]
    off, m0 = 1, 0
    for s, st in enumerate(stages):
        if st.get("type", "parallel") == "planetary":
            stage = PlanetaryStage(
                st,
                seed=seed,
                stage_index=s,
                F_rated=Fr[s],
                friction_coefficient=mu,
                friction_transition_speed_m_s=v0,
            )
            b = _PlanetaryBlock(stage, off, m0)
        else:
            view = _parallel_view(scenario, st, s, Fr[s])
            inertia = (float(st["pinion"]["inertia_kg_m2"]), float(st["wheel"]["inertia_kg_m2"]))
            b = _ParallelBlock(_Mesh(view, Fr[s]), view, off, m0, inertia)
        blocks.append(b)
        mass += list(b.mass())
        off += b.n_dof
        m0 += len(b.meshes)
    mass.append(float(d["machine"]["inertia_kg_m2"]))
    nd = off + 1
    ends = [(0, 1.0)] + [(b.i_out, b.sg_out) for b in blocks]
    starts = [(b.i_in, b.sg_in) for b in blocks] + [(nd - 1, 1.0)]
    motor = d["motor"]
    chain = {
        "shafts": [
            (a, ga, b_, gb, float(sh["stiffness_Nm_per_rad"]), float(sh.get("damping_Nms_per_rad", 0.0)))
            for (a, ga), (b_, gb), sh in zip(ends, starts, shafts, strict=True)
        ],
        "wsr": float(motor["synchronous_speed_rad_s"]),
        "Mb": float(motor["breakdown_torque_Nm"]),
        "sb": float(motor["breakdown_slip"]),
        "Mrated": float(d["machine"]["rated_torque_Nm"]),
        "speed_profile": scenario["operation"]["speed_profile"],
        "load_profile": scenario["operation"]["load_profile"],
    }
    return _Chain(blocks, nd, np.array(mass), chain=chain), blocks, Fr


def drive_initial_state(scenario: dict, system, blocks, Fr) -> np.ndarray:
    """``[q, v]`` at t = 0: "rest" (the nominal assembly at rest) or "steady" (the contract's steady
    start, stage by stage in power-flow order)."""
    nd = system.n_dof
    y = np.zeros(2 * nd)
    for b in blocks:
        if isinstance(b, _PlanetaryBlock):
            y[b.sl] = b.st.q_nominal
    kind = scenario["operation"]["initial_state"]
    if kind == "rest":
        return y
    if kind != "steady":
        raise ValueError(f"unknown initial_state {kind!r}")
    load0 = float(profile_value(0.0, scenario["operation"]["load_profile"]))
    shaft_k = [sh[4] for sh in system.chain["shafts"]]
    T_in = []
    for b, F in zip(blocks, load0 * Fr, strict=True):
        T_in.append(F * (b.st.r_eq_in if isinstance(b, _PlanetaryBlock) else b.law.r1))
    motor = scenario["design"]["motor"]
    wsr = float(motor["synchronous_speed_rad_s"])
    w = (
        wsr * float(profile_value(0.0, scenario["operation"]["speed_profile"]))
        - steady_slip(T_in[0], motor) * wsr
    )
    y[nd] = w
    phi_in = 0.0  # chain angle of the first stage's input: the gauge
    for s, b in enumerate(blocks):
        if isinstance(b, _PlanetaryBlock):
            st = b.st
            T_out = T_in[s] * st.r_eq_out / st.r_eq_in
            torques = np.zeros(3)
            torques[st.i_in] += st.s_in * T_in[s]
            torques[st.i_out] -= st.s_out * T_out
            wc = st.rigid_speeds(st.input, st.s_in * w)
            q = st.static_equilibrium(torques, theta_gauge=st.s_in * phi_in, carrier_speed_rad_s=wc[2])
            y[b.sl] = q
            y[nd:][b.sl] = st.rigid_state(wc, q)
            phi_out, w = st.s_out * q[3 * st.i_out + 2], st.s_out * wc[st.i_out]
        else:
            m = b.law
            u = phi_in * m.cz
            k = float(effective_stiffness(b.view, u)[0])
            E = float(total_error(b.view, u))
            F = load0 * Fr[s]
            delta = F / k + m.lu - E if F != 0.0 else 0.0
            phi_out = (m.r1 * phi_in - delta) / m.r2
            y[b.off], y[b.off + 1] = phi_in, phi_out
            y[nd + b.off], y[nd + b.off + 1] = w, w * m.r1 / m.r2
            w = w * m.r1 / m.r2
        if s + 1 < len(blocks):
            phi_in = phi_out - T_in[s + 1] / shaft_k[s + 1]
    y[0] = (blocks[0].sg_in * y[blocks[0].i_in]) + T_in[0] / shaft_k[0]
    y[nd - 1] = phi_out - float(scenario["design"]["machine"]["rated_torque_Nm"]) * load0 / shaft_k[-1]
    y[2 * nd - 1] = w
    return y


def simulate_reference_drive(
    scenario: dict, t_eval=None, *, rtol: float = 1e-10, atol=None, method: str = "DOP853"
) -> dict:
    """Integrate a resolved drive (canonical shape; stages planetary or parallel).  Returns time_s,
    coordinates / velocities (n_dof x n_t, ``[motor, stages..., machine]``), per stage (prefix "" for
    stage 1, ``stage_<s>_`` after) the per-planet ``planet_<n>_sun_mesh_force_N`` / ``_ring_...`` and
    ``_kd``, the members' ``<member>_q`` / ``_v``, or a parallel stage's ``mesh_force_N`` / ``kd``;
    F_rated_N per stage, nfev, n_segments."""
    system, blocks, Fr = build_drive(scenario)
    t_eval = _output_times(scenario, t_eval)
    y0 = drive_initial_state(scenario, system, blocks, Fr)
    if atol is None:
        atol = system.default_atol(rtol)
    res = integrate(system, y0, t_eval, rtol, atol, method)
    Y, F, T = res["Y"], res["out"]["F"], res["out"]["T"]
    nd = system.n_dof
    out = {"time_s": t_eval, "coordinates": Y[:nd], "velocities": Y[nd:], "F_rated_N": Fr}
    for s, b in enumerate(blocks):
        prefix = "" if s == 0 else f"stage_{s + 1}_"
        rows, fr = F[b.m0 : b.m0 + len(b.meshes)], T[b.m0 : b.m0 + len(b.meshes)]
        if isinstance(b, _PlanetaryBlock):
            out.update(planetary_signals(b.st, Y, rows, b.off, prefix, fr))
        else:
            out[f"{prefix}mesh_force_N"] = rows[0].copy()
            out[f"{prefix}friction_force_N"] = fr[0].copy()
            out[f"{prefix}kd"] = rows[0] / Fr[s]
    out["nfev"], out["n_segments"] = np.array(res["nfev"]), np.array(res["n_segments"])
    return out


__all__ = ["simulate_reference_drive", "drive_F_rated", "build_drive", "drive_initial_state"]
