"""The signal contract's naming rule: how a run's signals and a stage's plots are named by stage.

Stages are counted in power-flow order from the motor. The first stage's signals carry no prefix
(``mesh_force_N``), the others ``stage_<n>_`` with n counted from 1 (``stage_2_mesh_force_N``); a
parallel stage's gears are ``pinion``/``wheel``, then ``pinion_<n>``/``wheel_<n>`` (their signals
``pinion_2_angle_rad``), and a stage's plot files carry the tag ``_stage_<n>``
(``kd_time_stage_2.png``). Every module that names or looks up
a stage's signal uses these functions; this module imports nothing from gearbody, so that every layer
(analysis included) may use it.
"""

from __future__ import annotations

__all__ = ["gear_names", "stage_file_tag", "stage_prefix", "stage_signal"]


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
