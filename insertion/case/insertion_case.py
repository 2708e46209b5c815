"""The inputs of one insertion (docs/model.md): :class:`InsertionCase`, its checks and its key.

Every input has the model's default; mm, degrees, m/s and s are the user's units (SI inside the
solver). A sweep's results table has one input column per field (:mod:`colonsim.insertion.study.sweep`).
"""

from __future__ import annotations

import hashlib
import json
import math
import copy
from dataclasses import dataclass, fields

from colonsim.catalog import COLON_MODELS, colon_model
from colonsim.input_ranges import check_input_range
from colonsim.errors import ColonsimError
from colonsim.insertion.anatomy.centerline_file import load_centerline_points
from colonsim.insertion.anatomy.colon_segments import check_patient_tube
from colonsim.insertion.anatomy.patient_centerline import SMOOTHING_MM, load_patient_centerline
from colonsim.insertion.anatomy.scopes import colonoscope
from colonsim.insertion.case.case_material import case_material
from colonsim.insertion.engine.contact_points import FACE_SUBDIVISIONS, WALL_SAMPLINGS, valid_subdivision

# cases that do not use them stay what they were (existing sweep folders resume).
LATER_FIELDS = ("centerline", "centerline_smoothing_mm", "material_parameters", "failure_stretch")
# how the stable time step is estimated (docs/notes/2026-11-model-studies.md, "The global time-step estimate")
TIME_STEP_ESTIMATES = ("bounds", "global")
# fields left out of the key at the value that gives the runs of before they existed
# (a default changed to another value then gives new keys: no run of before is taken for one of it)
ABSENT_AT = {"distal_resistance_N": 0.0, "held_push_share": 1.0, "held_push_lead_mm": 0.0, "held_push_pace": 0.0,
             "relax_max_s": 0.0, "straighten_speed_factor": 1.0,
             "time_step_estimate": "bounds", "contact_surface": "nodes", "stiffness_factor": 1.0}


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
        For the models whose exit takes the whole available length (RSF, THF, fixed THF:
        ``exit_takes_length`` in the catalog) it is a minimum: the exit is lengthened so the tip
        never reaches its far end.
    distal_resistance_N : float
        The force the colon beyond the model opposes to the tip's advance once the tip is in the
        fixed exit, N (**assumption** 5, the light level of 0 / 5 / 10 / 20; 0: none; docs/model.md,
        "Loading").
    failure_stretch : float
        The run ends when the wall's largest stretch passes it (``ended_by = "wall_stretch"``;
        **assumption** 1.6, near the tissue's tearing).
    friction : float
        Coulomb coefficient mu between scope and wall.
    wall_thickness_mm : float
        Colon wall thickness (**assumption** 2 mm).
    material : str or None
        Material JSON (``colonsim calibrate`` output); None = the source's parameters.
    element_size_mm, scope_spacing_mm : float
        Wall triangle size and scope node spacing.
    push_speed : float
        Plateau push speed, m/s (0.15: a quarter of the source's 0.6; the loops behind a held
        tip that failed the rate check at 0.3 agree between 0.15 and 0.075; docs/notes/2026-11-model-studies.md, "The
        default push speed halved").
    held_push_share : float
        Once the distal resistance holds the tip, the push goes on at this share of
        ``push_speed`` (0.5; 1: no change; docs/model.md, "Loading"): a loop forming behind a held
        tip needs a slower push to stay quasi-static than the rest of the insertion.
    held_push_lead_mm : float
        The held push begins when the tip is this far (along the centerline, mm) before the fixed
        exit, so the tip meets the resistance already slowed (50; 0: when the resistance engages;
        docs/notes/2026-11-model-studies.md, "The push speed at which the tip meets the resistance" and "The defaults of
        2026-11-28").
    held_push_pace : float
        The loading-following held push (0: off, the default; docs/model.md, "Distal resistance"):
        once the tip is wholly in the resisted exit, the held push returns to ``push_speed`` while
        the tip keeps pace with the push (over the last centimetre of push it advanced along the
        lumen by at least this share of the push, e.g. 0.9: it slides through against the
        resistance and nothing behind it changes) and slows to ``held_push_share`` again when its
        pace falls :data:`~colonsim.insertion.case.held_push.PACE_HYSTERESIS` below.
    sheath_reserve_mm : float
        Scope length that stays in the sheath at the end of the push (**assumption** 20).
    straighten_speed_factor : float
        RSF/THF: the straightening push (the mobile part held to its axis) at this multiple of
        ``push_speed`` (1: the same speed, the default; docs/model.md, "Loading"). The system comes
        to rest after it (``relax_max_s``), so the final push starts from the same equilibrium; 2
        moves no output of the rate check by more than 0.4 % (9-15 % fewer steps).
    ramp_s, relax_s : float
        Speed-change ramp and the relax pause of RSF/THF, s (the straightening constraint fades
        over ``relax_s``).
    relax_max_s : float
        RSF/THF: with a value > 0 the relax goes on after ``relax_s`` until the released system
        has come to rest (the criterion of the closing hold), at most ``relax_max_s`` in all; the
        final push then starts from an equilibrium (5; docs/model.md, "Loading"). 0: the relax
        lasts ``relax_s`` (the runs of before 2026-11-28).
    stop_distance_mm, settle_s, settle_max_s : float
        The push ends at rest: it slows to a stop over ``stop_distance_mm`` of push (default 0:
        at once), every node is then stopped where it is (its kinetic energy removed) and the scope
        is held still for at least ``settle_s`` (0.5) and until it has come to rest (the criterion of
        :func:`colonsim.insertion.case.outcomes.rest_drift`), at most ``settle_max_s``; the final
        values are read then, and the summary says whether it came to rest (docs/model.md, "Loading").
    settle_lateral_damping : float
        Lateral damping of the scope while it settles, 1/s (20: near critical for the slowest
        bending modes of a loop, so it comes to rest in tenths of a second).
    colon_damping, scope_damping : float
        Mass-proportional damping, 1/s (the scope's drags its push: 0 by default).
    scope_lateral_damping : float
        Mass-proportional damping of the scope's velocity across its axis, 1/s (sliding along
        itself is not damped).
    scope_axial_damping_s : float
        Kelvin-Voigt damping time of the scope's axial springs, s (a dashpot tau EA / L0 on each;
        it damps the axial waves that make the push force ring and does not drag a sliding scope).
    record_interval_s : float
        Simulated time between recorded samples.
    time_step_factor : float
        Safety factor on the stable time step.
    contact_surface : str
        Where the contact samples the wall: "nodes" (its nodes) or "faces" (points spread over its
        triangles, ``contact_face_subdivision`` squared per triangle; docs/model.md, "Contact").
    contact_face_subdivision : int
        With "faces": L, the L^2 points per triangle (spaced about a 1 / L of the element size).
    time_step_estimate : str
        "global" (the default: the coupled system's largest frequency by power iteration, never a
        shorter step than the bounds') or "bounds" (element and Gershgorin bounds; the default of
        runs made before 2026-12-07, whose keys it keeps; docs/quasi_static.md).
    material_parameters : dict or None
        {name: Pa} replacing the parameters of ``material`` (its law stays); set by a sweep's
        ``[material]`` section (:mod:`colonsim.insertion.study.material_samples`). None = the file's.
    stiffness_factor : float
        Every parameter in Pa of the wall law (the file's or the drawn ones) times this factor: the
        wall's stress at every stretch scaled by it (1: the material as given; the patient-space
        sweeps vary it, :mod:`colonsim.insertion.study.tissue_stiffness`).
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
    push_speed: float = 0.15
    held_push_share: float = 0.5
    held_push_lead_mm: float = 50.0
    held_push_pace: float = 0.0
    straighten_speed_factor: float = 1.0
    ramp_s: float = 0.4
    relax_s: float = 0.1
    relax_max_s: float = 5.0
    stop_distance_mm: float = 0.0
    settle_s: float = 0.5
    settle_max_s: float = 1.0
    settle_lateral_damping: float = 20.0
    exit_length_mm: float = 100.0
    distal_resistance_N: float = 5.0
    failure_stretch: float = 1.6
    sheath_reserve_mm: float = 20.0
    colon_damping: float = 120.0
    scope_damping: float = 0.0
    scope_lateral_damping: float = 200.0
    scope_axial_damping_s: float = 3e-3
    record_interval_s: float = 1e-3
    time_step_factor: float = 0.9
    material_parameters: dict | None = None
    stiffness_factor: float = 1.0
    time_step_estimate: str = "global"
    contact_surface: str = "nodes"
    contact_face_subdivision: int = 2

    def validate(self):
        """Raise :class:`ColonsimError` naming the first bad input and its fix."""
        model = colon_model(self.segment)
        if model.reads_centerline and self.centerline is None:
            raise ColonsimError(f"segment {self.segment!r} is a patient's centerline; give the file "
                                "(--centerline FILE, or centerline = \"FILE\" in a sweep)")
        if self.centerline is not None and not model.reads_centerline:
            raise ColonsimError(f"a centerline file is given for segment {self.segment!r}, which has its own shape; "
                                "use segment 'patient' (--centerline implies it) or drop the centerline")
        for name in ("diameter_mm", "wall_thickness_mm", "element_size_mm", "exit_length_mm", "flexure_angle_deg",
                     "friction", "distal_resistance_N", "stiffness_factor"):  # the ranges every command shares
            check_input_range(name, getattr(self, name))
        checks = [
            ("scope_spacing_mm", self.scope_spacing_mm, 1.0, 50.0,
             f"scope node spacing in mm ({InsertionCase.scope_spacing_mm:g} by default)"),
            ("push_speed", self.push_speed, 1e-3, 5.0,
             f"push speed in m/s ({InsertionCase.push_speed:g}; 0.6 in the source)"),
            ("held_push_share", self.held_push_share, 0.05, 1.0,
             f"share of the push speed behind a held tip ({InsertionCase.held_push_share:g}; 1: not slowed)"),
            ("held_push_lead_mm", self.held_push_lead_mm, 0.0, 500.0,
             f"distance before the fixed exit at which the held push begins, mm ({InsertionCase.held_push_lead_mm:g})"),
            ("held_push_pace", self.held_push_pace, 0.0, 1.0,
             "share of the push the tip must keep for the held push to return to the push speed (0: never)"),
            ("straighten_speed_factor", self.straighten_speed_factor, 1.0, 4.0,
             f"speed of the straightening push as a multiple of push_speed ({InsertionCase.straighten_speed_factor:g})"),
            ("colon_damping", self.colon_damping, 0.0, 1e4, "damping in 1/s"),
            ("scope_damping", self.scope_damping, 0.0, 1e4, "damping in 1/s"),
            ("scope_lateral_damping", self.scope_lateral_damping, 0.0, 1e4, "damping in 1/s"),
            ("scope_axial_damping_s", self.scope_axial_damping_s, 0.0, 0.1, "Kelvin-Voigt damping time in s (3e-3)"),
            ("stop_distance_mm", self.stop_distance_mm, 0.0, 100.0, "push distance to slow to rest, mm (0)"),
            ("settle_s", self.settle_s, 0.0, 10.0, f"shortest hold at rest at the end, s ({InsertionCase.settle_s:g})"),
            ("settle_max_s", self.settle_max_s, self.settle_s, 10.0,
             "longest hold at rest at the end, s, at least settle_s (1.0)"),
            ("settle_lateral_damping", self.settle_lateral_damping, 0.0, 1e4, "damping in 1/s"),
            ("record_interval_s", self.record_interval_s, 1e-6, 1.0, "recording interval in s"),
            ("time_step_factor", self.time_step_factor, 0.01, 1.0, "a safety factor in (0, 1]"),
            ("ramp_s", self.ramp_s, 0.0, 10.0, "ramp duration in s (0.4)"),
            ("relax_s", self.relax_s, 1e-3, 10.0, "relax duration in s (0.1 by default)"),
            ("relax_max_s", self.relax_max_s, 0.0, 10.0,
             f"longest relax until at rest, s ({InsertionCase.relax_max_s:g}; 0: the relax lasts relax_s)"),
            ("failure_stretch", self.failure_stretch, 1.01, 10.0, "wall stretch at which a run ends (1.6)"),
            ("sheath_reserve_mm", self.sheath_reserve_mm, 0.0, 200.0, "scope length kept in the sheath, mm (20)"),
        ]
        for name, value, lo, hi, what in checks:
            if not (isinstance(value, (int, float)) and math.isfinite(value) and lo <= value <= hi):
                raise ColonsimError(f"{name} = {value!r} is outside [{lo:g}, {hi:g}]; give the {what}")
        if self.time_step_estimate not in TIME_STEP_ESTIMATES:
            raise ColonsimError(f"time_step_estimate = {self.time_step_estimate!r} is not one of "
                                f"{', '.join(TIME_STEP_ESTIMATES)}; give \"global\" (the default) or \"bounds\"")
        if self.contact_surface not in WALL_SAMPLINGS:
            raise ColonsimError(f"contact_surface = {self.contact_surface!r} is not one of "
                                f"{', '.join(WALL_SAMPLINGS)}; give \"nodes\" or \"faces\"")
        if not valid_subdivision(self.contact_face_subdivision):
            raise ColonsimError(f"contact_face_subdivision = {self.contact_face_subdivision!r} is not a whole number "
                                f"from {FACE_SUBDIVISIONS.start} to {FACE_SUBDIVISIONS.stop - 1}; give the points per "
                                f"triangle edge ({InsertionCase.contact_face_subdivision})")
        if 0.0 < self.relax_max_s < self.relax_s:
            raise ColonsimError(f"relax_max_s = {self.relax_max_s:g} s is shorter than relax_s = {self.relax_s:g} s; "
                                "give at least relax_s, or 0 for a relax of relax_s")
        if self.element_size_mm > self.diameter_mm / 3:
            raise ColonsimError(f"element size {self.element_size_mm} mm is too coarse for a {self.diameter_mm} mm colon; "
                                "use at most a third of the diameter")
        if self.material_parameters is not None or self.stiffness_factor != 1.0:
            case_material(self.material, self.material_parameters, self.stiffness_factor)
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
        """Every field by name; a mutable value (the drawn parameters) copied, as
        :func:`dataclasses.asdict` gives, without its recursion through every scalar (a tenth of
        the time: an adaptive sweep keys about a thousand candidates a round)."""
        return {f.name: _copied(getattr(self, f.name)) for f in _FIELDS}

    def key(self) -> str:
        """A short hash of the inputs (identifies a run in sweeps and output folders).

        A centerline enters as the digest of its content (points, labels, names, diameters), not
        its path: a moved or re-saved file keeps its runs, an edited one gets new ones."""
        inputs = self.to_dict()
        defaults = InsertionCase()
        for name in LATER_FIELDS:
            if inputs[name] == getattr(defaults, name):
                del inputs[name]
        for name, value in ABSENT_AT.items():
            if inputs[name] == value:
                del inputs[name]
        model = COLON_MODELS.get(self.segment)
        if model is not None and not model.straightens:  # no relax nor straightening: their settings do nothing
            inputs.pop("relax_max_s", None)
            inputs.pop("straighten_speed_factor", None)
        if "contact_surface" not in inputs:  # the wall's nodes: no face points to subdivide
            inputs.pop("contact_face_subdivision", None)
        if "distal_resistance_N" not in inputs:  # nothing holds the tip: the held push never starts
            inputs.pop("held_push_share", None)
            inputs.pop("held_push_lead_mm", None)
            inputs.pop("held_push_pace", None)
        if self.centerline is not None:
            inputs["centerline"] = "sha256:" + load_centerline_points(self.centerline).digest()
        return hashlib.sha256(json.dumps(inputs, sort_keys=True).encode()).hexdigest()[:12]


_FIELDS = fields(InsertionCase)


def _copied(value):
    return value if value is None or isinstance(value, (str, int, float)) else copy.deepcopy(value)
