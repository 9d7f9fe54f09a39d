"""Independent reference model for the *lateral* gear models of ``docs/scenario.md`` (section "Lateral
models: gears on bearings (Figs. 17, 18)"): gears of a ``one-stage`` scene or of a ``train`` whose
centres translate in the housing's x-y plane on a ``linear`` or ``hertzian`` bearing.

Written from the contract only; it shares no code with ``gearbody``.  It reuses the torsional helpers of
:mod:`validation.reference` (random draw, error shape, stiffness profiles, tooth factors, Kloss, profiles,
the locked-mode mesh law and the segment integrator with its missed-event scan).  So every stiffness
profile of the torsional reference works here too: "iso-6336-b" as "contact-ratio", and the "pairs" law
of "potential-energy" (pair table ``mesh.pair_table`` from ``validation.compare.reference_input``, its
grid points as phase break points, damping ``C_z k / k_healthy``); the steady start uses the law's
effective stiffness at the initial phase (:func:`validation.reference.effective_stiffness`).

Model
-----
A ``one-stage`` scenario is rewritten as a 1-stage train (coupling = shaft 0, output shaft = shaft 1,
production.error_mode / eccentricity and condition.damaged_teeth / pitted_teeth moved into the stage),
which is the same system.
State ``y = [q, v]`` with ``q = [motor, pinion_1, wheel_1, ..., pinion_N, wheel_N, machine, lateral...]``;
the lateral coordinates follow in the order stage 1 pinion (x, y as free), stage 1 wheel, stage 2
pinion, ...

Per stage (geometry ``n``, ``m = s1 (-n_y, n_x)``):
``delta = r1 phi_p - r2 phi_w + (u_p - u_w) . n``; F, T, rho_1, rho_2 as in the torsional model;
pinion: moment ``-r1 F + T rho_1``, force ``-F n + T m``; wheel: ``+r2 F - T rho_2``, ``+F n - T m``.
Fault errors (run-out, pits) are part of the error E and enter ``d = delta + E`` only, exactly as in
the torsional reference (its locked-mode constants and ``_mode_error``; the initial deflection uses
``total_error``); the lateral projection is part of ``delta`` and so sits beside them in ``d``.
The transition width (``mesh.transition_width`` w > 0: smoothed stiffness ramps, blended factor and
error at the tooth change, smoothed pit edges and friction sign) comes with the torsional reference's
locked-mode law as well; only the friction sign, a constant of the mode when w = 0, is here evaluated
from the mode's polynomial form (``_poly_eval`` / ``_mode_mu_sign``).
Bearing forces: linear ``-(k_x x + C_x x', k_y y + C_y y')``; hertzian
``-max(k_b (r - c)^n + C u'.u / r, 0) u / r`` for ``r > c``, else 0.

Discontinuities
---------------
As in :mod:`validation.reference`, integration is done segment by segment in locked modes with terminal
``solve_ivp`` events: per mesh the phase mode ``(n, k)`` and contact mode ``c`` (the deflection d now
contains the lateral projection), and per hertzian bearing a mode ``b``:

* ``b = 0``: out of contact (``r <= c``), force 0;
* ``b = 1``: in contact and ``f_r = k_b p^n + C u'.u/r > 0``: the full formula (the damping term makes
  the force jump at contact onset);
* ``b = 2``: in contact but ``f_r <= 0`` (separating faster than the spring pushes): force 0 (a kink).

Event hysteresis: 1e-15 m on ``r - c`` and 1e-9 N on ``f_r``.  Inside mode 1 the power ``p^n`` is
continued oddly (``sign(p) |p|^n``) so that trial steps slightly beyond the contact edge stay finite.
The linear bearing is smooth and needs no mode.
"""

from __future__ import annotations

import copy
import math

import numpy as np

from . import reference as ref

__all__ = [
    "simulate_reference_lateral",
    "resolve_lateral_defaults",
    "as_train",
    "gear_names",
    "mesh_geometry",
    "bearing_force",
    "static_displacement",
    "initial_state_lateral",
]

TWO_PI = 2.0 * math.pi
_ETA_R = 1e-15  # event hysteresis on r - c (m)
_ETA_F = 1e-9  # event hysteresis on the hertzian radial force f_r (N)
_MAX_ZERO_SEGMENTS = 1000
_AXES = {"none": (), "y": (1,), "xy": (0, 1)}

# documented example values used when a key is missing (docs/scenario.md; the lateral defaults are stated)
_MESH_DEFAULTS = {
    "stiffness_profile": "contact-ratio",
    "table_phase": [],
    "table_stiffness_N_per_m": [],
    "pressure_angle_deg": 20.0,
    "pitch_point_phase": 0.5,
    "backlash_um": 0.0,
    "centre_line_deg": 0.0,
    "line_of_action_deg": -90.0,
}


# ----------------------------------------------------------------------------------------------
# Scenario helpers
# ----------------------------------------------------------------------------------------------
def _fill_gear(g: dict) -> None:
    g.setdefault("lateral", "none")
    if g["lateral"] not in _AXES:
        raise ValueError(f"lateral must be 'none', 'y' or 'xy', got {g['lateral']!r}")
    if g["lateral"] != "none":
        if "bearing" not in g:
            raise ValueError("a lateral gear needs a bearing table")
        kind = g["bearing"]["kind"]
        if kind not in ("linear", "hertzian"):
            raise ValueError(f"unknown bearing kind {kind!r}")


def resolve_lateral_defaults(scenario: dict) -> dict:
    """Deep copy with the defaults stated by the contract filled in (lateral = "none",
    centre_line_deg = 0, line_of_action_deg = -90) and, for keys the files in scenes/ may omit, the
    documented example values (stiffness_profile "contact-ratio", pressure_angle_deg 20,
    pitch_point_phase 0.5, backlash 0, empty tables, no damaged teeth, shaft damping 0,
    solver.output_rate_hz 20000)."""
    sc = copy.deepcopy(scenario)
    scene = sc["meta"]["scene"]
    d = sc["design"]
    if scene == "one-stage":
        pairs = [(d["pinion"], d["wheel"], d["mesh"])]
        d.setdefault("coupling", {}).setdefault("damping_Nms_per_rad", 0.0)
        d.setdefault("output_shaft", {}).setdefault("damping_Nms_per_rad", 0.0)
        sc.setdefault("condition", {}).setdefault("damaged_teeth", [])
    elif scene == "train":
        pairs = [(st["pinion"], st["wheel"], st["mesh"]) for st in d["stages"]]
        for st in d["stages"]:
            st.setdefault("damaged_teeth", [])
        for sh in d["shafts"]:
            sh.setdefault("damping_Nms_per_rad", 0.0)
    else:
        raise ValueError(f"lateral models exist for scenes 'one-stage' and 'train', not {scene!r}")
    for pin, whl, mesh in pairs:
        _fill_gear(pin)
        _fill_gear(whl)
        for key, val in _MESH_DEFAULTS.items():
            mesh.setdefault(key, copy.deepcopy(val))
    sc.setdefault("condition", {}).setdefault("friction_coefficient", 0.0)
    sc.setdefault("solver", {}).setdefault("output_rate_hz", 20000.0)
    return sc


def as_train(scenario: dict) -> dict:
    """A (defaults-resolved) one-stage scenario as the equivalent 1-stage train; a train unchanged."""
    if scenario["meta"]["scene"] == "train":
        return scenario
    d = scenario["design"]
    tr = copy.deepcopy(scenario)
    tr["meta"]["scene"] = "train"
    tr["design"] = copy.deepcopy(
        {
            "motor": d["motor"],
            "machine": d["machine"],
            "shafts": [d["coupling"], d["output_shaft"]],
            "stages": [
                {
                    "pinion": d["pinion"],
                    "wheel": d["wheel"],
                    "mesh": d["mesh"],
                    "error_mode": scenario["production"]["error_mode"],
                    "damaged_teeth": scenario["condition"].get("damaged_teeth", []),
                    "eccentricity": scenario["production"].get("eccentricity", []),
                    "pitted_teeth": scenario["condition"].get("pitted_teeth", []),
                }
            ],
        }
    )
    return tr


def gear_names(s: int) -> tuple[str, str]:
    """Names of stage s (0-based): ("pinion", "wheel") for s = 0, ("pinion_2", "wheel_2") for s = 1, ..."""
    return ("pinion", "wheel") if s == 0 else (f"pinion_{s + 1}", f"wheel_{s + 1}")


def mesh_geometry(mesh: dict) -> dict:
    """n, e, e_perp, s1 = sign(n . e_perp) and m = s1 (-n_y, n_x); refuses |n . e_perp| < 0.5."""
    lam = math.radians(float(mesh.get("line_of_action_deg", -90.0)))
    gam = math.radians(float(mesh.get("centre_line_deg", 0.0)))
    n = np.array([math.cos(lam), math.sin(lam)])
    e = np.array([math.cos(gam), math.sin(gam)])
    e_perp = np.array([-math.sin(gam), math.cos(gam)])
    dot = float(n @ e_perp)
    if abs(dot) < 0.5:
        raise ValueError("line of action more than 60 deg away from the centre line's normal")
    s1 = 1.0 if dot > 0 else -1.0
    m = s1 * np.array([-n[1], n[0]])
    return {"n": n, "e": e, "e_perp": e_perp, "s1": s1, "m": m}


def bearing_force(bearing: dict, u, u_dot) -> np.ndarray:
    """Literal bearing law f_b = law.force_N(u, u') (u, u' in the housing frame, 2-vectors)."""
    kind = bearing["kind"]
    par = bearing["parameters"]
    x, y = float(u[0]), float(u[1])
    vx, vy = float(u_dot[0]), float(u_dot[1])
    if kind == "linear":
        return -np.array(
            [
                float(par["stiffness_x_N_per_m"]) * x + float(par["damping_x_Ns_per_m"]) * vx,
                float(par["stiffness_y_N_per_m"]) * y + float(par["damping_y_Ns_per_m"]) * vy,
            ]
        )
    if kind == "hertzian":
        r = math.hypot(x, y)
        p = r - float(par["radial_clearance_m"])
        if p <= 0.0 or r == 0.0:
            return np.zeros(2)
        f_r = (
            float(par["contact_stiffness_N_per_m_n"]) * p ** float(par["exponent"])
            + float(par["damping_Ns_per_m"]) * (vx * x + vy * y) / r
        )
        return -max(f_r, 0.0) * np.array([x, y]) / r
    raise ValueError(f"unknown bearing kind {kind!r}")


def static_displacement(bearing: dict, f, axes) -> np.ndarray:
    """u_0 with law.force_N(u_0, 0) + f = 0, f restricted to the free axes (zeros elsewhere)."""
    f = np.asarray(f, dtype=float).copy()
    mask = np.zeros(2, bool)
    mask[list(axes)] = True
    f[~mask] = 0.0
    par = bearing["parameters"]
    u0 = np.zeros(2)
    if bearing["kind"] == "linear":
        kk = [float(par["stiffness_x_N_per_m"]), float(par["stiffness_y_N_per_m"])]
        for a in axes:
            u0[a] = f[a] / kk[a]
        return u0
    fn = math.hypot(f[0], f[1])
    if fn == 0.0:
        return u0
    kb = float(par["contact_stiffness_N_per_m_n"])
    c = float(par["radial_clearance_m"])
    return f / fn * (c + (fn / kb) ** (1.0 / float(par["exponent"])))


# ----------------------------------------------------------------------------------------------
# The model
# ----------------------------------------------------------------------------------------------
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
        stages = ref.train_stages(sc)
        N = self.N = len(stages)
        self.n_tor = 2 * N + 2
        self.Frated = ref.stage_F_rated(sc)
        self.meshes = [ref._Mesh(ref.stage_view(sc, s), Fr) for s, Fr in enumerate(self.Frated)]
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
                nxt += len(gear.axes)
                self.gears.append(gear)
                pair.append(gear)
            self.stage_gears.append(tuple(pair))
        self.n_dof = nxt
        self.hertz = [g for g in self.gears if g.kind == "hertzian"]
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
        op = sc["operation"]
        self.speed_prof = op["speed_profile"]
        self.load_prof = op["load_profile"]
        # projections of the lateral coordinates on n (delta) per stage: [(index, +-n_a)]
        self.proj = []
        for s in range(N):
            n = self.geo[s]["n"]
            terms = []
            for gear, sign in zip(self.stage_gears[s], (1.0, -1.0), strict=True):
                if gear is not None:
                    terms += [(i, sign * float(n[a])) for a, i in gear.idx.items()]
            self.proj.append(terms)

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

    def deflection(self, s, n, k, y):
        u, delta, ddot = self.kin(s, y)
        return delta + ref._mode_error(self.meshes[s].mode_consts(n, k, 0), u - n), ddot

    def initial_modes(self, y):
        modes = []
        for s, m in enumerate(self.meshes):
            u, _, _ = self.kin(s, y)
            n, k = m.phase_mode(float(u), float(y[self.n_dof + self.ip[s]]) * m.cz)
            d, dd = self.deflection(s, n, k, y)
            modes.append([n, k, m.contact_mode(float(d), float(dd))])
        bmodes = [g.classify(y, self.n_dof) for g in self.hertz]
        return modes, bmodes

    # -- right-hand side -------------------------------------------------------------------------
    def make_rhs(self, modes, bmodes, chunk):
        mcs = []
        stage_data = []
        n_tor, nd = self.n_tor, self.n_dof
        for s, (n, k, c) in enumerate(modes):
            m = self.meshes[s]
            mc = m.mode_consts(n, k, c)
            mcs.append(mc)
            g = self.geo[s]
            nvec, mvec = g["n"], g["m"]
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
                    m.mu * m.iv[k][4] if mc.tw is None else mc.tw.mus,  # w > 0: mu s(p) in locked form
                    m.ppp,
                    m.pb,
                    m.r1 * m.tan_a,
                    m.r2 * m.tan_a,
                    self.proj[s],
                    lat_p,
                    lat_w,
                )
            )
        lin = []  # (lateral offset, k, C)
        hz = []  # (offset x | None, offset y | None, kb, c, ex, Cb, mode)
        bm = dict(zip([id(g) for g in self.hertz], bmodes, strict=True))
        for g in self.gears:
            if g.kind == "linear":
                lin += [(i - n_tor, g.k[a], g.C[a]) for a, i in g.idx.items()]
            else:
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
        mesh = ref._mesh_force
        peval = ref._poly_eval
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
                ip, iw, r1, r2, cz, nf, mc, mus, ppp, pb, r1tan, r2tan, proj, lat_p, lat_w = sd
                delta = r1 * q[ip] - r2 * q[iw]
                ddot = r1 * v[ip] - r2 * v[iw]
                for i, c in proj:
                    delta += c * q[i]
                    ddot += c * v[i]
                p = q[ip] * cz - nf
                F = mesh(mc, p, delta, ddot)
                T = (mus if mc.tw is None else peval(mus, p)) * abs(F)
                qq = (p - ppp) * pb
                acc.append((S[s] - r1 * F + T * (r1tan + qq)) / Ip[s])
                acc.append((r2 * F - T * (r2tan - qq) - S[s + 1]) / Iw[s])
                for j, na, ma in lat_p:  # pinion: -F n + T m
                    fl[j] += -F * na + T * ma
                for j, na, ma in lat_w:  # wheel: +F n - T m
                    fl[j] += F * na - T * ma
            acc.append((S[-1] - Mr) / Im)
            for j, kk, cc in lin:
                fl[j] -= kk * ql[j] + cc * vl[j]
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
        for s, (n, k, c) in enumerate(modes):
            m = self.meshes[s]
            ip, cz = self.ip[s], m.cz
            lo = n + float(m.bA[k]) - ref._ETA_U
            hi = n + float(m.bB[k]) + ref._ETA_U

            def ev_up(t, y, ip=ip, cz=cz, hi=hi):
                return y[ip] * cz - hi

            def ev_down(t, y, ip=ip, cz=cz, lo=lo):
                return y[ip] * cz - lo

            ev_up.terminal, ev_up.direction = True, 1.0
            ev_down.terminal, ev_down.direction = True, -1.0
            events += [ev_up, ev_down]
            actions += [("phase", s, +1), ("phase", s, -1)]
            if m.lu > 0.0:
                for offset, direction, new_c in ref._contact_edges(m.lu, c):

                    def ev(t, y, offset=offset, s=s, mc=mcs[s]):
                        u, delta, _ = self.kin(s, y)
                        return delta + ref._mode_error(mc, u - mc.nf) + offset

                    ev.terminal, ev.direction = True, direction
                    events.append(ev)
                    actions.append(("contact", s, new_c))
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
            else:
                Fr = float(self.Frated[g.stage])
                kk = g.ex * g.kb ** (1.0 / g.ex) * Fr ** (1.0 - 1.0 / g.ex)  # tangent stiffness at F_rated
            om = max(om, math.sqrt(max(kk, 0.0) / g.mass))
        n_lat = self.n_dof - self.n_tor
        pos = np.concatenate((np.full(self.n_tor, ang), np.full(n_lat, rtol * defl)))
        return np.concatenate((pos, pos * om))

    # -- outputs ---------------------------------------------------------------------------------
    def outputs(self, ys, modes, bmodes, mcs):
        """Stage forces F (N x n), friction T (N x n), and per lateral gear: centre displacement,
        velocity, bearing force f_b and mesh force on the centre (each 2 x n)."""
        nd = self.n_dof
        nt = ys.shape[1]
        F = np.empty((self.N, nt))
        T = np.empty((self.N, nt))
        fmesh = {}
        for s in range(self.N):
            u, delta, ddot = self.kin(s, ys)
            F[s] = ref._mesh_force(mcs[s], u - modes[s][0], delta, ddot)
            m = self.meshes[s]
            if mcs[s].tw is None:
                T[s] = m.mu * m.iv[modes[s][1]][4] * np.abs(F[s])
            else:  # transition width w > 0: smoothed friction sign
                T[s] = ref._mode_mu_sign(m, modes[s][1], mcs[s], u - modes[s][0]) * np.abs(F[s])
            nvec, mvec = self.geo[s]["n"], self.geo[s]["m"]
            gp, gw = self.stage_gears[s]
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


# ----------------------------------------------------------------------------------------------
# Initial state
# ----------------------------------------------------------------------------------------------
def initial_state_lateral(scenario: dict) -> tuple[np.ndarray, np.ndarray]:
    """Initial q, v of the lateral model (coordinate order of the module docstring)."""
    model = scenario if isinstance(scenario, _LatTrain) else _LatTrain(scenario)
    sc = model.sc
    N = model.N
    q0 = np.zeros(model.n_dof)
    v0 = np.zeros(model.n_dof)
    kind = sc["operation"]["initial_state"]
    if kind == "rest":
        return q0, v0
    if kind != "steady":
        raise ValueError(f"unknown initial_state {kind!r}")
    stages = ref.train_stages(sc)
    d_ = sc["design"]
    shaft_k = model.shaft_k
    load0 = float(ref.profile_value(0.0, sc["operation"]["load_profile"]))
    M_L = float(d_["machine"]["rated_torque_Nm"]) * load0
    r_p = [float(st["pinion"]["base_radius_m"]) for st in stages]
    r_w = [float(st["wheel"]["base_radius_m"]) for st in stages]
    z_p = [int(st["pinion"]["teeth"]) for st in stages]
    F = [load0 * Fr for Fr in model.Frated]
    pinion_torque = [F[s] * r_p[s] for s in range(N)]
    motor = d_["motor"]
    wsr = float(motor["synchronous_speed_rad_s"])
    ws0 = wsr * float(ref.profile_value(0.0, sc["operation"]["speed_profile"]))
    w = ws0 - ref.steady_slip(pinion_torque[0], motor) * wsr
    v0[0] = w
    for s in range(N):
        v0[1 + 2 * s] = w
        w = w * r_p[s] / r_w[s]
        v0[2 + 2 * s] = w
    v0[2 * N + 1] = w
    pinion = 0.0
    for s in range(N):
        view = ref.stage_view(sc, s)
        mesh = view["design"]["mesh"]
        u = pinion * z_p[s] / TWO_PI
        k = float(ref.effective_stiffness(view, u)[0])  # w > 0: blended factor; pairs: the pair sum
        E = float(ref.total_error(view, u))  # fault errors included
        lu = float(mesh["backlash_um"]) * 1e-6
        if F[s] == 0.0:
            delta = 0.0
        elif k == 0.0:
            raise ValueError(f"steady start: stage {s} meshes with zero stiffness at its initial angle")
        else:
            delta = F[s] / k + lu - E
        # static bearing displacements under the static mesh force (friction ignored)
        nvec = model.geo[s]["n"]
        proj = 0.0
        for gear, sign in zip(model.stage_gears[s], (-1.0, 1.0), strict=True):
            if gear is None:
                continue
            u0 = static_displacement(gear.bearing, sign * F[s] * nvec, gear.axes)
            for a_, idx in gear.idx.items():
                q0[idx] = u0[a_]
            proj += -sign * float(u0 @ nvec)  # (u_p0 - u_w0) . n
        q0[1 + 2 * s] = pinion
        wheel = (r_p[s] * pinion - delta + proj) / r_w[s]
        q0[2 + 2 * s] = wheel
        if s + 1 < N:
            pinion = wheel - pinion_torque[s + 1] / shaft_k[s + 1]
    q0[0] = q0[1] + pinion_torque[0] / shaft_k[0]
    q0[2 * N + 1] = q0[2 * N] - M_L / shaft_k[N]
    return q0, v0


# ----------------------------------------------------------------------------------------------
# Integration
# ----------------------------------------------------------------------------------------------
def simulate_reference_lateral(
    scenario: dict,
    t_eval: np.ndarray | None = None,
    *,
    rtol: float = 1e-10,
    atol: float | np.ndarray | None = None,
    method: str = "DOP853",
) -> dict:
    """Integrate a one-stage or train scenario with lateral gears; see the module docstring.

    Returns time_s (and time), coordinates / velocities (n_dof x n_t, order of the module docstring),
    stage_mesh_force_N, stage_kd, stage_friction_force_N (N x n_t), mesh_force_N / kd (stage 1), and per
    lateral gear name: centre_displacement_m, centre_velocity_m_s, bearing_force_N (force the gear
    exerts on the housing: -f_b in a free direction, the mesh force on the centre in a fixed one),
    mesh_force_on_centre_N, centre_accel_m_s2 (0 in fixed directions), housing_accel_m_s2 (each
    2 x n_t, rows x, y); nfev, n_segments, n_missed_events.
    """
    model = _LatTrain(scenario)
    t_eval = ref._output_times(model.sc, t_eval)
    t_stop = float(t_eval[-1])
    if atol is None:
        atol = model.default_atol(rtol)
    nd, N = model.n_dof, model.N
    q0, v0 = initial_state_lateral(model)
    y = np.concatenate((q0, v0))
    n_t = t_eval.size
    Y = np.full((2 * nd, n_t), np.nan)
    F_out = np.full((N, n_t), np.nan)
    T_out = np.full((N, n_t), np.nan)
    names = [g.name for g in model.gears]
    D = {nm: np.full((2, n_t), np.nan) for nm in names}
    V = {nm: np.full((2, n_t), np.nan) for nm in names}
    FB = {nm: np.full((2, n_t), np.nan) for nm in names}
    FM = {nm: np.full((2, n_t), np.nan) for nm in names}
    tbreaks = ref._time_breaks(model, t_stop)
    modes, bmodes = model.initial_modes(y)

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
            F, T, dd, vv, fb, fm = model.outputs(ys, modes, bmodes, mcs)
            F_out[:, i_out:j], T_out[:, i_out:j] = F, T
            for nm in names:
                D[nm][:, i_out:j], V[nm][:, i_out:j] = dd[nm], vv[nm]
                FB[nm][:, i_out:j], FM[nm][:, i_out:j] = fb[nm], fm[nm]
            i_out = j

    if t_stop == 0.0:
        _, mcs = model.make_rhs(modes, bmodes, ref._chunk(model, 0.0, 1.0, 0.0))
        fill_outputs(None, 0.0, mcs, True)

    for ib, tb in enumerate(tbreaks):
        if t >= tb:
            break
        chunk = ref._chunk(model, t, tb, 0.0)
        last_chunk = ib == len(tbreaks) - 1
        while t < tb:
            rhs, mcs = model.make_rhs(modes, bmodes, chunk)
            events, actions = model.make_events(modes, bmodes, mcs)
            first = min(h_prev, tb - t) if h_prev else None
            res, t_new, y_new, fired, was_missed = ref._segment(
                rhs, t, tb, y, events, method, rtol, atol, first
            )
            nfev += int(res.nfev)
            n_segments += 1
            n_missed += was_missed
            h_prev = ref._step_hint(res, h_prev)
            fill_outputs(res.sol, t_new, mcs, last_chunk and not fired)
            if fired:
                zero_segments = zero_segments + 1 if t_new == t else 0
                if zero_segments > _MAX_ZERO_SEGMENTS:
                    raise RuntimeError(f"mode chattering at t={t_new} (modes {modes}, bearings {bmodes})")
                phase_changed, contact_set = set(), set()
                for mi in fired:
                    kind, s, val = actions[mi]
                    if kind == "phase":
                        modes[s][0], modes[s][1] = model.meshes[s].step_phase(modes[s][0], modes[s][1], val)
                        phase_changed.add(s)
                    elif kind == "contact":
                        modes[s][2] = val
                        contact_set.add(s)
                    else:  # bearing s, action val
                        g = model.hertz[s]
                        if val == "leave":
                            bmodes[s] = 0
                        elif val == "clamp":
                            bmodes[s] = 2
                        elif val == "push":
                            bmodes[s] = 1
                        else:  # enter: pushing unless it already separates faster than it penetrates
                            bmodes[s] = 1 if float(g.radial(y_new, nd)[1]) > 0.0 else 2
                for s in phase_changed - contact_set:
                    mesh = model.meshes[s]
                    if mesh.lu > 0.0:
                        d_new, dd_new = model.deflection(s, modes[s][0], modes[s][1], y_new)
                        if abs(abs(d_new) - mesh.lu) > 10 * ref._ETA_D:
                            modes[s][2] = mesh.contact_mode(float(d_new), float(dd_new))
            t, y = t_new, y_new
    if i_out < n_t:
        raise RuntimeError("internal error: not all output times were filled")
    stage_kd = F_out / model.Frated[:, None]
    accel, housing, to_housing = {}, {}, {}
    for g in model.gears:
        nm = g.name
        a = np.zeros((2, n_t))
        for ax in g.idx:
            a[ax] = (FM[nm][ax] + FB[nm][ax]) / g.mass
        accel[nm] = a
        # force on the housing: -f_b in a free direction, the mesh force on the centre in a fixed one
        bf = FM[nm].copy()
        for ax in g.idx:
            bf[ax] = -FB[nm][ax]
        to_housing[nm] = bf
        housing[nm] = bf / g.housing_mass
    return {
        "time_s": t_eval,
        "time": t_eval,
        "coordinates": Y[:nd],
        "velocities": Y[nd:],
        "mesh_force_N": F_out[0].copy(),
        "kd": stage_kd[0].copy(),
        "stage_mesh_force_N": F_out,
        "stage_kd": stage_kd,
        "stage_friction_force_N": T_out,
        "centre_displacement_m": D,
        "centre_velocity_m_s": V,
        "centre_accel_m_s2": accel,
        "bearing_law_force_N": FB,
        "bearing_force_N": to_housing,
        "mesh_force_on_centre_N": FM,
        "housing_accel_m_s2": housing,
        "nfev": np.array(nfev),
        "n_segments": np.array(n_segments),
        "n_missed_events": np.array(n_missed),
    }
