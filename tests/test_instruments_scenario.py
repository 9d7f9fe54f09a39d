"""Issue 30: the scenario's [instruments] table: read, written back, every key range-checked by name when
the scenario is built, relative FRF files anchored to the scene file's folder; and what needs the
drive (force-signal names, the tacho's shaft, the FRF file's content) checked before a run starts."""

from __future__ import annotations

import os

import numpy as np
import pytest

import gearbody as gb
from gearbody.diagnosis.virtual import check_instruments, force_signal_names
from gearbody.model import dump_scenario, load_scenario, scenario_to_dict
from gearbody.model.scenes import list_scenes, scene_path
from gearbody.recording.frf import MeasuredFRF, write_frf
from gearbody.recording.instruments import HousingMode

TABLE = """
[instruments]
sample_rate_hz = 10000.0
seed = 7

[[instruments.accelerometers]]
name = "acc_pinion"
location = "pinion bearing housing, top"
direction = "+y"
noise_rms_g = 0.002
modes = [
  { frequency_hz = 3000.0, damping_ratio = 0.03, participation = { pinion_bearing_force_y_N = 0.033 } },
]

[[instruments.accelerometers]]
name = "acc_wheel"
frf_file = "frf/wheel.csv"

[instruments.tacho]
shaft = "output"
pulses_per_rev = 60
"""

ONE = (
    'instruments={accelerometers=[{name="a",modes=[{frequency_hz=3000.0,damping_ratio=0.03,'
    "participation={pinion_bearing_force_y_N=0.03}}]}]}"
)


def _frf_file(path, signal="wheel_bearing_force_y_N"):
    path.parent.mkdir(parents=True, exist_ok=True)
    mode = HousingMode(2000.0, 0.05, {signal: 0.02})
    return write_frf(MeasuredFRF.from_modes([mode], np.arange(0.0, 10_001.0, 2.0)), path)


def _scene(tmp_path, table=TABLE):
    path = tmp_path / "scene" / "ball.toml"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(scene_path("lateral-8dof-ball").read_text() + table)
    return path


def test_the_table_is_read_anchored_to_the_scene_file_and_written_back(tmp_path, monkeypatch):
    path = _scene(tmp_path)
    monkeypatch.chdir(tmp_path)  # a relative frf_file names the scene's folder, not the working one
    sc = load_scenario(path)
    inst = sc.instruments
    assert [a.name for a in inst.accelerometers] == ["acc_pinion", "acc_wheel"]
    assert inst.accelerometers[1].frf_file == str(tmp_path / "scene" / "frf" / "wheel.csv")
    assert inst.accelerometers[0].noise_m_s2 == pytest.approx(0.002 * 9.80665)
    assert inst.accelerometers[0].sensitivity_V_per_m_s2 == pytest.approx(0.1 / 9.80665)
    assert (inst.tacho.shaft, inst.tacho.pulses_per_rev, inst.seed) == ("output", 60, 7)
    again = load_scenario(dump_scenario(sc, tmp_path / "elsewhere.toml"))
    assert again == sc and scenario_to_dict(again)["instruments"] == scenario_to_dict(sc)["instruments"]
    override = load_scenario(path, ['instruments.accelerometers.2.frf_file="here.csv"'])
    assert override.instruments.accelerometers[1].frf_file == str(tmp_path / "here.csv")  # typed: cwd


def test_of_the_shipped_scenes_only_phm2009_has_instruments_its_published_acquisition():
    assert [s for s in list_scenes() if load_scenario(s).instruments is not None] == ["phm2009"]
    table = load_scenario("phm2009").instruments
    assert table.sample_rate_hz == pytest.approx(200e3 / 3, rel=1e-15)
    assert table.tacho.pulses_per_rev == 10 and table.tacho.shaft == "input"
    assert [a.name for a in table.accelerometers] == ["acc_input", "acc_output"]


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ("instruments.sample_rate_hz=30000.0", "instruments.sample_rate_hz = 30000: must be <= "),
        ("instruments.sample_rate_hz=7777.7", "instruments.sample_rate_hz = 7777.7: must be solver."),
        ("instruments.sample_rate_hz=0", "instruments.sample_rate_hz = 0: must be > 0"),
        ("instruments.seed=-1", "instruments.seed = -1: must be >= 0"),
        ("instruments.tacho.pulses_per_rev=0", "instruments.tacho.pulses_per_rev = 0: must be >= 1"),
        ("instruments.accelerometers=[]", "instruments.accelerometers = []: give at least one"),
        ('instruments.accelerometers.1.name="2nd"', "instruments.accelerometers.1.name = '2nd': must start"),
        ('instruments.accelerometers.2.name="acc_pinion"', "accelerometers.2.name = 'acc_pinion': another"),
        ("instruments.accelerometers.1.noise_rms_m_s2=0.1", "noise_rms_g: give the noise once"),
        ("instruments.accelerometers.1.noise_rms_g=-1", ".noise_rms_g = -1: must be >= 0 and <= 1000"),
        ("instruments.accelerometers.1.sensitivity_mV_per_g=0", ".sensitivity_mV_per_g = 0: must be > 0"),
        ('instruments.accelerometers.1.frf_file="x.csv"', "accelerometers.1.modes: both modes and frf_file"),
        ('instruments.accelerometers.2.frf_file=" "', "frf_file = '': name a CSV file"),
        (
            "instruments.accelerometers.1.modes.1.damping_ratio=1",
            ".damping_ratio = 1: must be >= 0.0001 and < 1",
        ),
        ("instruments.accelerometers.1.modes.1.frequency_hz=-5", ".frequency_hz = -5: must be > 0"),
        ("instruments.accelerometers.1.modes.1.frequency_hz=10000", ".frequency_hz = 10000: must be < 10000"),
        ("instruments.accelerometers.1.modes.1.participation={}", "participation = {}: name at least one"),
        (
            'instruments.accelerometers.1.modes.1.participation={a="x"}',
            "participation.a = 'x': must be a number",
        ),
        ("instruments.accelerometers.1.bogus=1", "unknown key 'instruments.accelerometers.1.bogus'"),
        ("instruments.tacho.shafts=1", "did you mean 'instruments.tacho.shaft'"),
    ],
)
def test_every_key_is_checked_when_the_scenario_is_built(tmp_path, override, message):
    with pytest.raises(gb.ScenarioError, match="--set") as exc:
        load_scenario(_scene(tmp_path), [override])
    assert message in str(exc.value).replace(" (on ", "\n"), str(exc.value)


def test_force_signal_names_are_what_a_run_gives():
    """The prediction made before a run, against the force signals of a short run of a lateral scene."""
    sc = load_scenario("lateral-8dof-ball", ["operation.t_end_s=0.004"])
    names = force_signal_names(sc)
    run = gb.simulate(sc)
    assert set(names) <= set(run.signals)
    assert {k for k in run.signals if "_bearing_force_" in k} <= set(names)
    assert force_signal_names(load_scenario("muller")) == ["mesh_force_N"]
    planetary = force_signal_names(load_scenario("planetary"))
    assert "carrier_bearing_force_x_N" in planetary and "ring_sensor_N" in planetary
    assert not any(n.startswith("planet_") for n in planetary)  # a planet's bearing is on the carrier


@pytest.mark.slow
@pytest.mark.parametrize("scene", list_scenes())
def test_force_signal_names_of_every_scene_are_what_its_run_gives(scene):
    sc = load_scenario(scene, ["operation.t_end_s=0.003"])
    names, run = force_signal_names(sc), gb.simulate(sc)
    assert set(names) <= set(run.signals), set(names) - set(run.signals)
    assert {k for k in run.signals if "_bearing_force_" in k} <= set(names)


def test_before_a_run_the_names_the_shaft_and_the_file_are_checked(tmp_path):
    path = _scene(tmp_path)
    _frf_file(tmp_path / "scene" / "frf" / "wheel.csv")
    frfs = check_instruments(load_scenario(path))
    assert list(frfs) == [2] and frfs[2].signals == ["wheel_bearing_force_y_N"]

    def refused(*overrides):
        with pytest.raises(gb.ScenarioError) as exc:
            check_instruments(load_scenario(path, list(overrides)))
        return str(exc.value)

    text = refused("instruments.accelerometers.1.modes.1.participation={pinion_bearing_force_z_N=1.0}")
    assert text.startswith("instruments.accelerometers.1.modes.1.participation.pinion_bearing_force_z_N: ")
    assert "its force signals: mesh_force_N, mesh_force_bandlimited_N, pinion_bearing_force_x_N" in text
    text = refused('instruments.tacho.shaft="wheel_7"')
    assert text.startswith("instruments.tacho.shaft = 'wheel_7': ") and "pinion, wheel" in text
    os.remove(tmp_path / "scene" / "frf" / "wheel.csv")
    text = refused()
    assert text.startswith("instruments.accelerometers.2.frf_file = ") and "no such FRF file" in text
    _frf_file(tmp_path / "scene" / "frf" / "wheel.csv", signal="wheel_force_N")
    text = refused()
    assert "frf_file = " in text and "column wheel_force_N: not a force signal" in text


def test_a_torsional_scene_offers_its_mesh_force_only():
    sc = load_scenario("one-stage", [ONE.replace("pinion_bearing_force_y_N", "mesh_force_bandlimited_N")])
    assert check_instruments(sc) == {}
    assert force_signal_names(sc) == ["mesh_force_N", "mesh_force_bandlimited_N"]
    with pytest.raises(gb.ScenarioError, match="its force signals: mesh_force_N, mesh_force_bandlimited_N$"):
        check_instruments(load_scenario("one-stage", [ONE]))


def test_gearbody_new_writes_the_table_with_every_key_commented_and_it_loads_back(tmp_path, capsys):
    from gearbody.cli import main

    path = _scene(tmp_path)
    assert main(["new", str(path), "--out", str(tmp_path / "new.toml")]) == 0
    text = (tmp_path / "new.toml").read_text()
    assert "[[instruments.accelerometers]]" in text and "# noise_rms_m_s2: not set;" in text
    assert load_scenario(tmp_path / "new.toml").instruments == load_scenario(path).instruments
    assert main(["new", "one-stage", "--out", str(tmp_path / "plain.toml")]) == 0
    assert "# [instruments]: not set;" in (tmp_path / "plain.toml").read_text()
    capsys.readouterr()
