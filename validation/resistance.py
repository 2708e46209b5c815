"""The validation report's section on the distal resistance (docs/model.md, "Loading"), read from
a sweep of the ``resistance`` preset (``colonsim sweep --preset resistance --out DIR``, passed as
``--resistance-sweep DIR``).

Per colon model and level: every scope's final and largest deformation, its lag, the peak contact
and push forces, how the run ended and its ringing ratio; RSF/THF laid out like the source's
comparison (rows: angle; columns: UTC - SDC and PDC - SDC final deformation); RSJ's points A, B,
C per level and whether C > A once the tip is held back; and the rate check at 10 N (half the push
speed) of one case per model. Runs missing from the table are listed, never filled in.

The runs that ring above the limit are listed with what their ringing is made of and, given a sweep
of the same runs at half the push speed (``benchmarks/sweeps/ringing_half_speed.toml``, written
from the resistance sweep by ``validation/ringing_half_speed.py``, passed as
``--ringing-half-sweep DIR``), with the proposed bound's verdict (docs/notes/2026-11-model-studies.md, "Ringing that no
push speed removes"): half the speed lowers the ratio by less than :data:`BOUND_RATIO_FALL` and
the rate pair passes.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from colonsim.insertion.case.insertion_case import InsertionCase
from colonsim.insertion.case.ringing import RINGING_LIMIT, ringing_at_drops, ringing_wavelength
from colonsim.insertion.study.claims import evaluate_claims
from colonsim.insertion.study.sweep_presets import HALF_SPEED
from colonsim.markdown import NOT_RUN, md_table, num
from .carry import carried_lines
from .resistance_readings import claim_readings
from .sections import PAIR_QUANTITIES, case_geometry, pair_quantities
from .sweeps import role, scope_label

LEVELS_N = (0.0, 5.0, 10.0, 20.0)
SHAPES_LEVEL_N = 10.0  # the level whose final shapes the section draws (the "typical")
# The proposed bound for a run above the ringing limit (not applied by the program): half the push
# speed lowers its ratio by less than this share, and its rate pair passes (docs/notes/2026-11-model-studies.md, "Ringing
# that no push speed removes"). A ringing that inertia makes falls with the speed (its forces go as
# the speed's square); one that stays or grows at half the speed is the mesh's or the path's.
BOUND_RATIO_FALL = 0.20


def _number(row, column):
    value = row.get(column) if row is not None else None
    return float(value) if value is not None and np.isfinite(value) else None


def _ended(row):
    """Why a run ended, and whether its tip ended turned back (docs/model.md, "Outputs"; rows of
    sweeps made before 2026-11-29 do not record it)."""
    back = row.get("tip_turned_back_cm")
    return row["ended_by"] + ("" if back is None else f", tip turned back from {back:.1f} cm")


def _where(case):
    if case.segment == "rsj":
        return f"D {case.diameter_mm:g} mm"
    return f"{'alpha' if case.segment == 'rsf' else 'beta'} {case.angle_deg:g} deg"


def resistance_section(sweep, half=None) -> dict:
    """Rows of every run of the sweep at the default push speed, the source-style differences, the
    RSJ points and the rate pairs; ``half``: the sweep of its runs above the ringing limit at half
    the push speed (or None), for the proposed bound."""
    if not sweep.ran:
        return {"ran": False}
    speed = InsertionCase().push_speed
    rows, missing = [], []
    for case in sweep.cases:
        if not math.isclose(case.push_speed, speed):
            continue
        row, status = sweep.run(case)
        if row is None:
            missing.append(f"{case.segment.upper()} {scope_label(case)} {_where(case)} {case.distal_resistance_N:g} N: "
                           f"{status}")
            continue
        rows.append({"segment": case.segment, "where": _where(case), "scope": scope_label(case), "role": role(case),
                     "angle_deg": case.angle_deg, "diameter_mm": case.diameter_mm,
                     "level_N": case.distal_resistance_N, **{c: _number(row, c) for c in (
                         "final_deformation_cm", "max_deformation_cm", "max_lag_cm", "final_lag_cm",
                         "peak_contact_force_N", "peak_push_force_N", "point_A_cm", "point_B_cm", "point_C_cm",
                         "ringing_ratio", "tip_turned_back_cm")},
                     "ended_by": str(row.get("ended_by", "")), "quasi_static": bool(row.get("quasi_static")),
                     "ringing_cause": str(row.get("ringing_cause") or "")})
    claims = claims_per_level(sweep, speed)
    return {"ran": True, "rows": rows, "missing": missing, "differences": _differences(rows),
            "rsj": [r for r in rows if r["segment"] == "rsj"], "rate": _rate_pairs(sweep, speed),
            "quasi_static": _quasi_static(rows), "remainder": ringing_remainder(sweep, speed, half), "claims": claims,
            "claims_largest": claims_per_level(sweep, speed, "max_deformation_cm"),
            "readings": claim_readings(claims, rows), "figures": []}


def claims_per_level(sweep, speed, quantity="final_deformation_cm") -> list:
    """The source's claims on the runs of each level at the default push speed (the preset's RSJ
    runs are at mu = 0, so the RSJ claims compare the scopes there and the friction claim cannot be
    evaluated), comparing ``quantity``. One row per claim: its verdict and reason at every level."""
    table = sweep.table
    at_speed = table[np.isclose(table["push_speed"].astype(float), speed)]
    rows = {}
    for level in LEVELS_N:
        subset = at_speed[np.isclose(at_speed["distal_resistance_N"].astype(float), level)]
        if subset.empty:
            continue
        for claim in evaluate_claims(subset, frictions=(0.0,), quantity=quantity):
            row = rows.setdefault(claim.name, {"name": claim.name, "statement": claim.statement, "levels": {}})
            row["levels"][f"{level:g}"] = {"verdict": claim.verdict, "reason": claim.reason,
                                           "missing": len(claim.missing)}
    return list(rows.values())


def _differences(rows) -> list:
    """RSF/THF per level and angle: UTC - SDC and PDC - SDC final deformation (cm), as the source."""
    out = []
    for segment in ("rsf", "thf", "thf-fixed"):
        for level in LEVELS_N:
            for angle in sorted({r["angle_deg"] for r in rows if r["segment"] == segment}):
                final = {r["role"]: r["final_deformation_cm"] for r in rows
                         if r["segment"] == segment and r["level_N"] == level and r["angle_deg"] == angle}
                if not final:
                    continue
                sdc = final.get("sdc")

                def minus(name, sdc=sdc, final=final):
                    return None if final.get(name) is None or sdc is None else final[name] - sdc
                out.append({"segment": segment, "level_N": level, "angle_deg": angle, "utc_minus_sdc": minus("utc"),
                            "pdc_minus_sdc": minus("pdc")})
    return out


def _quasi_static(rows) -> dict:
    """The ringing verdicts of the rows (docs/quasi_static.md): ``below`` counts the quasi-static runs
    (the ratio over max(mean, 1 N) below the limit, snap-throughs left out), ``above`` names the rest
    with their cause."""
    ratios = [r["ringing_ratio"] for r in rows if r["ringing_ratio"] is not None]
    above = [f"{r['segment'].upper()} {r['scope']} {r['where']} {r['level_N']:g} N: {num(r['ringing_ratio'])}"
             + (f" ({r['ringing_cause']})" if r.get("ringing_cause") else "")
             for r in rows if r["ringing_ratio"] is not None and not r["quasi_static"]]
    return {"runs": len(rows), "measured": len(ratios), "below": sum(bool(r["quasi_static"]) for r in rows
                                                                     if r["ringing_ratio"] is not None),
            "largest": max(ratios) if ratios else None, "above": above}


def measured_ringing(sweep, speed):
    """(case, row, ringing ratio) of each run of ``sweep`` at the push speed ``speed`` whose table
    row holds a ringing ratio, in the sweep's order."""
    for case in sweep.cases:
        row = sweep.run(case)[0] if math.isclose(case.push_speed, speed) else None
        ratio = _number(row, "ringing_ratio")
        if ratio is not None:
            yield case, row, ratio


def ringing_remainder(sweep, speed, half=None) -> dict:
    """The runs at the default speed that ring above the limit (``above``): the ringing in newtons
    next to the mean push force it is divided by, the push distance it repeats over
    (:func:`~colonsim.insertion.case.outcomes.ringing_wavelength`, from the run's time series as
    its summary measures it: the closing settle left out), the wall mesh's ring spacing and, from
    ``half`` (the same runs at half the push speed; None: not run), the proposed bound
    (:func:`ringing_bound`); and the ringing in newtons of the runs below the limit
    (``rms_below_N``), for scale."""
    above, rms_below = [], []
    for case, row, ratio in measured_ringing(sweep, speed):
        qs = sweep.summary(row).get("quasi_static") or {}
        if bool(row.get("quasi_static")):
            if qs.get("push_force_rms_N") is not None:
                rms_below.append(qs["push_force_rms_N"])
            continue
        ts = sweep.timeseries(row, ["phase", "depth_cm", "push_force_N", "contact_nodes"])
        wavelength, drops = None, None
        if ts is not None:
            ts = ts[ts["phase"] != "settle"]
            series = (ts["depth_cm"].to_numpy() / 100, ts["push_force_N"].to_numpy(),
                      ts["contact_nodes"].to_numpy() > 0)
            w = ringing_wavelength(*series)
            wavelength = 1e3 * w if np.isfinite(w) else None
            drops = ringing_at_drops(*series)
        geometry = case_geometry(case)
        rings = len(geometry.nodes) // (int(geometry.end_ring.sum()) // 2)  # two end rings of equal count
        above.append({"segment": case.segment, "scope": scope_label(case), "where": _where(case),
                      "level_N": case.distal_resistance_N, "ringing_ratio": ratio, "rms_N": qs.get("push_force_rms_N"),
                      "mean_N": qs.get("mean_push_force_N"), "wavelength_mm": wavelength, "drops": drops,
                      "ring_spacing_mm": 1e3 * geometry.centerline_length / (rings - 1),
                      **ringing_bound(row, half, case)})
    return {"above": above, "rms_below_N": rms_below, "half_ran": half is not None and half.ran}


def ringing_bound(row, half, case) -> dict:
    """The proposed bound for the run ``row`` of ``case``, from its run at half the push speed in
    the sweep ``half``: the ratio there (``half_ratio``), its relative change, the rate pair's
    changes (:func:`rate_changes`) and ``bound`` (True: quasi-static by the bound; None: the
    half-speed run is missing)."""
    variant = None if half is None else half.run(half_speed_twin(case))[0]
    if variant is None:
        return {"half_ratio": None, "ratio_change": None, "rate": None, "bound": None}
    ratio, half_ratio = _number(row, "ringing_ratio"), _number(variant, "ringing_ratio")
    change = None if ratio is None or half_ratio is None else half_ratio / ratio - 1
    rate = rate_changes(row, variant, case.segment)
    bound = None if change is None or rate["passed"] is None else change > -BOUND_RATIO_FALL and rate["passed"]
    return {"half_ratio": half_ratio, "ratio_change": change, "rate": rate, "bound": bound}


def rate_changes(base, variant, segment) -> dict:
    """The rate pair of the run ``base`` of ``segment`` and its half-speed run ``variant``, judged as
    the main sweep's pairs are (:func:`validation.sections.pair_quantities`): ``changes``, column ->
    relative change (None below the quantity's floor), tolerance and verdict; and ``passed``."""
    quantities, passed = pair_quantities(base, variant, segment, "rate")
    return {"changes": {q["column"]: {"change": None if not np.isfinite(q["change"]) else q["change"],
                                      "limit": q["tolerance"], "passed": q["passed"], "why": q.get("why", "")}
                        for q in quantities},
            "passed": passed}


def half_speed_twin(case):
    """``case`` at the rate check's half push speed, every other input the same."""
    return dataclasses.replace(case, push_speed=HALF_SPEED)


def _rate_pairs(sweep, speed) -> list:
    """Each run at the default speed whose half-speed twin the sweep defines, against that twin."""
    defined = {c.key() for c in sweep.cases}
    out = []
    for case in sweep.cases:
        twin = half_speed_twin(case)
        if not math.isclose(case.push_speed, speed) or twin.key() not in defined:
            continue
        base, variant = sweep.run(case)[0], sweep.run(twin)[0]
        row = {"segment": case.segment, "scope": scope_label(case), "where": _where(case),
               "level_N": case.distal_resistance_N, "changes": {}, "passed": None}
        if base is not None and variant is not None:
            row.update(rate_changes(base, variant, case.segment))
        out.append(row)
    return out


def _claims_table(claims) -> str:
    return md_table(claims, [("claim", "statement")] + [
        (f"{level:g} N", (lambda r, k=f"{level:g}": _verdict_cell(r["levels"].get(k)))) for level in LEVELS_N])


def _verdict_cell(entry):
    if entry is None:
        return "-"
    if entry["missing"]:
        return f"{entry['verdict']} ({entry['missing']} runs missing)"
    reason = " ".join(entry["reason"].split())  # one table cell
    return entry["verdict"] + (f": {reason}" if reason else "")


def _remainder_lines(remainder) -> list:
    if not remainder["above"]:
        return []
    below = np.asarray(remainder["rms_below_N"], dtype=float)
    scale = (f"; the {below.size} runs below the limit ring by {num(np.min(below))}-{num(np.max(below))} N (median "
             f"{num(np.median(below))} N)" if below.size else "")
    columns = [("model", lambda r: r["segment"].upper()), ("scope", "scope"), ("case", "where"),
               ("level [N]", lambda r: f"{r['level_N']:g}"), ("ringing", "ringing_ratio"), ("RMS [N]", "rms_N"),
               ("mean push [N]", "mean_N"), ("repeats every [mm of push]", "wavelength_mm"),
               ("ring spacing [mm]", "ring_spacing_mm"), ("at drops", _drops_cell)]
    intro = ("The runs above the limit: the ringing in newtons (RMS about the trend; over the mean push force it is "
             "the ratio), the push distance it repeats over (the peak of its periodogram, "
             "`outcomes.ringing_wavelength`) and the wall mesh's ring spacing (docs/model.md, \"Time integration and "
             f"damping\", what no push speed removes){scale}. \"At drops\": the share of the squared ringing within "
             "6 mm of push of a drop of the push force by more than 1 N within 2 mm (a loop snapping through: a step, "
             "not an oscillation), the share of the push that lies there and the number of drops "
             "(`outcomes.ringing_at_drops`)")
    if not remainder.get("half_ran"):
        return [intro + ":", "", md_table(remainder["above"], columns), "",
                f"The proposed bound: {NOT_RUN}: no --ringing-half-sweep (`python -m validation.ringing_half_speed "
                "RESISTANCE_SWEEP`, then `colonsim sweep benchmarks/sweeps/ringing_half_speed.toml --out DIR`).", ""]
    judged = [r for r in remainder["above"] if r["bound"] is not None]
    held = [r for r in judged if r["bound"]]
    columns += [("at half speed", lambda r: "-" if r["half_ratio"] is None else
                 f"{num(r['half_ratio'])} ({100 * r['ratio_change']:+.0f} %)"),
                ("rate pair", _rate_cell),
                ("bound", lambda r: {True: "holds", False: "NO", None: "-"}[r["bound"]])]
    return [intro + "; and the proposed bound (docs/notes/2026-11-model-studies.md, \"Ringing that no push speed removes\"): the same "
            f"run at half the push speed rings at least {100 * (1 - BOUND_RATIO_FALL):.0f} % as much (inertia's ringing "
            "would fall), and its rate pair passes (5 % on the deformations, 10 % on the peak forces; the failing "
            "columns are named):", "", md_table(remainder["above"], columns), "",
            f"By the proposed bound, {len(held)} of the {len(judged)} runs above the limit with a half-speed run count "
            f"as quasi-static ({len(remainder['above']) - len(judged)} without one).", ""]


def _drops_cell(r):
    d = r.get("drops")
    if d is None or not np.isfinite(d["share"]):
        return "-"
    return f"{100 * d['share']:.0f} % / {100 * d['push_share']:.0f} % ({d['drops']})" if d["drops"] else "no drop"


def _rate_cell(r):
    if r["rate"] is None:
        return "-"
    failed = [f"{c.replace('_cm', '').replace('_N', '')} " + ("count differs" if v["change"] is None else
                                                               f"{100 * v['change']:+.1f} %")
              for c, v in r["rate"]["changes"].items() if v["passed"] is False]
    return {True: "passes", None: "-"}.get(r["rate"]["passed"], "NO: " + ", ".join(failed))


def _turned_back_lines(rows) -> list:
    """The runs whose tip ended turned back (docs/model.md, "Distal resistance"): their final
    deformation and lag describe a fold of the scope, not a loop."""
    back = [r for r in rows if r.get("tip_turned_back_cm") is not None]
    if not back:
        return []
    runs = "; ".join(f"{r['segment'].upper()} {r['scope']} {r['where']} {r['level_N']:g} N from "
                     f"{r['tip_turned_back_cm']:.1f} cm of push (final {num(r['final_deformation_cm'])} cm, largest "
                     f"{num(r['max_deformation_cm'])} cm)" for r in back)
    return [f"Tip turned back at the end ({len(back)} run(s); their final deformation and lag describe a fold of "
            f"the scope in the exit, not a loop behind a held tip): {runs}.", ""]


def markdown(section) -> list:
    """The section's Markdown lines."""
    lines = ["## 14. Distal resistance", "",
             "The colon beyond the model holds the tip back (docs/model.md, \"Loading\", distal resistance): the "
             "`resistance` preset runs every colon model at 0 / 5 / 10 / 20 N (none, light, typical, difficult), the "
             "source's angles and the three meshed scopes, and the rate check at 10 N. Lag: pushed depth minus the "
             "tip's advance along the centerline.", ""] + carried_lines(section)
    if not section["ran"]:
        return lines + [f"{NOT_RUN}: no --resistance-sweep (`colonsim sweep --preset resistance --out DIR`).", ""]
    qs = section["quasi_static"]
    lines += [f"Quasi-static: {qs['below']} of {qs['measured']} measured runs ring below {RINGING_LIMIT:g} (largest "
              f"{num(qs['largest'])})" + (": above it " + "; ".join(qs["above"]) if qs["above"] else "") + ".", ""]
    if section.get("remainder"):
        lines += _remainder_lines(section["remainder"])
    lines += _turned_back_lines(section["rows"])
    if section["missing"]:
        lines += [f"Missing runs ({len(section['missing'])}): " + "; ".join(section["missing"]) + ".", ""]
    for segment in ("rsj", "rsf", "thf", "thf-fixed"):
        rows = [r for r in section["rows"] if r["segment"] == segment]
        if not rows:
            continue
        lines += [f"### {segment.upper()}", "",
                  md_table(rows, [("level [N]", lambda r: f"{r['level_N']:g}"), ("case", "where"), ("scope", "scope"),
                                  ("final [cm]", "final_deformation_cm"), ("max [cm]", "max_deformation_cm"),
                                  ("lag max / final [cm]", lambda r: f"{num(r['max_lag_cm'])} / {num(r['final_lag_cm'])}"),
                                  ("peak contact [N]", "peak_contact_force_N"), ("peak push [N]", "peak_push_force_N"),
                                  ("ended by", _ended), ("ringing", "ringing_ratio")]), ""]
    rsj = section["rsj"]
    if rsj:
        lines += ["RSJ points per level (C > A: the loop behind a held tip grows):", "",
                  md_table(rsj, [("level [N]", lambda r: f"{r['level_N']:g}"), ("case", "where"), ("scope", "scope"),
                                 ("A", "point_A_cm"), ("B", "point_B_cm"), ("C", "point_C_cm"),
                                 ("C > A", lambda r: "-" if r["point_A_cm"] is None or r["point_C_cm"] is None
                                  else ("yes" if r["point_C_cm"] > r["point_A_cm"] else "no"))]), ""]
    if section["claims"]:
        lines += ["The source's claims at every level (RSJ at mu = 0: the friction claim needs runs the preset "
                  "does not have):", "", _claims_table(section["claims"]), "",
                  "The same claims on the largest deformation during the run (the source's end values are also its "
                  "largest, docs/surrogate.md \"The pain proxy\"; the RSJ ordering compares points A and C either way):",
                  "", _claims_table(section["claims_largest"]), ""]
    readings = section.get("readings") or {}
    if readings:
        statements = {c["name"]: c["statement"] for c in section["claims"]}
        lines += ["Readings of the claims reproduced at no level, from the runs' numbers (lag: the length of scope "
                  "buckled behind the held tip):", ""]
        for name, sentences in readings.items():
            lines += [f"- *{statements[name]}*"] + [f"  - {x}" for x in sentences]
        lines += [""]
    for fig in section["figures"]:
        lines += [f"![{fig['title']}]({fig['file']})", ""]
    diffs = section["differences"]
    if diffs:
        lines += ["Laid out like the source (final deformation differences, cm; negative: the thinner scope deforms "
                  "less):", "",
                  md_table(diffs, [("model", lambda r: r["segment"].upper()), ("level [N]", lambda r: f"{r['level_N']:g}"),
                                   ("angle [deg]", lambda r: f"{r['angle_deg']:g}"), ("UTC - SDC", "utc_minus_sdc"),
                                   ("PDC - SDC", "pdc_minus_sdc")]), ""]
    if section["rate"]:
        lines += ["Rate check at half the push speed (as the main sweep's, section 8: limits 5 % on A and C (RSJ "
                  "only), final and max, 10 % on the peak forces; \"-\" below a quantity's floor):", "",
                  md_table(section["rate"], [("model", lambda r: r["segment"].upper()), ("scope", "scope"),
                                             ("case", "where"), ("level [N]", lambda r: f"{r['level_N']:g}"),
                                             *[(name, (lambda r, c=column: "-" if c not in r["changes"] or
                                                       r["changes"][c]["change"] is None
                                                       else f"{100 * r['changes'][c]['change']:+.1f} %"))
                                               for column, name, _, _ in PAIR_QUANTITIES],
                                             ("passes", lambda r: {True: "yes", False: "NO", None: "-"}[r["passed"]])]),
                  ""]
    return lines
