"""Studies: many runs of one scene with some scenario keys varied, in parallel, resumable; and the
K_d-against-speed sweep (:mod:`.speed`) on the same executors.

A :class:`Study` is a scene (name or TOML path), fixed ``KEY=VALUE`` overrides and the varied keys:

- ``vary``: a grid (cartesian product) of value lists per key, each given as ``start:stop:count``
  (``numpy.linspace``, both ends included) or ``v1,v2,...`` (TOML literals);
- ``random``: Monte-Carlo keys drawn from ``uniform(a,b)``, ``normal(mu,sigma)`` or
  ``choice(v1,v2,...)``, ``samples`` draws per key, reproducible from ``study_seed`` (each key has its
  own stream, so adding a key does not change the draws of the others);
- ``seeds``: ``meta.seed`` (the random per-tooth error factors) over 1..N.

The cases are the product grid x samples x seeds, in that order (the first ``vary`` key outermost);
each has a stable id (``case-0000``, ...) and a deterministic list of overrides. Every case is
validated (its scenario loaded) before anything runs; a study of more than ``MAX_CASES`` cases
(10,000) is refused before any is made, unless ``max_cases`` (``--max-cases``) allows it.

:func:`run_study` (:mod:`.runner`) runs the cases serially in-process, on a local process pool, or on
a Dask distributed cluster (:mod:`.executors`). Exudyn systems cannot be pickled: every worker rebuilds
its model from the scene's TOML data and the case's override strings (:mod:`.tasks`). Each finished
case is written at once and atomically to ``OUT/cases/<id>/`` (:mod:`.store`: ``result.npz``,
``scenario.toml``, ``summary.json``, or ``error.json`` for a failed case); ``OUT/study.json`` holds the
spec, so rerunning the same study on the same folder resumes it. Ctrl-C raises
:class:`StudyInterrupted` (finished cases kept, the others unrecorded); a pool worker that dies fails
only its own case, and the pool is restarted. At the end ``OUT/summary.csv``
(:mod:`.table`) and ``OUT/<value>_vs_<key>.png`` are written. Spec parsing: :mod:`.parse` (``--vary``,
``--random``) and :mod:`.spec` (:class:`Study`, its cases). See docs/sweep.md.

Global sensitivity analysis (:func:`sensitivity` of a scene, :func:`analyse_model` of any model function;
Morris, Sobol) and calibration of a scene's keys to measured features (:func:`calibrate_scene` with
:class:`Parameter` and :class:`Target`) run on the same executors: docs/calibration.md. Here
``sensitivity`` is that function, which hides its module of the same name (import the module with
``importlib.import_module("gearbody.studies.sensitivity")``).

Public: the names of ``__all__``, importable from here (``from gearbody.studies import ...``).
"""

from ..plotting.campbell import plot_campbell
from ..plotting.kd_speed import plot_kd_against_speed
from .calibration import CalibrationResult, Parameter, Target
from .parse import (
    MAX_CASES,
    Axis,
    Distribution,
    RandomAxis,
    SweepSpecError,
    parse_distribution,
    parse_random,
    parse_vary,
)
from .runner import StudyInterrupted, run_study
from .scene_calibration import SceneCalibration, calibrate_scene
from .sensitivity import SensitivityResult, analyse_model, ishigami, sensitivity
from .spec import Case, Study
from .speed import SpeedSweep, kd_speed_sweep, steady_overrides
from .table import StudyResult
from .tasks import run_case

__all__ = [
    "MAX_CASES",
    "Axis",
    "Case",
    "Distribution",
    "RandomAxis",
    "SpeedSweep",
    "Study",
    "StudyInterrupted",
    "StudyResult",
    "SweepSpecError",
    "kd_speed_sweep",
    "plot_campbell",
    "plot_kd_against_speed",
    "parse_distribution",
    "parse_random",
    "parse_vary",
    "run_case",
    "run_study",
    "steady_overrides",
    "CalibrationResult",
    "Parameter",
    "SceneCalibration",
    "SensitivityResult",
    "Target",
    "analyse_model",
    "calibrate_scene",
    "ishigami",
    "sensitivity",
]
