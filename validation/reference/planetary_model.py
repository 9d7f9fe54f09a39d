"""A planetary stage from the contract (docs/planetary.md, "The stage in a drive: scenario keys and
equations", and "Friction"), in the inertial frame: geometry and checks, the exact involute deflections
and lines of action, the bearings and supports, the generalised forces (friction as a force at the
contact point, placed from the tangent points, its direction opposing v_T, the velocity whose product
with it is the friction power: :meth:`PlanetaryStage.friction_forces`), the rigid speeds and the static
equilibrium.

Members are planar rigid bodies ``(x, y, theta)``, ordered sun, ring, carrier, planet 1 .. N (member m
at coordinates ``3 m .. 3 m + 2``).  The mesh normal force comes from the reference's own locked-mode
law (:class:`.mesh._Mesh` built from a mesh view, :func:`.modes._mesh_force`); here only the geometry.
Written from the equations; shares nothing with gearbody.
"""

from __future__ import annotations

import math

import numpy as np

from .lateral_scenario import bearing_force
from .mesh import _Mesh
from .modes import _mesh_force, _mode_error, _mode_mu_envelope, _slide_mode, _slide_sigma

MEMBERS = ("sun", "ring", "carrier")
SUN, RING, CARRIER = 0, 1, 2


def involute(a):
    """inv(a) = tan a - a."""
    return np.tan(a) - a


def _mesh_view(
    z1,
    r1,
    i1,
    z2,
    r2,
    i2,
    mesh: dict,
    em: dict,
    alpha_deg: float,
    F_rated: float,
    seed: int,
    mu: float = 0.0,
    v0: float | None = None,
):
    """A one-stage-shaped mesh view of one planetary mesh for :class:`.mesh._Mesh` (friction mu gives
    the law's magnitude, v_0 (None: the default) its direction's transition speed; no faults; the random
    draw is replaced by the caller)."""
    full = {
        "stiffness_profile": mesh.get("stiffness_profile", "contact-ratio"),
        "stiffness_single_N_per_m": float(mesh["stiffness_single_N_per_m"]),
        "stiffness_double_N_per_m": float(mesh["stiffness_double_N_per_m"]),
        "contact_ratio": float(mesh["contact_ratio"]),
        "damping_Ns_per_m": float(mesh.get("damping_Ns_per_m", 0.0)),
        "backlash_um": float(mesh.get("backlash_um", 0.0)),
        "pressure_angle_deg": alpha_deg,
        "pitch_point_phase": float(mesh.get("pitch_point_phase", 0.5)),
        "transition_width": float(mesh.get("transition_width", 0.0)),
    }
    if full["stiffness_profile"] not in ("contact-ratio", "iso-6336-b"):
        raise ValueError(f"planetary mesh: stiffness_profile {full['stiffness_profile']!r} not supported")
    condition = {"friction_coefficient": float(mu), "damaged_teeth": [], "pitted_teeth": []}
    if v0 is not None:
        condition["friction_transition_speed_m_s"] = float(v0)
    return {
        "meta": {"seed": seed, "scene": "train-stage", "stage_index": 0},
        "design": {
            "pinion": {"teeth": z1, "base_radius_m": r1, "inertia_kg_m2": i1},
            "wheel": {"teeth": z2, "base_radius_m": r2, "inertia_kg_m2": i2},
            "mesh": full,
            "machine": {"rated_torque_Nm": F_rated * r2},
        },
        "production": {"error_mode": dict(em), "eccentricity": []},
        "condition": condition,
    }


class PlanetaryStage:
    """Constants of one planetary stage (a ``design.stages`` item with ``type = "planetary"``).

    ``F_rated``: the rated force per planet and mesh (scales the tolerances; kd = F / F_rated);
    ``friction_coefficient``: mu of every sun and ring mesh (the drive's condition);
    ``friction_transition_speed_m_s``: their v_0 (None: the default of the contract).
    """

    def __init__(
        self,
        stage: dict,
        *,
        seed: int = 1,
        stage_index: int = 0,
        F_rated: float | None = None,
        friction_coefficient: float = 0.0,
        friction_transition_speed_m_s: float | None = None,
    ):
        self.mu = float(friction_coefficient)
        self.v0 = friction_transition_speed_m_s
        if stage.get("type", "planetary") != "planetary":
            raise ValueError("not a planetary stage")
        self.N = N = int(stage["planets"])
        if N < 1:
            raise ValueError("planets must be >= 1")
        sun, pl, ring, car = (stage[k] for k in ("sun", "planet", "ring", "carrier"))
        self.z_s, self.z_p, self.z_r = zs, zp, zr = int(sun["teeth"]), int(pl["teeth"]), int(ring["teeth"])
        m = float(stage["module_mm"]) * 1e-3
        self.alpha = alpha = math.radians(float(stage.get("pressure_angle_deg", 20.0)))
        if zr != zs + 2 * zp:
            raise ValueError(f"stage {stage_index + 1}: z_r = {zr} != z_s + 2 z_p = {zs + 2 * zp}")
        angles = list(stage.get("planet_angles_deg", []))
        if not angles:
            if (zs + zr) % N:
                raise ValueError(f"stage {stage_index + 1}: (z_s + z_r) / N = {(zs + zr) / N} not an integer")
            psi = [2.0 * math.pi * n / N for n in range(N)]
        else:
            if len(angles) != N or float(angles[0]) != 0.0 or np.any(np.diff(angles) <= 0):
                raise ValueError(f"stage {stage_index + 1}: planet_angles_deg: N increasing angles from 0")
            psi = [math.radians(float(a)) for a in angles]
            for a in angles:
                x = (zs + zr) * float(a) / 360.0
                if abs(x - round(x)) > 1e-9:
                    raise ValueError(
                        f"stage {stage_index + 1}: planet angle {a} deg: not on the mesh condition"
                    )
        self.psi = np.array(psi)
        self.r_c = m * (zs + zp) / 2.0
        r_s, r_p, r_r = m * zs / 2.0, m * zp / 2.0, m * zr / 2.0
        self.r_bs, self.r_bp, self.r_br = (r * math.cos(alpha) for r in (r_s, r_p, r_r))
        dpsi = np.diff(np.append(self.psi, self.psi[0] + 2.0 * math.pi)) if N > 1 else np.array([])
        if np.any(2.0 * self.r_c * np.sin(dpsi / 2.0) <= 2.0 * (r_p + m)):
            raise ValueError(f"stage {stage_index + 1}: neighbouring planets' tip circles overlap")
        pb = math.pi * m * math.cos(alpha)
        eps_s = (
            math.sqrt((r_s + m) ** 2 - self.r_bs**2)
            + math.sqrt((r_p + m) ** 2 - self.r_bp**2)
            - self.r_c * math.sin(alpha)
        ) / pb
        eps_r = (
            math.sqrt((r_p + m) ** 2 - self.r_bp**2)
            - math.sqrt((r_r - m) ** 2 - self.r_br**2)
            + self.r_c * math.sin(alpha)
        ) / pb
        self.contact_ratio = {"sun": eps_s, "ring": eps_r}
        # roles, turning sense (contract "Turning sense")
        self.input, self.output = stage.get("input", "sun"), stage.get("output", "carrier")
        if self.input not in MEMBERS or self.output not in MEMBERS or self.input == self.output:
            raise ValueError(f"stage {stage_index + 1}: input and output must be two of {MEMBERS}")
        self.fixed = next(x for x in MEMBERS if x not in (self.input, self.output))
        self.i_in, self.i_out, self.i_fix = (MEMBERS.index(x) for x in (self.input, self.output, self.fixed))
        w = self.rigid_speeds(self.input, 1.0)
        self.ratio = 1.0 / w[self.i_out]  # speed in / speed out
        self.s_in = 1.0 if self.input in ("sun", "ring") else -1.0
        self.s_out = self.s_in * math.copysign(1.0, w[self.i_out])
        arm = {"sun": N * self.r_bs, "ring": N * self.r_br, "carrier": N * (self.r_bs + self.r_br)}
        self.r_eq_in, self.r_eq_out = arm[self.input], arm[self.output]
        # members: mass, inertia, bearing (planet: on the carrier), torsion (the fixed member only)
        members = (sun, ring, car) + (pl,) * N
        self.mass = np.array([float(x["mass_kg"]) for x in members])
        self.inertia = np.array([float(x["inertia_kg_m2"]) for x in members])
        # a member gives either an isotropic linear bearing or a bearing law (contract "Bearing laws")
        self.kb = [float(x.get("bearing_stiffness_N_per_m", 0.0)) for x in (sun, ring, car, pl)]
        self.cb = [float(x.get("bearing_damping_Ns_per_m", 0.0)) for x in (sun, ring, car, pl)]
        self.law = [x.get("bearing") for x in (sun, ring, car, pl)]
        # faults (contract "Faults"): planet bearing factors, pin errors, damaged teeth
        self.bearing_factor = np.ones(N)
        for d in stage.get("planet_bearing_defects", []):
            n = int(d["planet"])
            if not 1 <= n <= N or not 0.0 < float(d["stiffness_factor"]) <= 1.0:
                raise ValueError(
                    f"stage {stage_index + 1}: planet bearing defect {d}: planet 1..N, factor (0, 1]"
                )
            self.bearing_factor[n - 1] = float(d["stiffness_factor"])
        pins = [float(e) * 1e-6 for e in stage.get("planet_position_errors_um", [])]
        if pins and len(pins) != N:
            raise ValueError(f"stage {stage_index + 1}: planet_position_errors_um needs N values")
        self.pin_angle = self.psi + (np.array(pins) / self.r_c if pins else 0.0)
        factors = {"sun": np.ones(zs), "ring": np.ones(zr), "planet": np.ones((N, zp))}
        for t in stage.get("damaged_teeth", []):
            member, tooth, f = t["member"], int(t["tooth"]), float(t["stiffness_factor"])
            row = factors[member] if member != "planet" else factors["planet"][int(t["planet"]) - 1]
            if not 0 <= tooth < row.size or not 0.0 <= f <= 1.0:
                raise ValueError(f"stage {stage_index + 1}: damaged tooth {t}: tooth or factor out of range")
            row[tooth] *= f
        for name, x in (("sun", sun), ("ring", ring), ("carrier", car)):
            if name != self.fixed and "torsion_stiffness_Nm_per_rad" in x:
                raise ValueError(f"stage {stage_index + 1}: torsion_stiffness on {name}, which is not fixed")
        fx = stage[self.fixed]
        if "torsion_stiffness_Nm_per_rad" not in fx:
            raise ValueError(f"stage {stage_index + 1}: fixed member {self.fixed} needs torsion_stiffness")
        self.kt = float(fx["torsion_stiffness_Nm_per_rad"])
        self.ct = float(fx.get("torsion_damping_Nms_per_rad", 0.0))
        self.n_dof = 3 * (N + 3)
        # meshes: the reference's own law on a mesh view each; z1 = sun (sun mesh) or ring (ring mesh)
        self.F_rated = float(F_rated) if F_rated is not None else 1.0
        self.g_ring = 0.0 if zp % 2 else 0.5
        # Planet n's tooth j meets the ring in the ring mesh's periods n_r = j + M_n + floor(z_p / 2)
        # (mod z_p), M_n = (z_s + z_r) psi_n / 2 pi: the ring view's wheel tooth k is planet tooth
        # k - M_n - floor(z_p / 2).
        M = np.rint((zs + zr) * self.psi / (2.0 * math.pi)).astype(int)

        def damaged(pinion: np.ndarray, wheel: np.ndarray) -> list:
            return [
                {"gear": gear, "tooth": i, "stiffness_factor": float(f)}
                for gear, arr in (("pinion", pinion), ("wheel", wheel))
                for i, f in enumerate(arr)
                if f != 1.0
            ]

        def law_of(kind, z1, r1, i1, key, wheel_factors):
            mesh = dict(stage[f"{kind}_mesh"])
            mesh.setdefault("contact_ratio", self.contact_ratio[kind])
            em = stage.get(f"{kind}_error_mode", {"a": 0.5, "e_um": 0.0, "r": 0.0})
            view = _mesh_view(
                z1,
                r1,
                float(i1["inertia_kg_m2"]),
                zp,
                self.r_bp,
                float(pl["inertia_kg_m2"]),
                mesh,
                em,
                math.degrees(alpha),
                self.F_rated,
                seed,
                self.mu,
                self.v0,
            )
            view["condition"]["damaged_teeth"] = damaged(factors[kind], wheel_factors)
            law = _Mesh(view, self.F_rated)
            l_rand = np.random.default_rng([seed, stage_index, key]).random(z1)
            law.e_amp = (1.0 - float(em["r"]) * (1.0 - l_rand)) * float(em["e_um"]) * 1e-6
            return law

        self.planet_laws = []
        healthy = None  # healthy planets share one pair of laws
        for n in range(N):
            fp = factors["planet"][n]
            if np.all(fp == 1.0) and healthy is not None:
                self.planet_laws.append(healthy)
                continue
            ring_wheel = np.array([fp[(k - M[n] - zp // 2) % zp] for k in range(zp)])
            laws = {
                "sun": law_of("sun", zs, self.r_bs, sun, 1, fp),
                "ring": law_of("ring", zr, self.r_br, ring, 2, ring_wheel),
            }
            if np.all(fp == 1.0):
                healthy = laws
            self.planet_laws.append(laws)
        self.laws = self.planet_laws[0]
        # the 2N meshes: planet n's sun mesh is mesh 2n, its ring mesh 2n + 1
        self.meshes = [self.planet_laws[n][k] for n in range(N) for k in ("sun", "ring")]
        q0 = np.zeros(self.n_dof)
        q0[9::3], q0[10::3] = self.r_c * np.cos(self.psi), self.r_c * np.sin(self.psi)
        self.delta0 = {"sun": np.zeros(N), "ring": np.zeros(N)}
        g = self.mesh_geometry(q0, np.zeros(self.n_dof))  # of the error-free assembly: pin errors preload
        self.delta0 = {"sun": g["sun"][0], "ring": g["ring"][0]}
        q0[9::3], q0[10::3] = self.r_c * np.cos(self.pin_angle), self.r_c * np.sin(self.pin_angle)
        self.q_nominal = q0

    # -- kinematics -------------------------------------------------------------------------------------
    def rigid_speeds(self, member: str, w_member: float, w_other: tuple[str, float] | None = None):
        """(w_sun, w_ring, w_carrier) of rigid rolling (Willis on base radii, r_bs (w_s - w_c) +
        r_br (w_r - w_c) = 0) with ``member`` at ``w_member`` and the fixed member at rest (or
        ``w_other`` = (name, speed) for the second given member)."""
        given = {member: w_member}
        given.update([w_other] if w_other is not None else [(self.fixed, 0.0)])
        rs, rr = self.r_bs, self.r_br
        if "carrier" in given:
            wc = given["carrier"]
            if "sun" in given:
                ws = given["sun"]
                wr = wc - rs * (ws - wc) / rr
            else:
                wr = given["ring"]
                ws = wc - rr * (wr - wc) / rs
        else:  # sun and ring given
            ws, wr = given["sun"], given["ring"]
            wc = (rs * ws + rr * wr) / (rs + rr)
        return np.array([ws, wr, wc])

    def rigid_state(self, w_central, q=None):
        """Velocities of rigid rolling at the central speeds (w_s, w_r, w_c): planets spin at
        w_n = w_c - (r_bs / r_bp)(w_s - w_c), their centres move with w_c z x (c_n - c_c) (positions
        from q)."""
        q = self.q_nominal if q is None else q
        v = np.zeros(self.n_dof)
        ws, wr, wc = w_central
        v[2], v[5], v[8] = ws, wr, wc
        v[11::3] = wc - self.r_bs / self.r_bp * (ws - wc)
        v[9::3], v[10::3] = -wc * (q[10::3] - q[7]), wc * (q[9::3] - q[6])  # about the carrier centre
        return v

    def mesh_geometry(self, q, v):
        """Per mesh kind ("sun", "ring"): (delta, delta_dot, n_x, n_y, law angle, its rate, alpha_w),
        arrays over the planets (q, v may carry further axes: states in columns)."""
        xs, ys, ts = q[0], q[1], q[2]
        xr, yr, tr = q[3], q[4], q[5]
        tc = q[8]
        xn, yn, tn = q[9::3], q[10::3], q[11::3]
        vxn, vyn, wn = v[9::3], v[10::3], v[11::3]
        col = (-1,) + (1,) * np.ndim(tc)  # the planets' axis first, states in columns after it
        ref = tc + self.psi.reshape(col)
        d0s, d0r = self.delta0["sun"].reshape(col), self.delta0["ring"].reshape(col)
        out = {}
        for kind, xa, ya, ta, va in (("sun", xs, ys, ts, v[0:3]), ("ring", xr, yr, tr, v[3:6])):
            dx, dy = xn - xa, yn - ya
            D = np.hypot(dx, dy)
            phi = ref + np.mod(np.arctan2(dy, dx) - ref + math.pi, 2.0 * math.pi) - math.pi
            ex, ey = dx / D, dy / D
            ddx, ddy = vxn - va[0], vyn - va[1]
            phidot = (ex * ddy - ey * ddx) / D
            if kind == "sun":
                R = self.r_bs + self.r_bp
                aw = np.arccos(R / D)
                sa, ca = np.sin(aw), np.cos(aw)
                nx, ny = sa * ex - ca * ey, sa * ey + ca * ex  # sin(a_w) e + cos(a_w) e_perp
                delta = self.r_bs * ta + self.r_bp * tn - R * phi - R * involute(aw) - d0s
                ddot = self.r_bs * va[2] + self.r_bp * wn - (nx * ddx + ny * ddy)
                ang, angdot = ta - phi, va[2] - phidot
            else:
                R = self.r_br - self.r_bp
                aw = np.arccos(R / D)
                sa, ca = np.sin(aw), np.cos(aw)
                nx, ny = -sa * ex - ca * ey, -sa * ey + ca * ex  # -sin(a_w) e + cos(a_w) e_perp
                delta = self.r_br * ta - self.r_bp * tn - R * phi + R * involute(aw) - d0r
                ddot = self.r_br * va[2] - self.r_bp * wn - (nx * ddx + ny * ddy)
                ang = phi - ta + 2.0 * math.pi * self.g_ring / self.z_r
                angdot = phidot - va[2]
            out[kind] = (delta, ddot, nx, ny, ang, angdot, aw)
        return out

    # -- forces -----------------------------------------------------------------------------------------
    def mesh_forces(self, geo, mcs, modes):
        """Normal forces (sun, ring) of every planet from the locked modes: F = law(p, delta, delta_dot)."""
        F = {}
        for j, kind in enumerate(("sun", "ring")):
            delta, ddot, ang = geo[kind][0], geo[kind][1], geo[kind][4]
            cz = self.laws[kind].cz  # z1 / 2 pi, the same for every planet
            F[kind] = [
                _mesh_force(mcs[2 * n + j], ang[n] * cz - modes[2 * n + j][0], delta[n], ddot[n])
                for n in range(self.N)
            ]
        return F

    def friction_forces(self, v, geo, mcs, modes, F):
        """Friction of every planet's meshes (contract "Friction in the meshes"): per kind, over the
        planets, T = -mu e(p) |F| sigma(v_T / v_0) with the velocity whose product with T is the friction
        power (the generalised force of a unit T, :meth:`generalised_forces`, dotted with v),

            sun mesh:  v_T = (c_n' - c_s') . m + w_s rho_s + w_p rho_p,
            ring mesh: v_T = (c_r' - c_n') . m + w_r rho_r - w_p rho_p,

        m = (n_y, -n_x), rho_1 = r_b1 tan(alpha_w) + (p - pitch) p_b, rho_p = r_bp tan(alpha_w) -+ (p -
        pitch) p_b; and the arm offsets (p - pitch) p_b (m).  p is the phase in the mesh's locked mode; v
        one state or states in columns.  Returns (T, offsets, v_T), each {kind: [per planet]}."""
        T, dp, vT = {}, {}, {}
        for j, kind in enumerate(("sun", "ring")):
            nx, ny, ang, aw = geo[kind][2], geo[kind][3], geo[kind][4], geo[kind][6]
            ia, r1 = (0, self.r_bs) if kind == "sun" else (3, self.r_br)
            T[kind], dp[kind], vT[kind] = [], [], []
            for n in range(self.N):
                law, (nn, _k, _c, g) = self.planet_laws[n][kind], modes[2 * n + j]
                mc = mcs[2 * n + j]
                p = ang[n] * law.cz - nn
                off = (p - law.ppp) * law.pb
                tan = np.tan(aw[n])
                b = 9 + 3 * n
                rel = (v[b] - v[ia]) * ny[n] - (v[b + 1] - v[ia + 1]) * nx[n]  # (c_n' - c_1') . m
                if kind == "sun":
                    v_T = rel + v[ia + 2] * (r1 * tan + off) + v[b + 2] * (self.r_bp * tan - off)
                else:
                    v_T = -rel + v[ia + 2] * (r1 * tan + off) - v[b + 2] * (self.r_bp * tan + off)
                Tn = -_mode_mu_envelope(law, mc, p) * np.abs(F[kind][n]) * _slide_sigma(g, v_T * law.inv_v0)
                T[kind].append(Tn)
                dp[kind].append(off)
                vT[kind].append(v_T)
        return T, dp, vT

    def generalised_forces(self, q, v, geo, F, damping: bool = True, friction=None):
        """Generalised forces of meshes (-F grad delta), bearings, supports and the fixed member's
        torsion on the stage's coordinates (no external torques); ``friction`` = (T, arm offsets) of
        :meth:`friction_forces`: a force along m = n turned -90 deg at the contact point C (sun mesh:
        C = T_s + rho_s n, T_s = c_s + r_bs m, +T m on the planet; ring mesh: C = T_r - rho_r n, T_r = c_r
        + r_br m, -T m on the planet; rho_1 = r_b1 tan(alpha_w) + (p - pitch) p_b), the opposite on the
        sun or ring, each member's moment (C - c) x f."""
        Q = np.zeros(self.n_dof)
        cf = 1.0 if damping else 0.0
        for m in range(3):  # central members on isotropic spring-dampers (or their law) to the ground
            if self.law[m] is not None:
                Q[3 * m : 3 * m + 2] += bearing_force(  # the member turns the inner race
                    self.law[m], q[3 * m : 3 * m + 2], cf * v[3 * m : 3 * m + 2], q[3 * m + 2]
                )
                continue
            Q[3 * m : 3 * m + 2] -= self.kb[m] * q[3 * m : 3 * m + 2] + cf * self.cb[m] * v[3 * m : 3 * m + 2]
        f = 3 * self.i_fix + 2
        Q[f] -= self.kt * q[f] + cf * self.ct * v[f]
        xc, yc, tc = q[6], q[7], q[8]
        vxc, vyc, wc = v[6], v[7], v[8]
        for n in range(self.N):
            kp, cp = self.kb[3] * self.bearing_factor[n], cf * self.cb[3] * self.bearing_factor[n]
            b = 9 + 3 * n
            a = tc + self.pin_angle[n]
            ax, ay = self.r_c * math.cos(a), self.r_c * math.sin(a)  # P_n - c_c
            if self.law[3] is None:
                fx = -kp * (q[b] - xc - ax) - cp * (v[b] - vxc + wc * ay)  # bearing force on the planet
                fy = -kp * (q[b + 1] - yc - ay) - cp * (v[b + 1] - vyc - wc * ax)
            else:  # the law in the carrier frame: radial along the pin's radius, tangential ahead of it
                ca, sa = math.cos(a), math.sin(a)
                ex, ey = q[b] - xc - ax, q[b + 1] - yc - ay
                dx, dy = v[b] - vxc + wc * ay, v[b + 1] - vyc - wc * ax
                fr, ft = bearing_force(
                    self.law[3],
                    (ca * ex + sa * ey, -sa * ex + ca * ey),
                    (cf * (ca * dx + sa * dy), cf * (-sa * dx + ca * dy)),
                    0.0,  # the pin is the inner race; the planet turns the outer relative to the carrier
                    q[b + 2] - tc,
                )
                fx, fy = ca * fr - sa * ft, sa * fr + ca * ft
            Q[b] += fx
            Q[b + 1] += fy
            Q[6] -= fx
            Q[7] -= fy
            Q[8] -= ax * fy - ay * fx  # (P_n - c_c) x (reaction -f)
            for kind, ia, r1, sp in (("sun", 0, self.r_bs, 1.0), ("ring", 3, self.r_br, -1.0)):
                Fn = F[kind][n]
                nx, ny = geo[kind][2][n], geo[kind][3][n]
                Q[ia + 2] -= Fn * r1
                Q[b + 2] -= sp * Fn * self.r_bp
                Q[ia] -= Fn * nx
                Q[ia + 1] -= Fn * ny
                Q[b] += Fn * nx
                Q[b + 1] += Fn * ny
                if friction is None:
                    continue
                Tn, aw = friction[0][kind][n], geo[kind][6][n]
                mx, my = ny, -nx
                rho1 = r1 * math.tan(aw) + friction[1][kind][n]
                out = sp * rho1  # sun: C = T_s + rho_s n; ring: C = T_r - rho_r n
                cx, cy = q[ia] + r1 * mx + out * nx, q[ia + 1] + r1 * my + out * ny
                tx, ty = sp * Tn * mx, sp * Tn * my  # on the planet
                Q[b] += tx
                Q[b + 1] += ty
                Q[b + 2] += (cx - q[b]) * ty - (cy - q[b + 1]) * tx
                Q[ia] -= tx
                Q[ia + 1] -= ty
                Q[ia + 2] -= (cx - q[ia]) * ty - (cy - q[ia + 1]) * tx
        return Q

    def mass_vector(self) -> np.ndarray:
        """Diagonal of the mass matrix: (m, m, I) per member."""
        return np.stack([self.mass, self.mass, self.inertia], axis=1).ravel()

    def mesh_modes(self, q, v):
        """Locked modes [n, k, c, g] of the 2N meshes at the state (q, v) (g: friction's slide mode)."""
        geo = self.mesh_geometry(q, v)
        modes = []
        for n in range(self.N):
            for kind in ("sun", "ring"):
                law = self.planet_laws[n][kind]
                delta, ddot, ang, angdot = geo[kind][0], geo[kind][1], geo[kind][4], geo[kind][5]
                nn, k = law.phase_mode(float(ang[n] * law.cz), float(angdot[n] * law.cz))
                mc = law.mode_consts(nn, k, 0)
                d = float(delta[n] + _mode_error(mc, ang[n] * law.cz - nn))
                g = _slide_mode(self.one_mesh_sliding(q, v, n, kind, nn) * law.inv_v0) if self.mu else 0
                modes.append([nn, k, law.contact_mode(d, float(ddot[n])), g])
        return modes

    def static_equilibrium(
        self, torques, theta_gauge: float = 0.0, q_start=None, carrier_speed_rad_s: float = 0.0
    ) -> np.ndarray:
        """Static equilibrium (exact deflections, mesh laws without damping) under the external torques
        (sun, ring, carrier) and the planets' centrifugal forces m_p w_c^2 (c_n - c_c) of a carrier
        turning at ``carrier_speed_rad_s``, the input member's rotation held at ``theta_gauge``: Newton
        from the nominal assembly (or q_start), the Jacobian by central differences in the modes of the
        iterate (the locked law is smooth there, so a mode boundary next to the state cannot spoil it)."""
        q = (self.q_nominal if q_start is None else q_start).copy()
        g = 3 * self.i_in + 2
        q[g] = theta_gauge
        free = np.array([i for i in range(self.n_dof) if i != g])
        zero = np.zeros(self.n_dof)
        ext = np.zeros(self.n_dof)
        ext[[2, 5, 8]] = torques

        def resid(qq, modes):
            mcs = [law.mode_consts(nn, k, c) for law, (nn, k, c, _g) in zip(self.meshes, modes, strict=True)]
            geo = self.mesh_geometry(qq, zero)
            Q = self.generalised_forces(qq, zero, geo, self.mesh_forces(geo, mcs, modes), damping=False)
            centrifugal = np.zeros(self.n_dof)
            w2 = self.mass[3] * carrier_speed_rad_s**2  # every planet's mass
            centrifugal[9::3], centrifugal[10::3] = w2 * (qq[9::3] - qq[6]), w2 * (qq[10::3] - qq[7])
            return (Q + ext + centrifugal)[free]

        # Every mesh is first locked on its loaded flank (contact mode 1: F = k (d - l_u), a law without
        # the backlash's dead zone, whose Jacobian at the unloaded start is regular); once converged the
        # true contact modes take over and Newton goes on until the modes agree with the state.
        if any(law is not None for law in self.law):
            # a bearing law with clearance carries nothing at the nominal assembly, where the Jacobian is
            # singular (the carrier hangs on nothing): Levenberg-Marquardt from there, the meshes locked
            # on their loaded flanks, then Newton as below
            from scipy.optimize import least_squares

            def locked_resid(x):
                qq = q.copy()
                qq[free] = x
                return resid(qq, [[nn, k, 1, 0] for nn, k, _c, _g in self.mesh_modes(qq, zero)])

            scale = np.where(free % 3 == 2, 1e-6 / self.r_c, 1e-6)
            q[free] = least_squares(
                locked_resid, q[free], method="lm", x_scale=scale, xtol=1e-15, ftol=1e-15, gtol=1e-15
            ).x
        locked = True
        for _it in range(40):
            modes = self.mesh_modes(q, zero)
            if locked:
                modes = [[nn, k, 1, 0] for nn, k, _c, _g in modes]
            r = resid(q, modes)
            J = np.empty((free.size, free.size))
            for c, i in enumerate(free):
                h = 1e-9 * max(1.0, abs(q[i]))
                qp, qm = q.copy(), q.copy()
                qp[i] += h
                qm[i] -= h
                J[:, c] = (resid(qp, modes) - resid(qm, modes)) / (2.0 * h)
            dq = np.linalg.solve(J, -r)
            q[free] += dq
            if np.max(np.abs(dq)) <= 1e-11 * max(np.max(np.abs(q - self.q_nominal)), 1e-12):
                if not locked:
                    return q
                locked = False
        raise RuntimeError("static equilibrium: Newton did not converge")

    def one_mesh(self, q, n: int, kind: str):
        """(law angle, delta) of planet n's ``kind`` mesh only (for the events; q may hold states in
        columns): the same expressions as :meth:`mesh_geometry`."""
        ia = 0 if kind == "sun" else 3
        b = 9 + 3 * n
        dx, dy = q[b] - q[ia], q[b + 1] - q[ia + 1]
        ref = q[8] + self.psi[n]
        phi = ref + np.mod(np.arctan2(dy, dx) - ref + math.pi, 2.0 * math.pi) - math.pi
        D = np.hypot(dx, dy)
        if kind == "sun":
            R = self.r_bs + self.r_bp
            delta = self.r_bs * q[2] + self.r_bp * q[b + 2] - R * phi - R * involute(np.arccos(R / D))
            return q[2] - phi, delta - self.delta0["sun"][n]
        R = self.r_br - self.r_bp
        delta = self.r_br * q[5] - self.r_bp * q[b + 2] - R * phi + R * involute(np.arccos(R / D))
        return phi - q[5] + 2.0 * math.pi * self.g_ring / self.z_r, delta - self.delta0["ring"][n]

    def one_mesh_sliding(self, q, v, n: int, kind: str, nn: int):
        """v_T of planet n's ``kind`` mesh in the locked phase period nn (for its slide events; q, v may
        hold states in columns): the expressions of :meth:`friction_forces` on :meth:`one_mesh`'s
        geometry."""
        ia = 0 if kind == "sun" else 3
        b = 9 + 3 * n
        dx, dy = q[b] - q[ia], q[b + 1] - q[ia + 1]
        D = np.hypot(dx, dy)
        ex, ey = dx / D, dy / D
        law = self.planet_laws[n][kind]
        ang = self.one_mesh(q, n, kind)[0]
        off = (ang * law.cz - nn - law.ppp) * law.pb
        if kind == "sun":
            R = self.r_bs + self.r_bp
            aw = np.arccos(R / D)
            sa, ca = np.sin(aw), np.cos(aw)
            nx, ny = sa * ex - ca * ey, sa * ey + ca * ex
        else:
            R = self.r_br - self.r_bp
            aw = np.arccos(R / D)
            sa, ca = np.sin(aw), np.cos(aw)
            nx, ny = -sa * ex - ca * ey, -sa * ey + ca * ex
        tan = np.tan(aw)
        rel = (v[b] - v[ia]) * ny - (v[b + 1] - v[ia + 1]) * nx  # (c_n' - c_1') . m, m = (n_y, -n_x)
        if kind == "sun":
            return rel + v[ia + 2] * (self.r_bs * tan + off) + v[b + 2] * (self.r_bp * tan - off)
        return -rel + v[ia + 2] * (self.r_br * tan + off) - v[b + 2] * (self.r_bp * tan + off)
