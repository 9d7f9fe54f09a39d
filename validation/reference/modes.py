"""Locked-mode form of the mesh law: inside one phase interval k of mesh period n (and one contact
mode c) every mesh quantity is a fixed polynomial of the phase p = u - n, stored in these constants and
evaluated by the functions here; the right-hand sides, the contact events and the outputs all form the
mesh force and the error through :func:`_mesh_force` / :func:`_mode_error` only, and a parallel mesh's
friction through :func:`_mode_friction` (its direction from the sliding velocity of the state, sigma
locked in the mesh's slide mode g).  The constants are built per mode by :class:`.mesh._Mesh`.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

if TYPE_CHECKING:
    from .mesh import _Mesh


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


def _mode_mu_envelope(mesh: _Mesh, mc: _ModeConsts, p):
    """mu e(p) in a locked mode at p (float or array): mu with w = 0, mu times the tooth-change envelope
    of :func:`.law_terms.friction_envelope` in its locked polynomial form with w > 0."""
    if mc.tw is None:
        return mesh.mu + 0.0 * p
    return _poly_eval(mc.tw.mue, p)


def _slide_sigma(g: int, x):
    """sigma(x) = 2 S(x / 2) - 1 of :func:`.law_terms.friction_sigma` (x = v_sl / v_0) locked in the
    slide mode g: +-1 (|x| >= 1 with that sign) or, for g = 0 (|x| < 1), the quintic itself, not clipped,
    so that it continues smoothly a little beyond |x| = 1 during trial steps (floats or arrays)."""
    if g:
        return g + 0.0 * x
    u = 0.5 * x + 0.5
    return 2.0 * (u * u * u * (10.0 - 15.0 * u + 6.0 * u * u)) - 1.0


def _slide_mode(x: float, g_old: int = 0) -> int:
    """Slide mode of x = v_sl / v_0: +1 for x >= 1, -1 for x <= -1, else 0; within 1e-9 of an edge the
    old mode is kept (the event hysteresis decides there)."""
    x = float(x)
    if g_old and abs(abs(x) - 1.0) < 1e-9:
        return g_old
    return 1 if x >= 1.0 else (-1 if x <= -1.0 else 0)


def _mode_friction(mesh: _Mesh, mc: _ModeConsts, g: int, p, F, w1, w2, v_c=0.0):
    """Friction of a parallel mesh in a locked mode (floats or arrays), docs/scenario.md "Friction":
    arms rho_1 = r1 tan(alpha_w) + (p - pitch) p_b, rho_2 = r2 tan(alpha_w) - (p - pitch) p_b, sliding
    velocity v_sl = rho_1 w1 - rho_2 w2 + v_c (v_c: the centres' (u_p' - u_w') . m of a lateral model),
    T = -mu e(p) |F| sigma(v_sl / v_0) with sigma locked in slide mode g.  Returns (T, rho_1, rho_2,
    v_sl); T = 0 without friction."""
    q = (p - mesh.ppp) * mesh.pb
    rho1 = mesh.r1tan + q
    rho2 = mesh.r2tan - q
    v_sl = rho1 * w1 - rho2 * w2 + v_c
    if mesh.mu == 0.0:
        return 0.0 * v_sl, rho1, rho2, v_sl
    return -_mode_mu_envelope(mesh, mc, p) * abs(F) * _slide_sigma(g, v_sl * mesh.inv_v0), rho1, rho2, v_sl


# ----------------------------------------------------------------------------------------------
# Locked-mode form of the smoothed law (transition width w > 0)
# ----------------------------------------------------------------------------------------------
# Inside one phase interval every smooth step S((q - c)/w) is either 0, 1 or its quintic (all ramp
# ends are break points), so each smoothed quantity is  A + B p + sum coef * P((p - c) / w + 1/2)
# with P(x) = x^3 (10 - 15 x + 6 x^2): stored as (A, B, ((coef, c, 1/w), ...)).  Evaluated with
# the quintic also slightly beyond the interval ends (trial steps), so the right-hand side is smooth.
class _SmoothMode(NamedTuple):
    kz: tuple  # k_z(p) (tables: the linear piece)
    mue: tuple  # mu e(p), the friction's tooth-change envelope
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
