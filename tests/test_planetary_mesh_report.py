"""`gearbody mesh` and `gearbody modes` on planetary stages (issue 25): the mesh report's table, k_z of
the sun-planet and ring-planet laws over the mesh cycle, damaged teeth in the meshes they enter and the
static transmission error, checked by hand; the modes' resonance speeds of a planetary first stage."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearbody.cli import main
from gearbody.model import load_scenario
from gearbody.reports.mesh import table_value
from gearbody.reports.mesh.planetary import (
    planetary_damage_windows,
    planetary_geometry_table,
    planetary_static_transmission_errors,
    planetary_stiffness_cycles,
)

DAMAGE = (
    'design.stages.1.damaged_teeth=[{member="sun",tooth=20,stiffness_factor=0.5},'
    '{member="planet",planet=2,tooth=5,stiffness_factor=0.4}]'
)


def standard_contact_ratios(z_s: int, z_p: int, z_r: int, m: float, alpha_deg: float) -> tuple[float, float]:
    """Contact ratios of standard teeth by the formulas of docs/planetary.md ("Geometry")."""
    a = math.radians(alpha_deg)
    r_s, r_p, r_r = m * z_s / 2, m * z_p / 2, m * z_r / 2
    rb = {k: r * math.cos(a) for k, r in (("s", r_s), ("p", r_p), ("r", r_r))}
    p_b = math.pi * m * math.cos(a)
    r_c = r_s + r_p
    tip_s, tip_p, tip_r = r_s + m, r_p + m, r_r - m
    sun = (math.sqrt(tip_s**2 - rb["s"] ** 2) + math.sqrt(tip_p**2 - rb["p"] ** 2) - r_c * math.sin(a)) / p_b
    ring = (
        math.sqrt(tip_p**2 - rb["p"] ** 2) - math.sqrt(tip_r**2 - rb["r"] ** 2) + (r_r - r_p) * math.sin(a)
    ) / p_b
    return sun, ring


def test_each_planet_mesh_law_is_single_and_double_contact_in_the_share_of_its_contact_ratio():
    sc = load_scenario("planetary")
    st = sc.stages[0]
    eps = standard_contact_ratios(st.sun.teeth, st.planet.teeth, st.ring.teeth, 3.0, st.pressure_angle_deg)
    cycles = planetary_stiffness_cycles(sc, 0, periods=4, points_per_period=2000)
    rows = planetary_geometry_table(sc, 0)
    for k, mesh in enumerate(("sun", "ring")):
        spec = getattr(st, f"{mesh}_mesh")
        cycle = cycles[mesh]
        k_z = cycle.stiffness_N_per_m
        assert set(np.unique(k_z)) == {spec.stiffness_single_N_per_m, spec.stiffness_double_N_per_m}
        double = np.mean(k_z == spec.stiffness_double_N_per_m)
        assert double == pytest.approx(eps[k] - 1.0, abs=1e-3)
        mean = (2 - eps[k]) * spec.stiffness_single_N_per_m + (eps[k] - 1) * spec.stiffness_double_N_per_m
        assert cycle.mean_N_per_m == pytest.approx(mean, rel=1e-9)
        assert table_value(rows, "transverse contact ratio eps_alpha", k) == pytest.approx(eps[k], rel=1e-12)
        assert table_value(rows, "k_z mean over a mesh period", k) == pytest.approx(mean, rel=1e-9)
    assert table_value(rows, "teeth z_r (ring)") == st.ring.teeth
    assert table_value(rows, "carrier radius r_c (planet centres)") == pytest.approx(1.5 * (29 + 37))
    assert table_value(rows, "mesh periods per input revolution f_m/f_in") == pytest.approx(29 * 103 / 132)


def test_a_damaged_tooth_weakens_the_meshes_it_enters_by_its_factor():
    """Sun tooth 20 in the sun mesh's period 20 (every planet); planet 2's tooth 5 in its sun mesh's period 5
    and in its ring mesh's period (5 + M_2 + floor(z_p / 2)) mod z_p, M_2 = (z_s + z_r) / 3."""
    sc = load_scenario("planetary", [DAMAGE])
    windows = {(w.gear, w.description.split(", ")[1].split()[0]): w for w in planetary_damage_windows(sc, 0)}
    assert set(windows) == {("sun", "sun"), ("planet 2", "sun"), ("planet 2", "ring")}
    ring_period = (5 + (29 + 103) // 3 + 37 // 2) % 37
    for key, factor, start in (
        (("sun", "sun"), 0.5, 20),
        (("planet 2", "sun"), 0.4, 5),
        (("planet 2", "ring"), 0.4, ring_period),
    ):
        w = windows[key]
        assert w.contact == (start, start + 1) and w.min_ratio == pytest.approx(factor)
        outside = (w.periods < start - 1) | (w.periods >= start + 2)
        assert np.allclose(w.ratio[outside], 1.0)
    assert planetary_damage_windows(load_scenario("planetary"), 0) == []


def test_static_transmission_error_of_perfect_teeth_is_force_over_stiffness_plus_backlash():
    sc = load_scenario("planetary", ["design.stages.1.sun_error_mode.e_um=0", DAMAGE])
    st = sc.stages[0]
    force = 0.5 * sc.stage_rated_force_N(0)
    tes = planetary_static_transmission_errors(sc, 0, load_fraction=0.5)
    for mesh, teeth in (("sun", st.sun.teeth), ("ring", st.ring.teeth)):
        te = tes[mesh]
        spec = getattr(st, f"{mesh}_mesh")
        assert te.force_N == pytest.approx(force) and te.periods.max() < teeth
        lo = force / spec.stiffness_double_N_per_m * 1e6 + spec.backlash_um
        hi = force / spec.stiffness_single_N_per_m * 1e6 + spec.backlash_um
        assert te.healthy_te_um.min() == pytest.approx(lo) and te.healthy_te_um.max() == pytest.approx(hi)
    # the damaged sun tooth (no tooth errors on the sun): TE rises to F/(0.5 k_single) in its period
    sun = tes["sun"]
    in_period_20 = (sun.periods >= 20) & (sun.periods < 21)
    assert sun.te_um[in_period_20].max() == pytest.approx(
        force / (0.5 * st.sun_mesh.stiffness_single_N_per_m) * 1e6 + st.sun_mesh.backlash_um
    )


def test_mesh_command_reports_the_planetary_stage_and_the_spur_stage_of_the_conveyor(tmp_path, capsys):
    assert main(["mesh", "planetary-conveyor", "--out", str(tmp_path), "--load", "0.5"]) == 0
    text = capsys.readouterr().out
    assert "stage 1 of 2 (design.stages.1)\n" in text and "stage 2 of 2 (design.stages.2), planetary" in text
    assert "sun-planet mesh (planet 1): static transmission error" in text and "50 % of F_rated" in text
    assert (tmp_path / "mesh_stage1.png").is_file() and (tmp_path / "mesh_stage2.png").is_file()
    assert main(["mesh", "planetary", "--stage", "1", "--no-plots", "--set", DAMAGE]) == 0
    text = capsys.readouterr().out
    assert "planet 2 tooth 5 (stiffness factor 0.4, ring mesh): min k_z/k_z,healthy 0.4000" in text


def test_modes_of_a_planetary_first_stage_give_the_sun_speeds_of_resonance(capsys):
    """w(k f_m) = 2 pi f_n / (k f_m per sun revolution), f_m per revolution = z_s z_r / (z_s + z_r) with the
    ring fixed and the carrier the output (Willis)."""
    assert main(["modes", "planetary", "--harmonics", "2"]) == 0
    lines = capsys.readouterr().out.splitlines()
    per_rev = 29 * 103 / (29 + 103)
    assert f"= {per_rev:.5g} w / 2 pi" in lines[-1] and lines[-1].startswith("(w(k f_z) = sun speed")
    rows = [line.split() for line in lines if line[:4].strip().isdigit()]
    assert len(rows) == 20
    for row in rows:
        f_n, w1, w2 = float(row[1]), row[-2], row[-1]
        if w1 == "-":
            continue
        assert float(w1) == pytest.approx(2 * math.pi * f_n / per_rev, abs=0.006)
        assert float(w2) == pytest.approx(2 * math.pi * f_n / (2 * per_rev), abs=0.006)
