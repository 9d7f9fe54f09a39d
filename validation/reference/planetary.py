"""Independent reference of planetary stages (docs/planetary.md, "The stage in a drive: scenario keys
and equations (the contract)"): a stage alone under constant torques
(:func:`simulate_reference_planetary_stage`) and a whole drive of planetary and parallel stages
(:func:`simulate_reference_drive`, in :mod:`.planetary_drive`).

The stage's model is :class:`.planetary_model.PlanetaryStage` (inertial frame, exact involute
deflections, the reference's own mesh law per mesh).  Integration: the reference's ONE segmented
integrator (:func:`.integrate.integrate`) with DOP853, every one of the 2N planetary meshes (and every
parallel mesh) in its own locked mode (phase interval, contact state, friction's slide mode).  Why: the
stiffness jumps at h and 1 - h and the tooth change would cut a plain adaptive step to first order;
with terminal events at each mode boundary (the law angle of the mesh crossing a phase break point, d
crossing the backlash, |v_T| crossing v_0) each segment is smooth.  The events here are functions of
the exact law angle (``theta_s - phi_n``, ``phi_n - theta_r + 2 pi g / z_r``) and of v_T on the exact
geometry (:meth:`.planetary_model.PlanetaryStage.one_mesh_sliding`), not of one coordinate.
Nothing is imported from gearbody.
"""

from __future__ import annotations

import numpy as np

from .integrate import _ETA_U, _chunk, _contact_edges, _output_times, integrate, slide_events
from .modes import _mode_error
from .planetary_model import PlanetaryStage

MEMBER_NAMES = ("sun", "ring", "carrier")
_NO_PROFILE = {"time_s": [0.0], "fraction": [0.0]}


class _PlanetaryBlock:
    """A planetary stage inside a chain: its coordinates start at ``off``, its meshes at ``m0``."""

    def __init__(self, stage: PlanetaryStage, off: int, m0: int):
        self.st, self.off, self.m0 = stage, off, m0
        self.n_dof = stage.n_dof
        self.meshes = stage.meshes
        self.i_in, self.sg_in = off + 3 * stage.i_in + 2, stage.s_in
        self.i_out, self.sg_out = off + 3 * stage.i_out + 2, stage.s_out
        self.sl = slice(off, off + stage.n_dof)

    def mass(self) -> np.ndarray:
        return self.st.mass_vector()

    def forces(self, q, v, modes, mcs) -> np.ndarray:
        st = self.st
        geo = st.mesh_geometry(q, v)
        F = st.mesh_forces(geo, mcs, modes)
        friction = st.friction_forces(v, geo, mcs, modes, F) if st.mu else None
        return st.generalised_forces(q, v, geo, F, friction=friction)

    def initial_modes(self, q, v) -> list:
        return self.st.mesh_modes(q, v)

    def deflection(self, j: int, n: int, k: int, q, v):
        st = self.st
        kind = ("sun", "ring")[j % 2]
        geo = st.mesh_geometry(q, v)[kind]
        law = st.planet_laws[j // 2][kind]
        p = geo[4][j // 2] * law.cz - n
        return geo[0][j // 2] + _mode_error(law.mode_consts(n, k, 0), p), geo[1][j // 2]

    def sliding(self, j: int, mode: list, q, v):
        """v_T of the stage's mesh j (planet j // 2, sun mesh for even j) in its locked phase mode."""
        return self.st.one_mesh_sliding(q, v, j // 2, ("sun", "ring")[j % 2], mode[0])

    def events(self, modes, mcs, nd: int):
        """Terminal events leaving the locked modes of the stage's meshes (global mesh indices)."""
        st, sl = self.st, self.sl
        events, actions = [], []
        for j, (n, k, c, g) in enumerate(modes):
            planet, kind = j // 2, ("sun", "ring")[j % 2]
            law = st.planet_laws[planet][kind]
            lo, hi = n + float(law.bA[k]) - _ETA_U, n + float(law.bB[k]) + _ETA_U

            def ev_up(t, y, a=(planet, kind, law.cz, hi)):
                return st.one_mesh(y[sl], a[0], a[1])[0] * a[2] - a[3]

            def ev_down(t, y, a=(planet, kind, law.cz, lo)):
                return st.one_mesh(y[sl], a[0], a[1])[0] * a[2] - a[3]

            ev_up.terminal, ev_up.direction = True, 1.0
            ev_down.terminal, ev_down.direction = True, -1.0
            events += [ev_up, ev_down]
            actions += [("phase", self.m0 + j, +1), ("phase", self.m0 + j, -1)]
            if law.lu > 0.0:
                for offset, direction, new_c in _contact_edges(law.lu, c):

                    def ev(t, y, a=(planet, kind, law.cz, mcs[j], offset)):
                        ang, delta = st.one_mesh(y[sl], a[0], a[1])
                        return delta + _mode_error(a[3], ang * a[2] - a[3].nf) + a[4]

                    ev.terminal, ev.direction = True, direction
                    events.append(ev)
                    actions.append(("contact", self.m0 + j, new_c))
            if st.mu:

                def v_T(y, a=(planet, kind, n)):
                    return st.one_mesh_sliding(y[sl], y[nd:][sl], *a)

                ev, ac = slide_events(self.m0 + j, g, law.inv_v0, v_T)
                events += ev
                actions += ac
        return events, actions

    def outputs(self, qs, vs, modes, mcs) -> list:
        """Mesh forces of the stage's meshes at states in columns, in mesh order (planet n: sun, ring)."""
        st = self.st
        geo = st.mesh_geometry(qs, vs)
        F = st.mesh_forces(geo, mcs, modes)
        return [F[kind][n] for n in range(st.N) for kind in ("sun", "ring")]

    def frictions(self, qs, vs, modes, mcs, F_rows) -> list:
        """Friction forces T (N) of the stage's meshes at states in columns, in mesh order."""
        st = self.st
        F = {kind: [F_rows[2 * n + j] for n in range(st.N)] for j, kind in enumerate(("sun", "ring"))}
        T = st.friction_forces(vs, st.mesh_geometry(qs, vs), mcs, modes, F)[0]
        return [T[kind][n] for n in range(st.N) for kind in ("sun", "ring")]


class _Chain:
    """A system for :func:`.integrate.integrate`: blocks (stages) on one coordinate vector, optionally
    joined to a motor and a machine by shafts (``chain``), plus constant external generalised forces
    ``ext`` (the stage alone)."""

    def __init__(self, blocks: list, n_dof: int, mass: np.ndarray, ext=None, chain=None):
        self.blocks = blocks
        self.n_dof = n_dof
        self.M = mass
        self.ext = np.zeros(n_dof) if ext is None else np.asarray(ext, dtype=float)
        self.chain = chain
        self.meshes = [m for b in blocks for m in b.meshes]
        self.block_of = [(b, j) for b in blocks for j in range(len(b.meshes))]
        if chain is None:
            self.speed_prof = self.load_prof = _NO_PROFILE
            self.wsr = 1.0
        else:
            self.speed_prof, self.load_prof = chain["speed_profile"], chain["load_profile"]
            self.wsr = chain["wsr"]

    # -- system interface of integrate() -------------------------------------------------------------
    def start_chunk(self, ib: int, t: float, tb: float) -> dict:
        return _chunk(self, t, tb, 0.0)

    def zero_chunk(self) -> dict:
        return _chunk(self, 0.0, 1.0, 0.0)

    def _split(self, modes_or_mcs, b):
        return modes_or_mcs[b.m0 : b.m0 + len(b.meshes)]

    def initial_modes(self, y, chunk):
        nd = self.n_dof
        modes = []
        for b in self.blocks:
            modes += b.initial_modes(y[b.sl], y[nd:][b.sl])
        return modes, None

    def deflection(self, s: int, n: int, k: int, t, y):
        b, j = self.block_of[s]
        return b.deflection(j, n, k, y[: self.n_dof][b.sl], y[self.n_dof :][b.sl])

    def sliding(self, s: int, mode: list, y):
        b, j = self.block_of[s]
        return b.sliding(j, mode, y[: self.n_dof][b.sl], y[self.n_dof :][b.sl])

    def make_rhs(self, modes, extra, chunk):
        mcs = [m.mode_consts(n, k, c) for m, (n, k, c, _g) in zip(self.meshes, modes, strict=True)]
        nd, M, ext, blocks = self.n_dof, self.M, self.ext, self.blocks
        parts = [(b, b.sl, self._split(modes, b), self._split(mcs, b)) for b in blocks]
        ch = self.chain
        if ch is not None:
            ta, sa, ss, la, ls = chunk["ta"], chunk["sa"], chunk["ss"], chunk["la"], chunk["ls"]
            wsr, Mb, sb, Mrated = ch["wsr"], ch["Mb"], ch["sb"], ch["Mrated"]
            shafts = ch["shafts"]

        def rhs(t, y):
            q, v = y[:nd], y[nd:]
            Q = ext.copy()
            for b, sl, md, mc in parts:
                Q[sl] += b.forces(q[sl], v[sl], md, mc)
            if ch is not None:
                tau = t - ta
                for a, ga, b_, gb, k, C in shafts:  # S = k (phi_a - phi_b) + C (...)', phi = sign q
                    S = k * (ga * q[a] - gb * q[b_]) + C * (ga * v[a] - gb * v[b_])
                    Q[a] -= ga * S
                    Q[b_] += gb * S
                slip = (wsr * (sa + ss * tau) - v[0]) / wsr
                Q[0] += 2.0 * Mb * sb * slip / (slip * slip + sb * sb)  # Kloss
                Q[nd - 1] -= Mrated * (la + ls * tau)
            return np.concatenate((v, Q / M))

        return rhs, mcs

    def make_events(self, modes, extra, mcs):
        events, actions = [], []
        for b in self.blocks:
            ev, ac = b.events(self._split(modes, b), self._split(mcs, b), self.n_dof)
            events += ev
            actions += ac
        return events, actions

    def output_buffers(self, n_t: int) -> dict:
        return {key: np.full((len(self.meshes), n_t), np.nan) for key in ("F", "T")}

    def outputs(self, ts, ys, modes, extra, mcs) -> dict:
        nd = self.n_dof
        F = np.empty((len(self.meshes), ts.size))
        T = np.empty((len(self.meshes), ts.size))
        for b in self.blocks:
            qs, vs, md, mc = ys[:nd][b.sl], ys[nd:][b.sl], self._split(modes, b), self._split(mcs, b)
            rows = b.outputs(qs, vs, md, mc)
            F[b.m0 : b.m0 + len(rows)] = rows
            T[b.m0 : b.m0 + len(rows)] = b.frictions(qs, vs, md, mc, rows)
        return {"F": F, "T": T}

    def default_atol(self, rtol: float) -> np.ndarray:
        """rtol times the deflection scale (lengths), over the largest base radius (angles), times the
        fastest mesh's frequency (rates); every coordinate is an angle or a length."""
        defl = min(m.defl_scale for m in self.meshes)
        r = max(max(m.r1, m.r2) for m in self.meshes)
        om = max(m.omega_n for m in self.meshes)
        ang = np.full(self.n_dof, rtol * defl / r)
        for b in self.blocks:
            if isinstance(b, _PlanetaryBlock):
                lengths = np.ones(b.n_dof, dtype=bool)
                lengths[2::3] = False
                ang[b.sl][lengths] = rtol * defl
        return np.concatenate((ang, ang * om))


def member_names(N: int) -> list[str]:
    return [*MEMBER_NAMES, *(f"planet_{n + 1}" for n in range(N))]


def planetary_signals(
    st: PlanetaryStage, Y: np.ndarray, F: np.ndarray, off: int, prefix: str, T: np.ndarray | None = None
) -> dict:
    """Per member ``<prefix><member>_q`` / ``_v`` (n_t x 3: x, y, theta) and per planet
    ``<prefix>planet_<n>_sun_mesh_force_N``, ``..._ring_mesh_force_N``, their ``_kd`` and (T given) the
    friction forces ``..._mesh_friction_force_N``."""
    nd_all = Y.shape[0] // 2
    out = {}
    for m, name in enumerate(member_names(st.N)):
        out[f"{prefix}{name}_q"] = Y[off + 3 * m : off + 3 * m + 3].T.copy()
        out[f"{prefix}{name}_v"] = Y[nd_all + off + 3 * m : nd_all + off + 3 * m + 3].T.copy()
    for n in range(st.N):
        for j, kind in enumerate(("sun", "ring")):
            key = f"{prefix}planet_{n + 1}_{kind}_mesh_force_N"
            out[key] = F[2 * n + j].copy()
            out[key.replace("_force_N", "_kd")] = F[2 * n + j] / st.F_rated
            if T is not None:
                out[key.replace("_force_N", "_friction_force_N")] = T[2 * n + j].copy()
    return out


def simulate_reference_planetary_stage(
    stage: dict,
    *,
    torques_Nm: dict,
    sun_speed_rad_s: float = 0.0,
    carrier_speed_rad_s: float = 0.0,
    t_end_s: float | None = None,
    t_eval=None,
    seed: int = 1,
    stage_index: int = 0,
    rtol: float = 1e-10,
    atol=None,
    method: str = "DOP853",
) -> dict:
    """The stage alone (no motor, shafts or machine) under constant torques ``torques_Nm`` on "sun",
    "ring", "carrier" (N m, counter-clockwise positive), from the nominal assembly moving by rigid
    rolling at the sun's and the carrier's speeds.  Output at ``t_eval`` (default: 20 kHz up to
    ``t_end_s``).  Returns time_s, coordinates / velocities (n_dof x n_t), the members' ``<member>_q``
    (n_t x 3), per-planet mesh forces and kd against F_rated = |T_sun| / (N r_bs) (or 1 N unloaded),
    nfev, n_segments."""
    bad = set(torques_Nm) - set(MEMBER_NAMES)
    if bad:
        raise ValueError(f"torques on unknown members {sorted(bad)}")
    pre = PlanetaryStage(stage, seed=seed, stage_index=stage_index)
    Fr = abs(float(torques_Nm.get("sun", 0.0))) / (pre.N * pre.r_bs) or 1.0
    st = PlanetaryStage(stage, seed=seed, stage_index=stage_index, F_rated=Fr)
    block = _PlanetaryBlock(st, 0, 0)
    ext = np.zeros(st.n_dof)
    for name, T in torques_Nm.items():
        ext[3 * MEMBER_NAMES.index(name) + 2] = float(T)
    system = _Chain([block], st.n_dof, st.mass_vector(), ext=ext)
    if t_eval is None:
        if t_end_s is None:
            raise ValueError("give t_end_s or t_eval")
        t_eval = np.arange(int(np.floor(t_end_s * 20000.0)) + 1) / 20000.0
    t_eval = _output_times({}, t_eval)
    w = st.rigid_speeds("sun", float(sun_speed_rad_s), ("carrier", float(carrier_speed_rad_s)))
    y0 = np.concatenate((st.q_nominal, st.rigid_state(w)))
    if atol is None:
        atol = system.default_atol(rtol)
    res = integrate(system, y0, t_eval, rtol, atol, method)
    Y, F = res["Y"], res["out"]["F"]
    return {
        "time_s": t_eval,
        "coordinates": Y[: st.n_dof],
        "velocities": Y[st.n_dof :],
        **planetary_signals(st, Y, F, 0, "", res["out"]["T"]),
        "F_rated_N": np.array(Fr),
        "nfev": np.array(res["nfev"]),
        "n_segments": np.array(res["n_segments"]),
    }


def __getattr__(name):  # the drive lives in its own module; imported lazily to keep this one small
    if name == "simulate_reference_drive":
        from .planetary_drive import simulate_reference_drive

        return simulate_reference_drive
    raise AttributeError(name)
