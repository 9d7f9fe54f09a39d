"""What a hostile user finds (issue "Nothing a user types crashes, hangs or leaves a folder that contradicts
itself"): each finding refused in one line before anything runs (exit 2), or handled."""

from __future__ import annotations

import pytest

from gearbody.cli import main


@pytest.mark.parametrize(
    ("scene", "sets", "key"),
    [
        (  # allocated 2.24 GiB before any check had a bound
            "planetary",
            ["design.stages.1.sun.teeth=100000001", "design.stages.1.ring.teeth=100000075"],
            "design.stages.1.sun.teeth = 100000001: must be >= 6 and <= 2000",
        ),
        ("one-stage", ["design.pinion.teeth=5000"], "design.pinion.teeth = 5000: must be >= 6 and <= 2000"),
    ],
)
def test_counts_that_size_arrays_are_bounded(tmp_path, capsys, scene, sets, key):
    args = [a for s in sets for a in ("--set", s)]
    assert main(["run", scene, "--out", str(tmp_path / "run"), *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and key in err[0]
    assert not (tmp_path / "run").exists()


# -- scenario files: only regular files, at most 1 MiB, nesting bounded -----------------------------------


def _one_line_refusal(capsys, argv: list[str], expected: str) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and expected in err[0], err
    return err[0]


def _main_reading_fifo(fifo, argv: list[str]) -> int:
    """``main(argv)`` in a thread; when it is still blocked on ``fifo`` after 20 s, a writer end opened and
    closed releases it and the test fails (on main the FIFO blocked forever)."""
    import os
    import threading

    outcome: list[int] = []
    worker = threading.Thread(target=lambda: outcome.append(main(argv)), daemon=True)
    worker.start()
    worker.join(20.0)
    if worker.is_alive():
        with open(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK), "wb"):
            pass
        worker.join(30.0)
        pytest.fail(f"gearbody {argv[0]} blocked on the FIFO {fifo}")
    return outcome[0]


def test_a_fifo_as_the_scenario_file_is_refused_not_waited_on(tmp_path, capsys):
    """On main ``gearbody run FIFO`` blocked forever in open(): nothing writes the FIFO."""
    import os

    fifo = tmp_path / "drive.toml"
    os.mkfifo(fifo)
    assert _main_reading_fifo(fifo, ["run", str(fifo), "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"{fifo}: a FIFO (named pipe), not a scenario file" in err[0]
    assert not (tmp_path / "r").exists()


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/null"])
def test_a_device_as_the_scenario_file_is_refused_before_it_is_read(tmp_path, capsys, device):
    """On main ``gearbody run /dev/zero`` read until MemoryError."""
    import os

    if not os.path.exists(device):
        pytest.skip(f"no {device} here")
    _one_line_refusal(
        capsys, ["run", device, "--out", str(tmp_path / "r")], f"{device}: a character device, not a scenario"
    )


def test_a_scenario_file_above_one_mebibyte_is_refused_naming_its_size(tmp_path, capsys):
    from gearbody.model.io import MAX_SCENARIO_BYTES

    big = tmp_path / "big.toml"
    big.write_text("# padding\n" * (MAX_SCENARIO_BYTES // 10 + 1))  # valid TOML: comments only
    size = big.stat().st_size
    assert size > MAX_SCENARIO_BYTES
    _one_line_refusal(
        capsys,
        ["run", str(big), "--out", str(tmp_path / "r")],
        f"{big}: too large for a scenario file ({size} bytes); allowed: at most 1048576 bytes",
    )


def test_a_profile_of_25000_points_is_within_the_size_limit(tmp_path):
    """The limit's reason: a measured load profile of 25,000 points still fits (docstring of the limit)."""
    import numpy as np

    from gearbody.model import load_scenario
    from gearbody.model.io import MAX_SCENARIO_BYTES
    from gearbody.model.scenes import scene_path

    rng = np.random.default_rng(0)
    times = np.concatenate([[0.0], np.sort(rng.uniform(0.001, 2.0, 24_999))])
    fractions = rng.uniform(0.0, 1.0, times.size)
    lines = scene_path("one-stage").read_text().splitlines()
    given = [k for k, line in enumerate(lines) if line.startswith("load_profile = ")]
    assert len(given) == 1
    lines[given[0]] = (
        "load_profile = { time_s = ["
        + ", ".join(repr(float(t)) for t in times)
        + "], fraction = ["
        + ", ".join(repr(float(f)) for f in fractions)
        + "] }"
    )
    path = tmp_path / "measured.toml"
    path.write_text("\n".join(lines) + "\n")
    assert path.stat().st_size <= MAX_SCENARIO_BYTES
    assert len(load_scenario(path).operation.load_profile.time_s) == 25_000


@pytest.mark.parametrize(
    ("text", "what"),
    [
        ("a = " + "[" * 600 + "]" * 600 + "\n", "an array nested 600 deep"),  # RecursionError on main
        ("x = " + "{a=" * 600 + "1" + "}" * 600 + "\n", "inline tables nested 600 deep"),
        ("[" + ".".join(["a"] * 900) + "]\n", "a 900-part table header"),  # RecursionError on main
        ("a = " + "[" * 33 + "]" * 33 + "\n", "an array nested 33 deep"),
    ],
)
def test_a_scenario_file_nested_too_deep_is_refused_in_one_line(tmp_path, capsys, text, what):
    path = tmp_path / "deep.toml"
    path.write_text(text)
    _one_line_refusal(
        capsys,
        ["run", str(path), "--out", str(tmp_path / "r")],
        f"{path}: tables and arrays nested more than 32 levels deep; allowed: at most 32",
    )


@pytest.mark.parametrize(
    "override",
    [
        "a=" + "[" * 600 + "]" * 600,  # RecursionError on main
        "a=" + "{b=" * 600 + "1" + "}" * 600,
        "condition." + ".".join(["a"] * 900) + "=1",
        "operation.speed_profile.time_s=" + "[" * 30 + "0" + "]" * 30,
    ],
)
def test_a_set_nested_too_deep_is_refused_in_one_line(tmp_path, capsys, override):
    line = _one_line_refusal(
        capsys,
        ["run", "one-stage", "--out", str(tmp_path / "r"), "--set", override],
        "nest",
    )
    assert "--set " in line and "more than 32 levels deep" in line and "allowed: at most 32" in line


def test_every_scene_nests_within_the_limit():
    from gearbody.model import load_scenario
    from gearbody.model.io import MAX_NESTING, nesting_depth, read_toml, scenario_to_dict
    from gearbody.model.scenes import list_scenes, scene_path

    for name in list_scenes():
        assert nesting_depth(read_toml(scene_path(name))) <= 7 < MAX_NESTING
        assert nesting_depth(scenario_to_dict(load_scenario(name))) <= 7


def test_studies_refuse_a_fifo_as_the_scene_too(tmp_path, capsys):
    import os

    fifo = tmp_path / "drive.toml"
    os.mkfifo(fifo)
    expected = f"{fifo}: a FIFO (named pipe), not a scenario file"
    for argv in (
        ["sweep", str(fifo), "--vary", "production.error_mode.e_um=0,5", "--out", str(tmp_path / "s")],
        ["sensitivity", str(fifo), "--key", "design.mesh.damping_Ns_per_m=3000:12000"]
        + ["--feature", "kd_max", "--out", str(tmp_path / "e")],
    ):
        assert _main_reading_fifo(fifo, argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and expected in err[0], err


# -- --scheduler: a Dask address, checked before anything runs -------------------------------------------

STUDIES = {
    "sweep": ["sweep", "one-stage", "--vary", "production.error_mode.e_um=0,5"],
    "sensitivity": ["sensitivity", "one-stage", "--key", "design.mesh.damping_Ns_per_m=3000:12000"]
    + ["--feature", "kd_max", "--samples", "2"],
    "calibrate": ["calibrate", "one-stage", "--param", "design.mesh.damping_Ns_per_m=3000:12000"]
    + ["--target", "kd_max", "1.2", "0.1"],
}


@pytest.mark.parametrize("command", list(STUDIES))
@pytest.mark.parametrize(
    ("address", "reason"),
    [
        ("not a url", "not a Dask scheduler address"),  # Dask's ValueError as a traceback on main
        ("", "not a Dask scheduler address"),
        ("http://127.0.0.1:1", "the scheme http:// is not one a study reaches a Dask scheduler by"),
        ("tcp://127.0.0.1:70000", "port 70000 does not exist"),
        ("tcp://127.0.0.1", "not a Dask scheduler address"),
    ],
)
def test_a_malformed_scheduler_is_refused_in_one_line_before_anything_runs(
    tmp_path, capsys, command, address, reason
):
    out = tmp_path / "study"
    argv = [*STUDIES[command], "--t-end", "0.003", "--scheduler", address, "--out", str(out)]
    line = _one_line_refusal(capsys, argv, f"--scheduler = {address!r}: {reason}")
    assert "allowed: SCHEME://HOST:PORT" in line and "tcp://head:8786" in line
    assert not out.exists()


@pytest.mark.parametrize(
    "address", ["tcp://head:8786", "head:8786", "tls://10.0.0.1:8786", "ws://[::1]:8786"]
)
def test_the_scheduler_addresses_dask_serves_pass_the_check(address):
    from gearbody.studies.executors import check_scheduler_address

    check_scheduler_address(address)


def test_a_scheduler_that_does_not_answer_fails_in_one_line_after_the_timeout(tmp_path, capsys, monkeypatch):
    """A well-formed address with no scheduler behind it (only 127.0.0.1 is contacted): exit 2, one line
    naming the address and the timeout."""
    pytest.importorskip("dask.distributed")
    from gearbody.studies import executors

    monkeypatch.setattr(executors, "CONNECT_TIMEOUT_S", 2.0)
    argv = [*STUDIES["sweep"], "--t-end", "0.003", "--scheduler", "tcp://127.0.0.1:1", "--out", str(tmp_path)]
    line = _one_line_refusal(capsys, argv, "--scheduler tcp://127.0.0.1:1: cannot connect: ")
    assert "after 2 s" in line


# -- run: a run too short for what it writes is refused before it runs ----------------------------------


@pytest.mark.parametrize(
    ("extra", "named"),
    [
        (["--t-end", "1e-4"], "--t-end = 0.0001: 3 output samples"),  # the spectrum plot raised on main
        (["--set", "operation.t_end_s=1e-4"], "operation.t_end_s = 0.0001: 3 output samples"),
        (["--t-end", "1e-4", "--no-plots", "--report"], "--t-end = 0.0001: 3 output samples"),
    ],
)
def test_a_run_too_short_for_its_plots_is_refused_before_it_runs(tmp_path, capsys, extra, named):
    from gearbody.plotting.run import MIN_PLOT_SAMPLES

    out = tmp_path / "run"
    line = _one_line_refusal(capsys, ["run", "one-stage", *extra, "--out", str(out)], named)
    option = named.split(" = ")[0]
    assert (
        f"need at least {MIN_PLOT_SAMPLES}; allowed: {option} >= {(MIN_PLOT_SAMPLES - 1) / 20000:g}" in line
    )
    assert "--no-plots" in line
    assert not out.exists()


def test_a_short_run_without_plots_still_writes_its_result(tmp_path):
    out = tmp_path / "run"
    assert main(["run", "one-stage", "--t-end", "1e-4", "--no-plots", "--quiet", "--out", str(out)]) == 0
    written = sorted(p.name for p in out.iterdir() if not p.name.startswith("."))
    assert written == ["result.npz", "scenario.toml", "summary.json"]


@pytest.mark.parametrize("scene", ["one-stage", "lateral-8dof-ball", "planetary-conveyor"])
def test_at_the_fewest_samples_accepted_every_plot_and_the_report_are_drawn(tmp_path, scene):
    from gearbody.plotting.run import MIN_PLOT_SAMPLES

    t_end = (MIN_PLOT_SAMPLES - 1) / 20000  # the scenes' output rate
    out = tmp_path / "run"
    argv = ["run", scene, "--t-end", repr(t_end), "--report", "--quiet", "--out", str(out)]
    assert main(argv) == 0
    assert (out / "report.html").is_file() and len(list(out.glob("*.png"))) >= 3
    shorter = ["run", scene, "--t-end", repr(t_end - 1 / 20000), "--quiet", "--out", str(tmp_path / "no")]
    assert main(shorter) == 2


# -- render --result: a result holding NaN is refused naming the signal ----------------------------------


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("short") / "run"
    assert main(["run", "one-stage", "--t-end", "0.005", "--no-plots", "--quiet", "--out", str(out)]) == 0
    return out


@pytest.mark.parametrize(
    ("spoil", "named"),
    [
        ("every", "time_s holds 101 of 101 values that are not finite"),  # an IndexError on main
        ("pinion_angle_rad", "pinion_angle_rad holds 1 of 101 values that are not finite (NaN or inf, "),
        ("wheel_angle_rad", "wheel_angle_rad holds 1 of 101 values that are not finite (NaN or inf, "),
    ],
)
def test_render_of_a_result_holding_nan_is_refused_naming_the_signal(
    short_run, tmp_path, capsys, spoil, named
):
    import numpy as np

    arrays = dict(np.load(short_run / "result.npz"))
    for name, values in arrays.items():
        if values.dtype.kind == "f" and (spoil == "every" or name == spoil):
            values = values.copy()
            if spoil == "every":
                values[:] = np.nan
            else:
                values[50] = np.nan  # one sample in the middle of the run
            arrays[name] = values
    spoiled = tmp_path / "spoiled.npz"
    np.savez(spoiled, **arrays)
    out = tmp_path / "render"
    argv = ["render", "one-stage", "--result", str(spoiled), "--frames", "2", "--quiet", "--out", str(out)]
    line = _one_line_refusal(capsys, argv, f"--result = {spoiled}: {named}")
    if spoil != "every":
        assert "the first at t = 0.0025 s" in line
    assert not list(out.glob("frame_*.png"))


# -- messages name the key the user wrote ----------------------------------------------------------------


@pytest.mark.parametrize(
    ("sets", "named"),
    [
        (  # on main: "design.stages.1: planet_angles_rad[1] = 0.523599: planets 1 and 2 overlap"
            ["design.stages.1.planet_angles_deg=[0,120,240]", "design.stages.1.planet_angles_deg.2=30"],
            "design.stages.1.planet_angles_deg.2 = 30: planets 1 and 2 overlap",
        ),
        (  # planet 1 is the reference at 0: the overlap with it is planet 3's to fix
            ["design.stages.1.planet_angles_deg=[0,120,338.1818181818182]"],
            "design.stages.1.planet_angles_deg.3 = 338.182: planets 3 and 1 overlap",
        ),
        (["design.stages.1.planets=7"], "design.stages.1.planets = 7: equally spaced planets need"),
    ],
)
def test_planet_angle_refusals_name_the_key_in_degrees_counted_from_one(tmp_path, capsys, sets, named):
    args = [a for s in sets for a in ("--set", s)]
    line = _one_line_refusal(capsys, ["run", "planetary", *args, "--out", str(tmp_path / "r")], named)
    assert "planet_angles_rad" not in line


# -- bearings in the stiff-mode check --------------------------------------------------------------------


@pytest.mark.parametrize(
    ("scene", "key", "value", "mass_key"),
    [  # on main 1e20 had not finished 0.01 s simulated after 120 s, 1e14 took 25 s
        (
            "lateral-8dof",
            "design.pinion.bearing.parameters.stiffness_x_N_per_m",
            "1e20",
            "pinion.mass_kg = 7.78",
        ),
        (
            "lateral-8dof",
            "design.pinion.bearing.parameters.stiffness_x_N_per_m",
            "1e14",
            "pinion.mass_kg = 7.78",
        ),
        (
            "lateral-6dof",
            "design.wheel.bearing.parameters.stiffness_y_N_per_m",
            "1e20",
            "wheel.mass_kg = 71.6",
        ),
        (  # a Hertzian law: its tangent stiffness where it carries the rated mesh force
            "lateral-8dof-ball",
            "design.pinion.bearing.parameters.contact_stiffness_N_per_m_n",
            "1e20",
            "pinion.mass_kg = 7.78",
        ),
    ],
)
def test_an_absurd_bearing_stiffness_is_refused_naming_it(scene, key, value, mass_key):
    from gearbody.assembly import check_resolved_modes
    from gearbody.errors import InputError
    from gearbody.model import load_scenario

    sc = load_scenario(scene, [f"{key}={value}", "operation.t_end_s=0.01"])
    with pytest.raises(InputError) as info:
        check_resolved_modes(sc)
    msg = str(info.value)
    canonical = key.replace("design.", "design.stages.1.", 1)
    assert f"design.stages.1.{mass_key} kg: against its stiffness" in msg
    assert f"mostly from {canonical}) this gives a natural frequency" in msg
    assert "lower that stiffness" in msg


def test_a_bearing_stiffness_enters_the_check_as_the_modes_see_it():
    """sqrt(K_ii / M_ii) with the bearing is the Rayleigh quotient of the linearised model: it grows with
    the bearing stiffness and stays below the highest natural frequency."""
    from gearbody.assembly import coordinate_frequencies
    from gearbody.engine.modes import scene_modes
    from gearbody.model import load_scenario

    key = "design.pinion.bearing.parameters.stiffness_x_N_per_m"
    for k in (4e8, 4e10):
        sc = load_scenario("lateral-8dof", [f"{key}={k:g}"])
        pinion_x = next(c for c in coordinate_frequencies(sc) if c.name == "pinion_x")
        assert pinion_x.stiffness == pytest.approx(k, rel=1e-9)  # no mesh stiffness along x
        assert pinion_x.frequency_hz <= scene_modes(sc).frequencies_hz.max() * (1 + 1e-9)


@pytest.mark.parametrize(
    ("key", "named"),
    [  # on main the planet bearing damping was blamed on "design.stages.1.sun_mesh / ring_mesh"
        ("design.stages.1.planet.bearing_damping_Ns_per_m", "planet.mass_kg = 0.66 kg: against its damping"),
        # on main left out: accepted and run
        ("design.stages.1.sun.bearing_damping_Ns_per_m", "sun.mass_kg = 0.4 kg: against its damping"),
        (
            "design.stages.1.carrier.bearing_damping_Ns_per_m",
            "carrier.mass_kg = 5.43 kg: against its damping",
        ),
    ],
)
def test_a_planetary_bearing_damping_is_blamed_on_its_own_key(key, named):
    from gearbody.assembly import check_resolved_modes
    from gearbody.errors import InputError
    from gearbody.model import load_scenario

    sc = load_scenario("planetary", [f"{key}=1e8"])
    with pytest.raises(InputError) as info:
        check_resolved_modes(sc)
    msg = str(info.value)
    assert f"design.stages.1.{named}" in msg and f"mostly from {key})" in msg


def test_planetary_bearing_laws_stay_below_the_modes():
    from gearbody.assembly import check_resolved_modes, coordinate_frequencies
    from gearbody.engine.modes import scene_modes
    from gearbody.model import load_scenario

    law = (
        "bearing={kind='hertzian',parameters={contact_stiffness_N_per_m_n=5e11,radial_clearance_m=1e-6,"
        "exponent=1.5,damping_Ns_per_m=200.0}}"
    )
    members = {
        "sun": "teeth=29,inertia_kg_m2=0.00061009,mass_kg=0.4",
        "planet": "teeth=37,inertia_kg_m2=0.00155335,mass_kg=0.66",
        "carrier": "inertia_kg_m2=0.0616483,mass_kg=5.43",
    }
    sc = load_scenario("planetary", [f"design.stages.1.{m}={{{v},{law}}}" for m, v in members.items()])
    check_resolved_modes(sc)
    freqs = {c.name: c for c in coordinate_frequencies(sc)}
    assert freqs["planet_1_y"].stiffness_source == "design.stages.1.planet.bearing.parameters"
    assert max(c.frequency_hz for c in freqs.values()) <= scene_modes(sc).frequencies_hz.max() * (1 + 1e-9)


# -- feature windows checked against the scenario before any run -----------------------------------------


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        (  # on main every run was simulated, then each failed with the FeatureError
            ["sensitivity", "one-stage", "--key", "design.mesh.damping_Ns_per_m=3000:12000"]
            + ["--feature", "kd_max:period=99", "--samples", "2", "--t-end", "0.005"],
            "--feature kd_max:period=99: period = 99: the record has periods 1..1 in a run of "
            "operation.t_end_s = 0.005 s (101 samples; operating periods 1..1, boundaries 0, 0.005 s)",
        ),
        (  # a window past the run
            ["sensitivity", "one-stage", "--key", "design.mesh.damping_Ns_per_m=3000:12000"]
            + ["--feature", "rms:signal=kd,from_s=1,to_s=2", "--samples", "2", "--t-end", "0.005"],
            "--feature rms:signal=kd,from_s=1,to_s=2: window {'from_s': 1.0, 'to_s': 2.0}: fewer than 2 "
            "samples in a run of operation.t_end_s = 0.005 s",
        ),
        (  # past the run of one sample row only: the varied t_end
            ["sensitivity", "one-stage", "--key", "operation.t_end_s=0.004:0.02"]
            + ["--feature", "kd_max:from_s=0.01", "--samples", "2"],
            "(sample row ",
        ),
        (
            ["calibrate", "one-stage", "--param", "design.mesh.damping_Ns_per_m=3000:12000"]
            + ["--target", "kd_max:period=4", "1.2", "0.1", "--t-end", "0.003"],
            "--target kd_max:period=4: period = 4: the record has periods 1..1 in a run of "
            "operation.t_end_s = 0.003 s (the fixed overrides)",
        ),
    ],
)
def test_a_feature_window_the_run_cannot_hold_is_refused_before_any_run(
    tmp_path, capsys, monkeypatch, argv, named
):
    import gearbody.engine

    def no_simulation(*args, **kwargs):
        raise AssertionError("a simulation ran before the feature window was checked")

    monkeypatch.setattr(gearbody.engine, "simulate", no_simulation)
    out = tmp_path / "study"
    line = _one_line_refusal(capsys, [*argv, "--workers", "1", "--out", str(out)], named)
    assert line.endswith("nothing was run")
    assert not out.exists()


def test_a_window_every_run_holds_passes_the_check():
    from gearbody.analysis.features import parse_feature
    from gearbody.model import load_scenario
    from gearbody.studies.sensitivity import check_feature_windows

    sc = load_scenario("one-stage", ["operation.t_end_s=1.3"])  # periods at 0, 0.5, 0.8, 1.2, 1.3 s
    specs = [parse_feature(f) for f in ("kd_max:period=4", "kd_max:from_s=1.0,to_s=1.3", "kd_mean")]
    check_feature_windows(sc, specs)
    with pytest.raises(Exception, match=r"period = 5: the record has periods 1\.\.4"):
        check_feature_windows(sc, [parse_feature("kd_max:period=5")])


@pytest.mark.parametrize(
    ("scene", "override", "named"),
    [  # on main: "LinearBearing.stiffness_x_N_per_m = -1.0" and "HertzianBearing.__init__() got an unexpected
        # keyword argument 'bogus'"
        (
            "lateral-8dof",
            "design.pinion.bearing.parameters.stiffness_x_N_per_m=-1",
            "design.pinion.bearing.parameters.stiffness_x_N_per_m = -1.0: must be > 0",
        ),
        (
            "lateral-8dof-ball",
            "design.pinion.bearing.parameters.exponent=3",
            "design.pinion.bearing.parameters.exponent = 3.0: must be in [1, 2]",
        ),
        (
            "lateral-8dof-ball",
            "design.pinion.bearing.parameters.bogus=3",
            "design.pinion.bearing.parameters.bogus = 3.0: not a parameter of the 'hertzian' law, which "
            "takes contact_stiffness_N_per_m_n, radial_clearance_m, exponent, damping_Ns_per_m",
        ),
        (
            "lateral-8dof-ball",
            "design.pinion.bearing.parameters={radial_clearance_m=1e-6}",
            "design.pinion.bearing.parameters.contact_stiffness_N_per_m_n: required by the 'hertzian' law",
        ),
    ],
)
def test_bearing_law_refusals_name_the_parameter_as_written(tmp_path, capsys, scene, override, named):
    line = _one_line_refusal(capsys, ["run", scene, "--set", override, "--out", str(tmp_path / "r")], named)
    assert "Bearing." not in line and "__init__" not in line


def test_a_run_refused_by_the_mode_check_leaves_no_folder(tmp_path, capsys):
    out = tmp_path / "run"
    key = "design.pinion.bearing.parameters.stiffness_x_N_per_m"
    argv = ["run", "lateral-8dof", "--set", f"{key}=1e20", "--t-end", "0.01", "--out", str(out)]
    _one_line_refusal(
        capsys, argv, "design.stages.1.pinion.mass_kg = 7.78 kg: against its stiffness (1e+20 N/m"
    )
    assert not out.exists()


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        (
            ["sweep", "one-stage", "--vary", "production.error_mode.e_um=" + "[" * 40 + "1" + "]" * 40],
            "--vary ",
        ),
        (
            ["sweep", "one-stage", "--vary", "production.error_mode.e_um=1," + "[" * 600 + "]" * 600],
            "--vary ",
        ),
        (
            ["calibrate", "one-stage", "--param", "design.mesh.damping_Ns_per_m=3000:12000"]
            + ["--target", "kd_max@c", "1.2", "0.1", "--case", "c", "a=" + "[" * 600 + "]" * 600],
            "--case c 'a=",
        ),
    ],
)
def test_study_values_nested_too_deep_are_refused_naming_the_option(tmp_path, capsys, argv, named):
    line = _one_line_refusal(capsys, [*argv, "--out", str(tmp_path / "study")], "more than 32 levels deep")
    assert named in line and "--set" not in line


def test_an_integrator_exudyn_names_but_does_not_implement_is_refused(tmp_path, capsys):
    """DVERK6 is in Exudyn's DynamicSolverType but its explicit solver raised NotImplementedFeatureError
    at the first step, which read as a numerical failure with a tolerance hint."""
    args = ["run", "one-stage", "--set", "solver.method=DVERK6", "--t-end", "0.01", "--no-plots"]
    assert main([*args, "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err
    assert "solver.method = 'DVERK6'" in err and "'RK67'" in err
    assert not (tmp_path / "r").exists()
