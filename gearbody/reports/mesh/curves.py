"""The mesh report's curves of one gear stage, evaluated with the solver's mesh law: healthy k_z over
the mesh cycle, k_z around each damaged tooth (as given and healthy), and the static transmission
error under load over whole pinion turns. Plain dataclasses of arrays; engine-free.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from gearbody.physics import mesh as _mesh
from gearbody.physics.mesh_stiffness import static_transmission_error_m

from .stage import angles, get_stage, half_double, parameter_pair, parameters

__all__ = [
    "DamageWindow",
    "StaticTransmissionError",
    "StiffnessCycle",
    "damage_windows",
    "load_label",
    "stage_data",
    "static_transmission_error",
    "stiffness_cycle",
    "tooth_label",
]


@dataclasses.dataclass(frozen=True)
class StiffnessCycle:
    """Healthy k_z over ``periods`` mesh periods from p = 0 of the stage's first pair (tooth 0)."""

    periods: np.ndarray  # u = phi_p z1 / 2 pi
    stiffness_N_per_m: np.ndarray
    half_double: float  # h = (eps_alpha - 1)/2: double contact for p < h and p >= 1 - h
    pitch_point_phase: float
    mean_N_per_m: float
    profile: str


def stiffness_cycle(
    scenario, stage: int = 0, periods: int = 2, points_per_period: int = 400
) -> StiffnessCycle:
    """k_z of healthy teeth over ``periods`` mesh periods, as the solver evaluates it."""
    st = get_stage(scenario, stage)
    P = parameters(scenario, stage, healthy=True)
    u = np.arange(periods * points_per_period + 1) / points_per_period
    u[-1] -= 1e-9  # stay inside the last period
    return StiffnessCycle(
        periods=u,
        stiffness_N_per_m=_mesh.effective_stiffness_series(angles(u, st.pinion.teeth), P),
        half_double=half_double(st.mesh),
        pitch_point_phase=st.mesh.pitch_point_phase,
        mean_N_per_m=_mesh.mean_stiffness_N_per_m(P),
        profile=st.mesh.stiffness_profile,
    )


@dataclasses.dataclass(frozen=True)
class DamageWindow:
    """k_z around the periods in which one damaged tooth's pair meshes, as given and healthy."""

    gear: str
    tooth: int
    description: str
    periods: np.ndarray  # u = phi_p z1 / 2 pi
    stiffness_N_per_m: np.ndarray
    healthy_stiffness_N_per_m: np.ndarray
    contact: tuple[float, float]  # u span [start, end) where the tooth acts on k_z

    @property
    def ratio(self) -> np.ndarray:
        """k_z / k_z,healthy (1 where both are 0)."""
        k, k0 = self.stiffness_N_per_m, self.healthy_stiffness_N_per_m
        return np.divide(k, k0, out=np.ones_like(k), where=k0 > 0)

    @property
    def min_ratio(self) -> float:
        """Least k_z / k_z,healthy while the tooth acts (within ``contact``)."""
        inside = (self.periods >= self.contact[0]) & (self.periods < self.contact[1])
        return float(self.ratio[inside].min()) if inside.any() else 1.0


def _describe(tooth) -> str:
    parts = []
    if tooth.stiffness_factor < 1.0:
        parts.append(f"stiffness factor {tooth.stiffness_factor:g}")
    if tooth.crack_depth_mm > 0:
        parts.append(f"root crack {tooth.crack_depth_mm:g} mm at {tooth.crack_angle_deg:g} deg")
    if tooth.broken_height_fraction > 0:
        parts.append(
            f"tip broken off, {tooth.broken_height_fraction:.0%} of the height over "
            f"{tooth.broken_width_fraction:.0%} of the face width"
        )
    if tooth.spall_width_fraction > 0:
        parts.append(
            f"spall d = {tooth.spall_start_diameter_mm:g}..{tooth.spall_end_diameter_mm:g} mm, "
            f"{tooth.spall_width_fraction:.0%} of the contact width"
        )
    return ", ".join(parts) or "no damage"


def _first_period(gear: str, tooth: int, z1: int, z2: int) -> int:
    """First period n >= 0 whose pair contains the tooth (n mod z1 = tooth, or n mod z2 = tooth)."""
    return tooth % z1 if gear == "pinion" else tooth % z2


def damage_windows(
    scenario, stage: int = 0, before: float = 1.5, after: float = 2.5, points_per_period: int = 400
) -> list[DamageWindow]:
    """One window per damaged tooth of the stage (stiffness factor < 1 or crack/breakage/spall): k_z
    over periods ``n0 - before .. n0 + after`` around the first period n0 of that tooth's pair."""
    st = get_stage(scenario, stage)
    z1, z2 = st.pinion.teeth, st.wheel.teeth
    P, P0 = parameter_pair(scenario, stage)
    h = half_double(st.mesh)
    whole_contact = st.mesh.stiffness_profile == "potential-energy"
    merged: dict[tuple[str, int], list] = {}
    for tooth in st.damaged_teeth:
        if tooth.stiffness_factor < 1.0 or tooth.has_geometric_damage:
            merged.setdefault((tooth.gear, tooth.tooth), []).append(tooth)
    out = []
    for (gear, index), teeth in sorted(merged.items()):
        n0 = _first_period(gear, index, z1, z2)
        n = int(round((before + after) * points_per_period))
        u = n0 - before + (np.arange(n) + 0.5) / points_per_period
        phi = angles(u, z1)
        out.append(
            DamageWindow(
                gear=gear,
                tooth=index,
                description="; ".join(_describe(t) for t in teeth),
                periods=u,
                stiffness_N_per_m=_mesh.effective_stiffness_series(phi, P),
                healthy_stiffness_N_per_m=_mesh.effective_stiffness_series(phi, P0),
                contact=(n0 - h, n0 + 1 + h) if whole_contact else (float(n0), n0 + 1.0),
            )
        )
    return out


@dataclasses.dataclass(frozen=True)
class StaticTransmissionError:
    """Loaded static TE along the line of action, TE = F/k(p) - E(p) + l_u, over whole pinion turns."""

    periods: np.ndarray  # u = phi_p z1 / 2 pi
    pinion_turns: int
    force_N: float
    rated_force_N: float
    backlash_um: float
    te_um: np.ndarray  # as given: damage, tooth errors, run-out, pits
    healthy_te_um: np.ndarray  # perfect gears: F/k_healthy + l_u
    stiffness_N_per_m: np.ndarray
    healthy_stiffness_N_per_m: np.ndarray
    error_um: np.ndarray  # E(p) as given

    @property
    def load_fraction(self) -> float:
        return self.force_N / self.rated_force_N


def _turns(st) -> int:
    """Pinion turns that show every damaged or pitted tooth (wheel teeth >= z1 need more than one)."""
    z1 = st.pinion.teeth
    last = max(
        [t.tooth + 2 for t in (*st.damaged_teeth, *st.pitted_teeth) if t.gear == "wheel"],
        default=0,
    )
    return max(1, math.ceil(last / z1))


def static_transmission_error(
    scenario, stage: int = 0, load_fraction: float = 1.0, points_per_period: int = 200
) -> StaticTransmissionError:
    """Static TE at ``load_fraction`` of the stage's rated force over one pinion turn (or the turns that
    reach the damaged or pitted wheel teeth), µm: as given and with perfect gears."""
    st = get_stage(scenario, stage)
    if not (math.isfinite(load_fraction) and load_fraction >= 0.0):
        raise ValueError(f"load_fraction = {load_fraction!r}: must be finite and >= 0")
    z1 = st.pinion.teeth
    P, P0 = parameter_pair(scenario, stage)
    turns = _turns(st)
    u = (np.arange(turns * z1 * points_per_period) + 0.5) / points_per_period
    phi = angles(u, z1)
    k, k0 = _mesh.effective_stiffness_series(phi, P), _mesh.effective_stiffness_series(phi, P0)
    error = _mesh.mesh_gap_series(phi, np.zeros_like(phi), P)
    rated = scenario.stage_rated_force_N(stage)
    force = load_fraction * rated
    lu = st.mesh.backlash_um * 1e-6
    return StaticTransmissionError(
        periods=u,
        pinion_turns=turns,
        force_N=force,
        rated_force_N=rated,
        backlash_um=st.mesh.backlash_um,
        te_um=static_transmission_error_m(k, force, error, lu) * 1e6,
        healthy_te_um=static_transmission_error_m(k0, force, 0.0, lu) * 1e6,
        stiffness_N_per_m=k,
        healthy_stiffness_N_per_m=k0,
        error_um=error * 1e6,
    )


def stage_data(scenario, stage: int, load_fraction: float, cycle, windows, te):
    """(cycle, windows, te) of a stage for ``summary_text`` and ``plot_stage``: those passed in (not
    None), the others computed with default sampling."""
    return (
        stiffness_cycle(scenario, stage) if cycle is None else cycle,
        damage_windows(scenario, stage) if windows is None else windows,
        static_transmission_error(scenario, stage, load_fraction) if te is None else te,
    )


def tooth_label(w: DamageWindow) -> str:
    return f"{w.gear} tooth {w.tooth}"


def load_label(te: StaticTransmissionError) -> str:
    return f"{te.load_fraction * 100:.3g} % of F_rated"
