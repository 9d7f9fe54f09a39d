"""gearbody mesh: geometry table, k_z over the mesh cycle and around damaged teeth, static TE, CLI."""

import math
import subprocess
import sys

import numpy as np
import pytest

from gearbody.assembly import mesh_parameters_from_scenario
from gearbody.cli import main
from gearbody.model import load_scenario
from gearbody.physics.mesh import mean_stiffness_N_per_m
from gearbody.reports import mesh as mr

CRACK = 'condition.damaged_teeth=[{gear="pinion",tooth=0,crack_depth_mm=2.0}]'


@pytest.fixture(scope="module")
def geometry_scene():
    return load_scenario("one-stage-geometry")


@pytest.fixture(scope="module")
def cracked_scene():
    return load_scenario("one-stage-geometry", [CRACK])


def test_geometry_table_agrees_with_the_resolved_scenario(geometry_scene):
    s = geometry_scene
    st = s.stages[0]
    rows = mr.geometry_table(s, 0)
    value = lambda name: mr.table_value(rows, name)  # noqa: E731
    assert value("teeth z1 (pinion)") == 29 and value("teeth z2 (wheel)") == 88
    assert value("transverse contact ratio eps_alpha") == pytest.approx(st.mesh.contact_ratio, rel=1e-12)
    for name, z, gear in (("base radius r_b1", 29, st.pinion), ("base radius r_b2", 88, st.wheel)):
        expected_mm = 5.0 * z * math.cos(math.radians(20.0)) / 2.0
        assert value(name) == pytest.approx(expected_mm, rel=1e-12)
        assert value(name) == pytest.approx(gear.base_radius_m * 1e3, rel=1e-12)
    assert value("pitch point phase") == pytest.approx(st.mesh.pitch_point_phase, rel=1e-12)
    assert (
        value("backlash half-width l_u") == pytest.approx(st.mesh.backlash_um) == pytest.approx(50.0, abs=0.1)
    )
    p_bt = value("transverse base pitch p_bt")
    assert value("length of path of contact g_alpha") / p_bt == pytest.approx(st.mesh.contact_ratio)
    assert value("centre distance a_w") == pytest.approx(0.5 * 5.0 * (29 + 88))
    k_mean = mean_stiffness_N_per_m(mesh_parameters_from_scenario(s, 0))
    assert value("k_z mean over a mesh period") == pytest.approx(k_mean, rel=1e-12)
    assert value("k_z single contact (zone mean)") == st.mesh.stiffness_single_N_per_m
    assert value("k_z min over a mesh period") < k_mean < value("k_z max over a mesh period")
    # ISO 6336-1 method B: c_gamma_alpha = c' (0.75 eps_alpha + 0.25), c_gamma_beta = 0.85 c_gamma_alpha
    c_alpha = value("c_gamma_alpha")
    assert c_alpha == pytest.approx(value("c'") * (0.75 * st.mesh.contact_ratio + 0.25))
    assert value("c_gamma_beta") == pytest.approx(0.85 * c_alpha)
    # the potential-energy mean (second row of that name) is the same law's mean, finer rule aside
    assert mr.table_value(rows, "k_z mean over a mesh period", 1) == pytest.approx(k_mean, rel=1e-3)
    text = mr.format_table(rows, "t")
    assert "N/(mm µm)" in text and "eps_alpha" in text


def test_hand_given_mesh_says_the_geometry_is_not_given():
    s = load_scenario("one-stage")
    rows = mr.geometry_table(s, 0)
    assert mr.table_value(rows, "geometry").startswith("not given")
    assert mr.table_value(rows, "transverse contact ratio eps_alpha") == 1.6
    eps = 1.6
    assert mr.table_value(rows, "k_z mean over a mesh period") == pytest.approx(
        (2 - eps) * 1.2e9 + (eps - 1) * 1.3e9
    )
    with pytest.raises(KeyError):
        mr.table_value(rows, "c'")


def test_cycle_is_the_healthy_law_over_the_period(geometry_scene):
    cycle = mr.stiffness_cycle(geometry_scene, 0, periods=2, points_per_period=200)
    h = cycle.half_double
    p = cycle.periods % 1.0
    single = (p > h + 0.01) & (p < 1 - h - 0.01)
    double = (p < h - 0.01) | (p > 1 - h + 0.01)
    assert cycle.stiffness_N_per_m[single].max() < cycle.stiffness_N_per_m[double].min()
    assert np.allclose(cycle.stiffness_N_per_m[:200], cycle.stiffness_N_per_m[200:400])


def test_damaged_tooth_lowers_kz_in_its_window_and_only_there(cracked_scene):
    s = cracked_scene
    (w,) = mr.damage_windows(s, 0)
    assert (w.gear, w.tooth) == ("pinion", 0) and "crack 2 mm" in w.description
    h = 0.5 * (s.stages[0].mesh.contact_ratio - 1.0)
    assert w.contact == pytest.approx((-h, 1 + h))
    lowered = w.ratio < 1 - 1e-12
    assert w.min_ratio < 0.99
    inside = (w.periods >= w.contact[0]) & (w.periods < w.contact[1])
    assert not np.any(lowered & ~inside)
    assert lowered[inside].mean() > 0.9  # all of the pair's contact but its first point(s)
    # over a whole pinion turn: lower only while pinion tooth 0's pair is in contact, equal elsewhere
    te = mr.static_transmission_error(s, 0)
    k, k0 = te.stiffness_N_per_m, te.healthy_stiffness_N_per_m
    in_contact = ((te.periods + h) % 29) < 1 + 2 * h
    assert np.all(k[in_contact] <= k0[in_contact])
    assert np.array_equal(k[~in_contact], k0[~in_contact])
    assert np.any(k[in_contact] < 0.99 * k0[in_contact])
    # the hand-given factor acts on its period only
    (w2,) = mr.damage_windows(load_scenario("industrial-two-stage"), 1)
    assert w2.contact == (5.0, 6.0) and w2.min_ratio == pytest.approx(0.8)


def test_static_te_mean_is_force_over_stiffness_without_errors():
    s = load_scenario("one-stage-geometry", ["production.error_mode.e_um=0"])
    te = mr.static_transmission_error(s, 0)
    assert te.force_N == s.stage_rated_force_N(0) and te.load_fraction == 1.0
    assert np.array_equal(te.te_um, te.healthy_te_um)
    elastic = te.te_um - te.backlash_um
    k_mean = mean_stiffness_N_per_m(mesh_parameters_from_scenario(s, 0))
    # mean F/k >= F/mean k (Jensen): 6.8 % apart for this strongly varying profile
    assert elastic.mean() == pytest.approx(te.force_N * np.mean(1e6 / te.stiffness_N_per_m), rel=1e-12)
    assert elastic.mean() == pytest.approx(te.force_N / k_mean * 1e6, rel=0.08)
    assert elastic.mean() >= te.force_N / k_mean * 1e6
    half = mr.static_transmission_error(s, 0, load_fraction=0.5)
    assert np.allclose(half.te_um - half.backlash_um, 0.5 * elastic)
    # two-level hand-given profile: within 0.2 %
    s1 = load_scenario("one-stage", ["production.error_mode.e_um=0"])
    te1 = mr.static_transmission_error(s1, 0)
    k1 = mean_stiffness_N_per_m(mesh_parameters_from_scenario(s1, 0))
    assert (te1.te_um - te1.backlash_um).mean() == pytest.approx(te1.force_N / k1 * 1e6, rel=2e-3)
    with pytest.raises(ValueError, match="load_fraction"):
        mr.static_transmission_error(s, 0, load_fraction=-1.0)


def test_static_te_shows_the_tooth_errors(geometry_scene):
    te = mr.static_transmission_error(geometry_scene, 0)
    assert te.periods.size == 29 * 200 and te.pinion_turns == 1
    expected = te.force_N * 1e6 / te.stiffness_N_per_m - te.error_um + te.backlash_um
    assert np.allclose(te.te_um, expected, rtol=1e-12, atol=1e-9)
    assert te.error_um.max() > 5.0  # e = 10 µm, r = 0.3


def test_cli_writes_the_plot_and_prints_the_table(tmp_path, capsys):
    out = tmp_path / "mesh"
    assert main(["mesh", "one-stage-geometry", "--set", CRACK, "--load", "0.5", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "transverse contact ratio eps_alpha" in text and "1.74182" in text
    assert "pinion tooth 0 (root crack 2 mm" in text and "50 % of F_rated" in text
    assert (out / "mesh_stage1.png").stat().st_size > 20_000


def test_cli_hand_given_scene_and_train(tmp_path, capsys):
    assert main(["mesh", "one-stage", "--no-plots", "--out", str(tmp_path / "none")]) == 0
    assert "not given (hand-given mesh)" in capsys.readouterr().out
    assert not (tmp_path / "none").exists()
    out = tmp_path / "two"
    assert main(["mesh", "two-stage", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "stage 1 of 2 (design.stages.1)" in text and "stage 2 of 2 (design.stages.2)" in text
    # .gearbody.json: what wrote the folder (gearbody.folders), so that a rerun knows its own plots
    assert sorted(p.name for p in out.iterdir()) == [".gearbody.json", "mesh_stage1.png", "mesh_stage2.png"]
    only = tmp_path / "only"
    assert main(["mesh", "two-stage", "--stage", "2", "--out", str(only)]) == 0
    assert sorted(p.name for p in only.iterdir()) == [".gearbody.json", "mesh_stage2.png"]


def test_cli_refuses_bad_stage_and_load(capsys):
    assert main(["mesh", "two-stage", "--stage", "3", "--no-plots"]) == 2
    err = capsys.readouterr().err
    assert "--stage = 3" in err and "1..2" in err
    assert main(["mesh", "one-stage", "--stage", "0", "--no-plots"]) == 2
    assert "--stage = 0" in capsys.readouterr().err
    assert main(["mesh", "one-stage", "--load", "-0.5", "--no-plots"]) == 2
    assert "--load = -0.5" in capsys.readouterr().err
    assert main(["mesh", "one-stage", "--set", "design.mesh.contact_ratio=3", "--no-plots"]) == 2


@pytest.mark.slow
def test_report_is_engine_free(tmp_path):
    code = (
        "import sys; from gearbody.model import load_scenario; "
        "from gearbody.reports.mesh.figure import plot_stage; "
        f"s = load_scenario('one-stage'); plot_stage(s, 0, {str(tmp_path / 'x.png')!r}); "
        "assert 'exudyn' not in sys.modules, 'exudyn imported'"
    )
    subprocess.run([sys.executable, "-c", code], check=True, cwd=tmp_path)  # installed gearbody
    assert (tmp_path / "x.png").is_file()
