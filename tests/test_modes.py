"""Natural frequencies through Exudyn equal scipy.linalg.eigh and reproduce the torsional-chain figures."""

import math

import numpy as np
import pytest
import scipy.linalg

from gearbody.assembly import (
    Inertia,
    MeshLink,
    ShaftLink,
    TorsionalLayout,
    mesh_parameters_from_scenario,
    reduced_mass_kg,
)
from gearbody.engine import natural_frequencies, scene_modes
from gearbody.model import load_scenario
from gearbody.physics import mean_stiffness_N_per_m


def chain(J, springs, meshes=()):
    return TorsionalLayout(
        tuple(Inertia(f"b{i}", j) for i, j in enumerate(J)),
        tuple(ShaftLink(i, j, k) for i, j, k in springs),
        tuple(meshes),
    )


def eigh_hz(M, K):
    w2 = scipy.linalg.eigh(K, M, eigvals_only=True)
    return np.sqrt(np.abs(w2)) / (2 * math.pi)


def test_two_disks_give_176_1_hz():
    f = natural_frequencies(chain([211.4, 8.3], [(0, 1, 9.775e6)])).frequencies_hz
    assert f[0] == pytest.approx(0.0, abs=1e-3)
    assert f[1] == pytest.approx(176.1, abs=0.05)


def test_five_disk_chain_matches_published_frequencies():
    J = [3.5e-3, 3.5e-3, 3.5e-3, 0.15, 0.05]
    f = natural_frequencies(chain(J, [(0, 1, 12e3), (1, 2, 12e3), (2, 3, 14e3), (3, 4, 10e3)])).frequencies_hz
    assert f == pytest.approx([0.0, 81.21, 141.21, 378.95, 536.36], abs=0.006)


def test_branched_geared_system_through_a_stiff_mesh_connector():
    # motor -k_m- gear A == gear B (ratio 1, very stiff mesh), each gear drives a rotor through k_R
    r = 0.05
    mesh = MeshLink(1, 2, r, r, np.zeros(1))
    layout = chain([400e-6, 25e-6, 25e-6, 700e-6, 700e-6], [(0, 1, 1e4), (1, 3, 5e3), (2, 4, 5e3)], [mesh])
    f = natural_frequencies(layout, mesh_stiffness_N_per_m=1e13).frequencies_hz
    assert f[:4] == pytest.approx([0.0, 425.4, 634.1, 3247.2], abs=0.06)
    assert f[4] > 100 * f[3]  # the mesh mode itself, far above


def test_scene_modes_equal_eigh_on_hand_built_matrices():
    sc = load_scenario("one-stage")
    d, st = sc.design, sc.stages[0]
    k = mean_stiffness_N_per_m(mesh_parameters_from_scenario(sc))
    eps = st.mesh.contact_ratio
    assert k == pytest.approx(
        (eps - 1) * st.mesh.stiffness_double_N_per_m + (2 - eps) * st.mesh.stiffness_single_N_per_m
    )
    r1, r2 = st.pinion.base_radius_m, st.wheel.base_radius_m
    k1, k2 = (sh.stiffness_Nm_per_rad for sh in d.shafts)
    M = np.diag(
        [d.motor.inertia_kg_m2, st.pinion.inertia_kg_m2, st.wheel.inertia_kg_m2, d.machine.inertia_kg_m2]
    )
    K = np.array(
        [
            [k1, -k1, 0, 0],
            [-k1, k1 + k * r1**2, -k * r1 * r2, 0],
            [0, -k * r1 * r2, k2 + k * r2**2, -k2],
            [0, 0, -k2, k2],
        ]
    )
    expected = eigh_hz(M, K)
    got = scene_modes(sc).frequencies_hz
    assert got[1:] == pytest.approx(expected[1:], rel=1e-6)
    assert got[0] == pytest.approx(0.0, abs=1e-3)
    # two-wheel: rigid shafts, motor and machine lumped with the gears
    sc2 = load_scenario("two-wheel")
    M2 = np.diag(
        [d.motor.inertia_kg_m2 + st.pinion.inertia_kg_m2, st.wheel.inertia_kg_m2 + d.machine.inertia_kg_m2]
    )
    K2 = k * np.array([[r1**2, -r1 * r2], [-r1 * r2, r2**2]])
    assert scene_modes(sc2).frequencies_hz[1] == pytest.approx(eigh_hz(M2, K2)[1], rel=1e-6)
    # Muller: one reduced mass on the mean mesh spring
    f_muller = scene_modes(load_scenario("muller")).frequencies_hz[0]
    assert f_muller == pytest.approx(math.sqrt(k / reduced_mass_kg(sc)) / (2 * math.pi), rel=1e-6)


def test_mode_shapes_name_their_dominant_inertia():
    modes = scene_modes(load_scenario("one-stage"))
    assert modes.dominant_dof(3) == "pinion"  # the mesh mode moves the light pinion most
