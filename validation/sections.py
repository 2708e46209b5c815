"""The numbers of the validation report's sweep sections, as JSON-ready rows.

Each function reads one or both sweeps (:mod:`validation.sweeps`) and returns plain
dicts (cm, N, s); the Markdown is written from the same dicts, so the two never disagree.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
import pandas as pd

from colonsim.insertion.case.outcomes import DEFORMATION_TOLERANCE, FORCE_FLOOR_N, FORCE_TOLERANCE
from colonsim.insertion.study.claims import NO_DEFORMATION_CM, advantage
from colonsim.insertion.anatomy.colon_segments import colon_geometry
from colonsim.insertion.study.reference import SOURCE_MESHES, SOURCE_RSJ_CM, SOURCE_RUN_MINUTES
from colonsim.insertion.case.scenario import InsertionCase

from .sweeps import SCOPES, find_case, paired, relative_change, role, scope_label

RSJ_DIAMETERS = (23.0, 36.0)
# Wall nodes of the source's colon meshes, where it gives them.
SOURCE_NODES = {key: nodes for key, (nodes, _) in SOURCE_MESHES.items()}
NODE_COUNT_MODELS = (("rsj", 23.0, 0.0), ("rsj", 36.0, 0.0), ("rsf", 36.0, 0.0), ("rsf", 36.0, 30.0),
                     ("rsf", 36.0, 45.0), ("thf", 36.0, 0.0), ("thf", 36.0, 30.0), ("thf", 36.0, 45.0),
                     ("thf-fixed", 36.0, 0.0))
# What a mesh pair or a rate check compares: (column, name, the size below which a relative change
# says nothing, the tolerance on the change).
PAIR_QUANTITIES = (("final_deformation_cm", "final", NO_DEFORMATION_CM, DEFORMATION_TOLERANCE),
                   ("max_deformation_cm", "max", NO_DEFORMATION_CM, DEFORMATION_TOLERANCE),
                   ("point_A_cm", "A", NO_DEFORMATION_CM, DEFORMATION_TOLERANCE),
                   ("point_C_cm", "C", NO_DEFORMATION_CM, DEFORMATION_TOLERANCE),
                   ("peak_contact_force_N", "peak contact", FORCE_FLOOR_N, FORCE_TOLERANCE),
                   ("peak_push_force_N", "peak push", FORCE_FLOOR_N, FORCE_TOLERANCE),
                   ("max_lag_cm", "lag", NO_DEFORMATION_CM, DEFORMATION_TOLERANCE))
FLEXURE_SCOPES = ("utc", "sdc")
# what a run with snap-throughs is judged on in the rate check (docs/quasi_static.md): the count,
# and these; its peak forces at the snap are dynamic values, reported
SNAP_JUDGED = ("max", "lag")
NEUTRAL_END = ("final deformation of a loop behind a tip held at mu 0: a nearly neutral end state, reported with "
               "its spread, not judged")
SNAP_DYNAMIC = "a run with snap-throughs: judged on their count, the largest deformation and the lag"


def neutral_end(row) -> bool:
    """Whether a run ended with its tip held back at mu = 0 (docs/quasi_static.md, "Rate and mesh"):
    frictionless, a distal resistance acting, and pushed until its available length was used."""
    friction, resistance = row.get("friction"), row.get("distal_resistance_N")
    return (friction is not None and float(friction) == 0.0 and resistance is not None and float(resistance) > 0.0
            and row.get("ended_by") == "length_used")


def _snaps(row):
    value = _number(row, "snap_throughs")
    return 0 if value is None or not math.isfinite(value) else int(value)


def _number(row, column):
    if row is None:
        return None
    v = row.get(column)
    return math.nan if v is None or pd.isna(v) else float(v)


def _flag(value):
    """A check column as True / False, None where the row does not say."""
    return None if value is None or pd.isna(value) else bool(value)


def _ratio(a, b):
    return a / b if a is not None and b is not None and np.isfinite(a) and np.isfinite(b) and b > 0 else math.nan


def case_geometry(case, exit_length_mm=None):
    """The colon of ``case`` as :func:`colonsim.insertion.anatomy.colon_segments.colon_geometry` builds it (SI)."""
    exit_mm = case.exit_length_mm if exit_length_mm is None else exit_length_mm
    return _geometry(case.segment, case.diameter_mm, case.angle_deg, case.element_size_mm, case.wall_thickness_mm,
                     exit_mm, case.flexure_angle_deg)


@lru_cache(maxsize=32)
def _geometry(segment, d_mm, angle, h_mm, t_mm, exit_mm, flexure):
    return colon_geometry(segment, d_mm * 1e-3, angle, h_mm * 1e-3, t_mm * 1e-3, exit_mm * 1e-3, flexure)


def describe_inputs(case) -> str:
    """The inputs that place a run in the study, in the user's units."""
    parts = []
    if case.segment == "rsj":
        parts.append(f"D {case.diameter_mm:g} mm")
    elif case.segment in ("rsf", "thf", "thf-fixed"):
        parts.append(f"{'alpha' if case.segment == 'rsf' else 'beta'} {case.angle_deg:g} deg")
        parts.append(f"flexure {case.flexure_angle_deg:g} deg")
    parts.append(f"mu {case.friction:g}")
    default = InsertionCase()
    if case.element_size_mm != default.element_size_mm:
        parts.append(f"mesh {case.element_size_mm:g} mm")
    if case.push_speed != default.push_speed:
        parts.append(f"push {case.push_speed:g} m/s")
    return ", ".join(parts)


def _run_fields(case, row, status):
    return {"segment": case.segment, "scope": scope_label(case), "role": role(case), "key": case.key(),
            "inputs": describe_inputs(case), "angle_deg": case.angle_deg, "flexure_angle_deg": case.flexure_angle_deg,
            "status": status, "ended_by": None if row is None else row["ended_by"]}


# --- RSJ against the source's table -----------------------------------------------------------

def rsj_facts(sweep, row) -> dict:
    """What an RSJ run's curve did: its points with their depths, where the tip first reached the
    sigmoid's fixed end (depth and deformation then), how the run ended; and its timeseries."""
    summary = sweep.summary(row)
    points = {k: v for k, v in (summary.get("points_cm") or {}).items() if v}
    junction = (summary.get("mesh") or {}).get("mobile_end_cm")
    ts = sweep.timeseries(row, ["depth_cm", "deformation_cm", "tip_arc_cm"])
    entry = None
    if junction is not None and ts is not None:
        past = np.flatnonzero(ts["tip_arc_cm"].to_numpy() >= junction)
        entry = int(past[0]) if past.size else None
    facts = {**{f"{p}_cm": _number(row, f"point_{p}_cm") for p in "ABC"},
             "final_cm": _number(row, "final_deformation_cm"), "max_cm": _number(row, "max_deformation_cm"),
             "ended_by": row["ended_by"], "end_depth_cm": _number(row, "end_depth_cm"),
             "points_depth_cm": {k: v["depth_cm"] for k, v in points.items()}, "junction_cm": junction,
             "junction_entry_depth_cm": None if entry is None else float(ts["depth_cm"].iloc[entry]),
             "junction_entry_deformation_cm": None if entry is None else float(ts["deformation_cm"].iloc[entry])}
    return facts, points, ts


def rsj_comparison(main):
    """RSJ at mu = 0 against the source's points A and C: one row per (D, scope), and the curves
    (depth, deformation, points) for the figure."""
    rows, curves = [], []
    for d in RSJ_DIAMETERS:
        for scope in SCOPES:
            src = SOURCE_RSJ_CM[(scope, d)]
            case = find_case(main.cases, "rsj", scope, diameter_mm=d, friction=0.0)
            row, status = main.run(case) if case else (None, "not in the sweep")
            out = {"case": f"{scope.upper()} D{d:g}", "scope_role": scope, "diameter_mm": d, "status": status,
                   "scope": scope_label(case) if case else scope.upper(), "A_source_cm": src["A"],
                   "C_source_cm": src["C"]}
            rows.append(out)
            if row is None:
                continue
            facts, points, ts = rsj_facts(main, row)
            a, c, final = facts["A_cm"], facts["C_cm"], facts["final_cm"]
            out.update({**facts, "A_source_over_ours": _ratio(src["A"], a), "C_source_over_ours": _ratio(src["C"], c),
                        "final_source_over_ours": _ratio(src["C"], final),
                        "C_gt_A": bool(np.isfinite(a) and np.isfinite(c) and c > a),
                        "quasi_static": _flag(row["quasi_static"]), "ringing_ratio": _number(row, "ringing_ratio")})
            if ts is not None:
                curves.append({"diameter_mm": d, "scope_role": scope, "depth_cm": ts["depth_cm"].to_numpy(),
                               "deformation_cm": ts["deformation_cm"].to_numpy(), "points": points,
                               "junction_entry_depth_cm": facts["junction_entry_depth_cm"],
                               "junction_entry_deformation_cm": facts["junction_entry_deformation_cm"]})
    return rows, curves


def rsj_checks(rows) -> dict:
    """The issue's RSJ targets, read off the rows (None where a run is missing)."""
    have = [r for r in rows if r["status"] == "ok"]
    complete = len(have) == len(rows)
    found = [bool(np.isfinite(r["A_cm"]) and np.isfinite(r["C_cm"])) for r in have]
    order = {}
    for d in RSJ_DIAMETERS:
        final = {r["scope_role"]: r["final_cm"] for r in have if r["diameter_mm"] == d}
        order[f"D{d:g}"] = (bool(final["sdc"] > final["pdc"] > final["utc"]) if len(final) == len(SCOPES) else None)
    ratios = [r[k] for r in have for k in ("A_source_over_ours", "C_source_over_ours", "final_source_over_ours")
              if np.isfinite(r[k])]
    return {"runs": f"{len(have)} of {len(rows)}", "A_and_C_found": all(found) if complete else None,
            "C_gt_A": all(r["C_gt_A"] for r in have) if complete else None, "final_ordered_sdc_pdc_utc": order,
            "source_over_ours_range": [min(ratios), max(ratios)] if ratios else None}


# --- RSF, THF, fixed THF -------------------------------------------------------------------------

def phases(sweep, row) -> list:
    """Depth range and deformation of each manoeuvre phase of a run, in order (timeseries ``phase``)."""
    ts = sweep.timeseries(row, ["phase", "depth_cm", "deformation_cm"])
    if ts is None or ts.empty:
        return []
    block = (ts["phase"] != ts["phase"].shift()).cumsum()
    out = []
    for _, g in ts.groupby(block, sort=True):
        out.append({"phase": str(g["phase"].iloc[0]), "from_cm": float(g["depth_cm"].iloc[0]),
                    "to_cm": float(g["depth_cm"].iloc[-1]), "max_deformation_cm": float(g["deformation_cm"].max()),
                    "end_deformation_cm": float(g["deformation_cm"].iloc[-1])})
    return out


def flexure_model_runs(sweep, segments=("rsf", "thf", "thf-fixed"), flexures=None):
    """One row per run of ``segments`` (ordered by model, angle, flexure, scope); ``flexures``
    limits the flexure turns shown."""
    order = {s: i for i, s in enumerate(SCOPES)}
    cases = [c for c in sweep.cases if c.segment in segments
             and (flexures is None or c.flexure_angle_deg in flexures)]
    cases.sort(key=lambda c: (segments.index(c.segment), c.angle_deg, c.flexure_angle_deg, order.get(role(c), 9),
                              c.element_size_mm, c.push_speed))
    rows = []
    for case in cases:
        row, status = sweep.run(case)
        out = _run_fields(case, row, status)
        if row is not None:
            out.update({name: _number(row, name) for name in (
                "final_deformation_cm", "max_deformation_cm", "peak_contact_force_N", "peak_push_force_N",
                "max_wall_stretch", "end_depth_cm")})
            out["quasi_static"] = _flag(row["quasi_static"])
            out["phases"] = phases(sweep, row)
        rows.append({**out, "_case": case, "_row": row})
    return rows


def public(rows):
    """The rows without their private (case, table row) fields, for the JSON."""
    return [{k: v for k, v in r.items() if not k.startswith("_")} for r in rows]


# --- mesh pair, rate check, flexure sensitivity ----------------------------------------------------

def pair_rows(validation, main, check):
    """The ``check`` ("mesh" or "rate") pairs: base and variant value of each quantity, their
    relative change and a pass / fail against its tolerance (:data:`PAIR_QUANTITIES`), and the
    ringing ratio of both runs."""
    rows = []
    for kind, changed, variant, base in paired(validation, main):
        if kind != check:
            continue
        vrow, vstatus = validation.run(variant)
        brow, bstatus = main.run(base) if base else (None, "not in the main sweep")
        out = {"segment": variant.segment, "scope": scope_label(variant), "inputs": describe_inputs(variant),
               "changed": changed, "base_value": getattr(base, changed) if base else None,
               "variant_value": getattr(variant, changed), "base_status": bstatus, "variant_status": vstatus,
               "quantities": [], "passed": None}
        if vrow is not None and brow is not None:
            out["quantities"], out["passed"] = pair_quantities(brow, vrow, variant.segment, check)
            out["ended_by"] = [brow["ended_by"], vrow["ended_by"]]
            out["ringing_ratio"] = [_number(brow, "ringing_ratio"), _number(vrow, "ringing_ratio")]
        rows.append(out)
    return rows


def pair_quantities(brow, vrow, segment, check="mesh"):
    """(quantities, passed) of a pair of runs of ``segment``: each of :data:`PAIR_QUANTITIES` (A and
    C only in the RSJ) with its base and variant value, relative change and verdict (None where
    both lie below its floor, or where a rule of docs/quasi_static.md leaves it unjudged: ``why``),
    and whether every judged one passes (None: none judged). The rules: the final deformation of
    two runs that end with the tip held at mu 0 (:func:`neutral_end`) is not judged; in the rate
    check a pair with snap-throughs is judged on their count and :data:`SNAP_JUDGED` only."""
    snapped = check == "rate" and (_snaps(brow) or _snaps(vrow))
    quantities, judged = [], []
    if snapped:
        ok = _snaps(brow) == _snaps(vrow)
        quantities.append({"quantity": "snap-throughs", "column": "snap_throughs", "base": _snaps(brow),
                           "variant": _snaps(vrow), "change": math.nan, "tolerance": 0, "passed": ok, "why": ""})
        judged.append(ok)
    for column, name, floor, tolerance in PAIR_QUANTITIES:
        if name in ("A", "C") and segment != "rsj":
            continue  # the characteristic points are the RSJ's reading of its curve
        b, v = _number(brow, column), _number(vrow, column)
        change = relative_change(b, v, floor)
        why = (NEUTRAL_END if name == "final" and neutral_end(brow) and neutral_end(vrow) else
               SNAP_DYNAMIC if snapped and name not in SNAP_JUDGED else "")
        ok = None if why or not np.isfinite(change) else bool(abs(change) < tolerance)
        quantities.append({"quantity": name, "column": column, "base": b, "variant": v, "change": change,
                           "tolerance": tolerance, "passed": ok, "why": why})
        judged += [ok] if ok is not None else []
    return quantities, (all(judged) if judged else None)


def flexure_sensitivity(validation, main):
    """RSF / THF per angle and flexure turn: final and largest deformation of the UTC and SDC and
    the small-caliber advantage (SDC - UTC) / SDC of the final deformation."""
    turns = {}  # key -> (case, the sweep that holds it): a 90 deg run is the base of several turns
    for kind, _, variant, base in paired(validation, main):
        if kind == "flexure":
            turns[variant.key()] = (variant, validation)
            if base is not None:
                turns[base.key()] = (base, main)
    groups = {}
    for case, sweep in turns.values():
        groups.setdefault((case.segment, case.angle_deg, case.flexure_angle_deg), {})[role(case)] = (case, sweep)
    rows = []
    for (segment, angle, flexure), by_scope in sorted(groups.items(), key=lambda kv: (("rsf", "thf").index(kv[0][0]),
                                                                                       kv[0][1], kv[0][2])):
        out = {"segment": segment, "angle_deg": angle, "flexure_angle_deg": flexure, "scopes": {}}
        values = {}
        for scope in FLEXURE_SCOPES:
            case, sweep = by_scope.get(scope, (None, None))
            row, status = sweep.run(case) if case else (None, "not in the sweeps")
            entry = {"scope": scope_label(case) if case else scope.upper(), "status": status,
                     "sweep": sweep.label if sweep else None}
            if row is not None:
                entry.update({"final_cm": _number(row, "final_deformation_cm"),
                              "max_cm": _number(row, "max_deformation_cm"), "ended_by": row["ended_by"]})
                values[scope] = entry["final_cm"]
            out["scopes"][scope] = entry
        out["advantage"] = (advantage(values["sdc"], values["utc"]) if len(values) == len(FLEXURE_SCOPES)
                            else None)
        rows.append(out)
    return rows


# --- ringing ratio ----------------------------------------------------------------------------------

def ringing_rows(sweep) -> dict:
    """The ringing ratio of every run of ``sweep`` (docs/model.md, "Time integration and damping")."""
    if not sweep.ran:
        return {"ran": False}
    rows = []
    for case in sweep.cases:
        row, status = sweep.run(case)
        if row is None:
            continue
        summary = sweep.summary(row) or {}
        qs = summary.get("quasi_static") or {}
        rows.append({**_run_fields(case, row, status), "ringing_ratio": _number(row, "ringing_ratio"),
                     "rms_N": qs.get("push_force_rms_N"), "mean_N": qs.get("mean_push_force_N"),
                     "snap_throughs": _number(row, "snap_throughs"),
                     "left_out_share": _number(row, "ringing_left_out_share"),
                     "quasi_static": _flag(row.get("quasi_static")), "cause": row.get("ringing_cause") or "",
                     "rules": row.get("rules") or ""})
    ratios = [r["ringing_ratio"] for r in rows if r["ringing_ratio"] is not None and np.isfinite(r["ringing_ratio"])]
    worst = max(rows, key=lambda r: r["ringing_ratio"] if np.isfinite(r["ringing_ratio"]) else -1.0, default=None)
    return {"ran": True, "runs": len(rows), "passed": sum(bool(r["quasi_static"]) for r in rows),
            "largest": max(ratios, default=math.nan), "median": float(np.median(ratios)) if ratios else math.nan,
            "largest_run": f"{worst['segment'].upper()} {worst['scope']} {worst['inputs']}" if worst else "-",
            "rows": rows}


# --- meshes, run ends, run times ---------------------------------------------------------------------

def node_counts():
    """Wall nodes of each model at the default mesh, with and without the fixed exit, next to the source's."""
    rows = []
    for segment, d, angle in NODE_COUNT_MODELS:
        case = InsertionCase(segment=segment, diameter_mm=d, angle_deg=angle)
        g = case_geometry(case).summary()
        bare = len(case_geometry(case, exit_length_mm=0.0).nodes)
        src = SOURCE_NODES.get((segment, d, angle))
        name = segment.upper() + (f" D{d:g}" if segment == "rsj" else
                                  f" {'alpha' if segment == 'rsf' else 'beta'} {angle:g}")
        rows.append({"model": name, "segment": segment, "diameter_mm": d, "angle_deg": angle,
                     "element_size_mm": case.element_size_mm, "exit_length_mm": case.exit_length_mm,
                     "flexure_angle_deg": case.flexure_angle_deg, "nodes": g["wall_nodes"],
                     "triangles": g["wall_triangles"], "mobile_nodes": g["mobile_nodes"],
                     "centerline_cm": g["centerline_length_cm"], "nodes_without_exit": bare, "source_nodes": src,
                     "ours_over_source": _ratio(g["wall_nodes"], src), "without_exit_over_source": _ratio(bare, src)})
    return rows


def run_ends(sweep) -> dict:
    """How every run of a sweep ended, and how many jammed."""
    rows = []
    for case in sweep.cases:
        row, status = sweep.run(case)
        out = {**_run_fields(case, row, status), "diameter_mm": case.diameter_mm, "friction": case.friction,
               "element_size_mm": case.element_size_mm, "push_speed": case.push_speed}
        if row is not None:
            out.update({name: _number(row, name) for name in ("end_depth_cm", "end_push_force_N", "end_contact_force_N")})
        rows.append(out)
    counts = {}
    for r in rows:
        key = r["ended_by"] or r["status"]
        counts[key] = counts.get(key, 0) + 1
    return {"sweep": sweep.describe(), "runs": rows, "counts": counts,
            "jams": sum(r["ended_by"] == "jam" for r in rows)}


def run_times(main):
    """Wall time of each run next to the source's minutes for that model and scope."""
    rows = []
    for case in main.cases:
        row, status = main.run(case)
        src = SOURCE_RUN_MINUTES.get((case.segment, role(case)))
        wall = _number(row, "wall_time_s") if row is not None else math.nan
        rows.append({"segment": case.segment, "scope": scope_label(case), "role": role(case),
                     "inputs": describe_inputs(case), "status": status, "wall_time_s": wall, "source_min": src,
                     "source_over_ours": _ratio(src * 60.0 if src else None, wall)})
    return rows


def run_time_summary(rows):
    out = {}
    for r in rows:
        if r["status"] == "ok":
            out.setdefault((r["segment"], r["scope"], r["role"]), []).append(r["wall_time_s"])
    summary = []
    rank = {s: i for i, s in enumerate(SCOPES)}
    for (segment, scope, scope_role), walls in sorted(out.items(), key=lambda kv: (kv[0][0], rank.get(kv[0][2], 9))):
        src = SOURCE_RUN_MINUTES.get((segment, scope_role))
        mean = float(np.mean(walls))
        summary.append({"segment": segment, "scope": scope, "runs": len(walls), "mean_s": mean, "max_s": max(walls),
                        "source_min": src, "ratio": _ratio(src * 60.0 if src else None, mean)})
    return summary
