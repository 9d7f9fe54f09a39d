"""Signals of a drive's planetary stages, from the recorded (resampled) states: every planet's sun- and
ring-mesh force, friction force, K_d, deflection, mesh phase and teeth in mesh; the central members'
centre motion and bearing forces on the housing; each planet's bearing deflection in the carrier frame
(docs/planetary.md, "Signals"). Forces come from the compiled law the solver integrated, on the same
states."""

from __future__ import annotations

import math

import numpy as np

from ..analysis.planet_pass import HannPassWindow, ring_sensor_signal
from ..assembly.compound import PlanetaryLink, compound_layout
from ..assembly.planetary_layout import CENTRAL
from ..model import Scenario
from ..model.kinds import register_stage_kind, stage_kind
from ..model.planetary import PlanetaryStage
from ..physics.mesh import mesh_phase_series
from ..physics.planetary_mesh import stage_contact_series, stage_mesh_series
from ..signals import stage_prefix
from .sampling import mesh_jump_times

__all__ = ["planetary_jump_times", "planetary_signals", "stage_input_name"]


def stage_input_name(scenario: Scenario, k: int) -> str:
    """The coordinate name of stage k's input rotation (pinion, or the planetary input member)."""
    return stage_kind(scenario.stages[k]).input_name(scenario, k)


def _planetary_input_name(scenario: Scenario, k: int) -> str:
    return stage_prefix(k) + scenario.stages[k].input


def _links(scenario: Scenario) -> tuple[PlanetaryLink, ...]:
    return compound_layout(scenario).planetary


def _stage_coordinates(link: PlanetaryLink, names: list[str], q: np.ndarray, v: np.ndarray):
    """A stage's absolute coordinates and their rates (n_t x (9 + 3 N)) on recorded displacements q, v
    (n_coordinates x n_t), and its planets' geometry rows."""
    first = names.index(link.names[0] + "_x")
    rows = slice(first, first + link.size)
    absolute = np.ascontiguousarray((q[rows] + link.reference()[:, None]).T)
    return absolute, np.ascontiguousarray(v[rows].T), link.geometry_rows()


def planetary_signals(scenario: Scenario, names: list[str], q, v, a) -> dict[str, np.ndarray]:
    """Every planetary stage's signals on the samples of q, v, a (rows in the order of ``names``)."""
    out: dict[str, np.ndarray] = {}
    for link in _links(scenario):
        out.update(_stage_signals(scenario, link, names, q, v, a))
    return out


def planetary_stage_signals(
    scenario: Scenario, k: int, names: list[str], t, q, v, a
) -> dict[str, np.ndarray]:
    """Planetary stage k's signals on the samples of q, v, a (the stage kind's ``signals``)."""
    return _stage_signals(scenario, compound_layout(scenario).parts[k], names, q, v, a)


def _stage_signals(
    scenario: Scenario, link: PlanetaryLink, names: list[str], q, v, a
) -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    k, st = link.stage, scenario.stages[link.stage]
    prefix = stage_prefix(k)
    absolute, rate, G = _stage_coordinates(link, names, q, v)
    states = stage_mesh_series(absolute, rate, G)  # law angle, deflection, rate per mesh
    contacts = stage_contact_series(absolute, rate, G, *link.layout.mesh_arrays())  # F, T, v_T
    for n in range(st.planets):
        planet = f"{prefix}planet_{n + 1}"
        laws = (("sun", link.layout.sun_mesh_of(n), 0), ("ring", link.layout.ring_mesh_of(n), 3))
        for mesh, P, col in laws:
            angle = np.ascontiguousarray(states[:, n, col])
            delta = np.ascontiguousarray(states[:, n, col + 1])
            F, T, v_T = (contacts[:, n, col + c] for c in range(3))
            p, i, j = mesh_phase_series(angle, P)
            key = f"{planet}_{mesh}_mesh"
            out[key + "_force_N"] = F
            out[key + "_friction_force_N"] = T  # opposes v_T: docs/planetary.md "Friction"
            out[key + "_sliding_velocity_m_s"] = v_T  # T v_T <= 0 is the friction power
            out[key + "_kd"] = F / link.rated_force_N
            out[key + "_deflection_m"] = delta
            out[key + "_phase"] = p
            out[f"{key}_{mesh}_tooth"] = i
            out[f"{key}_planet_tooth"] = j
        out.update(_planet_bearing(link, names, q, n, planet))
    for m, member in enumerate(link.layout.members):
        name = link.names[m]
        ix = names.index(name + "_x")
        law = member.bearing_law
        if law is not None:
            turn = q[ix + 2] if getattr(law, "ROTATING", False) else None  # the member turns the inner race
            on_member = np.array(
                [
                    law.force_N(q[ix : ix + 2, i], v[ix : ix + 2, i], *(() if turn is None else (turn[i],)))
                    for i in range(q.shape[1])
                ]
            ).T
        for d, axis in enumerate("xy"):
            u, du = q[ix + d], v[ix + d]
            out[f"{name}_{axis}_m"] = u
            out[f"{name}_{axis}_velocity_m_s"] = du
            out[f"{name}_{axis}_accel_m_s2"] = a[ix + d]
            if law is None:
                force = member.bearing_stiffness_N_per_m * u + member.bearing_damping_Ns_per_m * du
            else:
                force = -on_member[d]
            out[f"{name}_bearing_force_{axis}_N"] = force  # on the housing
    w = {c: v[names.index(link.names[m])] for m, c in enumerate(CENTRAL)}
    out[prefix + "mesh_frequency_hz"] = st.sun.teeth * np.abs(w["sun"] - w["carrier"]) / (2 * math.pi)
    out[prefix + "ring_sensor_N"] = _ring_sensor(link, st, names, q, out, prefix)
    return out


def _ring_sensor(link: PlanetaryLink, st: PlanetaryStage, names, q, signals, prefix: str) -> np.ndarray:
    """The ring-fixed sensor (docs/planetary.md, "Signals"): every planet's ring-mesh force weighted by
    the Hann planet-pass window of the planet's angle from the sensor in the ring's frame,
    theta_c + psi_n - theta_r - sensor angle (analysis.planet_pass.ring_sensor_signal)."""
    theta_c = q[names.index(link.names[2])]
    theta_r = q[names.index(link.names[1])]
    psi = np.array([theta_c + a - theta_r for a in link.layout.planet_angles_rad])
    forces = np.array([signals[f"{prefix}planet_{n + 1}_ring_mesh_force_N"] for n in range(st.planets)])
    window = HannPassWindow(math.radians(st.sensor_window_deg))
    t = np.arange(psi.shape[1], dtype=float)  # the sum does not depend on the times
    return ring_sensor_signal(t, psi, forces, math.radians(st.sensor_angle_deg), window).signal_N


def _planet_bearing(link: PlanetaryLink, names, q, n: int, planet: str) -> dict[str, np.ndarray]:
    """Planet n's centre (absolute, fixed frame) and its bearing deflection (centre minus its carrier
    point, the pin), radial and tangential in the carrier frame, m."""
    rc, psi = link.layout.carrier_radius_m, link.layout.pin_angle_rad(n)
    ic = names.index(link.names[2] + "_x")
    ip = names.index(planet + "_x")
    theta = q[ic + 2] + psi
    px, py = link.layout.planet_centre_m(n)
    ex = px + q[ip] - (q[ic] + rc * np.cos(theta))
    ey = py + q[ip + 1] - (q[ic + 1] + rc * np.sin(theta))
    c, s = np.cos(theta), np.sin(theta)
    return {
        f"{planet}_centre_x_m": px + q[ip],  # absolute, in the fixed frame
        f"{planet}_centre_y_m": py + q[ip + 1],
        f"{planet}_bearing_radial_m": c * ex + s * ey,
        f"{planet}_bearing_tangential_m": -s * ex + c * ey,
    }


def planetary_jump_times(
    scenario: Scenario, k: int, names, t_s: np.ndarray, q, v, signals=None
) -> list[np.ndarray]:
    """Times where stage k's mesh laws jump (every planet's two meshes), for band-limited sampling."""
    link = next(link for link in _links(scenario) if link.stage == k)
    states = stage_mesh_series(*_stage_coordinates(link, names, q, v))
    out = []
    for n in range(len(link.layout.planet_angles_rad)):
        for P, col in ((link.layout.sun_mesh_of(n), 0), (link.layout.ring_mesh_of(n), 3)):
            out.append(mesh_jump_times(t_s, states[:, n, col], states[:, n, col + 1], P))
    return out


register_stage_kind(
    "planetary",
    input_name=_planetary_input_name,
    signals=planetary_stage_signals,
    jump_times=planetary_jump_times,
)
