"""The PHM Society's 2009 Data Challenge gearbox (scenes/phm2009.toml): what the PHM Society published
(teeth, the 5 to 1 reduction, the ER-10K bearing geometry, the 200 kHz / 3 sample rate, a 10 pulse per
revolution tacho), the lines that follow from it in orders of the input shaft (each computed here by hand
from the standard formulas, not by gearbody), and a short run at high load: the rated torque through the
base radii, the mesh lines at teeth x shaft speed, no tooth separation."""

from __future__ import annotations

import math

import numpy as np
import pytest

import gearbody as gb
from gearbody.assembly.operating_point import nominal_speeds_rad_s
from gearbody.recording import Accelerometer, HousingMode, virtual_instruments

INCH_M = 0.0254
TEETH = [(32, 96), (48, 80)]  # input pinion / 1st idler gear, 2nd idler gear / output gear
BALLS, BALL_D_M, PITCH_D_M = 8, 0.3125 * INCH_M, 1.319 * INCH_M  # MB Manufacturing ER-10K, 0 deg
PHM_RATE_HZ = 200e3 / 3  # 66 666.67 samples per second
INPUT_HZ = 30.0  # the lowest of the PHM speeds, the scene's
OUTPUT_TORQUE_NM = 50.0  # high load on the output shaft (assumed: not published)
MODULE_M = INCH_M / 16  # diametral pitch 16 (assumed: not published)


@pytest.fixture(scope="module")
def scenario():
    return gb.load_scenario("phm2009")


@pytest.fixture(scope="module")
def run(scenario):
    """0.12 s at 30 Hz and high load, from the steady operating point (~2 s of wall time)."""
    return gb.simulate(scenario.replace(operation=gb.steady(0.12)))


def _input_orders(scenario) -> dict[str, float]:
    """Every kinematic line up to order 40 of the input shaft, by label."""
    return {ln.label: ln.frequency_hz for ln in gb.DriveKinematics.from_scenario(scenario).lines(1.0, 40.0)}


# -- the published facts ------------------------------------------------------------------------------


def test_the_published_teeth_give_the_5_to_1_reduction(scenario):
    assert [(st.pinion.teeth, st.wheel.teeth) for st in scenario.stages] == TEETH
    speeds = nominal_speeds_rad_s(scenario)
    assert speeds["wheel"] / speeds["pinion"] == pytest.approx(32 / 96)  # idler: 10 Hz at 30 Hz
    assert speeds["pinion_2"] == speeds["wheel"]  # both idler gears on one shaft
    assert speeds["machine"] / speeds["pinion"] == pytest.approx(1 / 5)  # output: 6 Hz at 30 Hz
    assert (32 / 96) * (48 / 80) == pytest.approx((16 / 48) * (24 / 40))  # the page's helical "16/48*24/40"


def test_every_gear_sits_on_the_published_er10k_geometry(scenario):
    bearings = scenario.rolling_bearings()
    assert [b.body for b in bearings] == ["pinion", "wheel", "pinion_2", "wheel_2"]
    for b in bearings:
        g = b.geometry
        assert (g.balls, g.contact_angle_deg) == (BALLS, 0.0)
        assert g.ball_diameter_m == pytest.approx(BALL_D_M, rel=1e-12)
        assert g.pitch_diameter_m == pytest.approx(PITCH_D_M, rel=1e-6)
    for st in scenario.stages:
        for gear in (st.pinion, st.wheel):
            assert gear.lateral == "xy" and gear.bearing.kind == "rolling-elements"


def test_the_run_is_sampled_at_the_data_rate(scenario):
    assert scenario.solver.output_rate_hz == pytest.approx(PHM_RATE_HZ, rel=1e-15)


# -- lines in orders of the input shaft, by hand -------------------------------------------------------


def test_the_bearing_lines_in_orders_of_the_input_shaft(scenario):
    r = BALL_D_M / PITCH_D_M * math.cos(0.0)
    per_shaft_rev = {
        "BPFO": BALLS / 2 * (1 - r),
        "BPFI": BALLS / 2 * (1 + r),
        "2 BSF": 2 * PITCH_D_M / (2 * BALL_D_M) * (1 - r * r),  # a ball defect strikes both races
        "FTF": (1 - r) / 2,
    }
    assert [round(per_shaft_rev[k], 4) for k in ("BPFO", "BPFI", "2 BSF", "FTF")] == [
        3.0523,
        4.9477,
        3.9839,
        0.3815,
    ]
    shaft = {  # each bearing turns with its shaft: input 1, idler 32/96, output 32/96 x 48/80
        "pinion bearing": 1.0,
        "wheel bearing": 32 / 96,
        "stage 2 pinion bearing": 32 / 96,
        "stage 2 wheel bearing": 32 / 96 * 48 / 80,
    }
    lines = _input_orders(scenario)
    for bearing, ratio in shaft.items():
        for symbol, order in per_shaft_rev.items():
            assert lines[f"{symbol} {bearing}"] == pytest.approx(order * ratio, rel=1e-9), (symbol, bearing)


def test_the_mesh_orders_are_teeth_times_shaft_orders(scenario):
    lines = _input_orders(scenario)
    assert lines["1 f_z1"] == pytest.approx(32.0, rel=1e-12)  # 960 Hz at 30 Hz
    assert lines["1 f_z2"] == pytest.approx(48 * 32 / 96, rel=1e-12)  # 16: 480 Hz at 30 Hz (idler 10 Hz)


# -- a short run at 30 Hz and high load ---------------------------------------------------------------


def _base_radius_m(teeth: int) -> float:
    return MODULE_M * teeth / 2 * math.cos(math.radians(20.0))


def test_a_short_run_carries_the_rated_torque_through_the_base_radii(run):
    steady = run.time_s >= 0.02
    output = OUTPUT_TORQUE_NM / _base_radius_m(80)
    first = OUTPUT_TORQUE_NM * (_base_radius_m(48) / _base_radius_m(80)) / _base_radius_m(96)
    assert run["stage_2_mesh_force_N"][steady].mean() == pytest.approx(output, rel=0.02)  # 838 N
    assert run["mesh_force_N"][steady].mean() == pytest.approx(first, rel=0.02)  # 419 N, 10 N m at input
    assert run["pinion_speed_rad_s"][steady].mean() / (2 * math.pi) == pytest.approx(INPUT_HZ, rel=0.002)


def test_at_rated_load_the_teeth_stay_in_contact(run):
    for kd in (run["kd"], run["stage_2_kd"]):
        assert 0.2 < kd.min() and 1.1 < kd.max() < 1.6


def _peak_hz(x: np.ndarray, fs: float, band: tuple[float, float]) -> float:
    spectrum = np.abs(np.fft.rfft((x - x.mean()) * np.hanning(x.size)))
    f = np.fft.rfftfreq(x.size, 1 / fs)
    inside = (f > band[0]) & (f < band[1])
    return float(f[inside][np.argmax(spectrum[inside])])


def test_the_mesh_lines_sit_at_teeth_times_shaft_speed(run):
    tail = run.time_s >= 0.02  # 0.1 s: 10 Hz bins
    fs = 1 / (run.time_s[1] - run.time_s[0])
    f_in = run["pinion_speed_rad_s"][tail].mean() / (2 * math.pi)
    f_idler = run["pinion_2_speed_rad_s"][tail].mean() / (2 * math.pi)
    stage_1, stage_2 = (run[f"{p}mesh_force_bandlimited_N"][tail] for p in ("", "stage_2_"))
    assert _peak_hz(stage_1, fs, (500, 1400)) == pytest.approx(32 * f_in, abs=10)  # 960 Hz
    assert _peak_hz(stage_2, fs, (200, 700)) == pytest.approx(48 * f_idler, abs=10)  # 480 Hz


def test_virtual_instruments_give_the_three_phm_channels(run):
    """Input- and output-side accelerometers (10 mV/g) at the data's rate and a 10 pulse/rev tacho on
    the input shaft; the housing modes are placeholders (the paths to the plates are not published)."""
    sides = {"input": ("pinion", "wheel"), "output": ("pinion_2", "wheel_2")}
    sensors = [
        Accelerometer(
            f"{side} accelerometer",
            [HousingMode(5000.0, 0.05, {f"{g}_bearing_force_y_N": 0.1 for g in gears})],
            sensitivity_v_per_m_s2=0.010 / 9.80665,
            location=f"{side} shaft retaining plate",
        )
        for side, gears in sides.items()
    ]
    rec = virtual_instruments(run, sensors, tacho_shaft="pinion", pulses_per_rev=10)
    assert rec.sample_rate_hz == pytest.approx(PHM_RATE_HZ, rel=1e-12)
    assert list(rec.channels) == ["input accelerometer", "output accelerometer"]
    pulses = rec.tacho.pulse_times_s
    assert rec.tacho.pulses_per_rev == 10
    assert 1 / np.diff(pulses).mean() == pytest.approx(10 * INPUT_HZ, rel=0.003)  # 300 pulses/s
