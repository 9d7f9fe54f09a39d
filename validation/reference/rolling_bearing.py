"""The ``rolling-elements`` bearing law, transcribed for the reference from its specification
(docs/scenario.md, "Rolling-element bearings ball by ball"; shares no code with gearbody).

Ball j of Z sits at ``phi_cage + 2 pi j / Z``. The cage, kinematically, turns ``r_c = (1 - g) / 2`` of the
inner race's turn relative to the outer (``g = d cos(alpha) / D``); with slip, the k-th ball spacing
(2 pi / Z) of that kinematic travel is covered at ``1 + eps_k`` of the rate, ``eps`` the 1024 numbers
``numpy.random.default_rng(slip_seed).uniform(-s, s, 1024)`` repeated. The ball's contact deflection is
``u . e_j - c - h_j`` and pushes ``K max(0, .)^n`` along ``-e_j``; the support adds ``-C u'``. A pit of
depth t and angular width w (about the bearing centre, or about the ball's centre for a ball defect)
drops a contact that is e inside its nearer edge by ``min(t, rho - sqrt(rho^2 - e^2))`` (rho once e >=
rho), ``1/rho = 2/d - 2/D_o`` on the outer race and ``2/d + 2/D_i`` on the inner (``D_o,i = D +- d
cos(alpha)``), edges measured along the surface of radius D_o/2, D_i/2 or d/2. The defective ball's spin
angle is ``psi_0 + D / (2 d) (1 - g^2) theta`` (theta the inner race's turn relative to the outer); it
meets the outer race around spin 0 and the inner around pi.
"""

from __future__ import annotations

import math

import numpy as np

TWO_PI = 2.0 * math.pi


class RollingBearing:
    """One ``rolling-elements`` bearing read from its scenario table (kind, parameters, geometry,
    defects); :meth:`force` on floats (outer race fixed), :meth:`forces` on arrays."""

    def __init__(self, bearing: dict):
        self.table = bearing
        par, geo = bearing["parameters"], bearing["geometry"]
        self.K = float(par["ball_stiffness_N_per_m_n"])
        self.c = float(par.get("radial_clearance_m", 0.0))
        self.n = float(par.get("exponent", 1.5))
        self.C = float(par.get("damping_Ns_per_m", 0.0))
        slip = float(par.get("cage_slip", 0.015))
        seed = int(par.get("slip_seed", 0))
        self.Z = int(geo["balls"])
        d, D = float(geo["ball_diameter_m"]), float(geo["pitch_diameter_m"])
        dcos = d * math.cos(math.radians(float(geo.get("contact_angle_deg", 0.0))))
        g = dcos / D
        self.rc = (1.0 - g) / 2.0
        self.spin = D / (2.0 * d) * (1.0 - g * g)
        self.pitch = TWO_PI / self.Z
        if slip > 0.0:
            eps = np.random.default_rng(seed).uniform(-slip, slip, 1024)
            self.starts = np.concatenate(
                ([0.0], np.cumsum(self.pitch * (1.0 + eps)))
            )  # cage angle at spacing k
        else:
            self.starts = None
        rho = {"outer": 1.0 / (2.0 / d - 2.0 / (D + dcos)), "inner": 1.0 / (2.0 / d + 2.0 / (D - dcos))}
        radius = {"outer": (D + dcos) / 2.0, "inner": (D - dcos) / 2.0, "ball": d / 2.0}
        self.rho = rho
        self.defects = []  # (race, centre rad, half width along the surface m, depth m, ball)
        for df in bearing.get("defects", ()):
            race = df["race"]
            half = math.radians(float(df["width_deg"])) / 2.0 * radius[race]
            centre = math.radians(float(df.get("angle_deg", 0.0)))
            self.defects.append(
                (race, centre, half, float(df["depth_m"]), int(df.get("ball", 0)), radius[race])
            )

    def cage(self, theta: float, outer: float = 0.0) -> float:
        """Cage angle with the inner race turned by theta and the outer by ``outer``."""
        kin = self.rc * (theta - outer)
        if self.starts is None:
            return outer + kin
        m = len(self.starts) - 1
        whole, rest = divmod(kin, self.pitch * m)  # whole tables of spacings, and the remainder
        k = min(int(rest // self.pitch), m - 1)
        frac = (rest - k * self.pitch) / self.pitch
        return outer + whole * self.starts[m] + self.starts[k] + frac * (self.starts[k + 1] - self.starts[k])

    @staticmethod
    def _sag(inside: float, depth: float, rho: float) -> float:
        if inside <= 0.0:
            return 0.0
        return min(depth, rho if inside >= rho else rho - math.sqrt(rho * rho - inside * inside))

    def drop(self, j: int, phi: float, theta: float, outer: float = 0.0) -> float:
        """How far ball j at angle phi falls into the defects (inner race at theta, outer at ``outer``)."""
        h = 0.0
        for race, centre, half, depth, ball, radius in self.defects:
            if race == "outer":
                off = math.remainder(phi - outer - centre, TWO_PI)
                h += self._sag(half - abs(off) * radius, depth, self.rho["outer"])
            elif race == "inner":
                off = math.remainder(phi - theta - centre, TWO_PI)
                h += self._sag(half - abs(off) * radius, depth, self.rho["inner"])
            elif ball == j:
                psi = centre + self.spin * (theta - outer)
                h += self._sag(half - abs(math.remainder(psi, TWO_PI)) * radius, depth, self.rho["outer"])
                h += self._sag(
                    half - abs(math.remainder(psi - math.pi, TWO_PI)) * radius, depth, self.rho["inner"]
                )
        return h

    def force(
        self, x: float, y: float, vx: float, vy: float, theta: float, outer: float = 0.0
    ) -> tuple[float, float]:
        """Force on the journal (N), the inner race turned by theta and the outer by ``outer``."""
        fx, fy = -self.C * vx, -self.C * vy
        base = self.cage(theta, outer)
        for j in range(self.Z):
            phi = base + j * self.pitch
            cx, cy = math.cos(phi), math.sin(phi)
            defl = x * cx + y * cy - self.c
            if defl > 0.0 and self.defects:
                defl -= self.drop(j, phi, theta, outer)
            if defl > 0.0:
                p = self.K * defl**self.n
                fx -= p * cx
                fy -= p * cy
        return fx, fy

    def forces(self, U: np.ndarray, V: np.ndarray, theta: np.ndarray) -> np.ndarray:
        """Forces (2 x n) at the samples of U, V (2 x n) and theta (n)."""
        return np.array(
            [self.force(U[0, i], U[1, i], V[0, i], V[1, i], theta[i]) for i in range(U.shape[1])]
        ).T

    def static_displacement(self, f: np.ndarray, axes) -> np.ndarray:
        """u_0 with force(u_0, 0, 0) + f = 0 on the free axes (races at angle 0)."""
        from scipy.optimize import fsolve

        free = list(axes)
        size = float(np.hypot(*f))
        if size == 0.0 or not free:
            return np.zeros(2)

        def res(x_um):
            u = np.zeros(2)
            u[free] = x_um * 1e-6
            return (np.array(self.force(u[0], u[1], 0.0, 0.0, 0.0)) + f)[free] / size

        for start in (3.0, 10.0, 30.0, 100.0):
            x, _, ok, _ = fsolve(res, start * f[free] / size, xtol=1e-14, full_output=True)
            if ok == 1 and np.max(np.abs(res(x))) < 1e-9:
                u = np.zeros(2)
                u[free] = x * 1e-6
                return u
        raise ValueError("rolling-elements bearing: no static equilibrium under the mesh force")
