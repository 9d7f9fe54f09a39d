"""The signal contract: how a run's signals and a stage's plots are named by stage, and the unit a
signal's name carries.

Stages are counted in power-flow order from the motor. The first stage's signals carry no prefix
(``mesh_force_N``), the others ``stage_<n>_`` with n counted from 1 (``stage_2_mesh_force_N``); a
parallel stage's gears are ``pinion``/``wheel``, then ``pinion_<n>``/``wheel_<n>`` (their signals
``pinion_2_angle_rad``), and a stage's plot files carry the tag ``_stage_<n>``
(``kd_time_stage_2.png``). Every module that names or looks up
a stage's signal uses these functions; this module imports nothing from gearbody, so that every layer
(analysis included) may use it.

Every signal carries its unit at the end of its name (``mesh_force_N``, ``pinion_speed_rad_s``,
``pinion_x_accel_m_s2``); :func:`signal_unit` reads it, and names without one (``kd``, ``mesh_phase``,
``pinion_tooth``) are dimensionless.
"""

from __future__ import annotations

__all__ = ["SIGNAL_UNITS", "gear_names", "signal_unit", "stage_file_tag", "stage_prefix", "stage_signal"]

SIGNAL_UNITS = (
    ("_rad_s2", "rad/s^2"),
    ("_m_s2", "m/s^2"),
    ("_rad_s", "rad/s"),
    ("_m_s", "m/s"),
    ("_rad", "rad"),
    ("_Nm", "N m"),
    ("_N", "N"),
    ("_m", "m"),
    ("_hz", "Hz"),
    ("_s", "s"),
)
"""(name suffix, unit) of the signals, the longer suffixes of one unit family first."""


def stage_prefix(stage_index: int) -> str:
    """``""`` for the first stage (``stage_index`` 0, counted from 0 in power-flow order), else
    ``"stage_<stage_index + 1>_"``."""
    return "" if stage_index == 0 else f"stage_{stage_index + 1}_"


def stage_signal(name: str, stage_index: int) -> str:
    """The name of stage ``stage_index``'s (from 0) signal ``name``: ``mesh_force_N``,
    ``stage_2_mesh_force_N``."""
    return stage_prefix(stage_index) + name


def stage_file_tag(stage_index: int) -> str:
    """The tag of stage ``stage_index``'s (from 0) plot files: ``""`` for the first, else
    ``"_stage_<stage_index + 1>"`` (``kd_time_stage_2.png``)."""
    return "" if stage_index == 0 else f"_stage_{stage_index + 1}"


def gear_names(stage_index: int) -> tuple[str, str]:
    """The names of a parallel stage's gears (``stage_index`` from 0): ``("pinion", "wheel")`` for the
    first, ``("pinion_<n>", "wheel_<n>")`` with n = stage_index + 1 after."""
    return (
        ("pinion", "wheel") if stage_index == 0 else (f"pinion_{stage_index + 1}", f"wheel_{stage_index + 1}")
    )


def signal_unit(name: str) -> str:
    """The unit a signal's name carries (``mesh_force_N`` -> ``N``, ``pinion_accel_rad_s2`` ->
    ``rad/s^2``); ``""`` for a dimensionless signal (``kd``, ``mesh_phase``, ``pinion_tooth``)."""
    return next((unit for suffix, unit in SIGNAL_UNITS if name.endswith(suffix)), "")
