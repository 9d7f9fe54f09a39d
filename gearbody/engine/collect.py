"""A finished Exudyn run read back into a :class:`~gearbody.result.Result`: the stored steps resampled onto
the output grid (cubic Hermite), the mesh force evaluated on the resampled states by the solver's own law,
band-limited acceleration and force signals (docs/scenario.md, "Output sampling and aliasing"), and the
metadata a Result carries (scenario, versions, stages, solver statistics)."""

from __future__ import annotations

import math

import exudyn as exu
import numpy as np

from ..analysis.antialias import band_limited_samples
from ..assembly import gear_names, mesh_parameters_from_scenario, pack_drive_parameters
from ..assembly.operating_point import nominal_speeds_rad_s
from ..errors import SimulationError
from ..model import Scenario, budget, scenario_to_dict
from ..model.kinds import register_stage_kind, stage_kind
from ..model.params import stage_key
from ..physics import load_torque_at, motor_torque_at, synchronous_angle_at
from ..physics.bearings import LinearBearing
from ..physics.lateral import mesh_directions
from ..physics.mesh import mesh_contact_series, mesh_phase_series
from ..result import Result
from ..signals import stage_prefix
from ..version import __version__
from .build import BuiltSystem
from .planetary_signals import stage_input_name
from .sampling import OVERSAMPLING, CubicHermite, is_band_limited, mesh_jump_times

__all__ = ["collect"]


def _stored(mbs, sensor_ids: list[int]) -> tuple[np.ndarray, np.ndarray]:
    data = [mbs.GetSensorStoredData(s) for s in sensor_ids]
    return data[0][:, 0], np.concatenate([d[:, 1:].T for d in data])


def collect(scenario: Scenario, built: BuiltSystem) -> Result:
    """The Result of a finished run (non-finite states and an early stop raise SimulationError)."""
    mbs = built.mbs
    t_steps, q = _stored(mbs, built.sensors["q"])
    _, v = _stored(mbs, built.sensors["v"])
    _, a = _stored(mbs, built.sensors["a"])
    t_end = scenario.operation.t_end_s
    bad = ~(np.isfinite(q).all(axis=0) & np.isfinite(v).all(axis=0))
    if bad.any():
        k = int(np.argmax(bad))
        raise SimulationError(
            f"non-finite state at t = {t_steps[k]:.6g} s. Hint: lower solver.max_step_s or "
            "check for zero or negative stiffness/inertia values"
        )
    if t_steps[-1] < t_end * (1 - 1e-9):
        raise SimulationError(f"the solver stopped at t = {t_steps[-1]:.6g} s before t_end = {t_end} s")
    steps = np.diff(t_steps)
    n_steps = int(np.count_nonzero(steps > 0))
    # The first acceleration row is not computed by the explicit solver; drop duplicate time rows.
    keep = np.concatenate([[True], steps > 0])
    t_steps, q, v, a = t_steps[keep], q[:, keep], v[:, keep], a[:, keep]
    a[:, 0] = a[:, 1] if a.shape[1] > 1 else 0.0
    rate = scenario.solver.output_rate_hz
    n_out = math.floor(t_end * rate + 1e-9) + 1
    position = CubicHermite(t_steps, q, v)
    velocity = CubicHermite(t_steps, v, a)

    def states(times):
        return position(times), velocity(times), np.stack([np.interp(times, t_steps, row) for row in a])

    band_limit = scenario.solver.anti_aliasing and scenario.meta.topology != "muller"
    if band_limit:
        M = _oversampling(scenario, built, v)
        t_fine = np.arange((n_out - 1) * M + 1) / (M * rate)
        t = t_fine[::M]
    else:
        t = np.arange(n_out) / rate
    signals: dict[str, np.ndarray] = {}
    if scenario.meta.topology == "muller":
        qs, vs, acc = states(t)
        signals.update(_muller_signals(scenario, t, qs[0], vs[0], acc[0]))
    elif not band_limit:
        signals.update(_point_signals(scenario, built.dof_names, t, *states(t)))
    else:
        signals.update(_band_limited_signals(scenario, built.dof_names, t_fine, *states(t_fine), M))
    stats = {
        "steps": n_steps,
        "method": scenario.solver.method,
        "min_step_s": float(steps[steps > 0].min()) if n_steps else 0.0,
        "max_step_s": float(steps.max()) if n_steps else 0.0,
    }
    stages = [_stage_meta(scenario, k) for k in range(len(scenario.stages))]
    meta = {
        "scene": scenario.name,
        "topology": scenario.meta.topology,
        "title": scenario.meta.title,
        "seed": scenario.meta.seed,
        "scenario": scenario_to_dict(scenario),
        "gearbody_version": __version__,
        "exudyn_version": exu.__version__,
        "output_rate_hz": rate,
        "dof_names": built.dof_names,
        "rated_mesh_force_N": scenario.rated_mesh_force_N,
        **_first_stage_teeth(stages[0]),
        "stages": stages,
        "sources": list(scenario.meta.sources),
        "nominal_speeds_rad_s": nominal_speeds_rad_s(scenario),
        "solver_statistics": stats,
    }
    return Result(time_s=t, signals=signals, meta=meta)


def _first_stage_teeth(stage_meta: dict) -> dict[str, int]:
    """pinion_teeth / wheel_teeth of a parallel first stage (a planetary one has its own in 'stages')."""
    return {key: stage_meta[key] for key in ("pinion_teeth", "wheel_teeth") if key in stage_meta}


def _stage_meta(scenario: Scenario, k: int) -> dict:
    """Stage k's entry of meta["stages"]: its kind's metadata (at least its type and rated force)."""
    kind = stage_kind(scenario.stages[k])
    if kind.metadata is None:
        return {"type": kind.name, "rated_mesh_force_N": scenario.stage_rated_force_N(k)}
    return kind.metadata(scenario, k)


def _parallel_meta(scenario: Scenario, k: int) -> dict:
    st = scenario.stages[k]
    return {
        "pinion_teeth": st.pinion.teeth,
        "wheel_teeth": st.wheel.teeth,
        "rated_mesh_force_N": scenario.stage_rated_force_N(k),
    }


def _planetary_meta(scenario: Scenario, k: int) -> dict:
    st = scenario.stages[k]
    return {
        "type": "planetary",
        "sun_teeth": st.sun.teeth,
        "planet_teeth": st.planet.teeth,
        "ring_teeth": st.ring.teeth,
        "planets": st.planets,
        "planet_angles_deg": [math.degrees(a) for a in st.geometry.planet_angles_rad],
        "input": st.input,
        "output": st.output,
        "fixed": st.fixed,
        "rated_mesh_force_N": scenario.stage_rated_force_N(k),
    }


def _point_signals(scenario, names, t, q, v, a, *, drive_torques=True) -> dict[str, np.ndarray]:
    """Every coordinate's motion, then the signals of each stage kind (the parallel kinds' first, then
    the drive torques and the lateral gears' signals, then the compound kinds')."""
    signals = _torsional_signals(scenario, names, t, q, v, a, drive_torques=drive_torques)
    if scenario.is_lateral:
        signals.update(_lateral_signals(scenario, names, q, v, a, signals))
    for k, st in enumerate(scenario.stages):
        kind = stage_kind(st)
        if kind.compound and kind.signals is not None:
            signals.update(kind.signals(scenario, k, names, t, q, v, a))
    return signals


def _oversampling(scenario: Scenario, built: BuiltSystem, v_steps: np.ndarray) -> int:
    """Fine points per output sample: OVERSAMPLING, or more so that every smoothed transition of the
    mesh law (``transition_width`` w of a mesh period) spans at least 3 fine points at the fastest
    mesh frequency of the run. The run's fine grid must fit its memory budget (estimated before the
    run from the expected speeds; checked here with the measured ones)."""
    M, stage = OVERSAMPLING, None
    for k, st in enumerate(scenario.stages):
        w = st.transition_width
        if w > 0:
            row = built.dof_names.index(stage_input_name(scenario, k))
            f_mesh_hz = st.mesh_frequency_hz(float(np.max(np.abs(v_steps[row]))))
            m = budget.oversampling(f_mesh_hz, w, scenario.solver.output_rate_hz)
            if m > M:
                M, stage = m, k
    need, limit = budget.output_memory_bytes(scenario, M), budget.memory_limit_bytes(scenario)
    if stage is not None and need > limit:
        w = scenario.stages[stage].transition_width
        raise SimulationError(
            f"stage {stage + 1}: the pinion ran faster than expected, and resolving its mesh's "
            f"transition_width = {w:g} needs {M} fine points per output sample (~{need / 2**20:.4g} MiB), "
            f"more than the memory budget solver.memory_limit_MiB = {limit / 2**20:g}. Hint: widen "
            f"{stage_key(stage, 'mesh')}.transition_width or raise solver.memory_limit_MiB"
        )
    return M


def _band_limited_signals(scenario, names, t_fine, q, v, a, M=OVERSAMPLING) -> dict[str, np.ndarray]:
    """Signals on the output grid ``t_fine[::M]``: states and instantaneous mesh forces as exact
    samples; accelerations, bearing and housing signals, and a ``mesh_force_bandlimited_N`` companion
    through the anti-aliasing filter with the mesh-law jumps treated exactly (smoothed transitions of
    a non-zero transition width are resolved on the fine grid instead)."""
    fine = _point_signals(scenario, names, t_fine, q, v, a, drive_torques=False)
    t = t_fine[::M]
    jumps = []
    for k, st in enumerate(scenario.stages):
        hook = stage_kind(st).jump_times
        jumps += hook(scenario, k, names, t_fine, q, v, fine) if hook is not None else []
    jumps = np.concatenate(jumps) if jumps else np.zeros(0)
    out = {}
    for name, x in fine.items():
        if is_band_limited(name):
            out[name] = band_limited_samples(t_fine, x, M, jumps)
        else:
            out[name] = x[::M]
        if name.endswith("mesh_force_N"):
            out[name[: -len("_N")] + "_bandlimited_N"] = band_limited_samples(t_fine, x, M, jumps)
    out.update(_drive_torques(scenario, t, out[f"{names[0]}_speed_rad_s"]))
    return out


def _drive_torques(scenario, t, motor_speed_rad_s) -> dict[str, np.ndarray]:
    D = pack_drive_parameters(scenario)
    return {
        "motor_torque_Nm": np.array(
            [motor_torque_at(tk, w, D) for tk, w in zip(t, motor_speed_rad_s, strict=True)]
        ),
        "load_torque_Nm": np.array([load_torque_at(tk, D) for tk in t]),
    }


def _mesh_signals(
    pinion_angle, delta, delta_rate, rated_force_N: float, P, speeds=None, centre_sliding=None
) -> dict[str, np.ndarray]:
    """Stage signals from the law the solver integrated. ``speeds`` = (pinion, wheel) rotation speeds
    (rad/s) and ``centre_sliding`` = (u_p' - u_w') . m (m/s) give the sliding velocity that sets the
    friction's direction; without them (Muller: no friction) both are taken as 0."""
    zero = np.zeros(len(pinion_angle))
    w_p, w_w = speeds if speeds is not None else (zero, zero)
    F, T, v_sl = mesh_contact_series(
        *(np.ascontiguousarray(x, dtype=float) for x in (pinion_angle, delta, delta_rate, w_p, w_w)),
        np.ascontiguousarray(zero if centre_sliding is None else centre_sliding, dtype=float),
        P,
    )
    p, i, j = mesh_phase_series(np.ascontiguousarray(pinion_angle), P)
    out = {
        "mesh_force_N": F,
        "kd": F / rated_force_N,
        "friction_force_N": T,
        "mesh_deflection_m": delta,
        "mesh_phase": p,
        "pinion_tooth": i,
        "wheel_tooth": j,
    }
    if speeds is not None:
        out["sliding_velocity_m_s"] = v_sl  # friction opposes it: T v_sl <= 0 (docs/scenario.md, "Friction")
    return out


def _torsional_signals(scenario, names, t, q, v, a, *, drive_torques=True) -> dict[str, np.ndarray]:
    out = {}
    for k, name in enumerate(names):
        if name.endswith(("_x", "_y")) and name[:-2] in names:
            continue  # a lateral gear's centre: see _lateral_signals
        out[f"{name}_angle_rad"] = q[k]
        out[f"{name}_speed_rad_s"] = v[k]
        out[f"{name}_accel_rad_s2"] = a[k]
    # Stage 1's mesh signals carry the plain names (mesh_force_N, kd, ...); later stages are prefixed
    # stage_2_, stage_3_, ... and their K_d is relative to their own rated force.
    for k, st in enumerate(scenario.stages):
        kind = stage_kind(st)
        if not kind.compound and kind.signals is not None:
            out.update(kind.signals(scenario, k, names, t, q, v, a))
    if drive_torques:
        out.update(_drive_torques(scenario, t, v[0]))
    return out


def _parallel_signals(scenario, k: int, names, t, q, v, a) -> dict[str, np.ndarray]:
    """A parallel stage's mesh signals (prefixed by its stage prefix)."""
    st = scenario.stages[k]
    pname, wname = gear_names(k)
    ip, iw = names.index(pname), names.index(wname)
    r1, r2 = st.pinion.base_radius_m, st.wheel.base_radius_m
    P = mesh_parameters_from_scenario(scenario, k)
    delta, rate = r1 * q[ip] - r2 * q[iw], r1 * v[ip] - r2 * v[iw]
    n, m, _ = mesh_directions(st.mesh.centre_line_deg, st.mesh.line_of_action_deg)
    sliding = np.zeros(len(t))
    for name, sign in ((pname, 1.0), (wname, -1.0)):
        if f"{name}_x" in names:
            ix, iy = names.index(f"{name}_x"), names.index(f"{name}_y")
            delta = delta + sign * (q[ix] * n[0] + q[iy] * n[1])
            rate = rate + sign * (v[ix] * n[0] + v[iy] * n[1])
            sliding = sliding + sign * (v[ix] * m[0] + v[iy] * m[1])
    sig = _mesh_signals(q[ip], delta, rate, scenario.stage_rated_force_N(k), P, (v[ip], v[iw]), sliding)
    sig["mesh_frequency_hz"] = st.pinion.teeth * v[ip] / (2 * math.pi)
    prefix = stage_prefix(k)
    return {prefix + key: value for key, value in sig.items()}


def _parallel_jump_times(scenario, k: int, names, t_fine, q, v, fine) -> list[np.ndarray]:
    angle = fine[f"{gear_names(k)[0]}_angle_rad"]
    delta = fine[stage_prefix(k) + "mesh_deflection_m"]
    return [mesh_jump_times(t_fine, angle, delta, mesh_parameters_from_scenario(scenario, k))]


def _lateral_signals(scenario, names, q, v, a, signals) -> dict[str, np.ndarray]:
    """Centre motion, bearing force to the housing and housing acceleration of every lateral gear
    (docs/scenario.md, 'Signals'): a fixed direction passes the mesh force component on."""
    out = {}
    for k, st in enumerate(scenario.stages):  # lateral gears are never combined with planetary stages
        prefix = stage_prefix(k)
        F, T = signals[prefix + "mesh_force_N"], signals[prefix + "friction_force_N"]
        n, m, s1 = mesh_directions(st.mesh.centre_line_deg, st.mesh.line_of_action_deg)
        for name, gear, sign in zip(gear_names(k), (st.pinion, st.wheel), (1.0, -1.0), strict=True):
            if gear.lateral == "none":
                continue
            ix, iy = names.index(f"{name}_x"), names.index(f"{name}_y")
            u, du = q[[ix, iy]], v[[ix, iy]]
            law = gear.bearing.law()
            if isinstance(law, LinearBearing):
                f_b = law.force_N(u, du)
            elif getattr(law, "ROTATING", False):  # the gear's rotation turns the inner race
                turn = sign * s1 * q[names.index(name)]  # counter-clockwise about +z
                f_b = np.array([law.force_N(u[:, s], du[:, s], turn[s]) for s in range(u.shape[1])]).T
            else:
                f_b = np.array([law.force_N(u[:, s], du[:, s]) for s in range(u.shape[1])]).T
            for d, axis in enumerate("xy"):
                if d in gear.free_directions:
                    out[f"{name}_{axis}_m"] = u[d]
                    out[f"{name}_{axis}_velocity_m_s"] = du[d]
                    out[f"{name}_{axis}_accel_m_s2"] = a[[ix, iy][d]]
                    force = -f_b[d]
                else:
                    force = sign * (-F * n[d] + T * m[d])  # mesh force on the gear, passed on
                out[f"{name}_bearing_force_{axis}_N"] = force
                out[f"{name}_housing_accel_{axis}_m_s2"] = force / gear.bearing.housing_mass_kg
    return out


def _muller_signals(scenario, t, x, xd, xdd) -> dict[str, np.ndarray]:
    D = pack_drive_parameters(scenario)
    theta = np.array([synchronous_angle_at(tk, D) for tk in t])
    out = {
        "deflection_m": x,
        "deflection_rate_m_s": xd,
        "deflection_accel_m_s2": xdd,
        "pinion_angle_rad": theta,
    }
    P = mesh_parameters_from_scenario(scenario, friction=False)
    out.update(_mesh_signals(theta, x, xd, scenario.rated_mesh_force_N, P))
    out["load_torque_Nm"] = np.array([load_torque_at(tk, D) for tk in t])
    out["mesh_frequency_hz"] = np.gradient(theta, t) * scenario.stages[0].pinion.teeth / (2 * math.pi)
    return out


register_stage_kind(
    "parallel",
    input_name=lambda scenario, k: gear_names(k)[0],
    metadata=_parallel_meta,
    signals=_parallel_signals,
    jump_times=_parallel_jump_times,
)
register_stage_kind("planetary", metadata=_planetary_meta)
