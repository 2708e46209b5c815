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
- quasi-static runs use mass-proportional damping, by default 60 1/s on the colon (about
  critical for its lowest bending modes of ~10 Hz) and 5 1/s on the scope (its rigid push
  through the sheath would otherwise feel a drag of alpha m v);
- no gravity, no insufflation pressure;
- a run ends (``ended_by``) when the tip crosses the plane normal to the centerline at the
  model's end depth while lying within one diameter of it along the centerline
  (``"tip_past_end"``: for RSJ 2 cm past the sigmoid's fixed end; ``"far_end"``: for RSF/THF the
  far end of the fixed exit, beyond which the tip would leave the model), when the available
  length is pushed in (``"length_used"``), or when the tip jams (``"jam"``,
  :func:`colonsim.insertion.case.outcomes.jammed`). A jam is an outcome: the summary says where and under which
  forces.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from dataclasses import asdict, dataclass

import numpy as np

from colonsim.catalog import CONTINUOUS_PUSH, colon_model
from colonsim.errors import ColonsimError
from colonsim.provenance import code_version
from colonsim.insertion.anatomy.colon_segments import check_patient_tube, colon_geometry
from colonsim.insertion.anatomy.centerline_file import load_centerline_points
from colonsim.insertion.anatomy.patient_centerline import SMOOTHING_MM, load_patient_centerline
from colonsim.insertion.engine.contact import RodShellContact
from colonsim.insertion.anatomy.manoeuvre import PushProfile, continuous_push, straighten_relax_push
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH
from colonsim.insertion.case.case_material import case_material
from colonsim.insertion.case.outcomes import JAM_PROGRESS, JAM_PUSH, characteristic_points, quasi_static_fraction
from colonsim.insertion.case.recording import InsertionRecorder
from colonsim.insertion.anatomy.scopes import colonoscope
from colonsim.insertion.engine.shell import Shell
from colonsim.insertion.engine.constraints import FixedNodes, LineConstraint, PrescribedVelocity
from colonsim.insertion.engine.solver import ExplicitSolver

COLON_DENSITY = 1040.0  # kg/m^3
# Fields added after sweep folders existed: left out of the key at their default, so the keys of
# cases that do not use them stay what they were (existing sweep folders resume).
LATER_FIELDS = ("centerline", "centerline_smoothing_mm", "material_parameters")


@dataclass
class InsertionCase:
    """Every input of one insertion (user units: mm, degrees, m/s, 1/s).

    Attributes
    ----------
    segment : str
        A colon model of :data:`colonsim.catalog.COLON_MODELS` (rsj, rsf, thf, thf-fixed, straight,
        patient).
    centerline : str or None
        A patient's centerline CSV (docs/model.md, "A patient's centerline"), for and only for
        segment ``patient``. With a ``diameter_mm`` column the file's profile runs and
        ``diameter_mm`` must state its median (to 0.1 mm).
    centerline_smoothing_mm : float
        RMS tolerance of the smoothed centerline (**assumption** 1 mm, about a CT voxel).
    scope : str
        ``utc``, ``pdc``, ``sdc`` or an outer diameter in mm.
    diameter_mm : float
        Colon inner diameter (the source: 23 or 36 for RSJ; 36 assumed elsewhere).
    angle_deg : float
        alpha of RSF or beta of THF (ignored for RSJ).
    flexure_angle_deg : float
        Turn of the splenic (RSF) or hepatic (THF) flexure (**assumption** 90).
    exit_length_mm : float
        Fixed colon after the last mobile piece (**assumption** 100; for THF the ascending colon).
    friction : float
        Coulomb coefficient mu between scope and wall.
    wall_thickness_mm : float
        Colon wall thickness (**assumption** 2 mm).
    material : str or None
        Material JSON (``colonsim calibrate`` output); None = the source's parameters.
    element_size_mm, scope_spacing_mm : float
        Wall triangle size and scope node spacing.
    push_speed : float
        Plateau push speed, m/s (the source: 0.6).
    sheath_reserve_mm : float
        Scope length that stays in the sheath at the end of the push (**assumption** 20).
    ramp_s, relax_s : float
        Speed-change ramp and the relax pause of RSF/THF, s.
    colon_damping, scope_damping : float
        Mass-proportional damping, 1/s.
    record_interval_s : float
        Simulated time between recorded samples.
    time_step_factor : float
        Safety factor on the stable time step.
    material_parameters : dict or None
        {name: Pa} replacing the parameters of ``material`` (its law stays); set by a sweep's
        ``[material]`` section (:mod:`colonsim.insertion.study.material_samples`). None = the file's.
    """

    segment: str = "rsj"
    centerline: str | None = None
    centerline_smoothing_mm: float = SMOOTHING_MM
    scope: str = "sdc"
    diameter_mm: float = 36.0
    angle_deg: float = 0.0
    flexure_angle_deg: float = 90.0
    friction: float = 0.0
    wall_thickness_mm: float = 2.0
    material: str | None = None
    element_size_mm: float = 3.0
    scope_spacing_mm: float = 5.0
    push_speed: float = 0.6
    ramp_s: float = 0.05
    relax_s: float = 0.1
    exit_length_mm: float = 100.0
    sheath_reserve_mm: float = 20.0
    colon_damping: float = 60.0
    scope_damping: float = 5.0
    record_interval_s: float = 1e-3
    time_step_factor: float = 0.9
    material_parameters: dict | None = None

    def validate(self):
        """Raise :class:`ColonsimError` naming the first bad input and its fix."""
        model = colon_model(self.segment)
        if model.reads_centerline and self.centerline is None:
            raise ColonsimError(f"segment {self.segment!r} is a patient's centerline; give the file "
                                "(--centerline FILE, or centerline = \"FILE\" in a sweep)")
        if self.centerline is not None and not model.reads_centerline:
            raise ColonsimError(f"a centerline file is given for segment {self.segment!r}, which has its own shape; "
                                "use segment 'patient' (--centerline implies it) or drop the centerline")
        checks = [
            ("diameter_mm", self.diameter_mm, 10.0, 80.0, "colon inner diameter in mm (23 or 36 in the source)"),
            ("wall_thickness_mm", self.wall_thickness_mm, 0.2, 10.0, "wall thickness in mm (2 assumed)"),
            ("element_size_mm", self.element_size_mm, 0.5, 20.0, "wall element size in mm (3 by default)"),
            ("scope_spacing_mm", self.scope_spacing_mm, 1.0, 50.0, "scope node spacing in mm (5 by default)"),
            ("push_speed", self.push_speed, 1e-3, 5.0, "push speed in m/s (0.6 in the source)"),
            ("colon_damping", self.colon_damping, 0.0, 1e4, "damping in 1/s"),
            ("scope_damping", self.scope_damping, 0.0, 1e4, "damping in 1/s"),
            ("record_interval_s", self.record_interval_s, 1e-6, 1.0, "recording interval in s"),
            ("time_step_factor", self.time_step_factor, 0.01, 1.0, "a safety factor in (0, 1]"),
            ("ramp_s", self.ramp_s, 0.0, 10.0, "ramp duration in s"),
            ("relax_s", self.relax_s, 1e-3, 10.0, "relax duration in s (0.1 by default)"),
            ("exit_length_mm", self.exit_length_mm, 0.0, 300.0, "fixed exit length in mm (100 by default)"),
            ("flexure_angle_deg", self.flexure_angle_deg, 1.0, 180.0, "flexure turn in degrees (90 by default)"),
            ("sheath_reserve_mm", self.sheath_reserve_mm, 0.0, 200.0, "scope length kept in the sheath, mm (20)"),
        ]
        for name, value, lo, hi, what in checks:
            if not (isinstance(value, (int, float)) and math.isfinite(value) and lo <= value <= hi):
                raise ColonsimError(f"{name} = {value!r} is outside [{lo:g}, {hi:g}]; give the {what}")
        if not (math.isfinite(self.friction) and 0.0 <= self.friction <= 2.0):
            raise ColonsimError(f"friction = {self.friction!r} must lie in [0, 2] (the source used 0, 0.05, 0.1)")
        if self.element_size_mm > self.diameter_mm / 3:
            raise ColonsimError(f"element size {self.element_size_mm} mm is too coarse for a {self.diameter_mm} mm colon; "
                                "use at most a third of the diameter")
        if self.material_parameters is not None:
            case_material(self.material, self.material_parameters)
        scope = colonoscope(self.scope)
        if self.centerline is None:
            scope.check_fits(self.diameter_mm * 1e-3)
            return
        centerline = self.patient_centerline()
        check_patient_tube(centerline, self.diameter_mm * 1e-3, self.wall_thickness_mm * 1e-3)
        if centerline.diameter_profile is None:
            scope.check_fits(self.diameter_mm * 1e-3)
        else:
            s, d = centerline.diameter_profile
            i = int(d.argmin())
            if scope.diameter >= d[i]:
                raise ColonsimError(f"scope {scope.name} ({scope.diameter * 1e3:.1f} mm) does not fit the narrowest "
                                    f"lumen of {self.centerline}, {d[i] * 1e3:.1f} mm at {s[i] * 100:.1f} cm (line "
                                    f"{centerline.source.lines[i]}); choose a thinner scope or check that diameter")

    def patient_centerline(self):
        """The smoothed centerline of ``centerline`` (cached per file state), or None."""
        if self.centerline is None:
            return None
        return load_patient_centerline(self.centerline, self.centerline_smoothing_mm)

    def to_dict(self) -> dict:
        return asdict(self)

    def key(self) -> str:
        """A short hash of the inputs (identifies a run in sweeps and output folders).

        A centerline enters as the digest of its content (points, labels, names, diameters), not
        its path: a moved or re-saved file keeps its runs, an edited one gets new ones."""
        inputs = self.to_dict()
        defaults = InsertionCase()
        for name in LATER_FIELDS:
            if inputs[name] == getattr(defaults, name):
                del inputs[name]
        if self.centerline is not None:
            inputs["centerline"] = "sha256:" + load_centerline_points(self.centerline).digest()
        return hashlib.sha256(json.dumps(inputs, sort_keys=True).encode()).hexdigest()[:12]


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


def build_insertion(case: InsertionCase) -> Insertion:
    """Bodies, contact, constraints and manoeuvre of ``case`` (SI inside)."""
    case.validate()
    D = case.diameter_mm * 1e-3
    geometry = colon_geometry(case.segment, D, case.angle_deg, case.element_size_mm * 1e-3,
                              case.wall_thickness_mm * 1e-3, case.exit_length_mm * 1e-3, case.flexure_angle_deg,
                              centerline=case.patient_centerline())
    material = case_material(case.material, case.material_parameters)
    shell = Shell(geometry.nodes, geometry.triangles, case.wall_thickness_mm * 1e-3, material,
                  density=COLON_DENSITY, name="colon")

    scope = colonoscope(case.scope)
    entry = np.asarray(geometry.entry_point, dtype=float)
    axis = np.asarray(geometry.entry_axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    anatomy = colon_model(case.segment)
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
                    spacing=case.scope_spacing_mm * 1e-3)
    if anatomy.manoeuvre == CONTINUOUS_PUSH:
        push = continuous_push(total_depth, case.push_speed, case.ramp_s)
    else:
        push = straighten_relax_push(geometry.straighten_depth, total_depth, case.push_speed, case.ramp_s,
                                     case.relax_s)

    # tube meshes are oriented with normals out of the lumen: the fixed wall's rest normals
    contact = RodShellContact(rod, shell, friction=case.friction,
                              held_normals=shell.node_normals(np.ascontiguousarray(shell.x0)))
    held = np.flatnonzero(geometry.fixed | geometry.end_ring)
    constraints = [FixedNodes(shell, held)]
    mobile = np.flatnonzero(geometry.mobile & ~geometry.end_ring)
    if anatomy.straightens:
        held_until = push.lateral_constraint_end
        # Lateral motion of the mobile part blocked while straightening ("birth and death"):
        # each mobile node may only move along the axis of the straight piece it belongs to.
        for direction, nodes in geometry.mobile_axes:
            constraints.append(LineConstraint(shell, point=geometry.nodes[nodes[0]], direction=direction,
                                              nodes=nodes, start=0.0, end=held_until))
    drive = PrescribedVelocity(rod, [0], lambda t: push.speed(t) * axis)
    # The sheath: every scope node behind the entry plane moves only along the entry axis.
    sheath = LineConstraint(rod, point=entry, direction=axis, extent=(-math.inf, -0.5 * scope.diameter))
    constraints += [drive, sheath]
    solver = ExplicitSolver([rod, shell], contacts=[contact], constraints=constraints,
                            damping={rod.name: case.scope_damping, "colon": case.colon_damping},
                            time_step_factor=case.time_step_factor)
    return Insertion(case, geometry, shell, rod, scope, contact, push, solver, drive, entry, axis, mobile, held,
                     total_depth, tip_end)


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


def run_insertion(case: InsertionCase, progress=None, snapshot_interval=None, chunk_s=0.01) -> InsertionResult:
    """Build and run one insertion.

    Parameters
    ----------
    case : InsertionCase
    progress : callable(tip_arc_m, tip_end_m) or None
        Called after every ``chunk_s`` of simulated time with the tip's position along the
        centerline and the position at which the run ends.
    snapshot_interval : float or None
        Simulated time between stored wall/scope positions (for VTU output), s.
    """
    t_build = time.perf_counter()
    model = build_insertion(case)
    recorder = InsertionRecorder(model, snapshot_interval)
    t0 = time.perf_counter()
    duration = model.push.duration
    last_phase = model.push.phases[-1]
    ended_by = "length_used"
    while model.solver.time < duration - 1e-9:
        step = min(chunk_s, duration - model.solver.time)
        model.solver.run(step, record_interval=case.record_interval_s, callbacks=[recorder], exact_end=False)
        if not recorder.rows or recorder.rows[-1]["time_s"] < model.solver.time:
            recorder(model.solver)  # the state at the end of every chunk is a sample
        last = recorder.rows[-1]
        if progress is not None:
            progress(last["tip_arc_m"], model.tip_end)
        if model.solver.time >= last_phase.start and tip_passed_end(last, model):
            ended_by = "tip_past_end" if model.geometry.end_depth < model.geometry.centerline_length else "far_end"
            break
        if recorder.jammed():
            ended_by = "jam"
            break
    wall = time.perf_counter() - t0
    frame = recorder.frame()
    summary = summarize(model, frame, wall, t0 - t_build)
    summary["ended_by"] = ended_by
    summary["end"] = end_state(model, frame, ended_by)
    final = {"colon_m": model.solver.state["colon"].x.copy(), "scope_m": model.solver.state[model.rod.name].x.copy()}
    return InsertionResult(case, frame, summary, recorder.snapshots, model, final)


ENDINGS = {
    "tip_past_end": "the tip passed the fixed end",
    "far_end": "the tip reached the model's far end",
    "length_used": "the scope's available length was pushed in",
    "jam": f"the tip jammed: under {JAM_PROGRESS * 1e3:g} mm of tip progress over {JAM_PUSH * 100:g} cm of push "
           "while the push force rose",
}


def end_state(model: Insertion, ts, ended_by) -> dict:
    """Where and under which forces a run ended (``ended_by`` explained, depth, tip, forces)."""
    last = ts.iloc[-1]
    reason = ENDINGS[ended_by]
    if ended_by == "length_used" and colon_model(model.case.segment).must_reach_end:
        reason += " before the tip passed the fixed end"
    return {"reason": reason, "depth_cm": float(last["depth_m"] * 100), "tip_arc_cm": float(last["tip_arc_m"] * 100),
            "push_force_N": float(last["push_force_N"]), "contact_force_N": float(last["contact_force_N"])}


def tip_passed_end(sample, model: Insertion) -> bool:
    """Has the tip crossed the end plane, near the end of the colon (not beside its entry)?"""
    near = sample["tip_arc_m"] >= model.tip_end - 1e-3 * model.case.diameter_mm
    return bool(near and sample["tip_past_end_m"] >= 0.0)


def summarize(model: Insertion, ts, wall_s, build_s) -> dict:
    """The summary of one run: deformation, points A/B/C, forces, energy check, sizes, inputs."""
    points = characteristic_points(ts["time_s"], ts["depth_m"], ts["deformation_m"])
    qs = {body: quasi_static_fraction(ts[f"kinetic_{body}_J"], ts[f"internal_{body}_J"]) for body in ("colon", "scope")}
    sliding = quasi_static_fraction(ts["kinetic_scope_sliding_J"], ts["internal_scope_J"])
    g = model.geometry
    return {
        "inputs": model.case.to_dict(),
        "key": model.case.key(),
        "code": code_version(),
        "scope": {**model.scope.describe(), "length_cm": float(model.rod.rest_length.sum() * 100)},
        "pushed_depth_cm": float(ts["depth_m"].iloc[-1] * 100),
        "tip_end_cm": float(model.tip_end * 100),
        "final_deformation_cm": float(ts["deformation_m"].iloc[-1] * 100),
        "max_deformation_cm": float(ts["deformation_m"].max() * 100),
        "points_cm": {k: (None if v is None else {"deformation_cm": v["deformation_m"] * 100,
                                                    "depth_cm": v["depth_m"] * 100, "time_s": v["time_s"]})
                      for k, v in points.items()},
        "peak_contact_force_N": float(ts["contact_force_N"].max()),
        "peak_push_force_N": float(ts["push_force_N"].max()),
        "max_wall_stretch": float(ts["max_stretch"].max()),
        "final_tip_arc_cm": float(ts["tip_arc_m"].iloc[-1] * 100),
        "quasi_static": {
            "criterion": "kinetic / internal energy < 10 % on most (> 50 %) of the samples, per body, the scope's "
                         "kinetic energy taken less that of sliding along itself at the push speed (imposed "
                         "kinematics, not inertia); the rate check (half push speed) is run separately",
            "fraction_below_10pct": {"colon": qs["colon"], "scope": sliding},
            "holds": bool(qs["colon"] > 0.5 and sliding > 0.5),
            "literal": {"fraction_below_10pct": qs, "holds": bool(all(f > 0.5 for f in qs.values())),
                        "meaning": "the scope's whole kinetic energy, imposed sliding included"},
        },
        "simulated_time_s": float(ts["time_s"].iloc[-1]),
        "steps": int(model.solver.step),
        "time_step_s": {"min": float(ts["dt_s"].min()), "max": float(ts["dt_s"].max())},
        "wall_time_s": float(wall_s),
        "build_time_s": float(build_s),
        "mesh": {**g.summary(), "scope_nodes": int(model.rod.n_nodes), "hinges": int(len(model.shell.hinges))},
        "material": {"law": model.shell.material.law, **model.shell.material.named_parameters,
                     "file": model.case.material or str(REFERENCE_MATERIAL_PATH)},
    }
