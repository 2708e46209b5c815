"""The validation report as Markdown, written from the same document as ``report.json``."""

from __future__ import annotations

import shlex
from pathlib import Path

from colonsim.files import atomic_path
from colonsim.insertion.case.run_summary import ENDINGS
from colonsim.insertion.study.verification_rules import GROUPS
from colonsim.markdown import NOT_RUN, md_table, num, percent
from .carry import carried_lines
from .changes import markdown as changes_markdown
from .markdown_checks import mesh_pair, rate_check, ringing, smoothness, verdict
from .resistance import markdown as resistance_markdown
from .sweep_records import RECORDS

ROOT = RECORDS.parents[1]
# a folder outside the repository, as the page names it (the JSON keeps the machine's path)
OUTSIDE = "DIR"


def shown_path(path) -> str:
    """``path`` as the page names it: relative to the repository, or, outside it, as DIR/NAME, so
    that no page names a build machine's folders (report.json keeps them as given)."""
    path = Path(path)
    if not path.is_absolute():
        return path.as_posix()
    return path.relative_to(ROOT).as_posix() if path.is_relative_to(ROOT) else f"{OUTSIDE}/{path.name}"


def shown_folder(folder) -> str:
    """A sweep folder as the page names it, with the committed record of the same name if there is one."""
    record = RECORDS / Path(folder).name
    return f"`{shown_path(folder)}`" + (f" (record `{record.relative_to(ROOT).as_posix()}`)" if record.is_dir() else "")


def shown_command(command) -> str:
    """The command that made the report, its paths as :func:`shown_path` names them."""
    return " ".join(shown_path(word) if word.startswith("/") else word for word in shlex.split(command))


def commits(counts) -> str:
    """How many commits of the code made a sweep's rows (report.json names them)."""
    return f"rows made by {len(counts)} commit{'s' if len(counts) != 1 else ''} of the code" if counts else "-"


def header(doc):
    h = doc["header"]

    def sweep_line(s):
        if s.get("carried_from"):
            mark = s["carried_from"]
            return f"carried from the report of {mark['date']}: " + sweep_line({k: v for k, v in s.items()
                                                                               if k != "carried_from"})
        if s["folder"] is None:
            return f"{NOT_RUN} (not given: --validation-sweep)"
        if not s["ran"]:
            return f"{shown_folder(s['folder'])}: {NOT_RUN} (no results table)"
        estimate = ", ".join(f"{k} ({n})" for k, n in (s.get("time_step_estimate") or {}).items()) or "-"
        rules = ", ".join(f"{k} ({n})" for k, n in (s.get("rules") or {}).items()) or "-"
        return (f"{shown_folder(s['folder'])}: {s['in_table']} of the {s['defined']} runs it defines in the table "
                f"({s['ok']} ok, {s['failed']} failed); {commits(s['code'])}; time-step estimate of its runs: "
                f"{estimate}; run rules: {rules}")

    return [
        "# colonsim validation report", "",
        f"- date: {h['date']}",
        f"- code: one commit of the repository ({h['commit_note']}); the commits of the report and of every "
        "sweep's rows are in `report.json` (`header`)",
        f"- machine: {h['machine']}",
        f"- command (from the repository's root; {OUTSIDE}: a folder outside it, e.g. a record unpacked with "
        f"`python -m validation.sweep_records unpack benchmarks/records/NAME {OUTSIDE}/NAME`): "
        f"`{shown_command(h['command'])}`",
        f"- main sweep: {sweep_line(h['sweeps']['main'])}",
        f"- validation sweep: {sweep_line(h['sweeps']['validation'])}",
        *([f"- sections carried from the previous report (their sweeps not given; each says so under its heading): "
           + ", ".join(h["carried"])] if h.get("carried") else []),
        f"- size of the verification part: **{h['size']}**"
        + (" (CI sizes of the tests, quick calibration budget)" if h["size"] == "reduced"
           else " (full sizes of the tests, default calibration budget)"),
        f"- generated in {doc['timings']['total_s']:.0f} s (verification {doc['timings']['verification_s']:.0f} s, "
        f"calibration {doc['timings']['calibration_s']:.0f} s), one Numba thread", "",
        "The model and its assumptions: `docs/model.md`. Every number of this project below is computed by this "
        "script or read from the sweeps' tables and run folders; the source's numbers are constants of "
        "`insertion/study/reference.py` (LS-DYNA results of the source's Chapter V). Scopes are named by the diameters of "
        "the source's scope meshes (UTC 9.2, PDC 11.1, SDC 13.3 mm; the catalogue's PDC and SDC are 11.3 and "
        "12.8 mm, docs/model.md, \"Colonoscope\").", ""]


def details(row):
    """The further measured numbers a row's rule judges, e.g. "active contacts 11"."""
    return "; ".join(f"{name} {num(value)}" for name, value in row["details"].items()) or "-"


def verification(rows):
    n_pass = sum(r["passed"] for r in rows)
    lines = ["## 1. Verification of the solver", "",
             f"{n_pass} of {len(rows)} checks pass. Each row is one entry of the verification table "
             "(`insertion/study/verification_table.py`: the problem, its rule and why), which the test-suite runs "
             "row by row; the relative error is (measured - analytic) / |analytic|.", ""]
    for group in dict.fromkeys(r["group"] for r in rows):
        lines += [f"### {GROUPS.get(group, group)}", "", md_table([r for r in rows if r["group"] == group], [
            ("quantity", "quantity"),
            ("analytic", lambda r: num(r["analytic"]) + (f" {r['unit']}" if r["unit"] and r["analytic"] is not None else "")),
            ("measured", lambda r: num(r["measured"]) + (f" {r['unit']}" if r["unit"] else "")),
            ("rel. error", lambda r: percent(r["relative_error"])), ("rule", "rule"), ("also measured", details),
            ("why", "why"), ("result", lambda r: verdict(r["passed"]))]), ""]
        if group == "rod":
            lines += ["![buckling](figures/buckling.png)", "",
                      "Dynamic relaxation of the clamped-free rod under a dead axial load with a lateral imperfection "
                      "of 1e-3 P: below the Euler load against linear beam-column theory, above it against the "
                      "elastica of the perfect rod (the imperfection adds a little).", ""]
        if group == "shell":
            lines += ["![inflation](figures/inflation.png)", ""]
    return lines


def calibration(c):
    return ["## 2. Calibration recovery", "",
            f"The bundled tensile data are synthetic (`data/README.md`): {c['specimen']} (thickness "
            f"{c['thickness_mm']:.3f} mm) was generated with known parameters on a 4x finer mesh plus "
            f"{c['noise_sd_N']:g} N load-cell noise. The FE pipeline (Latin hypercube -> CMA-ES -> Nelder-Mead, "
            f"{c['budget']} budget, seed {c['seed']}, {c['evaluations']} evaluations, {c['wall_time_s']:.0f} s) "
            "identified:", "",
            md_table(c["parameters"], [
                ("parameter", "parameter"), ("identified [Pa]", "identified_Pa"), ("sd [Pa]", "sd_Pa"),
                ("95 % interval [Pa]", lambda r: f"{num(r['ci95_Pa'][0])} .. {num(r['ci95_Pa'][1])}"),
                ("true [Pa]", "true_Pa"), ("(identified - true) / sd", "error_in_sd")]), "",
            f"- fit: RMS force error {c['rms_N']:.4f} N against the {c['noise_sd_N']:g} N noise put in; "
            f"R^2 = {c['r2']:.6f}; objective e1 {num(c['stages_e1']['initial'])} (initial guess) -> "
            f"{num(c['stages_e1']['cma-es'])} (CMA-ES) -> {num(c['stages_e1']['nelder-mead'])} N^2 (Nelder-Mead).",
            f"- the true parameters lie {'inside' if c['truth_in_95_region'] else '**outside**'} the fit's 95 % "
            f"joint confidence region (squared Mahalanobis distance {c['mahalanobis2']:.2f}, threshold "
            f"{c['region_threshold']:.2f}).",
            f"- C10 and C01 correlate at {c['correlation_C10_C01']:.4f}: uniaxial data pin their sum (mu0) and C11, "
            "not their split (docs/model.md, \"Tissue law\"), hence the wide individual intervals and the tight one "
            "of mu0.",
            f"- the clamped FE strip is {c['fe_over_closed_form_minus_1_at_end']:.2%} stiffer than the closed form at "
            "60 mm with the identified parameters.", "",
            "![calibration fit](figures/calibration_fit.png)", ""]


def _missing(rows, what="case"):
    gone = [r for r in rows if r["status"] != "ok"]
    return (["Runs without numbers (nothing guessed): " + ", ".join(f"{r[what]} ({r['status']})" for r in gone) + ".", ""]
            if gone else [])


def rsj(section):
    rows, checks = section["rows"], section["checks"]
    order = ", ".join(f"{d}: {num(v)}" for d, v in checks["final_ordered_sdc_pdc_utc"].items())
    span = checks["source_over_ours_range"]
    return ["## 3. RSJ against the source's table (mu = 0)", "",
            "Colon deformation (largest displacement of the mobile sigmoid, cm; docs/model.md, \"Outputs\") of the "
            "main sweep's RSJ runs at mu = 0, with the scope diameters of the source's meshes (UTC 9.2, PDC 11.1, "
            "SDC 13.3 mm). A = the first maximum (the tip negotiating the angulation), B = the following minimum, "
            "C = the largest value after B; final = the value at the end of the run (the tip 2 cm past the "
            "sigmoid's fixed end), max = the largest over the run. The source's final value equals its C. "
            "Quasi-static: the ringing ratio of the push force (docs/model.md, \"Time integration and damping\"; "
            "below 0.1), in brackets.", "",
            md_table(rows, [
                ("case", "case"), ("scope", "scope"), ("A", "A_cm"), ("B", "B_cm"), ("C", "C_cm"),
                ("final", "final_cm"), ("max", "max_cm"), ("A (source)", "A_source_cm"), ("C (source)", "C_source_cm"),
                ("source / ours: A", "A_source_over_ours"), ("C", "C_source_over_ours"),
                ("final", "final_source_over_ours"), ("C > A", "C_gt_A"),
                ("ended by", lambda r: r.get("ended_by") or r["status"]),
                ("quasi-static", lambda r: f"{num(r.get('quasi_static'))} ({num(r.get('ringing_ratio'))})"
                 if r["status"] == "ok" else "-")]), "",
            f"- runs: {checks['runs']}; A and C found in all six: {num(checks['A_and_C_found'])}; C > A in all six: "
            f"{num(checks['C_gt_A'])}; final deformation ordered SDC > PDC > UTC: {order}.",
            f"- the source's values over ours (A, C, final): {num(span[0], 3)} to {num(span[1], 3)}." if span else
            "- no ratio to the source: no RSJ run at mu = 0 in the table.", "",
            "![RSJ deformation](figures/rsj_deformation.png)", "",
            "Deformation against insertion depth of the six runs (our points A, B, C marked, x where the tip "
            "reaches the sigmoid's fixed end); the source's A "
            "(dotted) and C (dashed) values as horizontal lines in the scope's colour: the source's depths of "
            "these points are not known.", "", *_missing(rows)]


def claims(claim_list):
    def tally(cl):
        rows = [e for e in cl["evidence"] if "holds" in e]
        return f"{sum(e['holds'] is True for e in rows)} of {len(rows)}" if rows else "-"

    lines = ["## 4. The source's claims", "",
             "Each claim is evaluated on the main sweep's table by a function of `insertion/study/claims.py` (unit-tested "
             "in `tests/test_claims.py`). REPRODUCED: every comparison of the criterion holds. NOT REPRODUCED: all "
             "runs present and at least one comparison fails. NOT EVALUATED: a run the criterion needs is missing "
             "or failed; nothing is inferred from the runs present. Deformations in cm; reductions and advantages "
             "are fractions of the SDC's deformation. Where a claim fails, the reading below it is built from the "
             "runs' numbers (`validation/readings.py`).", "",
             "| claim | verdict | comparisons that hold |", "|---|---|---|"]
    lines += [f"| 4.{k} {cl['statement']} | {cl['verdict']} | {tally(cl)} |" for k, cl in enumerate(claim_list, start=1)]
    lines += [""]
    for k, cl in enumerate(claim_list, start=1):
        lines += [f"### 4.{k} {cl['statement']}", "", f"**Criterion.** {cl['criterion']}", "",
                  f"**Verdict: {cl['verdict']}** ({tally(cl)} comparisons hold)."
                  + (f" {cl['reason']}." if cl["reason"] else ""), ""]
        if cl["evidence"]:
            keys = list(dict.fromkeys(key for e in cl["evidence"] for key in e))
            lines += [md_table(cl["evidence"], [(key, key) for key in keys]), ""]
        if cl.get("reading"):
            lines += ["**Reading.**", "", *[f"- {s}" for s in cl["reading"]], ""]
    return lines


def _phases(r):
    return "; ".join(f"{p['phase']} {p['from_cm']:.1f}-{p['to_cm']:.1f} cm (max {p['max_deformation_cm']:.2f}, "
                     f"end {p['end_deformation_cm']:.2f})" for p in r.get("phases") or []) or "-"


def model_runs(rows):
    columns = [("model", lambda r: r["segment"].upper()), ("inputs", "inputs"), ("scope", "scope"),
               ("final [cm]", "final_deformation_cm"), ("max [cm]", "max_deformation_cm"),
               ("peak contact [N]", "peak_contact_force_N"), ("peak push [N]", "peak_push_force_N"),
               ("wall stretch", "max_wall_stretch"), ("ended by", lambda r: r.get("ended_by") or r["status"]),
               ("end depth [cm]", "end_depth_cm"), ("quasi-static", "quasi_static"),
               ("phases: depth range (max / end deformation, cm)", _phases)]
    return md_table(rows, columns)


def _relax(section):
    """How long the released colon relaxes before the push goes on, as the section's runs did."""
    short, longest = section.get("relax_s"), section.get("relax_max_s")
    if short is None:
        return "`relax`"
    if not longest:
        return f"`relax`, {short:g} s"
    return f"`relax`: {short:g} s, then on until the released colon has come to rest, at most {longest:g} s in all"


def flexure_models(section):
    lines = ["## 5. RSF, THF and fixed THF", "",
             "Main sweep, mu = 0, flexure turn 90 deg (the default; docs/model.md, \"Colon models\"). The mobile part "
             "is held to its straight axis while the scope straightens it (phase `straighten`) and slows to rest at "
             "the end of the mobile part (`stop`), released while the scope stands still (" + _relax(section) + "), then the "
             "scope is pushed through the flexure into the fixed exit (`push`) until its available length is used "
             "or the tip reaches the far end (docs/model.md, \"Loading\"); the phases are those each run's "
             "`timeseries.csv` records. Phases: pushed depth at the phase's start and end, and the largest and the last "
             "deformation in it. Quasi-static: the primary criterion, as in section 3.", "", model_runs(section["rows"]), "", *_missing(section["rows"], "inputs")]
    for fig in section["figures"]:
        lines += [f"![{fig['title']}]({fig['file']})", ""]
    lines += ["Final shapes in the plane of the centerline (the models are planar): the colon at rest (grey), the "
              "mobile part at rest (black dashed) and at the end of each run (the scope's colour), and each "
              "scope's final centerline (dash-dot). One panel per angle.", ""]
    return lines


def flexure_sensitivity(section):
    angles = section["angles_deg"]
    lines = ["## 10. Flexure-angle sensitivity (90 / 135 / 180 deg)", "",
             "The flexure turn is an assumption (docs/model.md, \"Colon models\"; default 90 deg, not chosen by "
             "matching a result). RSF and THF at alpha / beta = " + (" and ".join(f"{a:g}" for a in angles) or "-")
             + " deg with the UTC (9.2 mm) and the SDC (13.3 mm): the 90 deg runs are the main sweep's, the other "
             "turns the validation sweep's. Advantage = (SDC - UTC) / SDC of the final deformation (0 where both "
             "are below 0.1 cm, as in the claims).", ""] + carried_lines(section)
    if not section["ran"]:
        return lines + [f"{NOT_RUN}: {section['note']}", ""]

    def cell(r, scope, key):
        s = r["scopes"][scope]
        return num(s.get(key)) if s["status"] == "ok" else s["status"]

    lines += [md_table(section["rows"], [
        ("model", lambda r: r["segment"].upper()), ("angle [deg]", "angle_deg"), ("flexure [deg]", "flexure_angle_deg"),
        ("UTC final", lambda r: cell(r, "utc", "final_cm")), ("UTC max", lambda r: cell(r, "utc", "max_cm")),
        ("SDC final", lambda r: cell(r, "sdc", "final_cm")), ("SDC max", lambda r: cell(r, "sdc", "max_cm")),
        ("advantage", lambda r: "-" if r["advantage"] is None else f"{100 * r['advantage']:.0f} %"),
        ("ended by (UTC / SDC)", lambda r: " / ".join(r["scopes"][s].get("ended_by") or "-" for s in ("utc", "sdc")))]),
        ""]
    for fig in section["figures"]:
        lines += [f"![{fig['title']}]({fig['file']})", ""]
    return lines


def node_counts(rows):
    return ["## 11. Colon meshes next to the source's", "",
            "Wall nodes of each model at the default mesh (3 mm triangles, t = 2 mm, flexure 90 deg) as run (with the "
            "10 cm fixed exit) and without the exit, next to the source's meshes where it gives them. Ours mesh the "
            "wall's mid-surface (diameter D + t); the source's mesher, exits and exact centerlines are not known, so "
            "the same order of magnitude is what to expect.", "",
            md_table(rows, [("model", "model"), ("nodes", "nodes"), ("triangles", "triangles"),
                            ("mobile nodes", "mobile_nodes"), ("centerline [cm]", "centerline_cm"),
                            ("nodes without the exit", "nodes_without_exit"), ("source nodes", "source_nodes"),
                            ("ours / source", "ours_over_source"),
                            ("without exit / source", "without_exit_over_source")]), ""]


def run_ends(sections):
    lines = ["## 12. How every run ended", "",
             "`ended_by` (docs/model.md, \"Loading\"): `tip_past_end` (RSJ: the tip 2 cm past the sigmoid's fixed "
             "end), `far_end` (the tip at the far end of the exit), `length_used` (the scope's available length "
             "pushed in), `wall_stretch` (the wall's largest stretch past the failure stretch), `jam` "
             f"({ENDINGS['jam']}). End state: pushed depth, push and contact force at the end.", ""]
    for name, s in sections.items():
        sweep = s["sweep"]
        lines += [f"### {name.capitalize()} sweep", ""] + carried_lines(s)
        if not sweep["ran"]:
            lines += [f"{NOT_RUN}: " + (f"no results table in `{sweep['folder']}`." if sweep["folder"]
                                        else "no sweep given."), ""]
            continue
        counts = ", ".join(f"{k}: {v}" for k, v in s["counts"].items())
        lines += [f"{len(s['runs'])} runs defined; {counts}. **Jams: {s['jams']}.**", "",
                  md_table(s["runs"], [("model", lambda r: r["segment"].upper()), ("scope", "scope"),
                                       ("inputs", "inputs"), ("ended by", lambda r: r.get("ended_by") or r["status"]),
                                       ("end depth [cm]", "end_depth_cm"), ("end push [N]", "end_push_force_N"),
                                       ("end contact [N]", "end_contact_force_N")]), ""]
    return lines


def run_times(section):
    return ["## 13. Run times", "",
            "Wall time of each run of the main sweep as recorded in its table (one Numba thread per run; runs in "
            "flight at the same time share the machine's cores) next to the source's minutes per insertion "
            "(LS-DYNA on a 4-core laptop; none given for the fixed THF).", "",
            md_table(section["summary"], [
                ("model", lambda r: r["segment"].upper()), ("scope", "scope"), ("runs", "runs"),
                ("mean wall time [s]", "mean_s"), ("longest [s]", "max_s"), ("source [min]", "source_min"),
                ("source / ours (mean)", "ratio")]), "",
            md_table(section["rows"], [("model", lambda r: r["segment"].upper()), ("scope", "scope"),
                                       ("inputs", "inputs"), ("status", "status"), ("wall time [s]", "wall_time_s"),
                                       ("source [min]", "source_min"), ("source / ours", "source_over_ours")]), ""]


def write_markdown(doc, path):
    lines = (header(doc) + verification(doc["verification"]) + calibration(doc["calibration"]) + rsj(doc["rsj"])
             + claims(doc["claims"]) + flexure_models(doc["flexure_models"]) + ringing(doc["ringing"])
             + mesh_pair(doc["mesh_pair"])
             + rate_check(doc["rate_check"]) + smoothness(doc["smoothness"])
             + flexure_sensitivity(doc["flexure_sensitivity"])
             + node_counts(doc["node_counts"]) + run_ends(doc["run_ends"]) + run_times(doc["run_times"])
             + resistance_markdown(doc["resistance"]) + changes_markdown(doc.get("changes")))
    with atomic_path(path) as tmp:
        tmp.write_text("\n".join(lines), encoding="utf-8")
