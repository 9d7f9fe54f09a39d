"""A scenario's ``[instruments]`` on a run: what its virtual accelerometers and tacho record
(:func:`virtual_recording`, a :class:`~gearbody.recording.Recording` that ``gearbody analyze`` reads like
a logger's), and the checks that need the drive's kinematics or a file, made before a run starts
(:func:`check_instruments`). The instruments themselves (the sensor path, noise, rate, tacho) are
:mod:`gearbody.recording.instruments` and :mod:`gearbody.recording.frf`; this module reads them off the
scenario, with the drive's kinematics (:class:`DriveKinematics`) for the tacho's shaft.

A sensor path names force signals of the run. Before the run they are checked against
:func:`force_signal_names`, the names the run will give (the signal contract of
:mod:`gearbody.signals`): the bearing forces on the housing ``<body>_bearing_force_<x|y>_N`` of every
lateral gear and of every planetary stage's sun, ring and carrier (a planet's bearing sits on the
carrier), each parallel stage's mesh force (``mesh_force_N``, ``stage_2_mesh_force_N``; with
``solver.anti_aliasing`` their band-limited companions ``..._mesh_force_bandlimited_N``) and each
planetary stage's ring sensor (``ring_sensor_N``). A stage of a kind registered by a plugin
(docs/extending.md) names signals gearbody cannot foresee: its names are checked only after the run,
when the recording is made, against the force signals the run gave.
"""

from __future__ import annotations

import math

from ..errors import GearbodyError, InputError, ScenarioError
from ..recording.container import Recording
from ..signals import gear_names, stage_prefix
from .drive import DriveKinematics

__all__ = ["check_instruments", "force_signal_names", "virtual_recording"]


def force_signal_names(scenario) -> list[str] | None:
    """The force signals a run of ``scenario`` gives that a sensor path may name (module docstring); None
    when a stage is of a kind whose signals gearbody does not know."""
    if scenario.meta.topology == "muller":
        return ["mesh_force_N"]
    band_limited = scenario.solver.anti_aliasing
    names: list[str] = []
    for k, st in enumerate(scenario.stages):
        kind = getattr(type(st), "KIND", None)
        if kind == "parallel":
            mesh = stage_prefix(k) + "mesh_force_N"
            names += [mesh, mesh[: -len("_N")] + "_bandlimited_N"] if band_limited else [mesh]
            bodies = [
                b for b, g in zip(gear_names(k), (st.pinion, st.wheel), strict=True) if g.lateral != "none"
            ]
        elif kind == "planetary":  # the members in the housing (a planet's bearing is on the carrier)
            p = stage_prefix(k)
            names.append(p + "ring_sensor_N")
            bodies = [p + m for m in ("sun", "ring", "carrier")]
        else:
            return None
        names += [f"{b}_bearing_force_{axis}_N" for b in bodies for axis in "xy"]
    return names


def check_instruments(scenario) -> dict[int, object]:
    """Before a run: ScenarioError naming the key and its value where ``scenario.instruments`` names a
    force signal the run will not give (listing those it will), a tacho shaft that is not a rotating body
    of the drive, or an FRF file that cannot be read or used at ``solver.output_rate_hz``
    (:mod:`gearbody.recording.frf`). Returns the FRFs read, by accelerometer number (from 1)."""
    from ..recording.frf import read_frf

    inst = scenario.instruments
    if inst is None:
        return {}
    valid = force_signal_names(scenario)

    def check_names(names, key: str) -> None:
        for name in names:
            if valid is not None and name not in valid:
                raise ScenarioError(
                    f"{key}{name}: not a force signal of a run of scene {scenario.name!r}; its force "
                    f"signals: {', '.join(valid)}"
                )

    from fractions import Fraction

    from ..model.budget import output_samples

    rate, out_rate = inst.sample_rate_hz or scenario.solver.output_rate_hz, scenario.solver.output_rate_hz
    acquired = math.ceil(output_samples(scenario) * Fraction(rate / out_rate).limit_denominator(1000))
    if acquired < 2:
        raise ScenarioError(
            f"instruments.sample_rate_hz = {rate:g}: {acquired} sample(s) over operation.t_end_s = "
            f"{scenario.operation.t_end_s:g}; a recording needs at least 2"
        )
    frfs: dict[int, object] = {}
    for k, acc in enumerate(inst.accelerometers, 1):
        key = f"instruments.accelerometers.{k}"
        for m, mode in enumerate(acc.modes, 1):
            check_names(mode.participation, f"{key}.modes.{m}.participation.")
        if acc.frf_file is not None:
            try:
                frf = read_frf(acc.frf_file)
                frf.kernels(scenario.solver.output_rate_hz)
            except InputError as exc:
                raise ScenarioError(f"{key}.frf_file = {acc.frf_file!r}: {exc}") from None
            check_names(frf.signals, f"{key}.frf_file = {acc.frf_file!r}: column ")
            frfs[k] = frf
    try:
        DriveKinematics.from_scenario(scenario).resolve_body(inst.tacho.shaft)
    except InputError as exc:
        raise ScenarioError(f"instruments.tacho.shaft = {inst.tacho.shaft!r}: {exc}") from None
    return frfs


def virtual_recording(result, scenario=None) -> Recording:
    """What the ``[instruments]`` of ``scenario`` (default: the scenario ``result`` carries) record of the
    run ``result``: every accelerometer a channel [m/s^2] at ``instruments.sample_rate_hz``, the tacho's
    pulse times, the scenario in ``meta["scenario"]`` (docs/recordings.md, "Virtual instruments").
    :func:`check_instruments` runs first; a force signal the run lacks is a SignalError naming those it
    has."""
    from ..model import load_scenario, scenario_to_dict
    from ..recording.instruments import Accelerometer, HousingMode, virtual_instruments

    if scenario is None:
        if not isinstance(result.meta.get("scenario"), dict):
            raise InputError("virtual_recording: the result carries no scenario; pass the scenario")
        scenario = load_scenario(result.meta["scenario"])
    inst = scenario.instruments
    if inst is None:
        raise InputError(
            f"scene {scenario.name!r} has no [instruments] table (docs/scenario.md, 'Virtual instruments')"
        )
    frfs = check_instruments(scenario)
    accelerometers = [
        Accelerometer(
            acc.name,
            tuple(HousingMode(m.frequency_hz, m.damping_ratio, m.participation) for m in acc.modes),
            noise_rms_m_s2=acc.noise_m_s2,
            sample_rate_hz=inst.sample_rate_hz,
            location=acc.location,
            direction=acc.direction,
            sensitivity_v_per_m_s2=acc.sensitivity_V_per_m_s2,
            frf=frfs.get(k),
        )
        for k, acc in enumerate(inst.accelerometers, 1)
    ]
    shaft = DriveKinematics.from_scenario(scenario).resolve_body(inst.tacho.shaft)
    seed = scenario.meta.seed if inst.seed is None else inst.seed
    try:
        rec = virtual_instruments(
            result, accelerometers, tacho_shaft=shaft, pulses_per_rev=inst.tacho.pulses_per_rev, seed=seed
        )
    except GearbodyError as exc:
        raise type(exc)(f"writing the virtual instruments after the run: {exc}") from None
    # every accelerometer is analysed, as a logger's channels are (no "vibration_channel": a run's one)
    rec.meta.update(scenario=scenario_to_dict(scenario), title=str(scenario.meta.title or scenario.name))
    return rec
