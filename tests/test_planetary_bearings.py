"""Pluggable bearing laws on a planetary stage's members (docs/planetary.md, "Bearing laws"): any
registered law instead of the isotropic linear bearing, the central members' to the housing, a planet's
on its pin in the carrier frame; checked against the linear bearing it generalises, against the
independent reference with Hertzian bearings in clearance, and for refused combinations."""

from __future__ import annotations

import numpy as np
import pytest

from gearbody import simulate
from gearbody.model import ScenarioError, load_scenario, scenario_to_dict

S = "design.stages.1."
STEADY = [
    'operation.initial_state="steady"',
    "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
    "solver.anti_aliasing=false",
]
SUN = "teeth=29,inertia_kg_m2=0.00061009,mass_kg=0.4"
PLANET = "teeth=37,inertia_kg_m2=0.00155335,mass_kg=0.66"
CARRIER = "inertia_kg_m2=0.0616483,mass_kg=5.43"
HERTZ = (
    "kind='hertzian',parameters={{contact_stiffness_N_per_m_n=5e11,radial_clearance_m={c},exponent=1.5,"
    "damping_Ns_per_m=200.0}}"
)


def test_an_isotropic_linear_law_is_the_linear_bearing():
    """bearing = linear law with k_x = k_y = 1e8 N/m, c = 300 N s/m on every member equals
    bearing_stiffness_N_per_m = 1e8, bearing_damping_Ns_per_m = 300 (the compiled spring-dampers), 5 ms."""
    law = (
        "bearing={kind='linear',parameters={stiffness_x_N_per_m=1e8,stiffness_y_N_per_m=1e8,"
        "damping_x_Ns_per_m=300.0,damping_y_Ns_per_m=300.0}}"
    )
    plain = "bearing_stiffness_N_per_m=1e8,bearing_damping_Ns_per_m=300.0"
    ring = "teeth=103,inertia_kg_m2=0.0592013,mass_kg=2.35,torsion_stiffness_Nm_per_rad=1.9733782e7"
    runs = []
    for b in (plain, law):
        members = [S + f"sun={{{SUN},{b}}}", S + f"planet={{{PLANET},{b}}}", S + f"carrier={{{CARRIER},{b}}}",
                   S + f"ring={{{ring},{b}}}"]  # fmt: skip
        runs.append(simulate(load_scenario("planetary", [*STEADY, *members, "operation.t_end_s=0.005"])))
    F = load_scenario("planetary").rated_mesh_force_N
    for n in (1, 2, 3):
        for mesh in ("sun", "ring"):
            key = f"planet_{n}_{mesh}_mesh_force_N"
            assert np.max(np.abs(runs[0][key] - runs[1][key])) < 1e-5 * F, key  # 3e-7 F seen (step choice)
    np.testing.assert_allclose(
        runs[0]["sun_bearing_force_x_N"], runs[1]["sun_bearing_force_x_N"], atol=1e-6 * F
    )


def hertz_scenario(t_end: float):
    return load_scenario(
        "planetary",
        [
            *STEADY,
            S + f"sun={{{SUN},bearing={{{HERTZ.format(c=5e-6)}}}}}",
            S + f"planet={{{PLANET},bearing={{{HERTZ.format(c=2e-6)}}}}}",
            S + f"carrier={{{CARRIER},bearing={{kind='linear',parameters={{stiffness_x_N_per_m=1e8,"
            "stiffness_y_N_per_m=2e8,damping_x_Ns_per_m=100.0,damping_y_Ns_per_m=100.0}}}",
            f"operation.t_end_s={t_end}",
        ],
    )


@pytest.mark.slow
def test_hertzian_bearings_in_clearance_agree_with_the_reference():
    """A floating sun (Hertzian, 5 um clearance), planets on Hertzian pins (2 um), an anisotropic linear
    carrier bearing: every planet mesh force within 1e-4 of F_rated of the reference over 10 ms (1.1e-6
    measured); the steady start closed the planets' clearances (their bearings carry the mesh forces)."""
    from gearbody_validation.reference.planetary_drive import simulate_reference_drive

    sc = hertz_scenario(0.01)
    r = simulate(sc)
    ref = simulate_reference_drive(scenario_to_dict(sc), r.time_s)
    F = sc.rated_mesh_force_N
    for n in (1, 2, 3):
        for mesh in ("sun", "ring"):
            key = f"planet_{n}_{mesh}_mesh_force_N"
            assert np.max(np.abs(r[key] - ref[key])) < 1e-4 * F, key
    radial = np.hypot(r["planet_1_bearing_radial_m"], r["planet_1_bearing_tangential_m"])
    assert radial.min() > 2e-6  # in contact throughout


def test_the_bearing_force_signal_is_the_law_on_the_housing():
    sc = hertz_scenario(0.002)
    r = simulate(sc)
    law = sc.stages[0].sun.bearing.law()
    i = len(r.time_s) // 2
    f = law.force_N(
        np.array([r["sun_x_m"][i], r["sun_y_m"][i]]),
        np.array([r["sun_x_velocity_m_s"][i], r["sun_y_velocity_m_s"][i]]),
    )
    assert r["sun_bearing_force_x_N"][i] == pytest.approx(-f[0], abs=1e-9)
    assert r["sun_bearing_force_y_N"][i] == pytest.approx(-f[1], abs=1e-9)


def test_modes_linearise_the_laws_where_they_carry_the_rated_load():
    """In clearance the laws have no stiffness at the nominal assembly; the modes take them at the static
    state under the rated load, so every mode but the near-rigid rotation has a finite frequency."""
    from gearbody.engine import scene_modes

    f = scene_modes(hertz_scenario(0.01)).frequencies_hz
    assert f.size == 20 and f[0] < 2.0 and f[1] > 20.0


@pytest.mark.parametrize(
    ("member", "message"),
    [
        (f"sun={{{SUN}}}", "give either an isotropic linear bearing"),
        (
            f"sun={{{SUN},bearing_stiffness_N_per_m=1e8,bearing={{kind='linear',parameters={{stiffness_x_N_per_m=1e8,stiffness_y_N_per_m=1e8}}}}}}",
            "not both",
        ),
        (
            f"sun={{{SUN},bearing_damping_Ns_per_m=10.0,bearing={{{HERTZ.format(c=0.0)}}}}}",
            "the damping is the law's",
        ),
        (f"sun={{{SUN},bearing={{kind='hertzan'}}}}", "not a registered bearing law"),
    ],
)
def test_bad_bearings_are_refused_by_name(member, message):
    with pytest.raises(ScenarioError, match=message):
        load_scenario("planetary", [S + member])


def test_a_planet_bearing_defect_needs_the_linear_bearing():
    with pytest.raises(ScenarioError, match="planet_bearing_defects: they weaken the linear planet bearing"):
        load_scenario(
            "planetary",
            [S + f"planet={{{PLANET},bearing={{{HERTZ.format(c=0.0)}}}}}",
             S + "planet_bearing_defects=[{planet=1,stiffness_factor=0.5}]"],
        )  # fmt: skip
