"""Transition width: the regularised mesh law (docs/scenario.md, "Transition width") by hand, and the
convergence of a simulation to the sharp law as the width goes to zero."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearbody.engine import simulate
from gearbody.model import ScenarioError, load_scenario
from gearbody.physics.mesh import (
    I_V0,
    contact_force,
    friction_force,
    mean_stiffness_N_per_m,
    mesh_error_m,
    pack_mesh_parameters,
    smooth_step,
    stiffness_at_phase,
    tooth_change_envelope,
)

Z1, Z2 = 20, 41


def _P(w: float, *, a: float = 0.5, e_m: float = 0.0, factors=None, mu: float = 0.0, pits=None):
    return pack_mesh_parameters(
        r1_m=0.05,
        r2_m=0.05 * Z2 / Z1,
        z1=Z1,
        z2=Z2,
        stiffness_single_N_per_m=1.0e9,
        stiffness_double_N_per_m=1.5e9,
        contact_ratio=1.6,
        damping_Ns_per_m=0.0,
        backlash_m=0.0,
        friction_coefficient=mu,
        pitch_point_phase=0.5,
        pressure_angle_rad=math.radians(20),
        error_a=a,
        error_depths_m=np.full(Z1, e_m),
        pinion_factors=factors,
        pinion_pits=pits,
        transition_width=w,
    )


def _angle(tooth: int, p: float) -> float:
    """Pinion angle at which pinion tooth ``tooth`` is in mesh at phase p."""
    return 2 * math.pi * (tooth + p) / Z1


def test_smooth_step_shape():
    assert smooth_step(-0.5) == 0.0 and smooth_step(0.5) == 1.0 and smooth_step(0.0) == 0.5
    x = np.linspace(-0.49, 0.49, 11)
    np.testing.assert_allclose([smooth_step(v) + smooth_step(-v) for v in x], 1.0, atol=1e-15)
    assert np.all(np.diff([smooth_step(v) for v in x]) > 0)


def test_contact_ratio_ramps():
    w = 0.02
    P, P0 = _P(w), _P(0.0)
    h = 0.3
    assert stiffness_at_phase(h, P) == pytest.approx(1.25e9, rel=1e-12)  # centre: mean of k_s and k_d
    assert stiffness_at_phase(1 - h, P) == pytest.approx(1.25e9, rel=1e-12)
    for p in (0.0, h - w / 2, h + w / 2, 0.5, 1 - h - w / 2, 1 - h + w / 2, 0.99):
        assert stiffness_at_phase(p, P) == pytest.approx(stiffness_at_phase(p, P0), rel=1e-12)
    phases = (np.arange(200_000) + 0.5) / 200_000
    assert np.mean([stiffness_at_phase(p, P) for p in phases]) == pytest.approx(
        mean_stiffness_N_per_m(P0), rel=1e-9
    )


def test_friction_envelope_passes_zero_at_the_tooth_change_and_the_sliding_sets_the_direction():
    P = _P(0.02, mu=0.1)
    assert tooth_change_envelope(0.0, P) == pytest.approx(0.0, abs=1e-15)
    assert tooth_change_envelope(1 - 1e-12, P) == pytest.approx(0.0, abs=1e-9)
    assert tooth_change_envelope(0.005, P) == pytest.approx(2 * smooth_step(0.25) - 1, rel=1e-15)
    for p in (0.01, 0.25, 0.5, 0.75, 0.99):  # 1 outside w/2 of the tooth change (the pitch point too)
        assert tooth_change_envelope(p, P) == 1.0
    assert tooth_change_envelope(0.0, _P(0.0, mu=0.1)) == 1.0  # sharp law: no envelope
    v0 = P[I_V0]
    assert friction_force(5.0, 2 * v0, P) == -5.0 and friction_force(5.0, -2 * v0, P) == 5.0
    assert friction_force(5.0, 0.0, P) == 0.0


def test_tooth_factor_blends_across_the_tooth_change():
    f = np.ones(Z1)
    f[3] = 0.5
    P = _P(0.02, factors=f)
    k_double = 1.5e9
    d = 1e-6
    F_at_change = contact_force(_angle(3, 0.0), d, 0.0, P)[0]
    assert F_at_change == pytest.approx(0.75 * k_double * d, rel=1e-9)
    assert contact_force(_angle(3, 0.01), d, 0.0, P)[0] == pytest.approx(0.5 * k_double * d, rel=1e-9)
    assert contact_force(_angle(2, 0.99), d, 0.0, P)[0] == pytest.approx(k_double * d, rel=1e-9)
    # continuous from the outgoing side: just before the change equals just after
    before = contact_force(_angle(3, 0.0) - 1e-12, d, 0.0, P)[0]
    assert before == pytest.approx(F_at_change, rel=1e-6)


def test_error_is_continuous_across_the_tooth_change_for_a_zero():
    e = 10e-6
    P0, P = _P(0.0, a=0.0, e_m=e), _P(0.02, a=0.0, e_m=e)
    x = _angle(5, 0.0)
    eps = 1e-10
    assert mesh_error_m(x - eps, P0) == pytest.approx(0.0, abs=1e-12)  # sharp: jumps from 0 to e
    assert mesh_error_m(x + eps, P0) == pytest.approx(e, rel=1e-6)
    assert mesh_error_m(x - eps, P) == pytest.approx(mesh_error_m(x + eps, P), abs=1e-12)
    assert mesh_error_m(x, P) == pytest.approx(0.5 * e, rel=1e-6)  # midway between 0 and e


def test_pit_edges_are_ramps():
    pits = np.zeros((Z1, 3))
    pits[2] = (5e-6, 0.2, 0.6)
    P = _P(0.02, pits=pits)
    assert mesh_error_m(_angle(2, 0.2), P) == pytest.approx(-2.5e-6, rel=1e-9)
    assert mesh_error_m(_angle(2, 0.4), P) == pytest.approx(-5e-6, rel=1e-9)
    assert mesh_error_m(_angle(2, 0.6), P) == pytest.approx(-2.5e-6, rel=1e-9)
    assert mesh_error_m(_angle(2, 0.1), P) == pytest.approx(0.0, abs=1e-15)


def test_limits_are_checked_with_the_parameter_named():
    with pytest.raises(ScenarioError, match="transition_width"):
        load_scenario("one-stage", ["design.mesh.transition_width=0.5"])
    with pytest.raises(ScenarioError, match="transition_width"):
        load_scenario("one-stage", ["design.mesh.contact_ratio=1.02", "design.mesh.transition_width=0.05"])
    with pytest.raises(ScenarioError, match="transition_width"):
        load_scenario(
            "one-stage",
            [
                "design.mesh.transition_width=0.05",
                'condition.pitted_teeth=[{gear="pinion", tooth=1, depth_um=3.0, start_phase=0.2, '
                "end_phase=0.22}]",
            ],
        )


STEADY = [
    'operation.initial_state="steady"',
    "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
    "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
    "production.error_mode={a=0.5,e_um=10.0,r=0.3}",
    "condition.friction_coefficient=0.05",
    "solver.anti_aliasing=false",
    "operation.t_end_s=0.03",
    "solver.relative_tolerance=1e-13",
    "solver.absolute_tolerance=1e-11",
]


@pytest.fixture(scope="module")
def runs():
    return {
        w: simulate(load_scenario("one-stage", [*STEADY, f"design.mesh.transition_width={w}"]))
        for w in (0.0, 0.0025, 0.005, 0.01, 0.02)
    }


def test_results_converge_to_the_sharp_law_as_the_width_goes_to_zero(runs):
    """RMS |F_w - F_0| / F_rated falls at least 1.5x per halving of w, to below 0.02 % at w = 0.0025.
    (The max over samples does not fall uniformly: a sample that lands inside a ramp sees part of the
    jump whatever the width; it only becomes rarer.)"""
    F_rated = runs[0.0].meta["rated_mesh_force_N"]
    err = {
        w: np.sqrt(np.mean((r.mesh_force - runs[0.0].mesh_force) ** 2)) / F_rated
        for w, r in runs.items()
        if w
    }
    print({w: f"{100 * e:.4f} %" for w, e in err.items()})
    widths = sorted(err)
    for small, large in zip(widths, widths[1:], strict=False):
        assert err[small] < err[large] / 1.5, err
    assert err[0.0025] < 2e-4, err
    # the peak force converges too
    assert runs[0.0025].kd.max() == pytest.approx(runs[0.0].kd.max(), rel=1e-3)


def test_regularisation_removes_step_rejections(runs):
    """The sharp law's jumps force rejected steps at every breakpoint; the ramps need far fewer (counts
    of the same tolerance, not timings)."""
    rejected = {w: r.meta["solver_statistics"]["rejected_steps"] for w, r in runs.items()}
    assert rejected[0.01] < 0.7 * rejected[0.0], rejected
