"""What moved since the previous validation report: the same runs and checks read from two
``report.json`` documents, matched by what they are (model, scope, inputs), never by run key (a
key moves with every setting that enters it, so the same case at a new default has a new key).
The distal resistance sweep's runs (by model, scope, angle or diameter and level), its rate pairs
and the source's claims reproduced per level are compared too, where both reports have them.

``python -m validation.report --previous OLD/report.json`` adds the section; without it the section
says NOT RUN. Copy the landed report's JSON aside first, since the new report replaces it:
``git show HEAD:docs/validation/report.json > /tmp/previous_report.json``.
"""

from __future__ import annotations

from colonsim.markdown import NOT_RUN, md_table, num, percent

MOVED = 0.01  # a relative change at least this large is listed as moved
SMALL_CM = 0.05  # deformations below this (cm) are compared by their absolute change: a ratio of near-zeros means nothing
MOVED_CM = 0.005  # ... and have moved when that is at least this large (cm)
RESISTED_RATE = "rate (resistance sweep)"
RSJ_QUANTITIES = (("A", "A_cm"), ("C", "C_cm"), ("final", "final_cm"), ("max", "max_cm"))
RUN_QUANTITIES = (("final", "final_deformation_cm"), ("max", "max_deformation_cm"),
                  ("peak contact", "peak_contact_force_N"), ("peak push", "peak_push_force_N"))
RESISTED_QUANTITIES = RUN_QUANTITIES + (("largest lag", "max_lag_cm"),)


def _change(before, after, small=None):
    """(relative change, absolute change); the relative one None where ``before`` is below ``small``."""
    if before is None or after is None:
        return None, None
    rel = None if (small is not None and abs(before) < small) or before == 0 else (after - before) / abs(before)
    return rel, after - before


def _moved(rel, absolute):
    if rel is not None:
        return abs(rel) >= MOVED
    return absolute is not None and abs(absolute) >= MOVED_CM


def _quantities(before, after, pairs):
    out = []
    for name, key in pairs:
        rel, absolute = _change(before.get(key), after.get(key), SMALL_CM if key.endswith("_cm") else None)
        out.append({"quantity": name, "before": before.get(key), "after": after.get(key), "change": rel,
                    "absolute": absolute, "moved": _moved(rel, absolute)})
    return out


def _runs(previous, current):
    """RSJ rows (by case) and the RSF/THF/fixed THF runs of the main sweep (by model, scope, inputs)."""
    rows = []
    old_rsj = {r["case"]: r for r in previous.get("rsj", {}).get("rows", [])}
    for r in current.get("rsj", {}).get("rows", []):
        o = old_rsj.get(r["case"])
        if o is not None:
            rows.append({"run": f"RSJ {r['case']}", "status": f"{o.get('status')} -> {r.get('status')}",
                         "quantities": _quantities(o, r, RSJ_QUANTITIES)})
    old_runs = {(r["segment"], r["role"], r["inputs"]): r for r in previous.get("flexure_models", {}).get("rows", [])}
    for r in current.get("flexure_models", {}).get("rows", []):
        o = old_runs.get((r["segment"], r["role"], r["inputs"]))
        if o is not None:
            rows.append({"run": f"{r['segment'].upper()} {r['scope']} {r['inputs']}",
                         "status": f"{o.get('status')} -> {r.get('status')}",
                         "quantities": _quantities(o, r, RUN_QUANTITIES)})
    return rows


def _resisted_runs(previous, current):
    """The distal resistance sweep's runs, matched by model, scope, where and level."""
    def by_case(doc):
        return {(r["segment"], r["role"], r["where"], r["level_N"]): r
                for r in section_at(doc, "resistance", "rows") or []}

    old = by_case(previous)
    return [{"run": f"{k[0].upper()} {r['scope']} {k[2]}, {k[3]:g} N", "sweep": "resistance",
             "status": f"{old[k].get('ended_by')} -> {r.get('ended_by')}",
             "quantities": _quantities(old[k], r, RESISTED_QUANTITIES)}
            for k, r in by_case(current).items() if k in old]


def _verdicts(previous, current):
    """Every pass/fail of the rate and mesh pairs whose verdict changed, and the counts."""
    def pairs(doc):
        found = {}
        for name, section in (("rate", doc.get("rate_check", {})), ("mesh", doc.get("mesh_pair", {})),
                              ("rate (other angles)", doc.get("rate_check", {}).get("angles", {}))):
            for r in (section or {}).get("rows", []) or []:
                for q in r.get("quantities", []):
                    found[(name, r["segment"], r["scope"], r["inputs"], q["quantity"])] = q
        for r in section_at(doc, "resistance", "rate") or []:  # the rate check of the resistance sweep (10 N)
            for quantity, q in (r.get("changes") or {}).items():
                found[(RESISTED_RATE, r["segment"], r["scope"], f"{r['where']}, {r['level_N']:g} N", quantity)] = q
        return found

    old, new = pairs(previous), pairs(current)
    flips = [{"check": k[0], "run": f"{k[1].upper()} {k[2]} {k[3]}", "quantity": k[4],
              "before": old[k]["change"] if k in old else None, "after": new[k]["change"],
              "verdict": f"{_word(old.get(k, {}).get('passed'))} -> {_word(new[k].get('passed'))}",
              "rule": _rule(old.get(k), new[k], k[4])}
             for k in new if (old.get(k) or {}).get("passed") != new[k].get("passed")]

    def count(d):
        """(passed, compared) per check; a quantity below its floor has no verdict and is not compared."""
        counts = {}
        for name in ("rate", "mesh", "rate (other angles)", RESISTED_RATE):
            verdicts = [q["passed"] for k, q in d.items() if k[0] == name and q.get("passed") is not None]
            counts[name] = (sum(map(bool, verdicts)), len(verdicts))
        return counts

    return flips, count(old), count(new)


def _word(passed):
    return "not judged" if passed is None else "pass" if passed else "FAIL"


def _rule(old, new, quantity):
    """Which rule of docs/quasi_static.md changed a pair's verdict, or that its numbers moved."""
    if new.get("why"):
        return new["why"]
    if old is None:
        return ("judged since the rules of 2026-12-07: the largest lag" if quantity in ("lag", "max_lag_cm") else
                "judged since the rules of 2026-12-07: the count of snap-throughs at half the speed"
                if quantity in ("snap-throughs", "snap_throughs") else "judged now")
    return "its numbers moved"


def section_at(doc, *path):
    """``doc[path[0]][path[1]]...``, None where a level is missing (an older report, a section not run)."""
    for key in path:
        doc = doc.get(key) if isinstance(doc, dict) else None
    return doc


def _claims_reproduced(doc, part):
    """Per distal resistance level, how many of the source's claims are reproduced."""
    claims = section_at(doc, "resistance", part) or []
    levels = {level for c in claims for level in (c.get("levels") or {})}
    return {level: sum(c["levels"].get(level, {}).get("verdict") == "REPRODUCED" for c in claims) for level in levels}


def _claim_flips(previous, current):
    """The source's claims (main sweep) whose verdict changed: name, before, after."""
    old = {c["name"]: c.get("verdict") for c in previous.get("claims") or []}
    return [{"claim": c.get("statement") or c["name"], "before": old[c["name"]], "after": c.get("verdict")}
            for c in current.get("claims") or [] if c["name"] in old and old[c["name"]] != c.get("verdict")]


def _reproduced(doc):
    claims = doc.get("claims")
    return None if not claims else sum(c.get("verdict") == "REPRODUCED" for c in claims)


def _summaries(previous, current):
    """The ringing summaries, the claims reproduced (main sweep, and per level of the resistance sweep)
    and the smoothness and surrogate rows."""
    rows = [{"what": "main sweep: the source's claims reproduced", "before": _reproduced(previous),
             "after": _reproduced(current)}]
    rows += [{"what": label, "before": section_at(previous, *path), "after": section_at(current, *path)}
            for label, path in (("main sweep: largest ringing ratio", ("ringing", "sweeps", "main", "largest")),
                                ("main sweep: runs below the ringing limit", ("ringing", "sweeps", "main", "passed")),
                                ("resistance sweep: largest ringing ratio", ("resistance", "quasi_static", "largest")),
                                ("resistance sweep: runs below the ringing limit",
                                 ("resistance", "quasi_static", "below")))]
    for part, quantity in (("claims", "final"), ("claims_largest", "largest")):
        old, new = _claims_reproduced(previous, part), _claims_reproduced(current, part)
        rows += [{"what": f"resistance sweep: the source's claims reproduced on the {quantity} deformation at "
                          f"{level} N", "before": old.get(level), "after": new[level]}
                 for level in sorted(new, key=float)]
    for label, part, key in (("smoothness: departure from a cubic, share of range", "cubic", "departure"),
                             ("surrogate held-out RMSE, share of spread", "surrogate", "share")):
        old = {r["output"]: r for r in section_at(previous, "smoothness", part, "rows") or []}
        for r in section_at(current, "smoothness", part, "rows") or []:
            if r["output"] in old:
                o = old[r["output"]]
                rule = ("" if o.get("passed") == r.get("passed") else
                        f"verdict {_word(o.get('passed'))} -> {_word(r.get('passed'))}: bound now the larger of "
                        + ("2 % of the range and 2 x" if part == "cubic" else "5 % of the spread and 1.25 x")
                        + " the replicates' scatter")
                rows.append({"what": f"{label}: {r['output']}" + (f" ({rule})" if rule else ""),
                             "before": o.get(key), "after": r.get(key)})
    return rows


def changes(previous: dict | None, current: dict) -> dict:
    """The section's document: the runs whose numbers moved, the verdicts that flipped, the summaries."""
    if previous is None:
        return {"ran": False, "note": "pass --previous with the previous report's report.json"}
    runs = _runs(previous, current) + _resisted_runs(previous, current)
    flips, counts_before, counts_after = _verdicts(previous, current)
    header = previous.get("header", {})
    return {"ran": True, "previous": {"date": header.get("date"), "commit": header.get("commit"),
                                      "sweeps": {k: v.get("code") for k, v in header.get("sweeps", {}).items()},
                                      "carried": header.get("carried") or []},
            "runs": runs, "moved": [r for r in runs if any(q["moved"] for q in r["quantities"])],
            "flips": flips, "claim_flips": _claim_flips(previous, current),
            "carried": (current.get("header") or {}).get("carried") or [],
            "pair_counts": {"before": counts_before, "after": counts_after},
            "summaries": _summaries(previous, current)}


def _cell(q):
    if q["before"] is None or q["after"] is None:
        return "-"
    if q["change"] is not None:
        shown = f"{100 * q['change']:+.1f} %"
    elif not q["moved"]:
        shown = "near 0, unchanged"
    else:
        shown = f"{q['absolute']:+.3f} abs."
    return f"{num(q['before'])} -> {num(q['after'])} ({shown})"


def markdown(section) -> list:
    lines = ["## 15. Changes since the previous report", ""]
    if not section or not section.get("ran"):
        return lines + [f"{NOT_RUN}: {(section or {}).get('note', '')}", ""]
    p = section["previous"]
    n_resisted = sum(r.get("sweep") == "resistance" for r in section["runs"])
    code = "its commit and its sweeps' code: `changes.previous` in report.json"
    absent = [k for k, v in p["sweeps"].items() if not v]
    if absent:
        code += f"; sweeps not run there: {', '.join(absent)}"
    if p.get("carried"):
        code += f"; sections it carried from an earlier report: {', '.join(p['carried'])}"
    lines += [f"Against the report of {p['date']} ({code}). "
              "Runs are matched by model, scope and inputs. A quantity has moved when it changed by "
              f"{100 * MOVED:g} % or more (deformations below {SMALL_CM:g} cm: by {MOVED_CM:g} cm or more, shown as the "
              f"absolute change). Of the {len(section['runs'])} runs the report's tables show in both (RSJ at mu 0, every RSF, THF and "
              f"fixed THF run of the main sweep, and {n_resisted} of the distal resistance sweep), "
              f"{len(section['moved'])} moved."
              + (" The sections of the sweeps carried from the previous report (" + ", ".join(section["carried"])
                 + ") are its runs and compare equal." if section.get("carried") else ""), ""]
    tables = {"rsj": [], "main": [], "resistance": []}  # one table each: their rows show different quantities
    for r in section["moved"]:
        tables["resistance" if r.get("sweep") == "resistance" else "rsj" if r["run"].startswith("RSJ ") else
               "main"].append(r)
    for group in tables.values():
        if group:
            names = [q["quantity"] for q in group[0]["quantities"]]
            lines += [md_table(group, [("run", "run")] + [
                (n, (lambda i: lambda r: _cell(r["quantities"][i]))(i)) for i, n in enumerate(names)]), ""]
    before, after = section["pair_counts"]["before"], section["pair_counts"]["after"]
    lines += ["Pass counts of the pair checks (passed / compared quantities; one below its floor is not compared): " + "; ".join(
        f"{name} {before[name][0]}/{before[name][1]} -> {after[name][0]}/{after[name][1]}" for name in after) + ".", ""]
    if section["flips"]:
        lines += [md_table(section["flips"], [("check", "check"), ("run", "run"), ("quantity", "quantity"),
                                              ("change before", lambda r: percent(r["before"], "+.1f")),
                                              ("change now", lambda r: percent(r["after"], "+.1f")), ("verdict", "verdict"),
                                              ("what changed it", lambda r: r.get("rule") or "-")]), ""]
    if section.get("claim_flips"):
        lines += ["The source's claims (main sweep, section 4) whose verdict changed:", "",
                  md_table(section["claim_flips"], [("claim", "claim"), ("before", "before"), ("now", "after")]), ""]
    if section["summaries"]:
        lines += [md_table(section["summaries"], [("what", "what"), ("before", lambda r: num(r["before"])),
                                                  ("now", lambda r: num(r["after"]))]), ""]
    return lines
