"""The catalog: colon models, named scopes and results-table columns, each defined once (the
input ranges every command shares: :mod:`colonsim.input_ranges`).

The solver side (:mod:`colonsim.insertion.anatomy.colon_segments`,
:mod:`colonsim.insertion.anatomy.scopes`, :mod:`colonsim.insertion.case.scenario`), the sweep,
the surrogate and the command-line help read these entries; adding a colon model or a named scope
is one entry here (docs/architecture.md). The physics behind each entry is in docs/model.md
("Colon models", "Colonoscope", "Loading", "Outputs").

Ground floor: imports nothing of colonsim but :mod:`colonsim.errors`. A model's geometry builder is
therefore named as ``"module:function"`` text and resolved by
:func:`colonsim.insertion.anatomy.colon_segments.colon_geometry`.
"""

from __future__ import annotations

from dataclasses import dataclass

from colonsim.errors import ColonsimError

# -- colon models -------------------------------------------------------------------------------

ALPHA, BETA, NO_ANGLE = "alpha", "beta", "none"
CONTINUOUS_PUSH = "continuous push"
# push to the end of the mobile piece with its lateral motion blocked, pause, push on
STRAIGHTEN_RELAX_PUSH = "straighten-relax-push"
# The run ends when the tip is PAST_JUNCTION beyond the fixed end of the mobile piece; the scope
# must be long enough to get there.
PAST_MOBILE_END = "past the mobile piece's fixed end"
# The run ends when the tip reaches the model's far end; the scope must be long enough.
FAR_END = "far end"
# The run ends at the far end or when the scope's available length is pushed in, whichever first.
FAR_END_OR_LENGTH = "far end or available length"
PAST_JUNCTION = 0.02  # m, how far past the fixed end of the mobile piece a PAST_MOBILE_END run ends
# A model without a scope length of its own (a patient's centerline) gets a scope this much longer
# than the centerline (assumption; docs/model.md, "A patient's centerline"): room for the scope to
# bow before its tip reaches the far end, and plus the length kept in the sheath.
SCOPE_LENGTH_MARGIN = 0.20
ANGLE_LIMITS_DEG = (0.0, 60.0)  # RSF alpha and THF beta; the source used 0, 30, 45
# The smoke size of an insertion (tests, the smoke preset, the demo's check): the coarsest wall
# mesh, mm, on which every catalogue scope stays inside the RSJ colon (on 6 and 7.5 mm the thin
# scopes leave it through the wall, which the run then refuses: docs/model.md, "Contact"), with
# scope nodes twice as far apart as the default so that the scope does not set a short time step,
# pushed at the source's 0.6 m/s, four times the quasi-static default (InsertionCase.push_speed):
# a smoke RSJ run takes 2.2x fewer steps (measured: 10.1 / 10.9 s against 22.4 / 26.0 s for UTC /
# SDC on one core) and rings (ringing ratio 0.08-0.11). Not physics: for checking that things run.
SMOKE_ELEMENT_MM = 5.0
SMOKE_SCOPE_SPACING_MM = 10.0
SMOKE_PUSH_SPEED = 0.6  # m/s
_BUILDERS = "colonsim.insertion.anatomy.colon_segments"


@dataclass(frozen=True)
class ColonModel:
    """One colon model (docs/model.md, "Colon models"); lengths in m, angles in degrees.

    Attributes
    ----------
    name, title : str
        Key (``--segment``) and one-line description.
    builder : str
        ``"module:function"``; the function takes (diameter, angle_deg, element_size,
        wall_thickness, exit_length, flexure_angle_deg) in SI and returns a ``ColonGeometry``.
    scope_length : float or None
        Length of the scope the source pushed into this model, m; None: the centerline's length
        plus :data:`SCOPE_LENGTH_MARGIN` plus the length kept in the sheath
        (:meth:`scope_length_for`).
    angle : {"alpha", "beta", "none"}
        What ``angle_deg`` means for the geometry ("none": ignored).
    angle_limits_deg : (float, float) or None
        The angles the geometry builds (None with ``angle = "none"``).
    manoeuvre : {CONTINUOUS_PUSH, STRAIGHTEN_RELAX_PUSH}
    mobile_piece : str or None
        Name of the centerline's mobile piece the manoeuvre straightens or whose fixed end
        ``PAST_MOBILE_END`` refers to.
    end_rule : {PAST_MOBILE_END, FAR_END, FAR_END_OR_LENGTH}
    surrogate_angle : bool
        The surrogate's patient presets set this model's angle (sex -> alpha or beta).
    reads_centerline : bool
        The geometry is a user's centerline CSV (``InsertionCase.centerline``); the builder then
        also takes ``centerline=`` (a loaded centerline).
    exit_takes_length : bool
        The fixed exit is lengthened to take the whole available scope length (the tip, held back
        by the distal resistance, never reaches its far end; docs/model.md, "Loading").
    """

    name: str
    title: str
    builder: str
    scope_length: float | None
    angle: str = NO_ANGLE
    angle_limits_deg: tuple | None = None
    manoeuvre: str = CONTINUOUS_PUSH
    mobile_piece: str | None = None
    end_rule: str = FAR_END
    surrogate_angle: bool = False
    reads_centerline: bool = False
    exit_takes_length: bool = False

    def __post_init__(self):
        def bad(what):
            raise ColonsimError(f"catalog entry {self.name!r}: {what}; fix the entry in colonsim/catalog.py")

        if ":" not in self.builder:
            bad(f"builder {self.builder!r} is not 'module:function'")
        if self.scope_length is not None and not 0.0 < self.scope_length < 5.0:
            bad(f"scope_length {self.scope_length!r} m is not a scope length")
        if self.angle not in (ALPHA, BETA, NO_ANGLE) or (self.angle == NO_ANGLE) != (self.angle_limits_deg is None):
            bad("give angle alpha or beta with angle_limits_deg, or angle none without")
        if self.manoeuvre not in (CONTINUOUS_PUSH, STRAIGHTEN_RELAX_PUSH):
            bad(f"manoeuvre {self.manoeuvre!r}; use {CONTINUOUS_PUSH!r} or {STRAIGHTEN_RELAX_PUSH!r}")
        if self.end_rule not in (PAST_MOBILE_END, FAR_END, FAR_END_OR_LENGTH):
            bad(f"end_rule {self.end_rule!r}; use {PAST_MOBILE_END!r}, {FAR_END!r} or {FAR_END_OR_LENGTH!r}")
        if (self.straightens or self.end_rule == PAST_MOBILE_END) and not self.mobile_piece:
            bad("name the mobile_piece its manoeuvre straightens or its end rule refers to")
        if self.surrogate_angle and self.angle == NO_ANGLE:
            bad("surrogate_angle needs an angle")

    @property
    def straightens(self) -> bool:
        return self.manoeuvre == STRAIGHTEN_RELAX_PUSH

    @property
    def must_reach_end(self) -> bool:
        """The scope must be long enough for the tip to reach the end plane (else the run is refused)."""
        return self.end_rule in (PAST_MOBILE_END, FAR_END)

    def scope_length_for(self, centerline_length, sheath_reserve):
        """The scope's length, m, for a centerline of ``centerline_length`` with ``sheath_reserve``
        kept in the sheath (m): the catalog's, or sized to the centerline (``scope_length`` None)."""
        if self.scope_length is not None:
            return self.scope_length
        return centerline_length + SCOPE_LENGTH_MARGIN + sheath_reserve

    def check_angle(self, angle_deg):
        """Raise if ``angle_deg`` is outside the angles this geometry builds (ignored without an angle)."""
        if self.angle_limits_deg is None:
            return
        low, high = self.angle_limits_deg
        if not low <= angle_deg <= high:
            raise ColonsimError(f"--angle {angle_deg:g} deg is outside {low:g}-{high:g} deg, the range this geometry "
                                "builds (the source used 0, 30, 45)")


COLON_MODELS = {m.name: m for m in (
    ColonModel("rsj", "rectosigmoid junction",
               f"{_BUILDERS}:rsj_geometry", 0.30, mobile_piece="sigmoid", end_rule=PAST_MOBILE_END),
    ColonModel("rsf", "rectum to splenic flexure, the sigmoid tilted by alpha",
               f"{_BUILDERS}:rsf_geometry", 0.70, ALPHA, ANGLE_LIMITS_DEG, STRAIGHTEN_RELAX_PUSH, "sigmoid",
               FAR_END_OR_LENGTH, surrogate_angle=True, exit_takes_length=True),
    ColonModel("thf", "transverse colon as a V of angle beta, hepatic flexure",
               f"{_BUILDERS}:thf_geometry", 0.50, BETA, ANGLE_LIMITS_DEG, STRAIGHTEN_RELAX_PUSH, "transverse",
               FAR_END_OR_LENGTH, surrogate_angle=True, exit_takes_length=True),
    ColonModel("thf-fixed", "thf with the transverse colon fixed",
               f"{_BUILDERS}:thf_fixed_geometry", 0.50, BETA, ANGLE_LIMITS_DEG, end_rule=FAR_END_OR_LENGTH,
               exit_takes_length=True),
    ColonModel("straight", "a 20 cm straight tube, a sanity case",
               f"{_BUILDERS}:straight_geometry", 0.30),
    # a continuous push: the straighten-relax-push blocks lateral motion along straight mobile
    # pieces, which a measured centerline does not have (docs/model.md, "A patient's centerline")
    ColonModel("patient", "a patient's centerline from a CSV (--centerline)",
               f"{_BUILDERS}:patient_geometry", None, end_rule=FAR_END_OR_LENGTH, reads_centerline=True),
)}


def segment_names() -> tuple:
    """The ``--segment`` choices, in catalog order."""
    return tuple(COLON_MODELS)


def colon_model(name) -> ColonModel:
    """The catalog entry of colon model ``name`` (exact key)."""
    try:
        return COLON_MODELS[name]
    except (KeyError, TypeError):
        raise ColonsimError(f"unknown colon segment {name!r} (not a colon model); use one of "
                            f"{', '.join(COLON_MODELS)}") from None


# -- named scopes -------------------------------------------------------------------------------

SCOPE_YOUNGS_MODULUS = 16e6  # Pa, from the flexural rigidity of a 3-point bending test
SCOPE_DENSITY = 2944.0  # kg/m^3
SCOPE_POISSON = 0.3  # only reported: a rod pushed without torsion does not use it
# Plausible outer diameters of an insertion tube, m: outside, a number is a unit slip.
SCOPE_DIAMETER_RANGE = (3e-3, 20e-3)


@dataclass(frozen=True)
class NamedScope:
    """A colonoscope the source names (docs/model.md, "Colonoscope"); SI units.

    Attributes
    ----------
    name, title : str
    diameter : float
        Catalogue outer diameter, m.
    meshed_diameter : float
        The diameter the source's mesh of this scope had, m.
    standard : bool
        The reference the others ("small caliber") are compared with.
    youngs_modulus, density, poisson : float
    """

    name: str
    title: str
    diameter: float
    meshed_diameter: float
    standard: bool = False
    youngs_modulus: float = SCOPE_YOUNGS_MODULUS
    density: float = SCOPE_DENSITY
    poisson: float = SCOPE_POISSON

    def __post_init__(self):
        low, high = SCOPE_DIAMETER_RANGE
        if self.name != self.name.strip().lower() or not all(low <= d <= high for d in
                                                             (self.diameter, self.meshed_diameter)):
            raise ColonsimError(f"catalog scope {self.name!r}: give a lower-case name and diameters in "
                                f"{low * 1e3:g}-{high * 1e3:g} mm (in m); fix the entry in colonsim/catalog.py")


NAMED_SCOPES = {s.name: s for s in (
    NamedScope("utc", "ultrathin colonoscope", 9.2e-3, 9.2e-3),
    NamedScope("pdc", "pediatric colonoscope", 11.3e-3, 11.1e-3),
    NamedScope("sdc", "standard colonoscope", 12.8e-3, 13.3e-3, standard=True),
)}


def standard_scope() -> NamedScope:
    """The named scope the others are compared with (SDC)."""
    return next(s for s in NAMED_SCOPES.values() if s.standard)


def small_caliber_scopes() -> tuple:
    """Names of the named scopes other than the standard one (UTC, PDC)."""
    return tuple(name for name, s in NAMED_SCOPES.items() if not s.standard)


def meshed_diameters() -> dict:
    """Scope name -> the diameter of the source's mesh of it, m."""
    return {name: s.meshed_diameter for name, s in NAMED_SCOPES.items()}


def parse_scope(spec) -> tuple:
    """``(name, outer diameter in m)`` of a scope spec: a catalog name in any case (name ``"UTC"``)
    or a diameter in mm, ``"10.5"``, ``"10.5mm"`` or 10.5 (name ``"10.5 mm"``)."""
    key = str(spec).strip().lower()
    if key in NAMED_SCOPES:
        return key.upper(), NAMED_SCOPES[key].diameter
    try:
        d_mm = float(key.removesuffix("mm"))
    except ValueError:
        raise ColonsimError(f"unknown scope {spec!r}; use {', '.join(NAMED_SCOPES)} or a diameter in mm "
                            "such as 10.5") from None
    d = d_mm * 1e-3
    low, high = SCOPE_DIAMETER_RANGE
    if not (low <= d <= high):  # NaN fails too
        raise ColonsimError(f"scope diameter {d_mm!r} mm is outside {low * 1e3:g}-{high * 1e3:g} mm; "
                            "give the outer diameter in mm")
    return f"{d_mm:g} mm", d


def scope_role(diameter_mm):
    """The named scope a catalogue or source-mesh diameter (mm, to 0.05 mm) stands for, else None."""
    for name, scope in NAMED_SCOPES.items():
        if any(abs(diameter_mm - d * 1e3) < 0.05 for d in (scope.diameter, scope.meshed_diameter)):
            return name
    return None


# -- results-table columns ----------------------------------------------------------------------

INPUT, SETTING, OUTPUT, PROVENANCE = "input", "setting", "output", "provenance"
# What the surrogate makes of a column: a continuous input it models on, an output it fits by
# default, or one it may fit when asked (``--targets``).
SURROGATE_INPUT, DEFAULT_TARGET, TARGET = "input", "default target", "target"
# The wall material of a run as the surrogate sees it: its small-strain shear modulus and its C11
# (colonsim.insertion.study.material_samples fills both for every run, the default material too).
WALL_MU0, WALL_C11 = "wall_mu0_kPa", "wall_C11_kPa"
# ... and as one number, the factor on the reference wall law it amounts to
# (colonsim.insertion.study.tissue_stiffness: definition and mapping rule)
TISSUE_STIFFNESS = "tissue_stiffness"


@dataclass(frozen=True)
class Column:
    """One column of a sweep's ``results.parquet`` (docs/sweeps.md, "Results").

    ``label`` is the axis label of a surrogate input or target; ``option`` the ``colonsim insert``
    option that sets an input."""

    name: str
    kind: str
    unit: str
    description: str
    surrogate: str = ""
    label: str = ""
    option: str = ""

    def __post_init__(self):
        if self.kind not in (INPUT, SETTING, OUTPUT, PROVENANCE) or self.surrogate not in (
                "", SURROGATE_INPUT, DEFAULT_TARGET, TARGET):
            raise ColonsimError(f"catalog column {self.name!r}: kind {self.kind!r} or surrogate role "
                                f"{self.surrogate!r} unknown; fix the entry in colonsim/catalog.py")
        expected = {SURROGATE_INPUT: INPUT, DEFAULT_TARGET: OUTPUT, TARGET: OUTPUT}.get(self.surrogate, self.kind)
        if self.kind != expected or (self.surrogate and not self.label):
            raise ColonsimError(f"catalog column {self.name!r}: a surrogate {self.surrogate} must be an {expected} "
                                "with a label; fix the entry in colonsim/catalog.py")


# The wall counts as stretched where its largest principal stretch over the run passes this
# (assumption, docs/visualisation.md: 10 % beyond rest, well inside the tissue's failure stretch);
# a run's own threshold may lie in the range (colonsim insert --stretch-threshold).
STRETCHED_WALL_COLUMN = "wall_area_stretched_cm2"
STRETCHED_WALL_THRESHOLD, STRETCHED_WALL_THRESHOLD_RANGE = 1.1, (1.01, 2.0)

_P, _I, _S, _O = PROVENANCE, INPUT, SETTING, OUTPUT
COLUMNS = {c.name: c for c in (
    Column("key", _P, "", "hash of every input: identifies the run"),
    Column("status", _P, "", "ok or failed (only ok runs train the surrogate)"),
    Column("error", _P, "", "why a failed run failed"),
    Column("wall_time_s", _P, "s", "wall time of the run"),
    Column("timeseries_path", _P, "", "the run's timeseries.csv, relative to the sweep folder (OUT)"),
    Column("finished_at", _P, "", "UTC time the run finished (ISO 8601)"),
    Column("git_commit", _P, "", "the code that ran it (\"+modified\": uncommitted changes; empty outside a git "
                                 "checkout)"),
    Column("segment", _I, "", "colon model (a key of colonsim.catalog.COLON_MODELS)", option="--segment"),
    Column("scope", _I, "", "named scope or outer diameter in mm, as given", option="--scope"),
    Column("scope_diameter_mm", _I, "mm", "scope outer diameter (from scope)", SURROGATE_INPUT,
           "scope diameter [mm]", "--scope"),
    Column("diameter_mm", _I, "mm", "colon inner diameter", SURROGATE_INPUT, "colon diameter [mm]", "--diameter"),
    Column("angle_deg", _I, "deg", "alpha (RSF) or beta (THF, fixed THF)", SURROGATE_INPUT,
           "angle alpha/beta [deg]", "--angle"),
    Column("flexure_angle_deg", _S, "deg", "turn of the splenic (RSF) or hepatic (THF) flexure"),
    Column("friction", _I, "", "Coulomb friction coefficient scope/wall", SURROGATE_INPUT, "friction coefficient",
           "--friction"),
    Column("wall_thickness_mm", _I, "mm", "colon wall thickness", SURROGATE_INPUT, "wall thickness [mm]",
           "--wall-thickness"),
    Column("centerline", _I, "", "a patient's centerline CSV (segment patient; empty for the catalog's models)",
           option="--centerline"),
    Column("centerline_smoothing_mm", _S, "mm", "RMS tolerance of the smoothed patient centerline"),
    Column("material", _S, "", "material JSON (empty: the source's parameters)"),
    Column("material_parameters", _S, "Pa", "wall parameters drawn by a [material] section, {name: Pa} as JSON, "
                                             "replacing the material file's (empty: the file's)"),
    Column(WALL_MU0, _I, "kPa", "small-strain shear modulus mu0 = 2 (W1 + W2) of the run's wall material",
           SURROGATE_INPUT, "wall shear modulus mu0 [kPa]", "--wall-mu0"),
    Column(WALL_C11, _I, "kPa", "C11 of the run's wall material (NaN for a law without a C11 term)", SURROGATE_INPUT,
           "wall C11 [kPa]", "--wall-c11"),
    Column("stiffness_factor", _I, "", "factor on every parameter in Pa of the run's wall material (1: the material "
                                      "as given); the surrogate sees the wall through tissue_stiffness"),
    Column(TISSUE_STIFFNESS, _I, "", "the run's wall material as a factor on the reference wall law (1: the reference; "
                                     "colonsim.insertion.study.tissue_stiffness)", SURROGATE_INPUT,
           "tissue stiffness factor", "--stiffness"),
    Column("element_size_mm", _S, "mm", "wall triangle size"),
    Column("scope_spacing_mm", _S, "mm", "scope node spacing"),
    Column("push_speed", _S, "m/s", "plateau push speed"),
    Column("held_push_share", _S, "", "share of the push speed once the distal resistance holds the tip "
                                      "(docs/model.md, \"Loading\")"),
    Column("held_push_lead_mm", _S, "mm", "distance before the fixed exit at which the held push begins (0: when "
                                        "the resistance engages)"),
    Column("ramp_s", _S, "s", "speed-change ramp"),
    Column("relax_s", _S, "s", "relax pause of straighten-relax-push (the constraint fades over it)"),
    Column("relax_max_s", _S, "s", "longest relax: it goes on until the released system is at rest (0: relax_s)"),
    Column("stop_distance_mm", _S, "mm", "push over which the scope slows to rest at the end of the run (0: at once)"),
    Column("settle_s", _S, "s", "shortest time the scope is held still at the end before the final values are read"),
    Column("settle_max_s", _S, "s", "longest hold at the end: the final values are read once the run has come to rest "
                                    "(docs/model.md, \"Loading\") or after this"),
    Column("settle_lateral_damping", _S, "1/s", "lateral damping of the scope while it settles at rest"),
    Column("exit_length_mm", _S, "mm", "fixed colon after the last mobile piece (a minimum where the exit takes the "
                                       "whole available length: RSF, THF, fixed THF)"),
    Column("distal_resistance_N", _I, "N", "force the colon beyond the model opposes to the tip's advance once it is in "
                                           "the fixed exit (docs/model.md, \"Loading\")", SURROGATE_INPUT,
           "distal resistance [N]", "--distal-resistance"),
    Column("failure_stretch", _S, "", "wall stretch at which a run ends (ended_by wall_stretch)"),
    Column("sheath_reserve_mm", _S, "mm", "scope length kept in the sheath"),
    Column("colon_damping", _S, "1/s", "mass-proportional damping of the colon"),
    Column("scope_damping", _S, "1/s", "mass-proportional damping of the scope"),
    Column("scope_lateral_damping", _S, "1/s", "mass-proportional damping of the scope's velocity across its axis"),
    Column("scope_axial_damping_s", _S, "s", "Kelvin-Voigt damping time of the scope's axial springs"),
    Column("record_interval_s", _S, "s", "simulated time between recorded samples"),
    Column("time_step_factor", _S, "", "safety factor on the stable time step"),
    Column("time_step_estimate", _S, "", "what the stable time step rests on: global (default; power iteration "
                                         "on the coupled system) or bounds (element bounds; before 2026-12-07)"),
    Column("contact_surface", _S, "", "where the contact samples the wall: nodes (default) or faces (points spread "
                                      "over its triangles)"),
    Column("contact_face_subdivision", _S, "", "with faces: L, the L^2 contact points per wall triangle"),
    Column("final_deformation_cm", _O, "cm", "colon deformation at the end of the run", DEFAULT_TARGET,
           "final colon deformation [cm]"),
    Column("max_deformation_cm", _O, "cm", "largest colon deformation during the run", DEFAULT_TARGET,
           "maximum colon deformation [cm]"),
    Column("point_A_cm", _O, "cm", "deformation at point A, its first maximum (RSJ; docs/model.md, \"Outputs\")",
           DEFAULT_TARGET, "deformation at point A [cm]"),
    Column("point_B_cm", _O, "cm", "deformation at point B, the following minimum (RSJ)", TARGET,
           "deformation at point B [cm]"),
    Column("point_C_cm", _O, "cm", "deformation at point C, the largest value after B (RSJ)", DEFAULT_TARGET,
           "deformation at point C [cm]"),
    Column("peak_contact_force_N", _O, "N", "largest total contact force over the push, averaged over 5 mm of push "
                                            "(docs/model.md, \"Outputs\")", DEFAULT_TARGET, "peak contact force [N]"),
    Column("peak_push_force_N", _O, "N", "largest push force over the push, averaged over 5 mm of push", DEFAULT_TARGET,
           "peak push force [N]"),
    Column("max_wall_stretch", _O, "", "largest wall stretch over the run", DEFAULT_TARGET,
           "maximum wall stretch"),
    Column(STRETCHED_WALL_COLUMN, _O, "cm2", f"wall area (rest configuration) whose largest principal stretch over the "
                                             f"run passed {STRETCHED_WALL_THRESHOLD:g} (an assumption: a candidate pain "
                                             "measure; docs/visualisation.md)", TARGET, "stretched wall area [cm2]"),
    Column("ringing_ratio", _O, "", "RMS of the push force about its 1 cm moving average over max(its mean, 1 N), over "
                                    "the push from the first contact, the 6 mm after each snap-through left out "
                                    "(docs/quasi_static.md)"),
    Column("quasi_static", _O, "", "the ringing ratio is below 0.1 with at most a quarter of the push left out after "
                                   "snap-throughs: the push force follows the push without ringing"),
    Column("snap_throughs", _O, "", "number of snap-throughs: drops of the push force by more than 1 N and a quarter "
                                    "of its value within 2 mm of push (docs/quasi_static.md)"),
    Column("ringing_left_out_share", _O, "", "share of the push that the ringing ratio leaves out after "
                                             "snap-throughs"),
    Column("kinetic_energy_check", _O, "", "kinetic / internal energy below 10 % on most samples for both bodies, the "
                                           "scope's imposed sliding set aside (information: it passed runs that rang)"),
    Column("came_to_rest", _O, "", "the run came to rest in its closing hold before the final values were read: the "
                                   "deformation and the tip still within 0.02 mm over 0.05 s (docs/model.md, \"Loading\")"),
    Column("max_lag_cm", _O, "cm", "largest lag of the scope: pushed depth minus the tip's advance along the "
                                   "centerline (a proxy of the buckled length)", TARGET, "maximum scope lag [cm]"),
    Column("final_lag_cm", _O, "cm", "the scope's lag at the end of the run", TARGET, "final scope lag [cm]"),
    Column("tip_turned_back_cm", _O, "cm", "pushed depth from which the tip points back against the lumen (its last "
                                           "segment more than 90 deg from the lumen's direction) to the end of the "
                                           "run; empty if it does not at the end (docs/model.md, \"Distal resistance\")"),
    Column("ended_by", _O, "", "why the run ended: tip_past_end, far_end, length_used, wall_stretch, tip_folded or jam "
                               "(docs/model.md, \"Loading\")"),
    Column("end_depth_cm", _O, "cm", "pushed depth where the run ended"),
    Column("end_push_force_N", _O, "N", "push force where the run ended"),
    Column("end_contact_force_N", _O, "N", "contact force where the run ended"),
    Column("simulated_time_s", _O, "s", "simulated duration of the run"),
)}


def columns(kind=None, surrogate=None) -> tuple:
    """Names of the catalog's columns of ``kind`` and/or surrogate role (None: any), in catalog order."""
    return tuple(c.name for c in COLUMNS.values()
                 if (kind is None or c.kind == kind) and (surrogate is None or c.surrogate in surrogate))


# The pain proxy: the output the surrogate ranks scopes by, and predicts, plots and summarizes by
# default. The largest deformation over the run, not the final one: the source reports deformation
# at the end of its runs, which in its models is the largest; here the final value is read after
# the sigmoid has relaxed in the fixed exit (docs/surrogate.md, "The pain proxy").
PAIN_PROXY = "max_deformation_cm"

# A run whose tip folded back on itself ended outside the model (a real tip is steered): its
# ``ended_by``. Such runs are counted and shown, and left out of the claims and of surrogate
# training by default (docs/quasi_static.md, "A folded tip").
TIP_FOLDED = "tip_folded"

# Outputs that are, run by run, the larger of two others: in the RSJ the largest deformation is the
# larger of point A (the first maximum) and point C (the largest value after the minimum B) where a
# run has both. The surrogate models such an output through its two smooth parts where both are
# fitted and the identity holds on every training run (colonsim.surrogate.larger).
LARGER_OF = {"max_deformation_cm": ("point_A_cm", "point_C_cm")}


def column_unit(name) -> str:
    """Unit of a results-table column ("" for none, and for columns the catalog does not hold)."""
    column = COLUMNS.get(name)
    return column.unit if column is not None else ""
