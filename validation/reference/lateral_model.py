"""The lateral model as a system of :func:`.integrate.integrate`: a train (a legacy one-stage scenario
as its 1-stage train) whose gears may translate in the housing's x-y plane on linear or hertzian
bearings.  The meshes are the torsional reference's :class:`.mesh._Mesh` (so every stiffness profile,
the faults and the transition width come with it); the hertzian bearings add a mode each (out of
contact, pushing, clamped at f_r <= 0), see the docstring of :mod:`.lateral`. One class, one right-hand
side (~410 lines): its coordinates, modes and events are read together when checking it against the
contract, so it stays whole.
"""

from __future__ import annotations

import math

import numpy as np

from .integrate import _chunk, _contact_edges, phase_events, slide_events
from .lateral_scenario import _AXES, as_train, gear_names, mesh_geometry, resolve_lateral_defaults
from .mesh import _Mesh
from .modes import _mesh_force, _mode_error, _mode_friction, _slide_mode
from .rolling_bearing import RollingBearing
from .scenario import chain_constants, stage_F_rated, stage_view, train_stages

_ETA_R = 1e-15  # event hysteresis on r - c (m)
_ETA_F = 1e-9  # event hysteresis on the hertzian radial force f_r (N)


class _Gear:
    """A lateral gear: name, mass, free axes, indices of its lateral coordinates, bearing."""

    def __init__(self, name, stage, role, gear, first_index):
        self.name, self.stage, self.role = name, stage, role
        self.mass = float(gear["mass_kg"])
        self.axes = _AXES[gear["lateral"]]
        self.idx = {a: first_index + j for j, a in enumerate(self.axes)}
        self.bearing = gear["bearing"]
        self.kind = self.bearing["kind"]
        self.housing_mass = float(self.bearing.get("housing_mass_kg", float("nan")))
        par = self.bearing["parameters"]
        if self.kind == "linear":
            self.k = (float(par["stiffness_x_N_per_m"]), float(par["stiffness_y_N_per_m"]))
            self.C = (float(par["damping_x_Ns_per_m"]), float(par["damping_y_Ns_per_m"]))
        elif self.kind == "rolling-elements":  # smooth: no mode; the gear's rotation turns the inner race
            self.law = RollingBearing(self.bearing)
            self.turn = (1 if role == "pinion" else 2) + 2 * stage
        else:
            self.kb = float(par["contact_stiffness_N_per_m_n"])
            self.c = float(par["radial_clearance_m"])
            self.ex = float(par["exponent"])
            self.Cb = float(par["damping_Ns_per_m"])
            if self.c < 0.0 or self.kb <= 0.0:
                raise ValueError("hertzian bearing needs clearance >= 0 and k_b > 0")

    # hertzian helpers, vectorised over state columns
    def uv(self, y, nd):
        zero = 0.0 * y[0]
        x = y[self.idx[0]] if 0 in self.idx else zero
        yy = y[self.idx[1]] if 1 in self.idx else zero
        vx = y[nd + self.idx[0]] if 0 in self.idx else zero
        vy = y[nd + self.idx[1]] if 1 in self.idx else zero
        return x, yy, vx, vy

    def radial(self, y, nd):
        """(r - c, f_r) with the odd continuation of p^n."""
        x, yy, vx, vy = self.uv(y, nd)
        r = np.sqrt(x * x + yy * yy)
        p = r - self.c
        rs = np.where(r > 0.0, r, 1.0)
        f_r = self.kb * np.sign(p) * np.abs(p) ** self.ex + self.Cb * (x * vx + yy * vy) / rs
        return p, f_r

    def classify(self, y, nd) -> int:
        p, f_r = self.radial(y, nd)
        if float(p) <= 0.0:
            return 0
        return 1 if float(f_r) > 0.0 else 2


class _LatTrain:
    def __init__(self, scenario: dict):
        sc = as_train(resolve_lateral_defaults(scenario))
        self.sc = sc
        stages = train_stages(sc)
        N = self.N = len(stages)
        self.n_tor = 2 * N + 2
        self.Frated = stage_F_rated(sc)
        self.meshes = [_Mesh(stage_view(sc, s), Fr) for s, Fr in enumerate(self.Frated)]
        self.ip = [1 + 2 * s for s in range(N)]
        self.iw = [2 + 2 * s for s in range(N)]
        self.geo = [mesh_geometry(st["mesh"]) for st in stages]
        # lateral gears
        self.gears: list[_Gear] = []
        self.stage_gears = []  # per stage: (pinion _Gear | None, wheel _Gear | None)
        nxt = self.n_tor
        for s, st in enumerate(stages):
            pair = []
            for role, name in zip(("pinion", "wheel"), gear_names(s), strict=True):
                g = st[role]
                if g["lateral"] == "none":
                    pair.append(None)
                    continue
                gear = _Gear(name, s, role, g, nxt)
                # its rotation's sense about +z: the pinion's s1, the wheel's -s1 (docs: Geometry)
                gear.sense = self.geo[s]["s1"] * (1.0 if role == "pinion" else -1.0)
                nxt += len(gear.axes)
                self.gears.append(gear)
                pair.append(gear)
            self.stage_gears.append(tuple(pair))
        self.n_dof = nxt
        self.hertz = [g for g in self.gears if g.kind == "hertzian"]
        (self.shaft_k, self.shaft_C, self.wsr, self.Mb, self.sb, self.inertia, self.Mrated) = chain_constants(
            sc, stages
        )
        op = sc["operation"]
        self.speed_prof = op["speed_profile"]
        self.load_prof = op["load_profile"]
        # projections of the lateral coordinates on n (delta) and on m (the centres' share of the
        # sliding velocity, (u_p' - u_w') . m) per stage: [(index, +-n_a)], [(index, +-m_a)]
        self.proj, self.mproj = [], []
        for s in range(N):
            n, m = self.geo[s]["n"], self.geo[s]["m"]
            terms, mterms = [], []
            for gear, sign in zip(self.stage_gears[s], (1.0, -1.0), strict=True):
                if gear is not None:
                    terms += [(i, sign * float(n[a])) for a, i in gear.idx.items()]
                    mterms += [(i, sign * float(m[a])) for a, i in gear.idx.items()]
            self.proj.append(terms)
            self.mproj.append(mterms)

    # -- kinematics ------------------------------------------------------------------------------
    def kin(self, s: int, y):
        """u, delta, delta_dot of stage s (y one state or states in columns)."""
        m, ip, iw, nd = self.meshes[s], self.ip[s], self.iw[s], self.n_dof
        delta = m.r1 * y[ip] - m.r2 * y[iw]
        ddot = m.r1 * y[nd + ip] - m.r2 * y[nd + iw]
        for i, c in self.proj[s]:
            delta = delta + c * y[i]
            ddot = ddot + c * y[nd + i]
        return y[ip] * m.cz, delta, ddot

    def deflection(self, s, n, k, t, y):
        u, delta, ddot = self.kin(s, y)
        return delta + _mode_error(self.meshes[s].mode_consts(n, k, 0), u - n), ddot

    def sliding(self, s: int, mode: list, y):
        """Sliding velocity v_sl = rho_1 w_p - rho_2 w_w + (u_p' - u_w') . m of stage s in its locked phase
        mode (y one state or states in columns)."""
        m, ip, iw, nd = self.meshes[s], self.ip[s], self.iw[s], self.n_dof
        q = (y[ip] * m.cz - mode[0] - m.ppp) * m.pb
        v_sl = (m.r1tan + q) * y[nd + ip] - (m.r2tan - q) * y[nd + iw]
        for i, c in self.mproj[s]:
            v_sl = v_sl + c * y[nd + i]
        return v_sl

    # -- system interface of integrate() -------------------------------------------------------
    def start_chunk(self, ib: int, t: float, tb: float) -> dict:
        return _chunk(self, t, tb, 0.0)

    def zero_chunk(self) -> dict:
        return _chunk(self, 0.0, 1.0, 0.0)

    def switch(self, bmodes, kind: str, b: int, val: str, y) -> None:
        """Bearing b: leave -> out of contact, clamp -> f_r <= 0, push -> pushing; enter: pushing unless
        it already separates faster than it penetrates."""
        if val == "leave":
            bmodes[b] = 0
        elif val == "clamp":
            bmodes[b] = 2
        elif val == "push":
            bmodes[b] = 1
        else:
            bmodes[b] = 1 if float(self.hertz[b].radial(y, self.n_dof)[1]) > 0.0 else 2

    def output_buffers(self, n_t: int) -> dict:
        out = {"F": np.full((self.N, n_t), np.nan), "T": np.full((self.N, n_t), np.nan)}
        for g in self.gears:
            for kind in ("D", "V", "FB", "FM"):
                out[kind, g.name] = np.full((2, n_t), np.nan)
        return out

    def outputs(self, ts, ys, modes, bmodes, mcs) -> dict:
        F, T, dd, vv, fb, fm = self.forces(ys, modes, bmodes, mcs)
        out = {"F": F, "T": T}
        for g in self.gears:
            nm = g.name
            out["D", nm], out["V", nm], out["FB", nm], out["FM", nm] = dd[nm], vv[nm], fb[nm], fm[nm]
        return out

    def initial_modes(self, y, chunk):
        modes = []
        for s, m in enumerate(self.meshes):
            u, _, _ = self.kin(s, y)
            n, k = m.phase_mode(float(u), float(y[self.n_dof + self.ip[s]]) * m.cz)
            d, dd = self.deflection(s, n, k, 0.0, y)
            g = _slide_mode(self.sliding(s, [n, k, 0, 0], y) * m.inv_v0) if m.mu else 0
            modes.append([n, k, m.contact_mode(float(d), float(dd)), g])
        bmodes = [g.classify(y, self.n_dof) for g in self.hertz]
        return modes, bmodes

    # -- right-hand side -------------------------------------------------------------------------
    def make_rhs(self, modes, bmodes, chunk):
        mcs = []
        stage_data = []
        n_tor, nd = self.n_tor, self.n_dof
        for s, (n, k, c, slide) in enumerate(modes):
            m = self.meshes[s]
            mc = m.mode_consts(n, k, c)
            mcs.append(mc)
            nvec, mvec = self.geo[s]["n"], self.geo[s]["m"]
            lat_p, lat_w = [], []
            gp, gw = self.stage_gears[s]
            if gp is not None:
                lat_p = [(i - n_tor, float(nvec[a]), float(mvec[a])) for a, i in gp.idx.items()]
            if gw is not None:
                lat_w = [(i - n_tor, float(nvec[a]), float(mvec[a])) for a, i in gw.idx.items()]
            stage_data.append(
                (
                    self.ip[s],
                    self.iw[s],
                    m.r1,
                    m.r2,
                    m.cz,
                    float(n),
                    mc,
                    m,
                    slide,
                    self.proj[s],
                    self.mproj[s],
                    lat_p,
                    lat_w,
                )
            )
        rolling = [  # (offset x | None, offset y | None, rotation index, its sense about +z, law)
            (
                g.idx[0] - n_tor if 0 in g.idx else None,
                g.idx[1] - n_tor if 1 in g.idx else None,
                g.turn,
                g.sense,
                g.law.force,
            )
            for g in self.gears
            if g.kind == "rolling-elements"
        ]
        lin = []  # (lateral offset, k, C)
        hz = []  # (offset x | None, offset y | None, kb, c, ex, Cb, mode)
        bm = dict(zip([id(g) for g in self.hertz], bmodes, strict=True))
        for g in self.gears:
            if g.kind == "linear":
                lin += [(i - n_tor, g.k[a], g.C[a]) for a, i in g.idx.items()]
            elif g.kind == "hertzian":
                ox = g.idx[0] - n_tor if 0 in g.idx else None
                oy = g.idx[1] - n_tor if 1 in g.idx else None
                hz.append((ox, oy, g.kb, g.c, g.ex, g.Cb, bm[id(g)]))
        inv_mass = [0.0] * (nd - n_tor)
        for g in self.gears:
            for i in g.idx.values():
                inv_mass[i - n_tor] = 1.0 / g.mass
        n_lat = nd - n_tor
        shafts = [(2 * j, 2 * j + 1, self.shaft_k[j], self.shaft_C[j]) for j in range(self.N + 1)]
        ta, sa, ss, la, ls = chunk["ta"], chunk["sa"], chunk["ss"], chunk["la"], chunk["ls"]
        wsr, Mb, sb = self.wsr, self.Mb, self.sb
        sbsq = sb * sb
        Mrated = self.Mrated
        Is, Im = self.inertia[0], self.inertia[-1]
        Ip = self.inertia[1:-1:2]
        Iw = self.inertia[2:-1:2]
        mesh = _mesh_force
        friction = _mode_friction
        array = np.array
        sqrt = math.sqrt

        def rhs(t, y):
            yl = y.tolist()
            q, v = yl[:nd], yl[nd:]
            ql, vl = q[n_tor:], v[n_tor:]
            tau = t - ta
            S = [kj * (q[a] - q[b]) + Cj * (v[a] - v[b]) for a, b, kj, Cj in shafts]
            slip = (wsr * (sa + ss * tau) - v[0]) / wsr
            Ms = 2.0 * Mb * sb * slip / (slip * slip + sbsq)
            Mr = Mrated * (la + ls * tau)
            acc = [(Ms - S[0]) / Is]
            fl = [0.0] * n_lat
            for s, sd in enumerate(stage_data):
                ip, iw, r1, r2, cz, nf, mc, m, g, proj, mproj, lat_p, lat_w = sd
                delta = r1 * q[ip] - r2 * q[iw]
                ddot = r1 * v[ip] - r2 * v[iw]
                for i, c in proj:
                    delta += c * q[i]
                    ddot += c * v[i]
                p = q[ip] * cz - nf
                F = mesh(mc, p, delta, ddot)
                vc = 0.0  # (u_p' - u_w') . m: the centres' share of the sliding velocity
                for i, c in mproj:
                    vc += c * v[i]
                T, rho1, rho2, _ = friction(m, mc, g, p, F, v[ip], v[iw], vc)  # -mu e |F| sigma(v_sl / v_0)
                acc.append((S[s] - r1 * F + T * rho1) / Ip[s])
                acc.append((r2 * F - T * rho2 - S[s + 1]) / Iw[s])
                for j, na, ma in lat_p:  # pinion: -F n + T m
                    fl[j] += -F * na + T * ma
                for j, na, ma in lat_w:  # wheel: +F n - T m
                    fl[j] += F * na - T * ma
            acc.append((S[-1] - Mr) / Im)
            for j, kk, cc in lin:
                fl[j] -= kk * ql[j] + cc * vl[j]
            for ox, oy, it, sense, law in rolling:
                x, yy = (
                    (ql[ox], vl[ox]) if ox is not None else (0.0, 0.0),
                    (ql[oy], vl[oy]) if oy is not None else (0.0, 0.0),
                )
                fx, fy = law(x[0], yy[0], x[1], yy[1], q[it] * sense)
                if ox is not None:
                    fl[ox] += fx
                if oy is not None:
                    fl[oy] += fy
            for ox, oy, kb, c, ex, Cb, bmode in hz:
                if bmode != 1:
                    continue
                x = ql[ox] if ox is not None else 0.0
                yy = ql[oy] if oy is not None else 0.0
                vx = vl[ox] if ox is not None else 0.0
                vy = vl[oy] if oy is not None else 0.0
                r = sqrt(x * x + yy * yy)
                if r == 0.0:
                    continue
                pen = r - c
                spring = kb * pen**ex if pen >= 0.0 else -kb * (-pen) ** ex
                f_r = spring + Cb * (x * vx + yy * vy) / r
                if ox is not None:
                    fl[ox] -= f_r * x / r
                if oy is not None:
                    fl[oy] -= f_r * yy / r
            return array(v + acc + [f * im for f, im in zip(fl, inv_mass, strict=True)])

        return rhs, mcs

    # -- events ----------------------------------------------------------------------------------
    def make_events(self, modes, bmodes, mcs):
        events, actions = [], []
        for s, (n, k, c, g) in enumerate(modes):
            m = self.meshes[s]
            ip = self.ip[s]
            phase, phase_actions = phase_events(s, n, k, m, ip)
            events += phase
            actions += phase_actions
            if m.lu > 0.0:
                for offset, direction, new_c in _contact_edges(m.lu, c):

                    def ev(t, y, offset=offset, s=s, mc=mcs[s]):
                        u, delta, _ = self.kin(s, y)
                        return delta + _mode_error(mc, u - mc.nf) + offset

                    ev.terminal, ev.direction = True, direction
                    events.append(ev)
                    actions.append(("contact", s, new_c))
            if m.mu:
                ev, ac = slide_events(
                    s, g, m.inv_v0, lambda y, s=s, mode=[n, k, c, g]: self.sliding(s, mode, y)
                )
                events += ev
                actions += ac
        nd = self.n_dof
        for b, (g, bmode) in enumerate(zip(self.hertz, bmodes, strict=True)):
            edges = []
            if bmode == 0:
                edges.append((lambda t, y, g=g: g.radial(y, nd)[0] - _ETA_R, 1.0, "enter"))
            else:
                edges.append((lambda t, y, g=g: g.radial(y, nd)[0] + _ETA_R, -1.0, "leave"))
                if bmode == 1:
                    edges.append((lambda t, y, g=g: g.radial(y, nd)[1] + _ETA_F, -1.0, "clamp"))
                else:
                    edges.append((lambda t, y, g=g: g.radial(y, nd)[1] - _ETA_F, 1.0, "push"))
            for fun, direction, act in edges:

                def ev(t, y, fun=fun):
                    return fun(t, y)

                ev.terminal, ev.direction = True, direction
                events.append(ev)
                actions.append(("bearing", b, act))
        return events, actions

    # -- tolerances ------------------------------------------------------------------------------
    def default_atol(self, rtol: float) -> np.ndarray:
        defl = min(m.defl_scale for m in self.meshes)
        ang = min(rtol * m.defl_scale / max(m.r1, m.r2) for m in self.meshes)
        om = max(m.omega_n for m in self.meshes)
        for g in self.gears:
            if g.kind == "linear":
                kk = max(g.k[a] for a in g.axes)
            elif g.kind == "rolling-elements":  # tangent along the rated force's line, by differences
                Fr = float(self.Frated[g.stage])
                u0 = g.law.static_displacement(np.array([0.0, Fr]), (0, 1))
                h = 1e-3 * float(np.hypot(*u0))
                kk = abs(
                    g.law.force(u0[0], u0[1] + h, 0, 0, 0)[1] - g.law.force(u0[0], u0[1] - h, 0, 0, 0)[1]
                ) / (2 * h)
            else:
                Fr = float(self.Frated[g.stage])
                kk = g.ex * g.kb ** (1.0 / g.ex) * Fr ** (1.0 - 1.0 / g.ex)  # tangent stiffness at F_rated
            om = max(om, math.sqrt(max(kk, 0.0) / g.mass))
        n_lat = self.n_dof - self.n_tor
        pos = np.concatenate((np.full(self.n_tor, ang), np.full(n_lat, rtol * defl)))
        return np.concatenate((pos, pos * om))

    # -- outputs ---------------------------------------------------------------------------------
    def forces(self, ys, modes, bmodes, mcs):
        """Stage forces F (N x n), friction T (N x n), and per lateral gear: centre displacement,
        velocity, bearing force f_b and mesh force on the centre (each 2 x n)."""
        nd = self.n_dof
        nt = ys.shape[1]
        F = np.empty((self.N, nt))
        T = np.empty((self.N, nt))
        fmesh = {}
        for s in range(self.N):
            u, delta, ddot = self.kin(s, ys)
            p = u - modes[s][0]
            F[s] = _mesh_force(mcs[s], p, delta, ddot)
            nvec, mvec = self.geo[s]["n"], self.geo[s]["m"]
            gp, gw = self.stage_gears[s]
            vc = np.zeros(nt)  # (u_p' - u_w') . m
            for i, c in self.mproj[s]:
                vc = vc + c * ys[nd + i]
            ip, iw, g = self.ip[s], self.iw[s], modes[s][3]
            T[s] = _mode_friction(self.meshes[s], mcs[s], g, p, F[s], ys[nd + ip], ys[nd + iw], vc)[0]
            if gp is not None:
                fmesh[gp.name] = -np.outer(nvec, F[s]) + np.outer(mvec, T[s])
            if gw is not None:
                fmesh[gw.name] = np.outer(nvec, F[s]) - np.outer(mvec, T[s])
        bm = dict(zip([id(g) for g in self.hertz], bmodes, strict=True))
        disp, vel, fb = {}, {}, {}
        for g in self.gears:
            U = np.zeros((2, nt))
            V = np.zeros((2, nt))
            for a, i in g.idx.items():
                U[a] = ys[i]
                V[a] = ys[nd + i]
            if g.kind == "linear":
                f = -(np.array(g.k)[:, None] * U + np.array(g.C)[:, None] * V)
            elif g.kind == "rolling-elements":
                f = g.law.forces(U, V, g.sense * ys[g.turn])
            elif bm[id(g)] == 1:
                _, f_r = g.radial(ys, nd)
                r = np.sqrt(U[0] ** 2 + U[1] ** 2)
                f = -f_r * U / r
            else:
                f = np.zeros((2, nt))
            for a in (0, 1):
                if a not in g.idx:
                    f[a] = 0.0
            disp[g.name], vel[g.name], fb[g.name] = U, V, f
        return F, T, disp, vel, fb, fmesh
