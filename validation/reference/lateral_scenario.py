"""Reading the lateral part of a scenario (section "Lateral models: gears on bearings (Figs. 17, 18)"
of ``docs/scenario.md``): the stated defaults, the train form of a legacy one-stage scenario, the stage
gear names, the mesh geometry and the literal bearing law with its static displacement.
"""

from __future__ import annotations

import copy
import math

import numpy as np

from .scenario import topology

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


def _fill_gear(g: dict) -> None:
    g.setdefault("lateral", "none")
    if g["lateral"] not in _AXES:
        raise ValueError(f"lateral must be 'none', 'y' or 'xy', got {g['lateral']!r}")
    if g["lateral"] != "none":
        if "bearing" not in g:
            raise ValueError("a lateral gear needs a bearing table")
        kind = g["bearing"]["kind"]
        if kind not in ("linear", "hertzian", "rolling-elements"):
            raise ValueError(f"unknown bearing kind {kind!r}")


def resolve_lateral_defaults(scenario: dict) -> dict:
    """Deep copy with the defaults stated by the contract filled in (lateral = "none",
    centre_line_deg = 0, line_of_action_deg = -90) and, for keys the files in scenes/ may omit, the
    documented example values (stiffness_profile "contact-ratio", pressure_angle_deg 20,
    pitch_point_phase 0.5, backlash 0, empty tables, no damaged teeth, shaft damping 0,
    solver.output_rate_hz 20000).  Topology "train" only (a legacy one-stage scenario included)."""
    sc = copy.deepcopy(scenario)
    scene = topology(sc)
    d = sc["design"]
    if scene == "train" and "stages" not in d:  # legacy one-stage
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
        raise ValueError(f"lateral models exist for the topology 'train' (and one-stage), not {scene!r}")
    for pin, whl, mesh in pairs:
        _fill_gear(pin)
        _fill_gear(whl)
        for key, val in _MESH_DEFAULTS.items():
            mesh.setdefault(key, copy.deepcopy(val))
    sc.setdefault("condition", {}).setdefault("friction_coefficient", 0.0)
    sc.setdefault("solver", {}).setdefault("output_rate_hz", 20000.0)
    return sc


def as_train(scenario: dict) -> dict:
    """A (defaults-resolved) legacy one-stage scenario as the equivalent 1-stage train (legacy shape,
    meta.scene "train"); a scenario with design.stages (a train in either shape) unchanged."""
    if "stages" in scenario["design"]:
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


_ROLLING: dict[int, object] = {}  # id of a rolling-elements table -> its RollingBearing (made once)


def bearing_force(bearing: dict, u, u_dot, inner: float = 0.0, outer: float = 0.0) -> np.ndarray:
    """Literal bearing law f_b = law.force_N(u, u') (u, u' in the law's frame, 2-vectors; ``inner`` and
    ``outer`` the races' angles there, read by the rolling-elements law only)."""
    kind = bearing["kind"]
    par = bearing["parameters"]
    x, y = float(u[0]), float(u[1])
    vx, vy = float(u_dot[0]), float(u_dot[1])
    if kind == "rolling-elements":
        from .rolling_bearing import RollingBearing

        law = _ROLLING.get(id(bearing))
        if law is None or law.table is not bearing:
            law = _ROLLING[id(bearing)] = RollingBearing(bearing)
        return np.array(law.force(x, y, vx, vy, float(inner), float(outer)))
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
    if bearing["kind"] == "rolling-elements":
        from .rolling_bearing import RollingBearing

        return RollingBearing(bearing).static_displacement(f, axes)
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
