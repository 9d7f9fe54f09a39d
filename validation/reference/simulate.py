"""The reference's entry point: build the system of the scenario's topology, integrate it with the
segmented integrator and shape the outputs."""

from __future__ import annotations

import numpy as np

from .initial import initial_state
from .integrate import _output_times, integrate
from .models import _SingleMesh, _Train
from .scenario import is_train


def simulate_reference(
    scenario: dict,
    t_eval: np.ndarray | None = None,
    *,
    rtol: float = 1e-10,
    atol: float | np.ndarray | None = None,
    method: str = "DOP853",
) -> dict[str, np.ndarray]:
    """Integrate a resolved scenario (canonical shape, or the legacy one; see the package docstring).

    Returns time, coordinates and velocities (n_dof x n_t), mesh_force_N (F = F_el + F_t),
    kd = F / F_rated, stage_mesh_force_N, stage_kd and stage_friction_force_N (the friction force T,
    signed; n_stages x n_t; one row for muller, whose T is 0, and two-wheel) and nfev (0-d array);
    for diagnostics also n_segments (restarts of solve_ivp) and n_missed_events (mode boundaries found
    inside a step by the dense scan).

    Train (N stages): coordinates [motor, pinion_1, wheel_1, ..., pinion_N, wheel_N, machine]
    (n_dof = 2N + 2); mesh_force_N / kd are those of the first stage, stage_kd[s] = F_s / F_rated,s.
    """
    train = is_train(scenario)
    model = _Train(scenario) if train else _SingleMesh(scenario)
    t_eval = _output_times(scenario, t_eval)
    if atol is None:
        atol = model.default_atol(rtol)
    q0, v0 = initial_state(scenario)
    res = integrate(model, np.concatenate((q0, v0)), t_eval, rtol, atol, method)
    nd, Y, F_out, T_out = model.n_dof, res["Y"], res["out"]["F"], res["out"]["T"]
    stats = {
        "nfev": np.array(res["nfev"]),
        "n_segments": np.array(res["n_segments"]),
        "n_missed_events": np.array(res["n_missed"]),
    }
    if train:
        stage_kd = F_out / model.Frated[:, None]
        return {
            "time": t_eval,
            "coordinates": Y[:nd],
            "velocities": Y[nd:],
            "mesh_force_N": F_out[0].copy(),
            "kd": stage_kd[0].copy(),
            "stage_mesh_force_N": F_out,
            "stage_kd": stage_kd,
            "stage_friction_force_N": T_out,
            **stats,
        }
    return {
        "time": t_eval,
        "coordinates": Y[:nd],
        "velocities": Y[nd:],
        "mesh_force_N": F_out,
        "kd": F_out / model.Frated,
        "stage_mesh_force_N": F_out[None, :].copy(),
        "stage_kd": (F_out / model.Frated)[None, :],
        "stage_friction_force_N": T_out[None, :].copy(),
        **stats,
    }
