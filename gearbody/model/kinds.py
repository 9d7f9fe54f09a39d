"""Stage kinds: what a kind of gear stage declares so that the rest of gearbody treats it without asking
which kind it is. A kind is registered once under its ``type`` name (the ``type`` key of a
``design.stages`` table) with its model dataclass; each layer adds the hooks it calls (the assembly its
layout part, the engine its signals, ...), or a kind from outside gearbody registers them all at once.

The registry is the one place that maps a stage to its kind: code elsewhere calls ``stage_kind(st).hook``
instead of branching on the stage's class.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, fields, replace

__all__ = ["StageKind", "register_stage_kind", "stage_kind", "stage_kinds", "unregister_stage_kind"]


@dataclass(frozen=True)
class StageKind:
    """A kind of gear stage and its hooks (None: the kind does not provide it).

    - ``model``: the stage's dataclass (a :class:`gearbody.model.params.Node` with a ``KIND`` class
      variable equal to ``name``); it provides ``ratio``, ``input_arm_m``, ``output_arm_m``,
      ``transition_width``, ``mesh_frequency_hz(input_speed_rad_s)``, ``coordinate_count``, ``mesh_count``
      and ``input_teeth`` (the teeth that set the mesh period along the input's angle).
    - ``compound``: True (the default) when a drive with this stage is built as a compound layout, the
      motor, each stage's ``layout_part`` and the machine (:mod:`gearbody.assembly.compound`); only the
      parallel stage is False: a drive of parallel stages alone has its own layout (lateral gears, the
      two-wheel and Muller models, :mod:`gearbody.assembly.topology`).
    - ``check(k, scenario)``: refuses what a drive with this stage at index k cannot have.
    - ``resolve_geometry(stage, k)`` and ``resolve_rating(stage, k, rated_force_N)``: the stage with
      what its table states indirectly resolved (gear geometry; then what depends on its rated force).
    - ``layout_part(scenario, k, first, modal)``: the stage's part of the compound layout, starting at
      coordinate ``first``: an object with ``stage``, ``first``, ``coordinate_names``, ``ends`` (input
      coordinate, its sense, output coordinate, its sense), ``bodies()``, ``supports()``,
      ``modal_items(system, bearing_states)``, ``drive_meshes()`` and ``drive_terms()`` (the types of
      :mod:`gearbody.assembly.system`).
    - ``input_name(scenario, k)``: the coordinate name of the stage's input rotation.
    - ``metadata(scenario, k)``: the stage's entry of ``Result.meta["stages"]``.
    - ``signals(scenario, k, names, t, q, v, a)``: the stage's signals (by name) on recorded states
      (rows of q, v, a in the order of ``names``); names follow :mod:`gearbody.signals`.
    - ``jump_times(scenario, k, names, t, q, v, signals)``: the times at which the stage's mesh laws
      jump on the recorded states (for the anti-aliasing of the output).
    - ``stiffness_jumps(stage, k)``: lines naming the stage's meshes whose stiffness jumps sharply (the
      hint of a stalled run); ``zero_factor_teeth(stage, k)``: its teeth of stiffness factor 0, named
      by key (ditto); ``divergence_cause(scenario, k)``: why the stage's model may have diverged, or "".
    - ``nominal_speeds(stage, k, input_speed_rad_s)``: {rotation name: speed} of its rotations when its
      input turns at ``input_speed_rad_s`` and nothing deflects (for the rotation-direction summary).
    - ``check_result(scenario, k, result)``: raises SimulationError where the run left the stage's model
      range (a mesh deflection beyond its validity, say).
    - ``render_parts(scenario, k)``: the stage's part of the 3D picture (:mod:`gearbody.render`): an
      object with ``face_m`` (its axial room), ``ends`` (input body, its sense, output body, its sense),
      ``mesh_pair`` (the bodies of its first mesh, or None), ``fixes_sense`` and ``input_sense``,
      ``output_axis(xy)``, ``turn(sense)`` (its mirror and output sense), ``shaft_cap_m(end)`` and
      ``bodies(drive)`` (see :mod:`gearbody.render.drive`); None: ``gearbody render`` refuses the drive.
      Optionally ``render_parts.teeth(table)``: the teeth a saved stage table states (a tuple), by which
      a result of another drive is refused.
    - ``mesh_report(scenario, k, load_fraction, path)``: ``gearbody mesh``'s report of the stage, (its
      text, the plot written at ``path`` or None when ``path`` is None).
    - ``rolling_bearings(stage, k)``: the stage's bearings, a list of
      :class:`gearbody.model.components.RollingBearingSpec` (for the bearing defect frequencies).
    """

    name: str
    model: type
    compound: bool = True
    check: Callable | None = None
    resolve_geometry: Callable | None = None
    resolve_rating: Callable | None = None
    layout_part: Callable | None = None
    input_name: Callable | None = None
    metadata: Callable | None = None
    signals: Callable | None = None
    jump_times: Callable | None = None
    stiffness_jumps: Callable | None = None
    zero_factor_teeth: Callable | None = None
    divergence_cause: Callable | None = None
    check_result: Callable | None = None
    nominal_speeds: Callable | None = None
    render_parts: Callable | None = None
    mesh_report: Callable | None = None
    rolling_bearings: Callable | None = None


_KINDS: dict[str, StageKind] = {}
HOOKS = tuple(f.name for f in fields(StageKind) if f.name not in ("name", "model"))


def register_stage_kind(name: str, model: type | None = None, **hooks) -> StageKind:
    """Register a stage kind (with ``model``), or add hooks to a registered one; returns the kind."""
    unknown = set(hooks) - set(HOOKS)
    if unknown:
        raise TypeError(f"unknown stage-kind hook(s) {sorted(unknown)}; hooks: {', '.join(HOOKS)}")
    if name in _KINDS:
        kind = _KINDS[name]
        if model is not None and model is not kind.model:
            raise ValueError(f"stage kind {name!r} is registered with model {kind.model.__name__}")
        kind = replace(kind, **hooks)
    else:
        if model is None:
            raise ValueError(f"stage kind {name!r}: the first registration names its model dataclass")
        if getattr(model, "KIND", None) != name:
            raise ValueError(f"stage kind {name!r}: {model.__name__}.KIND must be {name!r}")
        kind = StageKind(name, model, **hooks)
    _KINDS[name] = kind
    return kind


def unregister_stage_kind(name: str) -> None:
    """Remove a registered stage kind (a test's own kind, say)."""
    _KINDS.pop(name, None)


def stage_kinds() -> tuple[StageKind, ...]:
    """Every registered stage kind, in registration order."""
    return tuple(_KINDS.values())


def stage_kind(stage) -> StageKind:
    """The kind of a stage (its model's ``KIND``)."""
    name = getattr(type(stage), "KIND", None)
    if name not in _KINDS:
        raise KeyError(f"{type(stage).__name__} is no registered stage kind ({', '.join(_KINDS)})")
    return _KINDS[name]
