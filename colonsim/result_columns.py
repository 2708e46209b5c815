"""The results table's columns (docs/sweeps.md, "Results"), each defined once: its kind, unit,
meaning and what the surrogate makes of it; the pain proxy and the ending of a folded tip.

Ground floor, part of the catalog (:mod:`colonsim.catalog` re-exports every name): imports nothing
of colonsim but :mod:`colonsim.errors`.
"""

from __future__ import annotations

from dataclasses import dataclass

from colonsim.errors import ColonsimError

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
                                f"{self.surrogate!r} unknown; fix the entry in colonsim/result_columns.py")
        expected = {SURROGATE_INPUT: INPUT, DEFAULT_TARGET: OUTPUT, TARGET: OUTPUT}.get(self.surrogate, self.kind)
        if self.kind != expected or (self.surrogate and not self.label):
            raise ColonsimError(f"catalog column {self.name!r}: a surrogate {self.surrogate} must be an {expected} "
                                "with a label; fix the entry in colonsim/result_columns.py")


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
    Column("held_push_pace", _S, "", "tip pace (advance over push) at which the held push returns to the push speed "
                                     "(0: never)"),
    Column("straighten_speed_factor", _S, "", "RSF/THF: speed of the straightening push as a multiple of the push "
                                              "speed"),
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
