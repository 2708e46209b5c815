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


# -- results-table columns: colonsim.result_columns, re-exported here (one catalog) ---------------

from colonsim.result_columns import (COLUMNS, DEFAULT_TARGET, INPUT, LARGER_OF, OUTPUT, PAIN_PROXY,  # noqa: E402,F401
                                     PROVENANCE, SETTING, STRETCHED_WALL_COLUMN, STRETCHED_WALL_THRESHOLD,
                                     STRETCHED_WALL_THRESHOLD_RANGE, SURROGATE_INPUT, TARGET, TIP_FOLDED,
                                     TISSUE_STIFFNESS, WALL_C11, WALL_MU0, Column, column_unit, columns)
