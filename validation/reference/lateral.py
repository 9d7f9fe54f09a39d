"""Independent reference model for the *lateral* gear models of ``docs/scenario.md`` (section "Lateral
models: gears on bearings (Figs. 17, 18)"): gears of a ``train`` whose
centres translate in the housing's x-y plane on a ``linear`` or ``hertzian`` bearing (topology
``train``, canonical or legacy shape; a legacy ``one-stage`` is read as its 1-stage train).

Written from the contract only; it shares no code with ``gearbody``.  It reuses the torsional helpers of
this package (random draw, error shape, stiffness profiles, tooth factors, Kloss, profiles,
the locked-mode mesh law and the ONE segmented integrator, :func:`.integrate.integrate`, with its
missed-event scan).  So every stiffness
profile of the torsional reference works here too: "iso-6336-b" as "contact-ratio", and the "pairs" law
of "potential-energy" (pair table ``mesh.pair_table`` from ``validation.compare.reference_input``, its
grid points as phase break points, damping ``C_z k / k_healthy``); the steady start uses the law's
effective stiffness at the initial phase
(:func:`.law.effective_stiffness`).  Modules: :mod:`.lateral_scenario` (defaults, geometry, bearing
law), :mod:`.lateral_model` (the system: right-hand side, events, outputs), this one (initial state,
entry point); ``validation.reference_lateral`` re-exports them.

Model
-----
A train of N >= 1 stages (a legacy ``one-stage`` scenario is rewritten as the 1-stage train: coupling
= shaft 0, output shaft = shaft 1, production.error_mode / eccentricity and condition.damaged_teeth /
pitted_teeth moved into the stage, which is the canonical shape).
State ``y = [q, v]`` with ``q = [motor, pinion_1, wheel_1, ..., pinion_N, wheel_N, machine, lateral...]``;
the lateral coordinates follow in the order stage 1 pinion (x, y as free), stage 1 wheel, stage 2
pinion, ...

Per stage (geometry ``n``, ``m = s1 (-n_y, n_x)``):
``delta = r1 phi_p - r2 phi_w + (u_p - u_w) . n``; F, rho_1, rho_2 as in the torsional model, T with
the centres' share in the sliding velocity (below);
pinion: moment ``-r1 F + T rho_1``, force ``-F n + T m``; wheel: ``+r2 F - T rho_2``, ``+F n - T m``.
Fault errors (run-out, pits) are part of the error E and enter ``d = delta + E`` only, exactly as in
the torsional reference (its locked-mode constants and ``_mode_error``; the initial deflection uses
``total_error``); the lateral projection is part of ``delta`` and so sits beside them in ``d``.
The transition width (``mesh.transition_width`` w > 0: smoothed stiffness ramps, blended factor and
error at the tooth change, smoothed pit edges and friction's envelope) comes with the torsional
reference's locked-mode law as well.  Friction (:func:`.modes._mode_friction`): its direction opposes
the sliding velocity ``v_sl = rho_1 phi_p' - rho_2 phi_w' + (u_p' - u_w') . m`` (the centres' velocities
along m included, a fixed direction's velocity 0), regularised by v_0 in each mesh's slide mode as in
the torsional reference.
Bearing forces: linear ``-(k_x x + C_x x', k_y y + C_y y')``; hertzian
``-max(k_b (r - c)^n + C u'.u / r, 0) u / r`` for ``r > c``, else 0.

Discontinuities
---------------
As in the torsional reference, integration is done segment by segment in locked modes with terminal
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

import numpy as np

from .initial import chain_speeds
from .integrate import _output_times, integrate
from .lateral_model import _LatTrain
from .lateral_scenario import static_displacement
from .law import effective_stiffness, total_error
from .scenario import TWO_PI, profile_value, stage_view, train_stages


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
    stages = train_stages(sc)
    d_ = sc["design"]
    shaft_k = model.shaft_k
    load0 = float(profile_value(0.0, sc["operation"]["load_profile"]))
    M_L = float(d_["machine"]["rated_torque_Nm"]) * load0
    r_p = [float(st["pinion"]["base_radius_m"]) for st in stages]
    r_w = [float(st["wheel"]["base_radius_m"]) for st in stages]
    z_p = [int(st["pinion"]["teeth"]) for st in stages]
    F = [load0 * Fr for Fr in model.Frated]
    pinion_torque = [F[s] * r_p[s] for s in range(N)]
    chain_speeds(sc, pinion_torque[0], r_p, r_w, v0)
    pinion = 0.0
    for s in range(N):
        view = stage_view(sc, s)
        mesh = view["design"]["mesh"]
        u = pinion * z_p[s] / TWO_PI
        k = float(effective_stiffness(view, u)[0])  # w > 0: blended factor; pairs: the pair sum
        E = float(total_error(view, u))  # fault errors included
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


def simulate_reference_lateral(
    scenario: dict,
    t_eval: np.ndarray | None = None,
    *,
    rtol: float = 1e-10,
    atol: float | np.ndarray | None = None,
    method: str = "DOP853",
) -> dict:
    """Integrate a train scenario (or a legacy one-stage) with lateral gears; see the module docstring.

    Returns time_s (and time), coordinates / velocities (n_dof x n_t, order of the module docstring),
    stage_mesh_force_N, stage_kd, stage_friction_force_N (N x n_t), mesh_force_N / kd (stage 1), and per
    lateral gear name: centre_displacement_m, centre_velocity_m_s, bearing_force_N (force the gear
    exerts on the housing: -f_b in a free direction, the mesh force on the centre in a fixed one),
    mesh_force_on_centre_N, centre_accel_m_s2 (0 in fixed directions), housing_accel_m_s2 (each
    2 x n_t, rows x, y); nfev, n_segments, n_missed_events.
    """
    model = _LatTrain(scenario)
    t_eval = _output_times(model.sc, t_eval)
    if atol is None:
        atol = model.default_atol(rtol)
    nd = model.n_dof
    q0, v0 = initial_state_lateral(model)
    res = integrate(model, np.concatenate((q0, v0)), t_eval, rtol, atol, method)
    Y, out = res["Y"], res["out"]
    n_t = t_eval.size
    F_out = out["F"]
    names = [g.name for g in model.gears]
    D, V, FB, FM = ({nm: out[kind, nm] for nm in names} for kind in ("D", "V", "FB", "FM"))
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
        "stage_friction_force_N": out["T"],
        "centre_displacement_m": D,
        "centre_velocity_m_s": V,
        "centre_accel_m_s2": accel,
        "bearing_law_force_N": FB,
        "bearing_force_N": to_housing,
        "mesh_force_on_centre_N": FM,
        "housing_accel_m_s2": housing,
        "nfev": np.array(res["nfev"]),
        "n_segments": np.array(res["n_segments"]),
        "n_missed_events": np.array(res["n_missed"]),
    }
