"""Independent reference model for the gearbody topologies ``muller``, ``two-wheel`` and ``train`` (a
chain of N >= 1 stages, section "Gear trains" of ``docs/scenario.md``; the former ``one-stage`` scene
is the train of one stage).

Written directly from ``docs/scenario.md`` (the contract) as a first-order ODE system and integrated
with :func:`scipy.integrate.solve_ivp`.  It deliberately shares no code with ``gearbody`` (and imports
nothing from it).

Input: the resolved scenario dict in the canonical shape, ``meta.topology``, ``design.motor / machine /
stages / shafts`` (each stage ``{pinion, wheel, mesh, error_mode, damaged_teeth, eccentricity,
pitted_teeth}``; muller and two-wheel: one stage, no shafts), ``condition.friction_coefficient`` (and
``friction_transition_speed_m_s``, default 0.01 m/s),
``operation``, ``solver`` (:mod:`.scenario`; the legacy shape with ``meta.scene`` is read as well).

Modules (one concern each; internal imports are relative, so the package works under any name):

* :mod:`.scenario`: reading the scenario (topology, stages, shafts, rated forces, the one-stage-shaped
  mesh view of each stage), profiles and the Kloss motor;
* :mod:`.law_terms` and :mod:`.law`: the literal transcription of the mesh law (terms; whole law);
* :mod:`.modes` and :mod:`.mesh`: the locked-mode form of the law (friction included) and one mesh's
  break points and modes;
* :mod:`.initial`: the initial states;
* :mod:`.models`: the right-hand sides (muller / two-wheel, train) as systems of the integrator;
* :mod:`.integrate`: the ONE segmented integrator (also used by the lateral model);
* :mod:`.simulate`: :func:`simulate_reference` and its outputs;
* :mod:`.lateral_scenario`, :mod:`.lateral_model`, :mod:`.lateral`: the lateral reference (re-exported
  by ``validation.reference_lateral``).

Discontinuities
---------------
The mesh stiffness, the per-tooth factors, the error branch, the friction arms (at the tooth change) and
(with backlash) the contact state all change discontinuously with the pinion angle / mesh deflection,
and friction's direction has a kink where the sliding speed crosses v_0.  Plain adaptive stepping
across such jumps is first order and slow, so the integration is done segment by segment in *locked
modes*:

* phase mode ``(n, k)``: the pinion mesh coordinate ``u = phi_p z1 / (2 pi)`` lies in
  ``[n + b_k, n + b_{k+1})`` where ``b`` are all phase break points in one mesh period (0, h, 1-h,
  error apex ``a``, table points, pair-table grid points, pit edges).  Inside such
  an interval every mesh quantity is a polynomial function of ``p = u - n`` (at most linear, except
  the "pairs" stiffness, a product of linear pieces, and the smooth steps of a transition width), plus
  the smooth run-out term, and is evaluated from that formula, so the right-hand side is smooth, also
  a little beyond the interval ends during trial steps;
* contact mode ``c`` in {+1 flank contact, 0 separated, -1 back-flank contact}; only used when the
  backlash ``l_u > 0`` (with ``l_u = 0`` the spring law ``k d`` is linear and damping is on for all
  ``d != 0``, so there is nothing to switch);
* slide mode ``g`` in {+1, 0, -1} of a mesh with friction: ``x = v_sl / v_0 >= 1``, ``|x| < 1``,
  ``x <= -1``.  Friction (docs/scenario.md "Friction") is ``T = -mu |F| e(p) sigma(x)``, ``sigma(x) =
  2 S(x/2) - 1``, with the sliding velocity ``v_sl = rho_1 phi_p' - rho_2 phi_w'`` (+ the centres'
  ``(u_p' - u_w') . m`` in lateral models; planetary meshes: docs/planetary.md) computed from the state
  at every evaluation; in mode g, sigma is the constant g or (g = 0) the quintic, so the right-hand
  side stays a polynomial in v_sl within a segment.  The pitch point is no break point: the direction
  passes through 0 there smoothly with v_sl.  After a tooth change (where the arms, and v_sl, jump)
  the slide mode is re-classified from the state (:func:`.integrate.integrate`).  Why the slide modes:
  inside a step the kink of sigma at ``|x| = 1`` cost DOP853 its order (one-stage-steady over 0.05 s,
  max |dF| against rtol 1e-11: 5.6e-5 % of F_rated without them, 4.2e-6 % with them, 3.8e-6 % with the
  phase-only direction of earlier versions).  The price: one more segment per mesh period and mesh
  (scene planetary, 0.02 s steady: 430 segments instead of 268, 1.4x the time).

``solve_ivp`` stops exactly at each mode boundary (terminal ``events``), the mode is switched and
the integration restarts from the event state.  The event functions carry a tiny hysteresis (1e-10
of a mesh period, 1e-15 m of deflection, 1e-10 of v_0) so that a state resting exactly on a boundary
(e.g. a gear at standstill at u = 0) cannot trigger an endless chain of zero-length segments.  The time
break points of the speed and load profiles are also segment boundaries.

Fault errors
------------
The run-out ``A_p sin(phi_p + theta_p) + A_w sin(2 pi u / z2 + theta_w)`` (the stage's eccentricity) and
the pits ``- depth`` (the stage's pitted_teeth, while the pitted tooth is in mesh and
``start_phase <= p < end_phase``) are added to the error E, which enters ``d = delta + E`` only (contact
events, elastic force, initial deflection), never the damping rate ``delta_dot``.  The pit edges are
phase break points, so within a locked mode the pit depth is a constant of the mode
(:class:`_ModeConsts`); the run-out is smooth in ``u`` and is evaluated as ``sin(2 pi (n + p) / z +
theta)`` by :func:`_mode_error`, the one place where a locked mode forms E (right-hand sides, contact
events, outputs, contact re-classification).  The literal helpers :func:`runout_error`,
:func:`pit_error` and :func:`total_error` transcribe the same paragraph for the self-checks and the
initial states.  Missing keys (older resolved scenarios) mean no fault.

Transition width
----------------
With ``mesh.transition_width = w > 0`` (a stage's own mesh; missing key: 0) every
jump of the law at fixed deflection is spread over ``|p - p_jump| < w/2`` with the C2 smooth step
``S`` (:func:`smooth_step`): contact-ratio stiffness ramps at h and 1 - h, the tooth factor and the
whole error blended with the outgoing pair (at phase p + 1) for p < w/2 and with the incoming pair (at
p - 1) for p > 1 - w/2 (the triangle extended by its straight lines, :func:`error_shape_ext`), smoothed
pit edges and the friction's tooth-change envelope e(p) (:func:`friction_envelope`, so that T rho stays
continuous where the arms jump); the damping uses the blended factor
("pairs": the contact weights of the outgoing and incoming pairs ramp at h and 1 - h instead of k_z, the
factor is not blended, each pair carries its own, and the damping keeps k / k_healthy).
The literal transcription is :func:`blended_law` / :func:`mesh_force_literal` /
:func:`friction_moments`.  For the segmented integration the break points become the ramp ends
``p_jump -+ w/2`` (modulo 1), plus the kinks (p = 0 where the friction arms jump, the apex a, table
and pair-table grid points); inside each interval every smooth step is then 0, 1 or its quintic, and
the locked mode carries that polynomial form (:class:`_SmoothMode`, :class:`_PairMode`), so the
right-hand side is again smooth within a segment.  With w = 0 nothing of this is used: the sharp code
path is unchanged.

The mesh force at the output times is evaluated from the (dense-output) states at those times with
the very same function (``_mesh_force``) that the right-hand side uses, in the mode that was active
when the sample time was reached.

Stiffness profiles
------------------
"contact-ratio" and "table" as in the contract; "iso-6336-b" is the "contact-ratio" law (its resolved
mesh carries stiffness_single / stiffness_double / contact_ratio) everywhere, limits included
(:func:`mesh_law`).  "potential-energy" is the "pairs" law (docs/scenario.md, "Pair stiffness table"):
the pair table ``mesh.pair_table`` (added to the resolved dict by
``validation.compare.reference_input``; :func:`pair_table`) holds the healthy pair stiffness K_m and the
damaged teeth's ratios R_m on the grid ``q_m = -h + m (1 + 2h)/(N - 1)``, and
``k = sum_{o=-1,0,1} c(p - o) K f_io g_jo R_pinion,io R_wheel,jo`` (tables at the pair's own phase
``q = p - o``, teeth ``(i + o, j + o)``), so a factor or a ratio acts on its tooth's pair over the whole
contact; the damping is ``C_z k / k_healthy``; error, friction and their blending are unchanged.  Literal
transcription: :func:`contact_weight`, :func:`pair_stiffness`, :func:`effective_stiffness`.  For the
segmented integration every grid point is a break point (``p = q_m + o`` modulo 1, ~N per period), so
each pair's tables are linear pieces in a mode (:class:`_PairMode`).  Why (measured on
one-stage-geometry, N = 81, the short validation cases steady / separation / run-up, errors against the
same model at rtol 1e-12): leaving the grid kinks inside the segments (tables interpolated in the
right-hand side) takes 1.8 / 4.4 / 6.5 s but DOP853's error estimate does not see the kinks: 3.6e-3 /
4.0e-2 / 6.7e-4 % of F_rated (RK45's does: 1e-4 / 2.4e-3 / 9e-5 % at rtol 1e-10, 9e-5 % in the separation
case only at rtol 1e-12, 7.5 s); with the break points 1e-4 / 1.2e-5 / 4.6e-4 % in 3.8 / 17 / 5.8 s.  The
price is one segment per grid interval: at the separation case's mesh frequency (2.8 kHz) 9x the time
of the same gears with the "iso-6336-b" law (5 break points), 2-4x at rated speed.

Gear trains
-----------
Each mesh is a :class:`_Mesh` built from the one-stage-shaped :func:`stage_view` of its
stage (its own pinion/wheel, stiffness profile, damping, backlash, error mode with its own random
draw, damaged teeth, run-out and pits, and the rated torque referred to its wheel), so the helpers
above serve trains unchanged.  Every mesh has its own locked mode ``(n_s, k_s, c_s)``; a segment of
the integration is locked in all of them at once and ends at the first boundary event of *any* mesh
(the events of all meshes are passed to ``solve_ivp`` together, and the sub-step scan covers all of
them).  For N = 1 the train (right-hand side, events, steady start) performs the same floating-point
operations as the former one-stage scene, so a one-stage scenario gives the same results to the last
bit in either shape.
"""

from __future__ import annotations

from .initial import initial_state
from .integrate import (
    _ETA_D,
    _ETA_U,
    _MAX_ZERO_SEGMENTS,
    _chunk,
    _contact_edges,
    _output_times,
    _scan_missed_events,
    _segment,
    _step_hint,
    _time_breaks,
    integrate,
)
from .law import (
    blended_law,
    effective_stiffness,
    friction_moments,
    mesh_force_literal,
    pair_law,
    pair_stiffness,
    total_error,
)
from .law_terms import (
    base_stiffness,
    check_transition_width,
    contact_weight,
    error_shape,
    error_shape_ext,
    friction_envelope,
    friction_sigma,
    friction_transition_speed,
    half_double,
    mesh_law,
    pair_table,
    pit_error,
    pitted_teeth,
    random_l,
    reduced_mass,
    runout_error,
    runout_terms,
    smooth_step,
    tooth_error_amplitudes,
    tooth_factors,
    transition_width,
)
from .mesh import _Mesh, _phase_breakpoints_smooth, phase_breakpoints
from .models import _SingleMesh, _Train
from .modes import (
    _mesh_force,
    _mode_error,
    _mode_friction,
    _mode_mu_envelope,
    _ModeConsts,
    _PairMode,
    _pairs_eval,
    _poly_eval,
    _PolyBuilder,
    _slide_mode,
    _slide_sigma,
    _smooth_error,
    _smooth_factor,
    _SmoothMode,
)
from .scenario import (
    TWO_PI,
    F_rated,
    design_shafts,
    design_stages,
    is_train,
    kloss_torque,
    load_scenario,
    profile_integral,
    profile_value,
    stage_F_rated,
    stage_view,
    steady_slip,
    topology,
    train_stages,
)
from .simulate import simulate_reference

__all__ = [
    "load_scenario",
    "simulate_reference",
    "F_rated",
    "profile_value",
    "profile_integral",
    "kloss_torque",
    "steady_slip",
    "random_l",
    "tooth_error_amplitudes",
    "error_shape",
    "runout_terms",
    "runout_error",
    "pitted_teeth",
    "pit_error",
    "total_error",
    "smooth_step",
    "transition_width",
    "check_transition_width",
    "error_shape_ext",
    "pair_law",
    "blended_law",
    "friction_sigma",
    "friction_envelope",
    "friction_transition_speed",
    "base_stiffness",
    "mesh_law",
    "half_double",
    "pair_table",
    "contact_weight",
    "pair_stiffness",
    "effective_stiffness",
    "tooth_factors",
    "reduced_mass",
    "mesh_force_literal",
    "friction_moments",
    "initial_state",
    "phase_breakpoints",
    "is_train",
    "train_stages",
    "stage_F_rated",
    "stage_view",
    "topology",
    "design_stages",
    "design_shafts",
]
