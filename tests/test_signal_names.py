"""The signal naming rule (gearbody.signals) is written once: every module names and looks up a stage's
signals, gears and plot files through it (issue 27, "one signal contract")."""

from __future__ import annotations

import re
from pathlib import Path

import gearbody
from gearbody.signals import gear_names, stage_file_tag, stage_prefix, stage_signal

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
