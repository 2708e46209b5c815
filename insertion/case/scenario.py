"""A colonoscopy insertion (docs/model.md): colon model + scope + manoeuvre -> explicit simulation.

:class:`InsertionCase` holds every input with the model's default (mm, degrees and m/s are the
user's units; SI inside). :func:`build_insertion` turns it into bodies, contact, constraints and
a push profile; :func:`run_insertion` integrates and records the outputs through
:class:`colonsim.insertion.case.recording.InsertionRecorder`.

Modelling choices (stated so they can be cited):
- the scope starts straight inside a rigid sheath on the extension of the colon entry axis, its
  tip at the entry plane; the sheath guides every scope node still behind the entry plane;
- the proximal scope node is driven along the sheath axis by the push profile; the push force is
  that constraint's reaction; at most the scope length less ``sheath_reserve_mm`` is pushed in
  (the scope's available length);
- fixed colon parts and the end rings are held (zero velocity); the mobile part is free;
- once the tip is past the start of the fixed exit, the distal resistance holds it back
  (:class:`colonsim.insertion.engine.tip_resistance.TipResistance`, ``distal_resistance_N``),
  engaged over the first :data:`DISTAL_RAMP` of the exit (:func:`resistance_share`, set after
  every chunk of push from the tip's position along the centerline), along the lumen's direction
  at the tip, regularised at :data:`DISTAL_CREEP_SHARE` of the held push's speed; in the models whose exit
  takes the whole available length, the exit is lengthened so the tip cannot reach its far end;
- once the tip is held (or, with ``held_push_lead_mm``, that far before the exit), the rest of the
  push goes on at ``held_push_share`` of the push speed, to the same depth
  (:meth:`PushProfile.slow`, the ``held push`` phase; docs/model.md, "Loading");
- with ``held_push_pace`` > 0, the held push returns to the push speed while the tip slides on
  through the exit at the push's pace, and slows again when it falls behind
  (:mod:`colonsim.insertion.case.held_push`);
- quasi-static runs use mass-proportional damping, by default 60 1/s on the colon (about
  critical for its lowest bending modes of ~10 Hz) and 5 1/s on the scope (its rigid push
  through the sheath would otherwise feel a drag of alpha m v);
- no gravity, no insufflation pressure;
- a run ends (``ended_by``) when the tip crosses the plane normal to the centerline at the
  model's end depth while lying within one diameter of it along the centerline
  (``"tip_past_end"``: for RSJ 2 cm past the sigmoid's fixed end; ``"far_end"``: for RSF/THF the
  far end of the fixed exit, beyond which the tip would leave the model), when the available
  length is pushed in (``"length_used"``), when the wall's largest stretch passes
  ``failure_stretch`` (``"wall_stretch"``), when the tip folds back on itself (``"tip_folded"``:
  its last segment more than 90 deg from the lumen's direction; a real tip is steered, so such a
  run is outside the model and ends at the fold), or when the tip jams (``"jam"``,
  :func:`colonsim.insertion.case.outcomes.jammed`; once the distal resistance has engaged, the
  tip is held back, not jammed, even where it slides back out of the exit's first millimetres).
  A jam, a fold or a torn wall is an outcome: the summary says where and under which forces.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from colonsim.catalog import CONTINUOUS_PUSH, TIP_FOLDED, colon_model
from colonsim.errors import ColonsimError
from colonsim.insertion.anatomy.centerline import TubeClash
from colonsim.insertion.anatomy.colon_segments import EXIT_LIMIT, colon_geometry
from colonsim.insertion.anatomy.manoeuvre import RELAX, PushProfile, continuous_push, straighten_relax_push
from colonsim.insertion.anatomy.scopes import colonoscope
from colonsim.insertion.case.case_material import case_material
from colonsim.insertion.case.held_push import paced_speed, tip_pace
from colonsim.insertion.case.insertion_case import InsertionCase
from colonsim.insertion.case.lumen_guard import check_scope_inside
from colonsim.insertion.case.outcomes import REST_TOLERANCE, REST_WINDOW, TURNED_BACK_DEG, rest_drift
from colonsim.insertion.case.recording import InsertionRecorder
from colonsim.insertion.case.run_summary import end_state, summarize, tip_passed_end
from colonsim.insertion.engine.constraints import FixedNodes, LineConstraint, PrescribedVelocity
from colonsim.insertion.engine.contact import RodShellContact
from colonsim.insertion.engine.global_time_step import GlobalTimeStep
from colonsim.insertion.engine.sheath_lip import SheathLip
from colonsim.insertion.engine.shell import Shell
from colonsim.insertion.engine.solver import ExplicitSolver
from colonsim.insertion.engine.tip_resistance import TipResistance

__all__ = ["COLON_DENSITY", "Insertion", "InsertionCase", "InsertionResult", "build_insertion", "insertion_geometry",
           "run_insertion"]

COLON_DENSITY = 1040.0  # kg/m^3
DISTAL_RAMP = 0.01  # m of exit over which the distal resistance engages (assumption, docs/model.md "Loading")
DISTAL_CREEP_SHARE = 0.01  # the resistance's regularisation speed, as a share of the held push's speed
EXIT_MARGIN = 0.05  # m of exit left beyond the available length (the tip may cut the bends' corners)


@dataclass
class Insertion:
    """A built insertion model, ready to run."""

    case: InsertionCase
    geometry: object
    shell: Shell
    rod: object
    scope: object
    contact: RodShellContact
    push: PushProfile
    solver: ExplicitSolver
    drive: PrescribedVelocity
    entry_point: np.ndarray
    entry_axis: np.ndarray
    mobile_nodes: np.ndarray
    fixed_nodes: np.ndarray
    total_depth: float
    tip_end: float
    resistance: TipResistance | None = None


def insertion_geometry(case: InsertionCase):
    """The colon ``case`` runs in (SI): its model's geometry, with the exit lengthened to take the
    scope's available length where the model says so (RSF, THF, fixed THF, fixed-ending patients)."""
    D = case.diameter_mm * 1e-3
    anatomy = colon_model(case.segment)

    def geometry_with_exit(exit_length, fold_after=None):
        return colon_geometry(case.segment, D, case.angle_deg, case.element_size_mm * 1e-3,
                              case.wall_thickness_mm * 1e-3, exit_length, case.flexure_angle_deg,
                              centerline=case.patient_centerline(), exit_fold_after=fold_after)

    exit_length = case.exit_length_mm * 1e-3
    geometry = geometry_with_exit(exit_length)
    if anatomy.exit_takes_length:
        before_exit = geometry.centerline_length - exit_length
        length = anatomy.scope_length_for(geometry.centerline_length, case.sheath_reserve_mm * 1e-3)
        needed = length - case.sheath_reserve_mm * 1e-3 - before_exit + EXIT_MARGIN
        if needed > EXIT_LIMIT:
            raise ColonsimError(f"the exit would need {needed * 100:.0f} cm to take the scope's available length, "
                                f"more than {EXIT_LIMIT * 100:.0f} cm; keep more in the sheath (sheath_reserve_mm)")
        if needed > exit_length:
            try:
                geometry = geometry_with_exit(needed)
            except TubeClash:  # run straight on, the exit would cross the colon: it folds out of the plane
                geometry = geometry_with_exit(needed, fold_after=exit_length)
    return geometry


def build_insertion(case: InsertionCase) -> Insertion:
    """Bodies, contact, constraints and manoeuvre of ``case`` (SI inside)."""
    case.validate()
    anatomy = colon_model(case.segment)
    geometry = insertion_geometry(case)
    material = case_material(case.material, case.material_parameters, case.stiffness_factor)
    shell = Shell(geometry.nodes, geometry.triangles, case.wall_thickness_mm * 1e-3, material,
                  density=COLON_DENSITY, name="colon")

    scope = colonoscope(case.scope)
    entry = np.asarray(geometry.entry_point, dtype=float)
    axis = np.asarray(geometry.entry_axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    length = anatomy.scope_length_for(geometry.centerline_length, case.sheath_reserve_mm * 1e-3)
    total_depth = length - case.sheath_reserve_mm * 1e-3
    tip_end = geometry.end_depth
    if anatomy.must_reach_end and total_depth <= tip_end:
        raise ColonsimError(f"a {length * 100:.0f} cm scope with {case.sheath_reserve_mm:g} mm kept in the sheath "
                            f"cannot reach {tip_end * 100:.1f} cm into the colon; shorten --exit-length")
    if geometry.straighten_depth is not None and total_depth <= geometry.straighten_depth:
        raise ColonsimError(f"a {length * 100:.0f} cm scope cannot pass the mobile part ending "
                            f"{geometry.straighten_depth * 100:.1f} cm in; reduce sheath_reserve_mm")
    rod = scope.rod(start=entry - length * axis, direction=axis, length=length,
                    spacing=case.scope_spacing_mm * 1e-3, damping_time=case.scope_axial_damping_s,
                    lateral_damping=case.scope_lateral_damping)
    stop = (case.stop_distance_mm * 1e-3, case.settle_max_s)
    if anatomy.manoeuvre == CONTINUOUS_PUSH:
        push = continuous_push(total_depth, case.push_speed, case.ramp_s, *stop)
    else:
        push = straighten_relax_push(geometry.straighten_depth, total_depth, case.push_speed, case.ramp_s,
                                     case.relax_s, *stop, straighten_speed=case.push_speed * case.straighten_speed_factor)

    # tube meshes are oriented with normals out of the lumen: the fixed wall's rest normals
    contact = RodShellContact(rod, shell, friction=case.friction,
                              held_normals=shell.node_normals(np.ascontiguousarray(shell.x0)),
                              surface=case.contact_surface, face_subdivision=case.contact_face_subdivision)
    held = np.flatnonzero(geometry.fixed | geometry.end_ring)
    constraints = [FixedNodes(shell, held)]
    mobile = np.flatnonzero(geometry.mobile & ~geometry.end_ring)
    if anatomy.straightens:
        held_until = push.lateral_constraint_end
        # Lateral motion of the mobile part blocked while straightening ("birth and death"):
        # each mobile node may only move along the axis of the straight piece it belongs to.
        for direction, nodes in geometry.mobile_axes:
            constraints.append(LineConstraint(shell, point=geometry.nodes[nodes[0]], direction=direction,
                                              nodes=nodes, start=0.0, end=held_until, release=case.relax_s))
    drive = PrescribedVelocity(rod, [0], lambda t: push.speed(t) * axis)  # push.stop() may end it early
    # The sheath: every scope node behind the entry plane moves only along the entry axis.
    sheath = LineConstraint(rod, point=entry, direction=axis, extent=(-math.inf, -0.5 * scope.diameter))
    constraints += [drive, sheath]
    # the sheath's lip supports the scope where it leaves, between nodes (a smooth exit)
    lip = SheathLip(rod, entry, axis, -0.5 * scope.diameter)
    resistance = None
    if case.distal_resistance_N > 0.0 and geometry.exit_start is not None:
        resistance = TipResistance(rod, rod.tip_node, lumen_direction(geometry, geometry.exit_start),
                                   case.distal_resistance_N,
                                   creep_speed=DISTAL_CREEP_SHARE * case.held_push_share * case.push_speed,
                                   engagement=0.0)
    solver = ExplicitSolver([rod, shell], contacts=[contact, lip], constraints=constraints,
                            damping={rod.name: case.scope_damping, "colon": case.colon_damping},
                            time_step_factor=case.time_step_factor, resistances=[resistance] if resistance else [],
                            global_estimate=GlobalTimeStep() if case.time_step_estimate == "global" else None)
    return Insertion(case, geometry, shell, rod, scope, contact, push, solver, drive, entry, axis, mobile, held,
                     total_depth, tip_end, resistance)


def resistance_share(geometry, tip_arc) -> float:
    """Share of the distal resistance engaged with the tip at ``tip_arc`` along the centerline (m):
    0 before the fixed exit, rising linearly to 1 over its first :data:`DISTAL_RAMP`."""
    return float(np.clip((tip_arc - geometry.exit_start) / DISTAL_RAMP, 0.0, 1.0))


def lumen_direction(geometry, s) -> np.ndarray:
    """Unit tangent of the centerline at arc length ``s`` (m), over the next millimetre (at the
    start of the exit: the exit's own direction)."""
    ends = np.clip([s, s + 1e-3], 0.0, geometry.centerline_length)
    if ends[1] - ends[0] < 5e-4:
        ends[0] = ends[1] - 1e-3
    p = np.asarray(geometry.centerline_points(ends))
    return (p[1] - p[0]) / np.linalg.norm(p[1] - p[0])


@dataclass
class InsertionResult:
    """Recorded time series (SI columns), the run's summary, optional snapshots and the final shape
    (``{"colon_m": (n, 3), "scope_m": (k, 3)}`` node positions at the end of the run)."""

    case: InsertionCase
    timeseries: object  # pandas.DataFrame
    summary: dict
    snapshots: list
    model: Insertion
    final_shape: dict | None = None


def begin_settling(model):
    """The push has stopped: the scope relaxes at rest with its settling lateral damping, and the
    distal colon holds the tip like static friction, a plain Coulomb resistance without creep
    (docs/model.md, "Loading"): a creeping tip would go on relaxing the scope for as long as the
    run waited, so the settled state would depend on the settle time and the push speed."""
    model.rod.lateral_damping = model.case.settle_lateral_damping
    if model.resistance is not None:
        model.resistance.creep_speed = 0.0


def bring_to_rest(model):
    """The push has come to rest: every node of the scope and the wall is stopped where it is, its
    kinetic energy removed, as dynamic relaxation does (docs/model.md, "Loading"), and the hold
    that follows finds the equilibrium at the final depth. Left moving, the scope's momentum
    carries the tip on past the state the push had reached (RSF alpha 45 at 10 N: the tip slid
    on by 0.9 cm at 0.3 m/s and 0.4 cm at 0.15 m/s), so the settled state would depend on the
    push speed."""
    for state in model.solver.state.values():
        state.v[:] = 0.0


def recent_drift(rows):
    """How far the colon deformation and the tip moved over the last
    :data:`~colonsim.insertion.case.outcomes.REST_WINDOW` of the recorded samples ``rows`` (the
    recorder's dicts), m (:func:`rest_drift`; None: the samples span less)."""
    k = len(rows) - 1
    while k > 0 and rows[k]["time_s"] > rows[-1]["time_s"] - REST_WINDOW:
        k -= 1  # back to the first sample at or before the window's start
    tail = rows[k:]
    return rest_drift([r["time_s"] for r in tail], [r["deformation_m"] for r in tail],
                      [r["tip_displacement_m"] for r in tail])


def came_to_rest(rows) -> bool:
    """Have the recorded samples ``rows`` been still over the last
    :data:`~colonsim.insertion.case.outcomes.REST_WINDOW`? (the criterion of :func:`rest_drift`)"""
    drift = recent_drift(rows)
    return drift is not None and max(drift) < REST_TOLERANCE


CHUNK_PUSH = 1e-3  # m: the end rules are checked after every millimetre of push (at most every 10 ms)
GUARD_CHUNKS = 5  # chunks between two checks that the scope is still inside the colon (lumen_guard)


def chunk_seconds(case: InsertionCase) -> float:
    """Simulated time between two checks of the end rules: :data:`CHUNK_PUSH` of push, at most 10 ms."""
    return min(0.01, CHUNK_PUSH / case.push_speed)


def run_insertion(case: InsertionCase, progress=None, snapshot_interval=None) -> InsertionResult:
    """Build and run one insertion.

    Parameters
    ----------
    case : InsertionCase
    progress : callable(time_s, tip_arc_m, tip_end_m) or None
        Called after every chunk (:data:`CHUNK_PUSH` of push) with the simulated time, the tip's
        position along the centerline and the position at which the run ends.
    snapshot_interval : float or None
        Simulated time between stored wall/scope positions (for VTU output), s.
    """
    t_build = time.perf_counter()
    model = build_insertion(case)
    recorder = InsertionRecorder(model, snapshot_interval)
    t0 = time.perf_counter()
    push = model.push
    chunk_s = chunk_seconds(case)
    ended_by = None
    settling = at_rest = False
    reached_exit = False  # the resistance has engaged: from then on the tip is held back, never jammed
    chunks = 0
    relax = next((p for p in push.phases if p.name == RELAX), None)
    relaxing = relax is not None and case.relax_max_s > 0.0  # the relax goes on until at rest
    relax_begun = False
    relax_outcome = None
    while model.solver.time < push.duration - 1e-9:
        if relaxing and model.solver.time >= relax.start - 1e-12:
            if not relax_begun:  # planned at its longest, cut once at rest
                relax_begun = True
                push.retime(RELAX, relax.start + case.relax_max_s)
            if model.solver.time >= relax.start + case.relax_s - 1e-12:  # the constraint has faded
                drift = recent_drift(recorder.rows)
                rested = drift is not None and max(drift) < REST_TOLERANCE
                if rested or model.solver.time >= relax.start + case.relax_max_s - 1e-12:
                    relaxing = False
                    end = min(model.solver.time, relax.start + case.relax_max_s)
                    relax_outcome = {"came_to_rest": rested, "held_s": end - relax.start,
                                     "deformation_drift_mm": None if drift is None else drift[0] * 1e3,
                                     "tip_drift_mm": None if drift is None else drift[1] * 1e3}
                    push.retime(RELAX, end)
        if not settling and push.settle_start is not None and model.solver.time >= push.settle_start:
            settling = True
            begin_settling(model)
        if not at_rest and push.hold_start is not None and model.solver.time >= push.hold_start - 1e-12:
            at_rest = True
            bring_to_rest(model)
        step = min(chunk_s, push.duration - model.solver.time)
        if relaxing and relax_begun:  # the relax's bound is a chunk's end
            step = min(step, max(relax.start + case.relax_max_s - model.solver.time, 1e-9))
        model.solver.run(step, record_interval=case.record_interval_s, callbacks=[recorder], exact_end=False)
        if not recorder.rows or recorder.rows[-1]["time_s"] < model.solver.time:
            recorder(model.solver)  # the state at the end of every chunk is a sample
        last = recorder.rows[-1]
        chunks += 1
        if chunks % GUARD_CHUNKS == 0:
            check_scope_inside(model, last["depth_m"])
        if progress is not None:
            progress(model.solver.time, last["tip_arc_m"], model.tip_end)
        held = False
        if model.resistance is not None:  # engaged by where the tip is, along the lumen there (an exit may bend)
            share = resistance_share(model.geometry, last["tip_arc_m"])
            held = share > 0.0
            reached_exit = reached_exit or held
            model.resistance.engage(share, lumen_direction(model.geometry, last["tip_arc_m"]) if held else None)
            # held, or within the lead before the exit (at lead 0 this is ``held``: share > 0)
            slowing = last["tip_arc_m"] > model.geometry.exit_start - case.held_push_lead_mm * 1e-3
            if slowing and not settling and ended_by is None:
                push.slow(model.solver.time, case.held_push_share)  # once, in the last push (docs/model.md, "Loading")
            if case.held_push_pace > 0.0 and push.slowed_at is not None and not settling and ended_by is None:
                pace = tip_pace(recorder.rows, resisted_from=model.geometry.exit_start + DISTAL_RAMP)
                push.change_speed(model.solver.time, paced_speed(pace, case.held_push_pace, push.last_push.speed,
                                                                 case.push_speed, case.held_push_share * case.push_speed))
        if ended_by is not None:
            if at_rest and model.solver.time >= push.hold_start + case.settle_s - 1e-12 and came_to_rest(recorder.rows):
                break
            continue
        if last["max_stretch"] > case.failure_stretch:
            ended_by = "wall_stretch"
        elif last["tip_heading_deg"] > TURNED_BACK_DEG:
            ended_by = TIP_FOLDED
        elif push.settle_start is not None and model.solver.time >= push.settle_start:
            ended_by = "length_used"
        elif model.solver.time >= push.last_push.start and tip_passed_end(last, model):
            ended_by = "tip_past_end" if model.geometry.end_depth < model.geometry.centerline_length else "far_end"
        elif not reached_exit and recorder.jammed():
            ended_by = "jam"
        if ended_by is None:
            continue
        if ended_by in ("jam", "wall_stretch", TIP_FOLDED) or push.settle_start is None:
            break  # a jam, a tear or a fold ends where it happened, under its load; a profile without a settle phase, at its rule
        push.stop(model.solver.time, case.stop_distance_mm * 1e-3, case.settle_max_s)
    ended_by = ended_by or "length_used"
    check_scope_inside(model, recorder.rows[-1]["depth_m"])
    wall = time.perf_counter() - t0
    frame = recorder.frame()
    summary = summarize(model, frame, wall, t0 - t_build)
    summary["ended_by"] = ended_by
    summary["end"] = end_state(model, frame, ended_by)
    if relax_outcome is not None:
        summary["relax"] = {"criterion": f"once the straightening constraint has faded, the colon deformation and the tip "
                                         f"each move less than {REST_TOLERANCE * 1e3:g} mm over {REST_WINDOW:g} s, "
                                         "or relax_max_s has passed", **relax_outcome}
    final = {"colon_m": model.solver.state["colon"].x.copy(), "scope_m": model.solver.state[model.rod.name].x.copy()}
    return InsertionResult(case, frame, summary, recorder.snapshots, model, final)
