"""Friction opposes the sliding in every mesh and every direction of turning (docs/scenario.md, "Friction";
docs/planetary.md, "Friction"): the friction power is <= 0 at every sample in forward motoring, in
generator mode (back flanks while turning forward) and when an overrunning load turns the drive
backwards, for parallel, lateral and planetary meshes; a drive that turns backwards is reported."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from gearbody import simulate
from gearbody.analysis import rotation_directions
from gearbody.cli import main
from gearbody.model import load_scenario

MU = 0.05
CASES = {
    # forward motoring: steady rated running
    "forward": [
        'operation.initial_state="steady"',
        "operation.speed_profile={time_s=[0.0],fraction=[1.0]}",
        "operation.load_profile={time_s=[0.0],fraction=[1.0]}",
    ],
    # generator mode: the converter ramps down with no load, the machine's inertia drives the gearbox
    # (back flanks) while everything still turns forward
    "generator": [
        'operation.initial_state="steady"',
        "operation.speed_profile={time_s=[0.0,0.01,0.3],fraction=[1.0,1.0,0.2]}",
        "operation.load_profile={time_s=[0.0],fraction=[0.0]}",
    ],
    # backwards: the converter held at 0 Hz, twice the rated load from rest (the case)
    "backward": [
        'operation.initial_state="rest"',
        "operation.speed_profile={time_s=[0.0],fraction=[0.0]}",
        "operation.load_profile={time_s=[0.0],fraction=[2.0]}",
    ],
}
T_END = {"one-stage": 0.15, "lateral-8dof": 0.15, "planetary-conveyor": 0.06, "planetary": 0.03}


def run(scene: str, case: str, t_end: float | None = None):
    sc = load_scenario(
        scene,
        [*CASES[case], f"condition.friction_coefficient={MU}", f"operation.t_end_s={t_end or T_END[scene]}"],
    )
    return sc, simulate(sc)


def parallel_sliding_by_hand(sc, res, k: int) -> np.ndarray:
    """rho_1 w_p - rho_2 w_w (+ the centres' velocities along m) of stage k from its phase and speeds."""
    st = sc.stages[k]
    prefix = "" if k == 0 else f"stage_{k + 1}_"
    pname, wname = ("pinion", "wheel") if k == 0 else (f"pinion_{k + 1}", f"wheel_{k + 1}")
    r1, r2 = st.pinion.base_radius_m, st.wheel.base_radius_m
    ta = math.tan(math.radians(st.mesh.pressure_angle_deg))
    dp = res[prefix + "mesh_phase"] - st.mesh.pitch_point_phase
    pb = 2 * math.pi * r1 / st.pinion.teeth
    v = (r1 * ta + dp * pb) * res[pname + "_speed_rad_s"] - (r2 * ta - dp * pb) * res[wname + "_speed_rad_s"]
    if st.pinion.lateral != "none" or st.wheel.lateral != "none":
        lam = math.radians(st.mesh.line_of_action_deg)
        n = np.array([math.cos(lam), math.sin(lam)])
        gam = math.radians(st.mesh.centre_line_deg)
        s1 = 1 if n @ np.array([-math.sin(gam), math.cos(gam)]) > 0 else -1
        m = s1 * np.array([-n[1], n[0]])
        for name, gear, sign in ((pname, st.pinion, 1.0), (wname, st.wheel, -1.0)):
            for d, axis in enumerate("xy"):
                if d in gear.free_directions:
                    v = v + sign * m[d] * res[f"{name}_{axis}_velocity_m_s"]
    return v


def check_friction_power(sc, res, case: str) -> dict[str, float]:
    """P_f = T v <= 0 at every sample of every mesh; returns the share of samples with T != 0 per mesh."""
    active = {}
    for k, st in enumerate(sc.stages):
        prefix = "" if k == 0 else f"stage_{k + 1}_"
        if hasattr(st, "planets"):
            meshes = [
                f"{prefix}planet_{n}_{m}_mesh_" for n in range(1, st.planets + 1) for m in ("sun", "ring")
            ]
        else:
            meshes = [prefix]
            v_hand = parallel_sliding_by_hand(sc, res, k)
            np.testing.assert_allclose(res[prefix + "sliding_velocity_m_s"], v_hand, rtol=0, atol=1e-9)
        for mesh in meshes:
            T, v = res[mesh + "friction_force_N"], res[mesh + "sliding_velocity_m_s"]
            P = T * v
            assert np.all(P <= 0.0), f"{case}: {mesh or 'stage 1'} P_f > 0 at {np.mean(P > 0):.2%}"
            assert np.mean(P) < 0.0
            active[mesh] = float(np.mean(T != 0.0))
    return active


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("scene", ["one-stage", "lateral-8dof", "planetary-conveyor"])
def test_friction_power_is_never_positive(scene, case):
    sc, res = run(scene, case)
    speed = res["pinion_speed_rad_s"]
    late = res.time_s > 0.5 * res.time_s[-1]
    if case == "backward":
        assert np.all(speed[late] < -1.0)  # an overrunning load: the drive turns backwards
    else:
        assert np.all(speed > 1.0)
    if case == "generator":  # the parallel stage's back flanks carry the load
        assert np.mean(res["mesh_force_N"][late] < 0.0) > 0.9
    active = check_friction_power(sc, res, case)
    assert min(active.values()) > 0.5  # friction acts: the check is not vacuous


def test_friction_power_in_the_planetary_scene_turning_backwards():
    """The Lin & Parker stage (sun in, ring fixed) at 0 Hz under twice its load: every planet's sun and ring
    mesh dissipates at every sample (the phase-only law gave P_f > 0 at 100 % / 94-97 % of them)."""
    sc, res = run("planetary", "backward")
    assert np.all(res["sun_speed_rad_s"][res.time_s > 0.01] < 0.0)
    check_friction_power(sc, res, "backward")


def test_forward_motoring_is_the_phase_law_where_the_sliding_exceeds_v0():
    """Where |v_sl| >= v_0 in forward motoring the friction force is exactly +-mu |F| with the paper's
    reversal at the pitch point (before it +, after it -), bit for bit."""
    sc, res = run("one-stage", "forward", t_end=0.05)
    v0 = sc.condition.friction_transition_speed_m_s
    v, p = res["sliding_velocity_m_s"], res["mesh_phase"]
    fast = (np.abs(v) >= v0) & (res["mesh_force_N"] != 0.0)
    phase_law = (
        MU * np.abs(res["mesh_force_N"]) * np.where(p < sc.stages[0].mesh.pitch_point_phase, 1.0, -1.0)
    )
    assert np.mean(fast) > 0.95
    assert np.array_equal(res["friction_force_N"][fast], phase_law[fast])


def test_rotation_directions_by_hand():
    t = np.linspace(0.0, 1.0, 11)
    speeds = {"motor": np.linspace(10.0, -10.0, 11), "ring": np.zeros(11), "planet_1": -np.ones(11)}
    nominal = {"motor": 100.0, "ring": 0.0, "planet_1": -50.0}
    d = rotation_directions(t, speeds, nominal)
    assert d.driven_speed_min_rad_s == {"motor": -10.0, "planet_1": 1.0}  # the fixed ring is left out
    assert d.backward_since_s == {"motor": pytest.approx(0.6)}  # -2 rad/s < -1 % of 100 rad/s
    assert d.turned_backwards and d.first == ("motor", pytest.approx(0.6))
    calm = rotation_directions(t, {"motor": np.full(11, -0.5)}, {"motor": 100.0})  # wind-up: < 1 %
    assert not calm.turned_backwards and calm.message() == ""


def test_a_drive_that_turns_backwards_is_reported(tmp_path, capsys):
    out = tmp_path / "run"
    sets = [s for c in CASES["backward"] for s in ("--set", c)]
    code = main(["run", "one-stage", "--t-end", "0.1", "--no-plots", "--quiet", "--out", str(out), *sets])
    assert code == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("gearbody: warning: the drive turned backwards")
    summary = json.loads((out / "summary.json").read_text())
    assert summary["turned_backwards"] is True and summary["turned_backwards_at_s"] < 0.02
    assert summary["pinion_driven_speed_min_rad_s"] < -1.0
    # forward running: nothing said, every driven speed positive
    out2 = tmp_path / "fwd"
    sets = [s for c in CASES["forward"] for s in ("--set", c)]
    assert (
        main(["run", "one-stage", "--t-end", "0.05", "--no-plots", "--quiet", "--out", str(out2), *sets]) == 0
    )
    assert capsys.readouterr().err == ""
    summary = json.loads((out2 / "summary.json").read_text())
    assert summary["turned_backwards"] is False
    assert min(v for k, v in summary.items() if k.endswith("_driven_speed_min_rad_s")) > 30.0  # wheel: 35
