"""Reading a resolved scenario dict: topology, stages, shafts, rated forces, the one-stage-shaped view
of each mesh, and the operating profiles and motor law (each helper a literal transcription of one
sentence of ``docs/scenario.md``).

Canonical shape (what ``gearbody.model.scenario_to_dict`` produces for every scene):

* ``meta``: ``name``, ``topology`` in {"muller", "two-wheel", "train"}, ``title``, ``sources``, ``seed``;
* ``design``: ``motor``, ``machine``, ``stages`` = list of ``{pinion, wheel, mesh, error_mode,
  damaged_teeth, eccentricity, pitted_teeth}``, ``shafts`` (train: N + 1 shafts, motor -> stage 1 ->
  ... -> machine; muller and two-wheel: empty, their one stage is ``stages[0]``);
* ``condition``: ``friction_coefficient`` (and ``friction_transition_speed_m_s``, default 0.01 m/s);
  ``operation``, ``solver`` as before.

The legacy shape (``meta.scene`` in {"muller", "two-wheel", "one-stage", "train"}, one-mesh scenes with
``design.pinion / wheel / mesh / coupling / output_shaft``, ``production.error_mode / eccentricity`` and
``condition.damaged_teeth / pitted_teeth``) is still read: a legacy ``one-stage`` is the train of one
stage with shafts ``[coupling, output_shaft]``.  Everything below the readers sees only
:func:`topology`, :func:`design_stages`, :func:`design_shafts` and :func:`stage_view`.

The mesh helpers of the other modules take a *mesh view*: a one-stage-shaped dict (``design.pinion /
wheel / mesh / machine``, ``production.error_mode / eccentricity``, ``condition.friction_coefficient /
damaged_teeth / pitted_teeth``, ``meta.seed / scene / stage_index``), as built by :func:`stage_view`
(a legacy one-mesh scenario is its own mesh view).
"""

from __future__ import annotations

import math

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover
    import tomli as tomllib

import numpy as np

TWO_PI = 2.0 * math.pi
TOPOLOGIES = ("muller", "two-wheel", "train")


def load_scenario(path) -> dict:
    """Read a (resolved) scenario TOML file."""
    with open(path, "rb") as fh:
        return tomllib.load(fh)


# ----------------------------------------------------------------------------------------------
# Topology, stages and shafts (canonical shape; legacy shape read as well)
# ----------------------------------------------------------------------------------------------
def topology(scenario: dict) -> str:
    """meta.topology ("muller", "two-wheel" or "train"); a legacy meta.scene "one-stage" is a train."""
    meta = scenario["meta"]
    if "topology" in meta:
        topo = meta["topology"]
    else:  # legacy shape, or a mesh view (meta.scene "train-stage": one stage of a train)
        scene = meta["scene"]
        if scene == "train-stage":
            return scene
        topo = "train" if scene == "one-stage" else scene
    if topo not in TOPOLOGIES:
        raise ValueError(f"unknown topology {topo!r}")
    return topo


def is_train(scenario: dict) -> bool:
    return topology(scenario) == "train"


def _legacy_stage(scenario: dict) -> dict:
    """The one stage of a legacy one-mesh scenario (pinion, wheel, mesh and its per-tooth faults)."""
    d = scenario["design"]
    prod = scenario.get("production", {})
    cond = scenario.get("condition", {})
    return {
        "pinion": d["pinion"],
        "wheel": d["wheel"],
        "mesh": d["mesh"],
        "error_mode": prod["error_mode"],
        "damaged_teeth": cond.get("damaged_teeth", []),
        "eccentricity": prod.get("eccentricity", []),
        "pitted_teeth": cond.get("pitted_teeth", []),
    }


def design_stages(scenario: dict) -> list[dict]:
    """design.stages (legacy one-mesh scenario: its one stage), unchecked."""
    d = scenario["design"]
    if "stages" in d:
        return list(d["stages"])
    return [_legacy_stage(scenario)]


def design_shafts(scenario: dict) -> list[dict]:
    """design.shafts (legacy one-stage: [coupling, output_shaft]; legacy muller / two-wheel: none)."""
    d = scenario["design"]
    if "shafts" in d:
        return list(d["shafts"])
    if "coupling" in d or "output_shaft" in d:
        return [d["coupling"], d["output_shaft"]]
    return []


def chain_constants(scenario: dict, stages: list[dict]):
    """(shaft stiffnesses, shaft dampings, rated synchronous speed, M_b, s_b, inertias of [motor, pinion 1,
    wheel 1, ..., machine], rated machine torque) of a chain, as the train models use them."""
    d = scenario["design"]
    shafts = design_shafts(scenario)
    motor = d["motor"]
    inertia = [float(motor["inertia_kg_m2"])]
    for st in stages:
        inertia += [float(st["pinion"]["inertia_kg_m2"]), float(st["wheel"]["inertia_kg_m2"])]
    inertia.append(float(d["machine"]["inertia_kg_m2"]))
    return (
        [float(sh["stiffness_Nm_per_rad"]) for sh in shafts],
        [float(sh.get("damping_Nms_per_rad", 0.0)) for sh in shafts],
        float(motor["synchronous_speed_rad_s"]),
        float(motor["breakdown_torque_Nm"]),
        float(motor["breakdown_slip"]),
        inertia,
        float(d["machine"]["rated_torque_Nm"]),
    )


def train_stages(scenario: dict) -> list[dict]:
    """design.stages of a train, checked: N >= 1 stages and exactly N + 1 shafts."""
    stages = design_stages(scenario)
    n_shafts = len(design_shafts(scenario))
    if len(stages) < 1:
        raise ValueError("a train needs at least one stage")
    if n_shafts != len(stages) + 1:
        raise ValueError(f"a train of {len(stages)} stages needs {len(stages) + 1} shafts, got {n_shafts}")
    return stages


def single_stage(scenario: dict) -> dict:
    """The one stage of a muller / two-wheel scenario."""
    stages = design_stages(scenario)
    if len(stages) != 1:
        raise ValueError(f"a {topology(scenario)} scenario has exactly one stage, got {len(stages)}")
    return stages[0]


# ----------------------------------------------------------------------------------------------
# Rated forces and mesh views
# ----------------------------------------------------------------------------------------------
def F_rated(scenario: dict) -> float:
    """F_rated = machine.rated_torque_Nm / r2 (train: F_rated,0 of the first stage)."""
    d = scenario["design"]
    if "wheel" in d:  # a mesh view or a legacy one-mesh scenario (one-stage: the same as F_rated,0)
        return float(d["machine"]["rated_torque_Nm"]) / float(d["wheel"]["base_radius_m"])
    if is_train(scenario):
        return float(stage_F_rated(scenario)[0])
    wheel = single_stage(scenario)["wheel"]
    return float(d["machine"]["rated_torque_Nm"]) / float(wheel["base_radius_m"])


def stage_F_rated(scenario: dict) -> np.ndarray:
    """Rated force per stage (s = 0 .. N-1 here): the rated machine torque passed upstream through the
    base radii, F_rated,N = rated_torque_Nm / r_wN, F_rated,s = F_rated,s+1 r_p,s+1 / r_ws.

    Any other topology: the single F_rated in an array of length 1.
    """
    if not is_train(scenario):
        return np.array([F_rated(scenario)])
    stages = train_stages(scenario)
    r_p = [float(st["pinion"]["base_radius_m"]) for st in stages]
    r_w = [float(st["wheel"]["base_radius_m"]) for st in stages]
    N = len(stages)
    out = np.empty(N)
    out[N - 1] = float(scenario["design"]["machine"]["rated_torque_Nm"]) / r_w[N - 1]
    for s in range(N - 2, -1, -1):
        out[s] = out[s + 1] * r_p[s + 1] / r_w[s]
    return out


def stage_view(scenario: dict, s: int = 0) -> dict:
    """Stage s as a one-stage-shaped mesh view for the mesh helpers (tooth_factors,
    tooth_error_amplitudes, mesh_force_literal, friction_moments, F_rated, _Mesh, ...).

    Train: meta.scene becomes "train-stage" and meta.stage_index = s selects the random draw;
    production.error_mode / eccentricity and condition.damaged_teeth / pitted_teeth are the stage's own
    (missing keys: none), condition.friction_coefficient (and friction_transition_speed_m_s, when given)
    the common ones; machine.rated_torque_Nm is the
    rated torque on this stage's wheel, F_rated,s r_ws, so that F_rated(view) = F_rated,s (to round-off).

    muller / two-wheel (s = 0 only): meta.scene is the topology, motor and machine are the scenario's.
    """
    topo = topology(scenario)
    friction = scenario["condition"]["friction_coefficient"]
    if topo == "train":
        st = train_stages(scenario)[s]
        m_wheel = float(stage_F_rated(scenario)[s]) * float(st["wheel"]["base_radius_m"])
        meta = {**scenario["meta"], "scene": "train-stage", "stage_index": s}
        design = {"pinion": st["pinion"], "wheel": st["wheel"], "mesh": st["mesh"]}
        design["machine"] = {"rated_torque_Nm": m_wheel}
    else:
        if s != 0:
            raise ValueError(f"a {topo} scenario has one stage, no stage {s}")
        st = single_stage(scenario)
        meta = {**scenario["meta"], "scene": topo}
        d = scenario["design"]
        design = {"pinion": st["pinion"], "wheel": st["wheel"], "mesh": st["mesh"]}
        design.update(motor=d["motor"], machine=d["machine"])
    return {
        "meta": meta,
        "design": design,
        "production": {"error_mode": st["error_mode"], "eccentricity": st.get("eccentricity", [])},
        "condition": {
            "friction_coefficient": friction,
            "damaged_teeth": st.get("damaged_teeth", []),
            "pitted_teeth": st.get("pitted_teeth", []),
            **friction_speed(scenario),
        },
    }


def friction_speed(scenario: dict) -> dict:
    """{"friction_transition_speed_m_s": v_0} when the scenario's condition gives it, else {} (the mesh
    helpers then take the contract's default, :func:`.law_terms.friction_transition_speed`)."""
    key = "friction_transition_speed_m_s"
    cond = scenario.get("condition", {})
    return {key: float(cond[key])} if key in cond else {}


def is_muller_view(view: dict) -> bool:
    """The mesh view of a muller scenario (no friction: the pinion angle is prescribed)."""
    meta = view["meta"]
    return meta.get("scene", meta.get("topology")) == "muller"


# ----------------------------------------------------------------------------------------------
# Operating profiles and the motor
# ----------------------------------------------------------------------------------------------
def _profile_arrays(profile: dict) -> tuple[np.ndarray, np.ndarray]:
    times = np.asarray(profile["time_s"], dtype=float).ravel()
    fr = np.asarray(profile["fraction"], dtype=float).ravel()
    if times.size == 0 or times.size != fr.size:
        raise ValueError("profile needs equally long, non-empty time_s and fraction")
    if np.any(np.diff(times) < 0):
        raise ValueError("profile time_s must be non-decreasing")
    return times, fr


def profile_value(t, profile: dict):
    """Piecewise linear through the points, held constant before the first / after the last."""
    times, fr = _profile_arrays(profile)
    return np.interp(t, times, fr)


def profile_integral(t, profile: dict):
    """Exact integral of the profile from 0 to t (t >= 0)."""
    times, fr = _profile_arrays(profile)
    tt = np.atleast_1d(np.asarray(t, dtype=float))
    out = np.empty_like(tt)
    for m, tm in enumerate(tt):
        if tm < 0:
            raise ValueError("profile_integral needs t >= 0")
        pts = np.unique(np.concatenate(([0.0, tm], times[(times > 0.0) & (times < tm)])))
        vals = np.interp(pts, times, fr)
        out[m] = float(np.sum(0.5 * (vals[1:] + vals[:-1]) * np.diff(pts)))
    return out if np.ndim(t) else float(out[0])


def kloss_torque(w, ws_t: float, motor: dict):
    """Kloss torque M_s = 2 M_b s s_b / (s^2 + s_b^2), s = (w_s(t) - w) / synchronous_speed_rad_s."""
    wsr = float(motor["synchronous_speed_rad_s"])
    mb = float(motor["breakdown_torque_Nm"])
    sb = float(motor["breakdown_slip"])
    s = (ws_t - np.asarray(w, dtype=float)) / wsr
    return 2.0 * mb * s * sb / (s * s + sb * sb)


def steady_slip(m_p: float, motor: dict) -> float:
    """Stable-branch slip with M_s = m_p: s = s_b (M_b - sqrt(M_b^2 - M_p^2)) / M_p, 0 for M_p = 0."""
    mb = float(motor["breakdown_torque_Nm"])
    sb = float(motor["breakdown_slip"])
    if m_p == 0.0:
        return 0.0
    if abs(m_p) > mb:
        raise ValueError(f"pinion torque {m_p} exceeds the breakdown torque {mb}: no steady state")
    return sb * (mb - math.sqrt(mb * mb - m_p * m_p)) / m_p
