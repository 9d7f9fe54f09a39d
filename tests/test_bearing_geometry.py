"""Rolling-bearing geometry in the scenario's bearing tables (data for the bearing defect frequencies):
its keys and their refusals, the TOML round trip, the 'rigid' bearing table of a torsional gear, the
drive's list of rolling bearings (Scenario.rolling_bearings), and that geometry never changes a run."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from gearbody import RollingBearingSpec, RollingGeometry, simulate
from gearbody.assembly.operating_point import nominal_speeds_rad_s
from gearbody.model import ScenarioError, dump_scenario, load_scenario, scenario_to_dict, scene_path
from gearbody.model.io import read_toml

SKF_6308 = {"balls": 8, "ball_diameter_m": 0.015081, "pitch_diameter_m": 0.065}
GEOMETRY = "{balls=9, ball_diameter_m=0.0127, pitch_diameter_m=0.0625, contact_angle_deg=15.0}"
RIGID_PINION = f'design.pinion.bearing={{kind="rigid", geometry={GEOMETRY}}}'


def refused(scene, *overrides: str) -> str:
    with pytest.raises(ScenarioError) as info:
        load_scenario(scene, list(overrides))
    return str(info.value)


# -- the geometry table and its refusals ----------------------------------------------------------------


@pytest.mark.parametrize(
    ("key", "value", "named"),
    [
        ("balls", "2", "design.pinion.bearing.geometry.balls = 2: must be >= 3 and <= 100"),
        ("balls", "101", "design.pinion.bearing.geometry.balls = 101: must be >= 3 and <= 100"),
        (
            "balls",
            "8.5",
            "design.pinion.bearing.geometry.balls = 8.5: must be a whole number (>= 3 and <= 100)",
        ),
        ("ball_diameter_m", "0", "design.pinion.bearing.geometry.ball_diameter_m = 0: must be > 0"),
        (
            "pitch_diameter_m",
            "-0.065",
            "design.pinion.bearing.geometry.pitch_diameter_m = -0.065: must be > 0",
        ),
        (
            "contact_angle_deg",
            "90",
            "design.pinion.bearing.geometry.contact_angle_deg = 90: must be >= 0 and < 90",
        ),
        (
            "contact_angle_deg",
            "-1",
            "design.pinion.bearing.geometry.contact_angle_deg = -1: must be >= 0 and < 90",
        ),
        (
            "ball_diameter_m",
            "0.07",
            "design.pinion.bearing.geometry.ball_diameter_m = 0.07: must be < pitch_diameter_m",
        ),
        (
            "ball_diameter_m",
            "0.065",
            "ball_diameter_m = 0.065: must be < pitch_diameter_m = 0.065 (the ball must fit",
        ),
        ("bogus", "1", "unknown key 'design.pinion.bearing.geometry.bogus'"),
    ],
)
def test_a_bad_geometry_is_refused_naming_the_key_the_value_and_the_range(key, value, named):
    assert named in refused("lateral-8dof-ball", f"design.pinion.bearing.geometry.{key}={value}")


def test_a_geometry_needs_its_three_sizes():
    message = refused("lateral-8dof-ball", "design.pinion.bearing.geometry={balls=8, pitch_diameter_m=0.065}")
    assert "missing required key 'design.pinion.bearing.geometry.ball_diameter_m'" in message


def test_a_geometry_built_in_python_is_checked_as_one_read_from_a_file():
    g = RollingGeometry(**SKF_6308)
    assert g.contact_angle_deg == 0.0
    with pytest.raises(ScenarioError, match=r"balls = 2: must be >= 3 and <= 100"):
        RollingGeometry(**{**SKF_6308, "balls": 2})
    with pytest.raises(ScenarioError, match=r"contact_angle_deg = 90: must be >= 0 and < 90"):
        RollingGeometry(**SKF_6308, contact_angle_deg=90.0)
    with pytest.raises(ScenarioError, match=r"ball_diameter_m = 0.07: must be < pitch_diameter_m = 0.065"):
        RollingGeometry(**{**SKF_6308, "ball_diameter_m": 0.07})
    with pytest.raises(ScenarioError, match=r"ball_diameter_m = 0.015081: must be < pitch_diameter_m = 0.01"):
        g.replace(pitch_diameter_m=0.01)


# -- TOML round trip ------------------------------------------------------------------------------------


def test_the_geometry_survives_the_toml_round_trip(tmp_path):
    scenario = load_scenario("lateral-8dof-ball")
    table = scenario_to_dict(scenario)["design"]["stages"][0]["pinion"]["bearing"]["geometry"]
    assert table == {**SKF_6308, "contact_angle_deg": 0.0}
    again = load_scenario(dump_scenario(scenario, tmp_path / "again.toml"))
    assert again.design == scenario.design
    assert again.rolling_bearings() == scenario.rolling_bearings()


def test_a_rigid_table_and_a_planetary_geometry_survive_the_round_trip(tmp_path):
    for scenario in (
        load_scenario("one-stage", [RIGID_PINION]),
        load_scenario("planetary", [f"design.stages.1.planet.bearing_geometry={GEOMETRY}"]),
    ):
        again = load_scenario(dump_scenario(scenario, tmp_path / "again.toml"))
        assert again.design == scenario.design
        assert again.rolling_bearings() == scenario.rolling_bearings()


# -- the rigid bearing of a torsional gear --------------------------------------------------------------


def test_a_torsional_gear_takes_a_rigid_bearing_table():
    scenario = load_scenario("one-stage", [RIGID_PINION])
    bearing = scenario.stages[0].pinion.bearing
    assert (bearing.kind, bearing.parameters, scenario.stages[0].pinion.lateral) == ("rigid", {}, "none")
    assert not scenario.is_lateral


def test_a_torsional_gear_refuses_a_bearing_law():
    law = '{kind="linear", parameters={stiffness_x_N_per_m=1e8, stiffness_y_N_per_m=1e8}}'
    message = refused("one-stage", f"design.pinion.bearing={law}")
    assert "design.pinion.bearing.kind = 'linear': the gear is torsional (lateral = 'none')" in message
    assert "set kind = 'rigid'" in message and "lateral = 'y' or 'xy'" in message
    # a table of geometry alone is of the default kind, 'linear', without its parameters: refused, saying
    # what a torsional gear's table is
    message = refused("one-stage", f"design.pinion.bearing.geometry={GEOMETRY}")
    assert "design.pinion.bearing.parameters.stiffness_x_N_per_m: required by the 'linear' law" in message
    assert "a torsional gear's bearing table is kind = 'rigid'" in message


def test_a_lateral_gear_refuses_a_rigid_bearing():
    message = refused("lateral-8dof-ball", 'design.pinion.bearing={kind="rigid"}')
    assert "design.pinion.bearing.kind = 'rigid': a rigid bearing holds the gear centre fixed" in message
    assert "lateral = 'xy'" in message and "set lateral = 'none'" in message
    # the kind alone changed: the law's parameters are refused, pointing at the rule
    message = refused("lateral-8dof-ball", 'design.pinion.bearing.kind="rigid"')
    assert "not a parameter of the 'rigid' law, which takes no parameters" in message
    assert "lateral = 'none'" in message


def test_a_planetary_member_refuses_a_rigid_bearing_and_a_doubled_geometry():
    d = read_toml(scene_path("planetary"))
    sun = d["design"]["stages"][0]["sun"]
    del sun["bearing_stiffness_N_per_m"]
    sun["bearing"] = {"kind": "rigid"}
    with pytest.raises(ScenarioError, match=r"design.stages.1.sun.bearing.kind = 'rigid': the members of a"):
        load_scenario(d)
    sun["bearing"] = {
        "kind": "linear",
        "parameters": {"stiffness_x_N_per_m": 1e8, "stiffness_y_N_per_m": 1e8},
        "geometry": SKF_6308,
    }
    load_scenario(copy.deepcopy(d))  # the geometry inside the law's table
    sun["bearing_geometry"] = SKF_6308
    with pytest.raises(ScenarioError, match=r"design.stages.1.sun.bearing_geometry: with a bearing law"):
        load_scenario(d)


def test_a_rigid_bearing_table_leaves_the_run_bit_identical():
    plain = load_scenario("one-stage", ["operation.t_end_s=0.02"])
    rigid = load_scenario(
        "one-stage",
        ["operation.t_end_s=0.02", RIGID_PINION, 'design.wheel.bearing={kind="rigid"}'],
    )
    a, b = simulate(plain), simulate(rigid)
    assert a.names == b.names and a.time_s.size > 10
    for name in a.names:
        assert np.array_equal(a[name], b[name], equal_nan=True), name


# -- Scenario.rolling_bearings() --------------------------------------------------------------------------


def test_the_rolling_bearings_of_the_lateral_ball_scene():
    scenario = load_scenario("lateral-8dof-ball")
    pinion, wheel = scenario.rolling_bearings()
    assert isinstance(pinion, RollingBearingSpec)
    assert (pinion.name, pinion.body, pinion.reference, pinion.body_race) == (
        "pinion bearing",
        "pinion",
        None,
        "inner",
    )
    assert pinion.key == "design.stages.1.pinion.bearing.geometry" and not pinion.relative
    assert pinion.geometry == RollingGeometry(**SKF_6308)
    assert (wheel.name, wheel.body) == ("wheel bearing", "wheel")
    assert wheel.geometry.balls == 8 and wheel.geometry.pitch_diameter_m == pytest.approx(0.095)
    speeds = nominal_speeds_rad_s(scenario)
    assert {b.body for b in scenario.rolling_bearings()} <= set(speeds)


def test_the_rolling_bearings_of_a_torsional_drive_with_a_rigid_table():
    assert load_scenario("one-stage").rolling_bearings() == []  # no bearing tables: none known
    (pinion,) = load_scenario("one-stage", [RIGID_PINION]).rolling_bearings()
    assert (pinion.name, pinion.body, pinion.reference) == ("pinion bearing", "pinion", None)
    assert pinion.geometry == RollingGeometry(
        balls=9, ball_diameter_m=0.0127, pitch_diameter_m=0.0625, contact_angle_deg=15.0
    )
    (wheel_2,) = load_scenario(
        "two-stage", ['design.stages.2.wheel.bearing={kind="rigid"}']
    ).rolling_bearings()
    assert (wheel_2.name, wheel_2.body, wheel_2.geometry) == ("stage 2 wheel bearing", "wheel_2", None)
    assert wheel_2.key == "design.stages.2.wheel.bearing.geometry"


def test_the_rolling_bearings_of_a_planetary_stage_with_a_geometry_override():
    scenario = load_scenario("planetary", [f"design.stages.1.planet.bearing_geometry={GEOMETRY}"])
    bearings = scenario.rolling_bearings()
    assert [b.name for b in bearings] == [
        "sun bearing",
        "ring bearing",
        "carrier bearing",
        "planet 1 bearing",
        "planet 2 bearing",
        "planet 3 bearing",
    ]
    speeds = nominal_speeds_rad_s(scenario)
    for b in bearings:
        assert b.body in speeds and (b.reference is None or b.reference in speeds)
    sun, planet = bearings[0], bearings[3]
    assert (sun.body, sun.reference, sun.body_race, sun.geometry) == ("sun", None, "inner", None)
    assert sun.key == "design.stages.1.sun.bearing_geometry"
    assert (planet.body, planet.reference, planet.body_race) == ("planet_1", "carrier", "outer")
    assert planet.relative and planet.key == "design.stages.1.planet.bearing_geometry"
    assert planet.geometry.balls == 9 and planet.geometry.contact_angle_deg == 15.0
    assert all(b.geometry == planet.geometry for b in bearings[3:])


def test_the_rolling_bearings_of_a_later_planetary_stage_carry_its_prefix():
    d = read_toml(scene_path("planetary-conveyor"))
    stages = d["design"]["stages"]
    k = next(i for i, st in enumerate(stages) if st.get("type") == "planetary")
    scenario = load_scenario(d)
    planets = [b for b in scenario.rolling_bearings() if b.reference is not None]
    label, prefix = ("", "") if k == 0 else (f"stage {k + 1} ", f"stage_{k + 1}_")
    assert planets[0].name == f"{label}planet 1 bearing"
    assert (planets[0].body, planets[0].reference) == (f"{prefix}planet_1", f"{prefix}carrier")
    assert {b.body for b in scenario.rolling_bearings()} <= set(nominal_speeds_rad_s(scenario))


# -- geometry is data only ----------------------------------------------------------------------------------


def test_the_ball_scene_runs_bit_identically_with_and_without_its_geometry():
    with_geometry = read_toml(scene_path("lateral-8dof-ball"))
    without = copy.deepcopy(with_geometry)
    for gear in ("pinion", "wheel"):
        assert without["design"][gear]["bearing"].pop("geometry")
    short = ["operation.t_end_s=0.01"]
    a = simulate(load_scenario(with_geometry, short))
    b = simulate(load_scenario(without, short))
    assert a.names == b.names and a.time_s.size > 10
    for name in a.names:
        assert np.array_equal(a[name], b[name], equal_nan=True), name
