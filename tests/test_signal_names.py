"""The signal naming rule (gearbody.signals) is written once: every module names and looks up a stage's
signals, gears and plot files through it (issue 27, "one signal contract")."""

from __future__ import annotations

import re
from pathlib import Path

import gearbody
from gearbody.signals import gear_names, signal_unit, stage_file_tag, stage_prefix, stage_signal

PACKAGE = Path(gearbody.__file__).parent
COPIES = re.compile(r'f"_?stage_\{|f"(pinion|wheel)_\{')
"""An f-string that spells a stage's prefix, file tag or gear name itself."""


def test_the_names_by_stage():
    assert [stage_prefix(k) for k in range(3)] == ["", "stage_2_", "stage_3_"]
    assert stage_signal("mesh_force_N", 0) == "mesh_force_N"
    assert stage_signal("mesh_force_N", 2) == "stage_3_mesh_force_N"
    assert [stage_file_tag(k) for k in range(3)] == ["", "_stage_2", "_stage_3"]
    assert [gear_names(k) for k in range(3)] == [
        ("pinion", "wheel"),
        ("pinion_2", "wheel_2"),
        ("pinion_3", "wheel_3"),
    ]


def test_no_module_but_the_rule_spells_a_stage_name_itself():
    copies = [
        f"{path.relative_to(PACKAGE.parent)}:{n}: {line.strip()}"
        for path in sorted(PACKAGE.rglob("*.py"))
        if path != PACKAGE / "signals.py"
        for n, line in enumerate(path.read_text().splitlines(), 1)
        if COPIES.search(line)
    ]
    assert copies == []


def test_a_run_names_its_signals_by_the_rule():
    from gearbody import load_scenario, simulate

    result = simulate(load_scenario("two-stage", ["operation.t_end_s=0.002"]))
    for k in range(2):
        assert stage_signal("mesh_force_N", k) in result.names
        assert f"{gear_names(k)[0]}_angle_rad" in result.names
        assert result.stage_signal("kd", k).shape == result.time_s.shape
    # every signal carries its unit in its name, or is one of the dimensionless kinds
    dimensionless = re.compile(r"(^|_)(kd|mesh_phase|tooth)$")
    unitless = [n for n in result.names if not signal_unit(n) and not dimensionless.search(n)]
    assert unitless == []


def test_the_unit_a_name_carries():
    units = {
        "pinion_accel_rad_s2": "rad/s^2",
        "pinion_housing_accel_y_m_s2": "m/s^2",
        "pinion_speed_rad_s": "rad/s",
        "pinion_x_velocity_m_s": "m/s",
        "pinion_angle_rad": "rad",
        "motor_torque_Nm": "N m",
        "stage_2_mesh_force_N": "N",
        "mesh_deflection_m": "m",
        "mesh_frequency_hz": "Hz",
        "time_s": "s",
        "kd": "",
        "stage_2_planet_1_sun_mesh_phase": "",
    }
    assert {name: signal_unit(name) for name in units} == units
