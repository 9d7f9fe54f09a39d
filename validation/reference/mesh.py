"""One gear mesh for the segmented integration: its phase break points (every jump or kink of the law
in one mesh period) and :class:`_Mesh`, the mesh's constants, its per-interval table and the locked-mode
constants of any mode (n, k, c), plus the mode bookkeeping (locate, step, classify the contact).
"""

from __future__ import annotations

import math

import numpy as np

from .law_terms import (
    base_stiffness,
    check_transition_width,
    friction_transition_speed,
    half_double,
    mesh_law,
    pair_table,
    pitted_teeth,
    reduced_mass,
    runout_terms,
    tooth_error_amplitudes,
    tooth_factors,
)
from .modes import _ModeConsts, _PairMode, _PolyBuilder, _SmoothMode
from .scenario import TWO_PI, F_rated, is_muller_view


def phase_breakpoints(scenario: dict) -> np.ndarray:
    """All phases in [0, 1) at which some mesh quantity jumps or kinks (0 always included).  The pitch
    point is none: friction's direction follows the sliding velocity, smooth in the state there."""
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
    end).  Kinks stay break points: p = 0 (the friction arms jump there while the envelope e passes 0),
    the error apex a and the table points.  The centres of the ramps are not needed (the law is a polynomial
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
    for _gear, _tooth, _depth, lo, hi in pitted_teeth(scenario):
        centres += [lo, hi]
    pts = kinks + [(c + sgn * 0.5 * w) % 1.0 for c in centres for sgn in (-1.0, 1.0)]
    pts = np.unique([x for x in pts if 0.0 <= x < 1.0])
    keep = [pts[0]]
    for x in pts[1:]:
        if x - keep[-1] > 1e-9 and 1.0 - x > 1e-9:
            keep.append(x)
    return np.array(keep)


class _Mesh:
    """Constants of one gear mesh, plus its per-mode constants.

    ``sc`` is a mesh view, :func:`.scenario.stage_view` of stage s (a train's stage: ``Frated`` =
    F_rated,s exactly; muller / two-wheel: their one stage), or a legacy one-mesh scenario."""

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
        self.r1tan = self.r1 * self.tan_a  # the friction arms at the pitch point
        self.r2tan = self.r2 * self.tan_a
        muller = is_muller_view(sc)
        self.mu = float(sc["condition"]["friction_coefficient"]) if not muller else 0.0
        self.inv_v0 = 1.0 / friction_transition_speed(sc)  # 1 / v_0 of sigma(v_sl / v_0)
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
        self.iv = []  # per interval: (kA, kS, Ea, Eb)
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
            self.iv.append((kA, kS, Ea, Eb))
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
        # friction magnitude: mu e(p), e = (2 S(p/w) - 1)(1 - 2 S((p - 1)/w)); the two ramps do not
        # overlap on [0, 1) (w <= 0.1), so e = 2 S(p/w) - 2 S((p - 1)/w) - 1 there
        mue = _PolyBuilder(w, mid, A=-self.mu)
        mue.step(2.0 * self.mu, 0.0)
        mue.step(-2.0 * self.mu, 1.0)
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
            mue=mue.done(),
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
        kA, kS, Ea, Eb = self.iv[k]
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
