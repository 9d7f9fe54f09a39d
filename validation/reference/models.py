"""The torsional models' right-hand sides as systems for :func:`.integrate.integrate`:
:class:`_SingleMesh` (topologies "muller" and "two-wheel", one mesh) and :class:`_Train` (topology
"train", N >= 1 stages, 2N + 2 torsional coordinates; a legacy "one-stage" scene is the train of one
stage).  For N = 1 the train right-hand side performs the same floating-point operations as the
former one-stage right-hand side (coupling = shaft 0, output shaft = shaft 1).
"""

from __future__ import annotations

import numpy as np

from .integrate import _ETA_U, _chunk, _contact_edges, phase_events, slide_events
from .mesh import _Mesh
from .modes import _mesh_force, _mode_error, _mode_friction, _slide_mode
from .scenario import chain_constants, stage_F_rated, stage_view, topology, train_stages


class _SingleMesh(_Mesh):
    """A resolved muller or two-wheel scenario: its one mesh (built from the mesh view of stage 0),
    motor, inertias and profiles.  muller: 1 coordinate (the deflection x), the pinion angle theta(t)
    prescribed by the speed profile; two-wheel: pinion and wheel angles on rigid shafts."""

    def __init__(self, scenario: dict):
        self.scene = topology(scenario)
        if self.scene not in ("muller", "two-wheel"):
            raise ValueError(f"not a one-mesh topology: {self.scene!r}")
        sc = stage_view(scenario, 0)
        self.sc = scenario
        super().__init__(sc)
        d_ = sc["design"]
        mot = d_["motor"]
        self.wsr = float(mot["synchronous_speed_rad_s"])
        self.Mb = float(mot["breakdown_torque_Nm"])
        self.sb = float(mot["breakdown_slip"])
        self.Is = float(mot["inertia_kg_m2"])
        self.I1 = float(d_["pinion"]["inertia_kg_m2"])
        self.I2 = float(d_["wheel"]["inertia_kg_m2"])
        self.Im = float(d_["machine"]["inertia_kg_m2"])
        self.Mrated = float(d_["machine"]["rated_torque_Nm"])
        op = scenario["operation"]
        self.speed_prof = op["speed_profile"]
        self.load_prof = op["load_profile"]
        self.n_dof = {"muller": 1, "two-wheel": 2}[self.scene]
        self.meshes = [self]
        self.theta = _zero_theta  # prescribed pinion angle of the current chunk (muller)

    # -- kinematics of the mesh (u, delta, delta_dot) ------------------------------------------
    def kin(self, t, y, theta):
        """theta: callable t -> prescribed pinion angle (muller) or unused."""
        if self.scene == "muller":
            return theta(t) * self.cz, y[0], y[1]
        nd = self.n_dof
        return y[0] * self.cz, self.r1 * y[0] - self.r2 * y[1], self.r1 * y[nd] - self.r2 * y[nd + 1]

    def u_dot(self, t, y, chunk) -> float:
        if self.scene == "muller":
            return chunk["ws"](t) * self.cz
        return y[self.n_dof] * self.cz

    # -- system interface of integrate() -------------------------------------------------------
    def start_chunk(self, ib: int, t: float, tb: float) -> dict:
        """Chunk on [t, tb]; muller: the prescribed angle continues from theta(t) of the last chunk."""
        theta_a = 0.0 if ib == 0 else self.theta(t)
        chunk = _chunk(self, t, tb, theta_a)
        wsr, ta, sa, ss, tha = self.wsr, chunk["ta"], chunk["sa"], chunk["ss"], chunk["theta_a"]

        def theta(tt):
            tau = tt - ta
            return tha + wsr * (sa * tau + 0.5 * ss * tau * tau)

        self.theta = theta
        return chunk

    def zero_chunk(self) -> dict:
        self.theta = _zero_theta
        return _chunk(self, 0.0, 1.0, 0.0)

    def initial_modes(self, y, chunk):
        u0, _, _ = self.kin(0.0, y, self.theta)
        n, k = self.phase_mode(u0, self.u_dot(0.0, y, chunk) if chunk else 0.0)
        d0, dd0 = self.deflection(0, n, k, 0.0, y)
        g = _slide_mode(self.sliding(0, [n, k, 0, 0], y) * self.inv_v0) if self.mu else 0
        return [[n, k, self.contact_mode(d0, dd0), g]], None

    def deflection(self, s: int, n: int, k: int, t, y) -> tuple[float, float]:
        """d = delta + E in mode (n, k) and its rate (for re-classifying the contact mode)."""
        u, delta, ddot = self.kin(t, y, self.theta)
        return delta + _mode_error(self.mode_consts(n, k, 0), u - n), ddot

    def sliding(self, s: int, mode: list, y):
        """Sliding velocity v_sl = rho_1 w_p - rho_2 w_w in the locked phase mode (two-wheel; y one state
        or states in columns)."""
        p = y[0] * self.cz - mode[0]
        q = (p - self.ppp) * self.pb
        return (self.r1tan + q) * y[2] - (self.r2tan - q) * y[3]

    def output_buffers(self, n_t: int) -> dict:
        return {"F": np.full(n_t, np.nan), "T": np.full(n_t, np.nan)}

    def outputs(self, ts, ys, modes, extra, mcs) -> dict:
        u, delta, ddot = self.kin(ts, ys, self.theta)
        p = u - modes[0][0]
        F = _mesh_force(mcs[0], p, delta, ddot)
        if self.scene == "muller":  # no friction: the pinion angle is prescribed
            return {"F": F, "T": np.zeros(ts.size)}
        nd = self.n_dof
        return {"F": F, "T": _mode_friction(self, mcs[0], modes[0][3], p, F, ys[nd], ys[nd + 1])[0]}

    # -- right-hand sides ----------------------------------------------------------------------
    def make_rhs(self, modes: list, extra, chunk: dict):
        ((n, k, c, g),) = modes
        mc = self.mode_consts(n, k, c)
        ta, sa, ss, la, ls = chunk["ta"], chunk["sa"], chunk["ss"], chunk["la"], chunk["ls"]
        wsr, Mb, sb = self.wsr, self.Mb, self.sb
        sbsq = sb * sb
        Mrated = self.Mrated
        r1, r2, cz = self.r1, self.r2, self.cz
        mesh = _mesh_force
        friction = _mode_friction
        nf = float(n)
        array = np.array

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

            return rhs, [mc]

        J1 = self.Is + self.I1
        J2 = self.I2 + self.Im

        def rhs(t, y):
            p1, p2, w1, w2 = y.tolist()
            tau = t - ta
            p = p1 * cz - nf
            F = mesh(mc, p, r1 * p1 - r2 * p2, r1 * w1 - r2 * w2)
            T, rho1, rho2, _ = friction(self, mc, g, p, F, w1, w2)  # T = -mu e |F| sigma(v_sl / v_0)
            slip = (wsr * (sa + ss * tau) - w1) / wsr
            Ms = 2.0 * Mb * sb * slip / (slip * slip + sbsq)
            Mr = Mrated * (la + ls * tau)
            return array([w1, w2, (Ms - r1 * F + T * rho1) / J1, (r2 * F - T * rho2 - Mr) / J2])

        return rhs, [mc]

    # -- events --------------------------------------------------------------------------------
    def make_events(self, modes: list, extra, mcs: list):
        """Terminal events leaving the locked mode; each carries the resulting mode change."""
        ((n, k, c, g),) = modes
        mc = mcs[0]
        lo = n + float(self.bA[k]) - _ETA_U
        hi = n + float(self.bB[k]) + _ETA_U
        kin = self.kin
        theta = self.theta
        nf = float(n)

        def ev_up(t, y):
            return kin(t, y, theta)[0] - hi

        def ev_down(t, y):
            return kin(t, y, theta)[0] - lo

        ev_up.terminal, ev_up.direction = True, 1.0
        ev_down.terminal, ev_down.direction = True, -1.0
        events = [ev_up, ev_down]
        actions = [("phase", 0, +1), ("phase", 0, -1)]
        if self.lu > 0.0:

            def dfun(t, y):
                u, delta, _ = kin(t, y, theta)
                return delta + _mode_error(mc, u - nf)

            for offset, direction, new_c in _contact_edges(self.lu, c):

                def ev(t, y, offset=offset):
                    return dfun(t, y) + offset

                ev.terminal, ev.direction = True, direction
                events.append(ev)
                actions.append(("contact", 0, new_c))
        if self.mu:
            ev, ac = slide_events(0, g, self.inv_v0, lambda y, mode=list(modes[0]): self.sliding(0, mode, y))
            events += ev
            actions += ac
        return events, actions

    def default_atol(self, rtol: float) -> np.ndarray:
        if self.scene == "muller":
            return np.array([1.0, self.omega_n]) * rtol * self.defl_scale
        ang = rtol * self.defl_scale / max(self.r1, self.r2)
        return np.concatenate((np.full(self.n_dof, ang), np.full(self.n_dof, ang * self.omega_n)))


def _zero_theta(tt):
    return 0.0


class _Train:
    """Constants of a resolved train scenario (N stages, 2N + 2 torsional coordinates).

    Coordinates ``[motor, pinion_1, wheel_1, ..., pinion_N, wheel_N, machine]``: stage s (0-based
    here) has its pinion at index 1 + 2s and its wheel at 2 + 2s, and shaft j joins the coordinates
    2j and 2j + 1 (shaft 0: motor - pinion_1, shaft s: wheel_s - pinion_(s+1), shaft N: wheel_N -
    machine).  Each mesh is a :class:`_Mesh` built from its :func:`stage_view`; every mesh has its own
    locked mode ``(n_s, k_s, c_s)``, a segment is locked in all of them at once and ends at the first
    boundary event of *any* mesh.
    """

    def __init__(self, sc: dict):
        self.sc = sc
        stages = train_stages(sc)
        self.N = len(stages)
        self.n_dof = 2 * self.N + 2
        self.meshes = [_Mesh(stage_view(sc, s), Fr) for s, Fr in enumerate(stage_F_rated(sc))]
        self.ip = [1 + 2 * s for s in range(self.N)]
        self.iw = [2 + 2 * s for s in range(self.N)]
        (self.shaft_k, self.shaft_C, self.wsr, self.Mb, self.sb, self.inertia, self.Mrated) = chain_constants(
            sc, stages
        )
        self.Frated = np.array([m.Frated for m in self.meshes])
        op = sc["operation"]
        self.speed_prof = op["speed_profile"]
        self.load_prof = op["load_profile"]

    # -- per-mesh kinematics (u, delta, delta_dot); y may be one state or states in columns -----
    def kin(self, s: int, y):
        m, ip, iw, nd = self.meshes[s], self.ip[s], self.iw[s], self.n_dof
        return y[ip] * m.cz, m.r1 * y[ip] - m.r2 * y[iw], m.r1 * y[nd + ip] - m.r2 * y[nd + iw]

    def deflection(self, s: int, n: int, k: int, t, y) -> tuple[float, float]:
        """d = delta + E of stage s in phase mode (n, k), and its rate."""
        u, delta, ddot = self.kin(s, y)
        return delta + _mode_error(self.meshes[s].mode_consts(n, k, 0), u - n), ddot

    def sliding(self, s: int, mode: list, y):
        """Sliding velocity v_sl = rho_1 w_p - rho_2 w_w of stage s in its locked phase mode."""
        m, ip, iw, nd = self.meshes[s], self.ip[s], self.iw[s], self.n_dof
        q = (y[ip] * m.cz - mode[0] - m.ppp) * m.pb
        return (m.r1tan + q) * y[nd + ip] - (m.r2tan - q) * y[nd + iw]

    # -- system interface of integrate() -------------------------------------------------------
    def start_chunk(self, ib: int, t: float, tb: float) -> dict:
        return _chunk(self, t, tb, 0.0)

    def zero_chunk(self) -> dict:
        return _chunk(self, 0.0, 1.0, 0.0)

    def output_buffers(self, n_t: int) -> dict:
        return {"F": np.full((self.N, n_t), np.nan), "T": np.full((self.N, n_t), np.nan)}

    def outputs(self, ts, ys, modes, extra, mcs) -> dict:
        F = np.empty((self.N, ts.size))
        T = np.empty((self.N, ts.size))
        nd = self.n_dof
        for s in range(self.N):
            u, delta, ddot = self.kin(s, ys)
            p = u - modes[s][0]
            F[s] = _mesh_force(mcs[s], p, delta, ddot)
            m, g = self.meshes[s], modes[s][3]
            T[s] = _mode_friction(m, mcs[s], g, p, F[s], ys[nd + self.ip[s]], ys[nd + self.iw[s]])[0]
        return {"F": F, "T": T}

    def initial_modes(self, y, chunk):
        modes = []
        for s, m in enumerate(self.meshes):
            u, _, _ = self.kin(s, y)
            n, k = m.phase_mode(float(u), float(y[self.n_dof + self.ip[s]]) * m.cz)
            d, dd = self.deflection(s, n, k, 0.0, y)
            g = _slide_mode(self.sliding(s, [n, k, 0, 0], y) * m.inv_v0) if m.mu else 0
            modes.append([n, k, m.contact_mode(float(d), float(dd)), g])
        return modes, None

    # -- right-hand side in locked modes -------------------------------------------------------
    def make_rhs(self, modes: list, extra, chunk: dict):
        """First-order right-hand side with every mesh locked in its mode; also returns the per-mesh
        mode constants (for the outputs)."""
        mcs = []
        stage_data = []
        for s, (n, k, c, g) in enumerate(modes):
            m = self.meshes[s]
            mc = m.mode_consts(n, k, c)
            mcs.append(mc)
            stage_data.append((self.ip[s], self.iw[s], m.r1, m.r2, m.cz, float(n), mc, m, g))
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
        friction = _mode_friction
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
            for s, (ip, iw, r1, r2, cz, nf, mc, m, g) in enumerate(stage_data):
                p = q[ip] * cz - nf
                F = mesh(mc, p, r1 * q[ip] - r2 * q[iw], r1 * v[ip] - r2 * v[iw])
                T, rho1, rho2, _ = friction(m, mc, g, p, F, v[ip], v[iw])  # T = -mu e |F| sigma(v_sl / v_0)
                # I_ps phi_ps'' = S_{s-1} - r_ps F_s + M_zt1,s;  I_ws phi_ws'' = r_ws F_s - M_zt2,s - S_s
                acc.append((S[s] - r1 * F + T * rho1) / Ip[s])
                acc.append((r2 * F - T * rho2 - S[s + 1]) / Iw[s])
            acc.append((S[-1] - Mr) / Im)  # machine: I_m phi_M'' = S_N - M_r
            return array(v + acc)

        return rhs, mcs

    # -- events --------------------------------------------------------------------------------
    def make_events(self, modes: list, extra, mcs: list):
        """Terminal events leaving the locked modes of all meshes; actions[m] = (kind, stage, value)."""
        events, actions = [], []
        for s, (n, k, c, g) in enumerate(modes):
            m = self.meshes[s]
            ip, iw, cz, r1, r2 = self.ip[s], self.iw[s], m.cz, m.r1, m.r2
            phase, phase_actions = phase_events(s, n, k, m, ip)
            events += phase
            actions += phase_actions
            if m.lu > 0.0:
                for offset, direction, new_c in _contact_edges(m.lu, c):

                    def ev(t, y, offset=offset, c_=(ip, iw, cz, r1, r2, mcs[s])):
                        ip, iw, cz, r1, r2, mc = c_
                        return r1 * y[ip] - r2 * y[iw] + _mode_error(mc, y[ip] * cz - mc.nf) + offset

                    ev.terminal, ev.direction = True, direction
                    events.append(ev)
                    actions.append(("contact", s, new_c))
            if m.mu:
                ev, ac = slide_events(
                    s, g, m.inv_v0, lambda y, s=s, mode=[n, k, c, g]: self.sliding(s, mode, y)
                )
                events += ev
                actions += ac
        return events, actions

    def default_atol(self, rtol: float) -> np.ndarray:
        """Same rule as the one-mesh scenes, with the smallest angle scale and the fastest mesh of all
        stages."""
        ang = min(rtol * m.defl_scale / max(m.r1, m.r2) for m in self.meshes)
        om = max(m.omega_n for m in self.meshes)
        return np.concatenate((np.full(self.n_dof, ang), np.full(self.n_dof, ang * om)))
