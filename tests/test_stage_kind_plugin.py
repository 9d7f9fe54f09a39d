"""A stage kind registered from this test module alone (a belt drive: two pulleys and an elastic belt),
without editing gearbody, runs in a drive: the scenario parses its ``type``, the one builder creates its
bodies and its force term, the Result carries its signals and metadata (issue 27, D1)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest

import gearbody
from gearbody.assembly.system import Body, SliceTerm
from gearbody.errors import InputError, ScenarioError, StageError
from gearbody.model.kinds import register_stage_kind, stage_kind, unregister_stage_kind
from gearbody.model.params import Node, param
from gearbody.signals import stage_prefix


@dataclass(frozen=True, kw_only=True)
class BeltStage(Node):
    """Two pulleys on an elastic belt: force k (r1 phi1 - r2 phi2) + c (r1 w1 - r2 w2) along the belt."""

    KIND: ClassVar[str] = "belt"
    driver_radius_m: float = param(0.05, gt=0)
    driven_radius_m: float = param(0.1, gt=0)
    driver_inertia_kg_m2: float = param(0.01, gt=0)
    driven_inertia_kg_m2: float = param(0.04, gt=0)
    belt_stiffness_N_per_m: float = param(2e6, gt=0)
    belt_damping_Ns_per_m: float = param(200.0, ge=0)
    transition_width: ClassVar[float] = 0.0
    coordinate_count: ClassVar[int] = 2
    mesh_count: ClassVar[int] = 0
    input_teeth: ClassVar[int] = 1  # no teeth: no mesh period shorter than a revolution

    @property
    def ratio(self) -> float:
        return self.driven_radius_m / self.driver_radius_m

    @property
    def input_arm_m(self) -> float:
        return self.driver_radius_m

    @property
    def output_arm_m(self) -> float:
        return self.driven_radius_m

    def mesh_frequency_hz(self, input_speed_rad_s: float) -> float:
        return 0.0


def _belt_force_N(st: BeltStage, q, v):
    r1, r2 = st.driver_radius_m, st.driven_radius_m
    return st.belt_stiffness_N_per_m * (r1 * q[0] - r2 * q[1]) + st.belt_damping_Ns_per_m * (
        r1 * v[0] - r2 * v[1]
    )


@dataclass(frozen=True)
class BeltPart:
    """The belt stage's part of the drive's layout, from coordinate ``first``."""

    stage: int
    first: int
    st: BeltStage

    @property
    def coordinate_names(self) -> list[str]:
        return [f"{stage_prefix(self.stage)}driver", f"{stage_prefix(self.stage)}driven"]

    @property
    def ends(self) -> tuple[int, int, int, int]:
        return (self.first, 1, self.first + 1, 1)

    def bodies(self) -> list[Body]:
        return [
            Body("rotation", self.st.driver_inertia_kg_m2),
            Body("rotation", self.st.driven_inertia_kg_m2),
        ]

    def supports(self) -> list:
        return []

    def modal_items(self, system, bearing_states) -> list:
        return []

    def drive_meshes(self) -> list:
        return []

    def drive_terms(self) -> list[SliceTerm]:
        st = self.st

        def factory():
            def forces(q, q_t):
                F = _belt_force_N(st, q, q_t)
                return np.array([-st.driver_radius_m * F, st.driven_radius_m * F])

            return forces

        return [SliceTerm(self.first, 2, factory)]


def _signals(scenario, k, names, t, q, v, a):
    i = names.index(f"{stage_prefix(k)}driver")
    return {f"{stage_prefix(k)}belt_force_N": _belt_force_N(scenario.stages[k], q[i : i + 2], v[i : i + 2])}


@pytest.fixture
def belt_kind():
    register_stage_kind(
        "belt",
        BeltStage,
        compound=True,
        check=lambda k, scenario: None,
        layout_part=lambda scenario, k, first, modal: BeltPart(k, first, scenario.stages[k]),
        signals=_signals,
        metadata=lambda scenario, k: {"type": "belt", "ratio": scenario.stages[k].ratio},
    )
    yield
    unregister_stage_kind("belt")


def _one_stage_and_belt(t_end_s: float = 0.3):
    """The one-stage scene with a belt stage after its gear stage (and a third shaft), from rest, as the
    nested dict a TOML file gives."""
    data = gearbody.scenario_to_dict(gearbody.load_scenario("one-stage"))
    data["design"]["stages"].append({"type": "belt", "driven_radius_m": 0.12})
    data["design"]["shafts"].append(dict(data["design"]["shafts"][-1]))
    data["operation"]["t_end_s"] = t_end_s
    return gearbody.load_scenario(data)


def test_a_kind_registered_from_outside_simulates(belt_kind):
    sc = _one_stage_and_belt()
    assert stage_kind(sc.stages[1]).name == "belt" and sc.stages[1].driven_radius_m == 0.12
    result = gearbody.simulate(sc)
    assert result.meta["stages"][1] == {"type": "belt", "ratio": pytest.approx(2.4)}
    driver, driven = result["stage_2_driver_speed_rad_s"], result["stage_2_driven_speed_rad_s"]
    late = result.time_s > 0.2  # after the run-up: the pulleys turn at the belt's ratio
    assert driver[late].mean() > 10.0
    assert driven[late].mean() == pytest.approx(driver[late].mean() / 2.4, rel=0.02)
    force = result["stage_2_belt_force_N"]  # the kind's own signal, from its own law
    assert np.all(np.isfinite(force)) and np.ptp(force) > 0
    assert result["machine_speed_rad_s"][late].mean() == pytest.approx(driven[late].mean(), rel=0.02)


def test_a_kind_without_a_steady_start_refuses_it_in_one_line(belt_kind):
    sc = _one_stage_and_belt()
    steady = sc.replace(operation=dataclasses.replace(sc.operation, initial_state="steady"))
    with pytest.raises(InputError, match=r"stage 2 \(type 'belt'\) has no steady start"):
        gearbody.simulate(steady)


def test_an_unregistered_kind_is_refused_with_the_choices():
    with pytest.raises(ScenarioError, match=r"type.*'belt'.*'parallel'.*'planetary'"):
        _one_stage_and_belt()


def test_registration_names_what_is_wrong():
    with pytest.raises(TypeError, match="unknown stage-kind hook"):
        register_stage_kind("parallel", layout=None)
    with pytest.raises(ValueError, match="KIND must be 'pulley'"):
        register_stage_kind("pulley", BeltStage)


def test_every_result_method_works_for_the_kind_or_refuses_in_one_line(belt_kind, tmp_path):
    result = gearbody.simulate(_one_stage_and_belt(0.25))
    assert result.stage_kind(1) == "belt" and result.stages[1].kind == "belt"
    assert result.teeth(0) == (result.meta["pinion_teeth"], result.meta["wheel_teeth"])
    for call, words in (
        (lambda: result.teeth(1), "stage 2 is a belt stage"),
        (lambda: result.planetary_teeth(1), "stage 2 is a belt stage"),
        (lambda: result.fold_kd(1), "stage 2 is a belt stage"),
        (lambda: result.mesh_frequency_hz(1), "stage 2 (belt) has no mesh"),
    ):
        with pytest.raises(StageError) as exc:
            call()
        assert "\n" not in str(exc.value) and words in str(exc.value), str(exc.value)
    summary = result.summary()  # the first stage's K_d keys, then every stage's own
    assert summary["kd_max"] == pytest.approx(float(np.max(result["kd"])))
    spectrum = result.spectrum()  # the gear pair's lines; the belt adds none
    assert spectrum.peaks and any("f_z1" in " ".join(p.labels) for p in spectrum.peaks if p.labels)
    assert result.fold_kd(0).mean.size == 100
    written = {p.name for p in result.plot(tmp_path)}
    assert {"kd_time.png", "kd_folded.png", "spectrum.png"} <= written
    path = result.save_npz(tmp_path / "belt.npz")
    again = gearbody.Result.load_npz(path)
    assert again.stages[1] == result.stages[1] == {"type": "belt", "ratio": pytest.approx(2.4)}


def test_no_module_outside_the_kinds_own_branches_on_a_stage_type():
    """Code that works for every stage asks the stage's kind; only a kind's own modules know its class."""
    import importlib.util
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]  # the checkout (gearbody may be installed elsewhere)
    spec = importlib.util.spec_from_file_location("code_shape", root / "benchmarks" / "code_shape.py")
    code_shape = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(code_shape)
    STAGE_KIND = code_shape.STAGE_KIND
    own = {  # the modules of the parallel and planetary kinds (each registers its hooks at its end)
        "model/scenario.py",
        "model/planetary.py",
        "reports/mesh/planetary.py",
    }
    found = [
        f"{path.relative_to(root / 'gearbody')}:{n}: {line.strip()}"
        for path in sorted((root / "gearbody").rglob("*.py"))
        if str(path.relative_to(root / "gearbody")) not in own
        for n, line in enumerate(path.read_text().splitlines(), 1)
        if STAGE_KIND.search(line) and not line.lstrip().startswith("#")
    ]
    assert found == []
