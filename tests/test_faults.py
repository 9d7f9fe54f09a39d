"""Fault errors of the mesh law (docs/scenario.md, 'Fault errors'): run-out and local pits, by hand."""

import math

import numpy as np
import pytest

from gearbody.assembly import mesh_parameters_from_scenario
from gearbody.model import ScenarioError, load_scenario
from gearbody.physics.mesh import (
    contact_force,
    mesh_breakpoint_phases,
    mesh_error_m,
)

QUIET = ["production.error_mode={a=0.5,e_um=0.0,r=0.0}", "condition.friction_coefficient=0.0"]


def _P(*overrides):
    return mesh_parameters_from_scenario(load_scenario("one-stage", [*QUIET, *overrides]))


def test_runout_of_each_gear_by_hand():
    P = _P(
        'production.eccentricity=[{gear="pinion",amplitude_um=3.0,phase_deg=90.0},'
        '{gear="wheel",amplitude_um=20.0,phase_deg=30.0}]'
    )
    for phi in (0.0, 0.7, 5.1, 40.0):
        expected = 3e-6 * math.sin(phi + math.pi / 2) + 20e-6 * math.sin(phi * 29 / 88 + math.pi / 6)
        assert mesh_error_m(phi, P) == pytest.approx(expected, abs=1e-15)


def test_pits_act_on_their_tooth_and_window_only():
    P = _P(
        'condition.pitted_teeth=[{gear="pinion",tooth=3,depth_um=5.0,start_phase=0.2,end_phase=0.5},'
        '{gear="wheel",tooth=3,depth_um=2.0,start_phase=0.4,end_phase=1.0}]'
    )

    def E(u):  # u = mesh cycles, pinion tooth n mod 29, wheel tooth n mod 88
        return mesh_error_m(2 * math.pi * u / 29, P)

    assert E(3.1) == 0.0 and E(3.3) == pytest.approx(-5e-6) and E(3.45) == pytest.approx(-7e-6)
    assert E(3.7) == pytest.approx(-2e-6) and E(3.99) == pytest.approx(-2e-6)
    assert E(32.3) == pytest.approx(-5e-6)  # pinion tooth 3 again (32 mod 29), wheel tooth 32: no pit
    assert E(32.7) == 0.0
    assert E(91.7) == pytest.approx(-2e-6)  # wheel tooth 3 again (91 mod 88), pinion tooth 4
    # tooth change, single/double switches (h = 0.3), pit edges 0.2, 0.5, 0.4 (1.0 is the tooth change)
    np.testing.assert_allclose(mesh_breakpoint_phases(P), [0.0, 0.2, 0.3, 0.4, 0.5, 0.7])


def test_a_pit_lowers_the_force_by_k_times_depth():
    P = _P('condition.pitted_teeth=[{gear="pinion",tooth=0,depth_um=5.0,start_phase=0.2,end_phase=0.5}]')
    phi = 2 * math.pi * 0.35 / 29  # tooth 0, single contact (h = 0.3)
    F_pit = contact_force(phi, 60e-6, 0.0, P)[0]
    F_next_rev = contact_force(phi + 2 * math.pi, 60e-6, 0.0, P)[0]  # tooth 0 again: the pit recurs
    F_other = contact_force(phi + 2 * math.pi / 29, 60e-6, 0.0, P)[0]  # tooth 1
    assert F_pit == pytest.approx(F_next_rev)
    assert F_other - F_pit == pytest.approx(1.2e9 * 5e-6)


@pytest.mark.parametrize(
    "override, needle",
    [
        (
            'condition.pitted_teeth=[{gear="pinion",tooth=1,depth_um=1.0,start_phase=0.6,end_phase=0.5}]',
            "end_phase",
        ),
        (
            'condition.pitted_teeth=[{gear="wheel",tooth=88,depth_um=1.0,start_phase=0.1,end_phase=0.5}]',
            "tooth = 88",
        ),
        (
            'production.eccentricity=[{gear="wheel",amplitude_um=1.0},{gear="wheel",amplitude_um=2.0}]',
            "one entry per gear",
        ),
        ('production.eccentricity=[{gear="shaft",amplitude_um=1.0}]', "gear"),
    ],
)
def test_bad_fault_input_is_refused_by_name(override, needle):
    with pytest.raises(ScenarioError, match=needle):
        load_scenario("one-stage", [override])


def test_a_missing_tooth_next_to_a_loaded_one_is_reported_not_hung():
    """Stiffness factor 0 on one tooth: the lumped mesh has no load path for a whole mesh period. Either
    the pinion chatters across that tooth's edge and Exudyn's step control rejects steps forever (the
    watchdog reports a stall), or the pinion runs millimetres ahead through the wheel (the deflection
    check reports it); never a silent result."""
    from gearbody.engine import SimulationError, simulate

    sc = load_scenario(
        "one-stage",
        [
            'operation.initial_state="steady"',
            "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
            "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
            "operation.t_end_s=0.03",
            'condition.damaged_teeth=[{gear="pinion",tooth=5,stiffness_factor=0.0}]',
            *QUIET,
        ],
    )
    with pytest.raises(SimulationError, match=r"stalled at t = 0\.01|lumped mesh model is outside its range"):
        simulate(sc)


def test_numba_cache_is_dropped_when_any_physics_source_changes(tmp_path):
    """numba re-checks only a function's own file; a kernel calling into a changed module would keep the
    old callee. gearbody drops the package's cache files whenever any source differs."""
    from gearbody.physics._numba_cache import refresh

    (tmp_path / "a.py").write_text("x = 1\n")
    cache = tmp_path / "__pycache__"
    cache.mkdir()
    (cache / "a.f-1.py311.nbi").write_bytes(b"old")
    assert refresh(tmp_path) and not list(cache.glob("*.nbi"))  # first sight: unknown sources
    (cache / "a.f-1.py311.nbi").write_bytes(b"compiled")
    assert not refresh(tmp_path) and list(cache.glob("*.nbi"))  # unchanged: kept
    (tmp_path / "b.py").write_text("y = 2\n")  # another module changes
    assert refresh(tmp_path) and not list(cache.glob("*.nbi"))
