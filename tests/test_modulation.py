"""Two-stage interaction (the paper's Fig. 20): the second stage's mesh vibration reaches the first
stage, at the frequencies kinematics gives it; a control run with a silent second stage shows the
lines are caused by it.

Both meshes are excited by E(0.5, 10, 0): the same error on every tooth, so that the excitation is
periodic and the band around f_z1 is not filled by the random-error shaft orders of r > 0. Friction
is off because it also excites each mesh at its own mesh frequency, so a control run could not
silence the second stage.

Not reproduced (issue 3, deliverable 8; docs/design-notes.md): the sidebands f_z1 +- f_z2 around the
first stage's mesh line. At the scene's parameters they are expected at ~0.2 N (2.4 % stiffness
modulation times the ~9 N f_z2 component of the deflection) and are measured at <= 0.13 N, no
higher than in the control run, i.e. below other lines of the spectrum.
"""

import numpy as np
import pytest

from gearbody.analysis import amplitude_spectrum, peak_near, sideband_lines
from gearbody.engine import simulate
from gearbody.model import load_scenario, scenario_to_dict

RECORD_S = 1.0  # analysed: the last 1 s (1 Hz resolution), after 0.3 s of settling


def _run(stage_2_excited: bool):
    data = scenario_to_dict(
        load_scenario(
            "two-stage",
            [
                'operation.initial_state="steady"',
                "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
                "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
                f"operation.t_end_s={RECORD_S + 0.3}",
                # steady running needs no more (benchmarks/RESULTS.md: 0.0003 % of F_rated at 1e-10)
                "solver.relative_tolerance=1e-10",
                "solver.absolute_tolerance=1e-10",
                # friction also excites each mesh at its mesh frequency (sign reversal at the pitch
                # point); without it the control run below can silence the second stage entirely
                "condition.friction_coefficient=0.0",
            ],
        )
    )
    for stage in data["design"]["stages"]:
        stage["error_mode"]["r"] = 0.0
    if not stage_2_excited:  # constant stiffness and no error: the second mesh is a plain spring
        mesh = data["design"]["stages"][1]["mesh"]
        mesh["stiffness_single_N_per_m"] = mesh["stiffness_double_N_per_m"]
        data["design"]["stages"][1]["error_mode"]["e_um"] = 0.0
    return simulate(load_scenario(data))


@pytest.fixture(scope="module")
def two_stage_run():
    return _run(stage_2_excited=True)


def _line(res, f_hz: float) -> float:
    window = res.time_s >= res.time_s[-1] - RECORD_S
    spectrum = amplitude_spectrum(res["mesh_force_N"][window], res.sample_rate_hz, window="hann")
    return peak_near(spectrum, f_hz, 2 * spectrum.resolution_hz)


def test_second_stage_mesh_lines_reach_the_first_stage_where_kinematics_puts_them(two_stage_run):
    res = two_stage_run
    window = res.time_s >= res.time_s[-1] - RECORD_S
    f_z1 = float(np.mean(res["mesh_frequency_hz"][window]))
    f_z2 = float(np.mean(res["stage_2_mesh_frequency_hz"][window]))
    # kinematics: f_z2 = z3 f_intermediate = f_z1 z3 / z2 (rigid shafts, base radii in ratio)
    assert f_z2 == pytest.approx(f_z1 * 23 / 88, rel=1e-4)
    quiet = _run(stage_2_excited=False)
    for harmonic in (1,):  # 2 f_z2 (~1 N) sits among other lines of that size; see the docstring
        line = _line(res, harmonic * f_z2)
        assert abs(line.frequency_hz - harmonic * f_z2) <= 1.0  # within the 1 Hz resolution
        control = _line(quiet, harmonic * f_z2)
        assert 20 * np.log10(line.amplitude / control.amplitude) > 20.0, (harmonic, line, control)
    assert _line(res, f_z1).amplitude > 5 * _line(res, f_z2).amplitude  # the first stage's own line leads


def test_sideband_lines_finds_an_amplitude_modulated_sine():
    """Hand case: (1 + 0.1 cos 2 pi 40 t) sin 2 pi 500 t has lines of 0.05 at 460 and 540 Hz."""
    fs, t = 10000.0, np.arange(20000) / 10000.0
    x = (1 + 0.1 * np.cos(2 * np.pi * 40 * t)) * np.sin(2 * np.pi * 500 * t)
    x += 1e-4 * np.random.default_rng(3).standard_normal(t.size)
    sp = amplitude_spectrum(x, fs, window="hann")
    lines = {
        ln.label: ln
        for ln in sideband_lines(
            sp, 500.0, 40.0, (1,), (-2, -1, 1, 2), carrier_symbol="f_c", modulation_symbol="f_m"
        )
    }
    assert lines["f_c-f_m"].found_hz == pytest.approx(460.0)
    assert lines["f_c+f_m"].amplitude == pytest.approx(0.05, rel=1e-3)
    assert lines["f_c+f_m"].prominence_db > 40
    assert lines["f_c+2f_m"].prominence_db < 10  # no second-order sideband in pure AM
