"""Every public Result method on a planetary drive and on the compound conveyor drive (issue 25): each
answers with the stage kind's analogue (planetary teeth, K_d folded over a planet mesh's phase, the
ring-sensor spectrum, the K_d features over the planet meshes) or refuses in one line with a gearbody
error that names the stage and what applies; no bare KeyError."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearbody.analysis.features import FeatureError
from gearbody.engine import simulate
from gearbody.errors import GearbodyError, StageError
from gearbody.model import load_scenario
from gearbody.result import PlanetaryTeeth, Result


@pytest.fixture(scope="module")
def planetary() -> Result:
    return simulate(load_scenario("planetary", ["operation.t_end_s=0.03"]))


@pytest.fixture(scope="module")
def conveyor() -> Result:
    return simulate(load_scenario("planetary-conveyor", ["operation.t_end_s=0.03"]))


def one_line_refusal(exc: pytest.ExceptionInfo | Exception, *words: str) -> None:
    error = exc.value if isinstance(exc, pytest.ExceptionInfo) else exc
    assert isinstance(error, GearbodyError) and error.exit_code == 2
    text = str(error)
    assert "\n" not in text and all(w in text for w in words), text


def test_stage_facts_of_a_planetary_result(planetary):
    sc = load_scenario("planetary")
    st = sc.stages[0]
    assert planetary.n_stages == 1 and planetary.stage_names == ["stage 1"] and planetary.name == "planetary"
    assert planetary.stage_kind(0) == "planetary" and planetary.planetary_stages == [0]
    assert planetary.planetary_teeth(0) == PlanetaryTeeth(
        st.sun.teeth, st.planet.teeth, st.ring.teeth, st.planets
    )
    with pytest.raises(StageError) as exc:
        planetary.teeth(0)
    one_line_refusal(exc, "stage 1 is planetary", "planetary_teeth(0)")
    with pytest.raises(StageError) as exc:
        planetary.stage_kind(1)
    one_line_refusal(exc, "stage = 1", "1 stage(s)")
    for name in ("kd", "mesh_force"):
        with pytest.raises(StageError) as exc:
            getattr(planetary, name)
        one_line_refusal(exc, "stage 1 is planetary", "planet_<n>_sun_mesh_")


def test_mesh_frequency_follows_the_sun_speed_by_willis(planetary):
    """f_m = z_s |w_s - w_c| / 2 pi with w_c = w_s z_s / (z_s + z_r) (ring fixed), from the sun's mean
    speed over the final quarter."""
    z = planetary.planetary_teeth(0)
    w_s = float(np.mean(planetary["sun_speed_rad_s"][planetary.final_window()]))
    expected = z.sun * w_s * z.ring / (z.sun + z.ring) / (2 * math.pi)
    assert planetary.mesh_frequency_hz(0) == pytest.approx(expected, rel=2e-3)
    assert planetary.stage_signal("planet_2_ring_mesh_kd", 0) is planetary["planet_2_ring_mesh_kd"]


def test_fold_kd_of_a_planet_mesh_is_over_its_law_phase(planetary):
    """A hand-made planetary result whose K_d is a known function of the planet mesh's phase folds back
    to that function; the default is planet 1's sun mesh."""
    t = np.arange(4000) / 20000.0
    phase = (t * 553.0) % 1.0
    signals = {
        "planet_1_sun_mesh_phase": phase,
        "planet_1_sun_mesh_kd": 1.0 + 0.2 * np.sin(2 * np.pi * phase),
        "planet_3_ring_mesh_phase": phase,
        "planet_3_ring_mesh_kd": 1.0 - 0.3 * np.cos(2 * np.pi * phase),
    }
    stage = {"type": "planetary", "sun_teeth": 29, "planet_teeth": 37, "ring_teeth": 103, "planets": 3}
    res = Result(time_s=t, signals=signals, meta={"stages": [stage], "output_rate_hz": 20000.0})
    centre = (np.arange(20) + 0.5) / 20
    sun = res.fold_kd(0, bins=20, fraction=1.0)
    assert np.allclose(sun.mean, 1.0 + 0.2 * np.sin(2 * np.pi * centre), atol=0.02)
    ring = res.fold_kd(0, bins=20, fraction=1.0, planet=3, mesh="ring")
    assert np.allclose(ring.mean, 1.0 - 0.3 * np.cos(2 * np.pi * centre), atol=0.03)
    for kwargs, words in (
        ({"planet": 4}, ("planet = 4", "planets 1..3")),
        ({"mesh": "carrier"}, ("mesh = 'carrier'", "'sun' or 'ring'")),
    ):
        with pytest.raises(StageError) as exc:
            res.fold_kd(0, **kwargs)
        one_line_refusal(exc, *words)
    # on the simulated run: the folded mean, weighted by the bin counts, is the window's mean K_d
    folded = planetary.fold_kd(0, bins=10, planet=2, mesh="ring")
    kd = planetary["planet_2_ring_mesh_kd"][planetary.final_window()]
    assert np.nansum(folded.mean * folded.count) / folded.count.sum() == pytest.approx(np.mean(kd))


def test_spectrum_of_a_planetary_run_is_the_ring_sensor_labelled_by_its_lines(planetary):
    spec = planetary.spectrum()
    assert spec.signal == planetary.vibration_signal_name == "ring_sensor_N"
    f_m = planetary.mesh_frequency_hz(0)
    assert spec.f_max_hz == pytest.approx(3.5 * f_m, rel=0.01)  # the run plot's: 3 mesh harmonics
    labelled = [p for p in spec.peaks if p.labels]
    assert labelled, spec.table()
    # a labelled peak lies within the label tolerance of a harmonic of f_m or one of its sidebands
    for p in labelled:
        k = round(p.frequency_hz / f_m)
        assert any(f"{k} f_m" in label for label in p.labels), (p.frequency_hz, p.labels)
    assert "N" in spec.plot().get_ylabel()


def test_features_of_a_planetary_run_read_its_planet_meshes(planetary):
    summary = planetary.summary()
    win = planetary.final_window()
    got = planetary.features(
        ["kd_max:fraction=1", "kd_mean", "kd_max:planet=2,mesh=ring", "separation_fraction:fraction=1"]
    )
    assert got["kd_max:fraction=1"] == pytest.approx(summary["kd_max"])
    assert got["kd_mean"] == pytest.approx(summary["kd_mean_final"])
    assert got["kd_max:planet=2,mesh=ring"] == pytest.approx(np.max(planetary["planet_2_ring_mesh_kd"][win]))
    assert got["separation_fraction:fraction=1"] == pytest.approx(summary["separation_fraction"])
    x = planetary["ring_sensor_N"][win]
    assert planetary.features(["rms:signal=ring_sensor_N"])["rms:signal=ring_sensor_N"] == pytest.approx(
        np.sqrt(np.mean(x**2))
    )
    assert planetary.features(["natural_frequency_hz:mode=2"], natural_frequencies_hz=[0.0, 5.0, 7.0]) == {
        "natural_frequency_hz:mode=2": 7.0
    }
    record = planetary.record()
    assert record.pinion_teeth is None and record.planets(1) == (1, 2, 3)
    for spec, words in (
        ("line_amplitude:signal=ring_sensor_N,mesh=1", ("parallel first stage", "planetary")),
        ("fm4:signal=ring_sensor_N", ("parallel first stage", "kd_*")),
        ("kd_max:planet=4", ("planet = 4", "planets 1..3")),
        ("kd_max:mesh=carrier", ("mesh = 'carrier'",)),
    ):
        with pytest.raises(FeatureError) as exc:
            planetary.features([spec])
        one_line_refusal(exc, *words)


def test_plot_summary_and_saved_result_of_a_planetary_run(planetary, tmp_path):
    paths = planetary.plot(tmp_path / "plots")
    assert sorted(p.name for p in paths) == [
        "load_sharing.png",
        "planet_kd_time.png",
        "ring_sensor_spectrum.png",
    ]
    assert all(p.is_file() for p in paths)
    assert planetary.summary()["sun_mesh_load_sharing_factor"] >= 1.0
    again = Result.load_npz(planetary.save_npz(tmp_path / "r.npz"))
    assert again.planetary_teeth(0) == planetary.planetary_teeth(0)
    assert again.names == planetary.names and "ring_sensor_N" in again
    assert again.period_boundaries_s() == planetary.period_boundaries_s()
    assert planetary.time is planetary.time_s and planetary.sample_rate_hz == 20000.0
    assert set(planetary.bearing_gears) == {"sun", "ring", "carrier"}


def test_a_compound_drive_answers_per_stage(conveyor, tmp_path):
    """planetary-conveyor: a spur stage (pinion, wheel) then a planetary stage."""
    assert [conveyor.stage_kind(k) for k in (0, 1)] == ["parallel", "planetary"]
    assert conveyor.teeth(0) == (29, 88) and conveyor.planetary_teeth(1).planets == 3
    with pytest.raises(StageError) as exc:
        conveyor.planetary_teeth(0)
    one_line_refusal(exc, "stage 1 is a parallel stage", "teeth(0)")
    with pytest.raises(StageError) as exc:
        conveyor.fold_kd(0, planet=1)
    one_line_refusal(exc, "parallel stage", "planetary stages")
    assert conveyor.fold_kd(0).mean.size == 100 and conveyor.fold_kd(1, bins=10, mesh="ring").mean.size == 10
    assert conveyor.mesh_frequency_hz(1) == pytest.approx(
        float(np.mean(conveyor["stage_2_mesh_frequency_hz"][conveyor.final_window()]))
    )
    summary = conveyor.summary()
    got = conveyor.features(["kd_max:stage=2,fraction=1", "kd_max:stage=2,mesh=sun,fraction=1", "kd_max"])
    assert got["kd_max:stage=2,fraction=1"] == pytest.approx(
        max(summary["stage_2_sun_mesh_kd_max"], summary["stage_2_ring_mesh_kd_max"])
    )
    assert got["kd_max:stage=2,mesh=sun,fraction=1"] == pytest.approx(summary["stage_2_sun_mesh_kd_max"])
    assert got["kd_max"] == pytest.approx(summary["kd_max_final"])
    with pytest.raises(FeatureError) as exc:
        conveyor.features(["kd_max:planet=1"])
    one_line_refusal(exc, "stage 1 is no planetary stage")
    record = conveyor.record()
    assert (record.pinion_teeth, record.wheel_teeth) == (29, 88) and record.planets(2) == (1, 2, 3)
    line = "line_amplitude:signal=pinion_accel_rad_s2,mesh=1"
    assert conveyor.features([line])[line] > 0
    # the spectrum: the pinion's acceleration, labelled with the spur stage's and the planetary lines
    spec = conveyor.spectrum()
    assert spec.signal == "pinion_accel_rad_s2"
    strongest = max(spec.peaks, key=lambda p: p.amplitude)
    assert any("f_z1" in label for label in strongest.labels), spec.table()
    names = {p.name for p in conveyor.plot(tmp_path)}
    assert names == {
        "kd_time.png",
        "kd_folded.png",
        "spectrum.png",
        "planet_kd_time_stage_2.png",
        "load_sharing_stage_2.png",
        "ring_sensor_spectrum_stage_2.png",
    }


def test_every_feature_evaluates_or_refuses_in_one_line_on_each_stage_kind(planetary, conveyor):
    """Each feature of analysis.features on the planetary result and on the conveyor (spur stage first):
    a finite value, or a one-line FeatureError. The planetary first stage refuses exactly the features
    that read a pinion; the conveyor's 0.03 s holds too few pinion turns for a synchronous average."""
    from gearbody.analysis.features import FEATURES, INDICATORS

    refused = {}
    for result, signal in ((planetary, "ring_sensor_N"), (conveyor, "pinion_accel_rad_s2")):
        for name, options in FEATURES.items():
            spec = name + (f":signal={signal},fraction=1" if "signal" in options else "")
            try:
                value = result.features([spec], natural_frequencies_hz=[0.0, 100.0])[spec]
            except FeatureError as exc:
                one_line_refusal(exc, f"feature {spec}")
                refused[(result.name, name)] = str(exc)
            else:
                assert math.isfinite(value), spec
    # 'recording' (any feature of a recording's analysis) needs its feature named: refused without it
    assert {n for s, n in refused if s == "planetary"} == {"line_amplitude", "recording", *INDICATORS}
    assert all("give the feature" in m for (_, n), m in refused.items() if n == "recording")
    refused = {k: m for k, m in refused.items() if k[1] != "recording"}
    assert all("parallel first stage" in m for (s, _), m in refused.items() if s == "planetary")
    assert {n for s, n in refused if s == "planetary-conveyor"} == set(INDICATORS)
    assert all("less than 2 revolutions" in m for (s, _), m in refused.items() if s == "planetary-conveyor")


def test_a_signal_the_result_does_not_hold_is_a_one_line_gearbody_error(planetary):
    from gearbody.errors import SignalError

    with pytest.raises(KeyError) as exc:  # still a KeyError for mapping-style lookups
        planetary["pinion_angle_rad"]
    assert isinstance(exc.value, SignalError)
    one_line_refusal(exc, "no signal 'pinion_angle_rad'", "ring_sensor_N")
