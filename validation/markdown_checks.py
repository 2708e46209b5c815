"""The validation report's Markdown for its quasi-static checks (docs/quasi_static.md): the ringing
ratio of every run, the mesh pair, the rate check and the smoothness checks."""

from __future__ import annotations

import math

from colonsim.markdown import NOT_RUN, md_table, num, percent
from .carry import carried_lines


def verdict(passed):
    return "-" if passed is None else ("pass" if passed else "**FAIL**")


PAIR_SHOWN = ("final", "max", "A", "C", "peak contact", "peak push", "lag")


def _pair_section(number, title, intro, section):
    lines = [f"## {number}. {title}", "", intro, ""] + carried_lines(section)
    if not section["ran"]:
        return lines + [f"{NOT_RUN}: {section['note']}", ""]
    rows = []
    for p in section["rows"]:
        cells = {q["quantity"]: q for q in p["quantities"]}
        rows.append({**p, **{f"{k}_{q}": cells.get(q, {}).get(k) for q in PAIR_SHOWN
                             for k in ("base", "variant", "change")}})
    cols = [("model", lambda r: r["segment"].upper()), ("inputs", "inputs"), ("scope", "scope"),
            ("runs", lambda r: f"{r['base_status']} / {r['variant_status']}")]
    for q in PAIR_SHOWN:
        cols += [(f"{q}", lambda r, q=q: f"{num(r[f'base_{q}'])} / {num(r[f'variant_{q}'])}"
                  if r[f"base_{q}"] is not None else "-"),
                 (f"change {q}", lambda r, q=q: percent(r[f"change_{q}"]))]
    cols += [("ringing", lambda r: " / ".join(num(v) for v in r.get("ringing_ratio") or []) or "-"),
             ("ended by", lambda r: " / ".join(r.get("ended_by") or []) or "-"),
             ("snap-throughs", lambda r: next((f"{q['base']} / {q['variant']}" for q in r["quantities"]
                                               if q["quantity"] == "snap-throughs"), "-")),
             ("not judged (rule)", lambda r: "; ".join(sorted({q["quantity"] for q in r["quantities"] if q.get("why")}))
              or "-"),
             ("pass", lambda r: verdict(r["passed"]))]
    reasons = sorted({q["why"] for p in section["rows"] for q in p["quantities"] if q.get("why")})
    notes = [f"Not judged: {why}." for why in reasons]
    return lines + [md_table(rows, cols), "", section["summary"], ""] + ([" ".join(notes), ""] if notes else [])


_PAIR_RULE = ("Deformations and the largest lag in cm (A and C: the RSJ's points), peak forces in N (averaged "
              "over 5 mm of push, docs/model.md \"Outputs\"); change = (variant - base) / base. Pass: every judged "
              "deformation and the lag change by under 5 % and every judged peak force by under 10 % (a deformation "
              "is not judged where both values are below 0.1 cm, `insertion/study/claims.py` NO_DEFORMATION_CM; a "
              "force where both are below 0.5 N). The rules of docs/quasi_static.md leave out the final deformation "
              "of two runs that end with the tip held at mu 0 (a nearly neutral end state, reported with its "
              "spread) and, in the rate check, judge a pair with snap-throughs on their count, its largest "
              "deformation and lag only. Ringing: the ringing ratio of both runs (quasi-static below 0.1).")


def mesh_pair(section):
    return _pair_section(7, "Mesh pair: 3 mm against 2 mm wall triangles",
                         "One 13.3 mm scope case per colon model (RSJ D36; RSF alpha 45; THF beta 45; fixed THF) of the "
                         "main sweep (3 mm triangles, the source's size) run again on 2 mm triangles by the validation "
                         "sweep. Each cell: 3 mm / 2 mm. " + _PAIR_RULE, section)


def rate_check(section):
    base, half = section.get("speeds") or ("?", "?")
    share, lead = section.get("held_share"), section.get("held_lead_mm")
    begins = ("Once the distal resistance holds the tip," if not lead else
              f"From {lead:g} mm before the fixed exit, where the distal resistance will hold the tip,")
    held = ("" if share is None or share == 1.0 else
            f" {begins} both push at {share:g} of these speeds (docs/model.md, "
            "\"Loading\").")
    lines = _pair_section(8, f"Rate check: {base} against {half} m/s",
                         "Every scope of one case per colon model pushed at half the speed (docs/model.md, \"Time "
                         f"integration and damping\": a quasi-static run does not depend on the push speed). Each cell: "
                         f"{base} / {half} m/s.{held} Velocity-proportional damping resists the slow motion of the "
                         "insertion with a force that halves with the speed: if the drag is linear in the speed, "
                         "a pair's change is half of what the damping moves at the default speed. " + _PAIR_RULE,
                         section)
    angles = section.get("angles")
    if angles is None:
        return lines
    lines += ["**At the other angles** (`benchmarks/sweeps/rate_angles.toml`: RSF alpha and THF beta 0 and 30 "
              "deg, every scope, at half the speed, against the main sweep's runs; not among the check's cases "
              "above, shown because the loops behind a held tip form at every angle):", ""]
    if not angles["ran"]:
        return lines + [f"{NOT_RUN}: {angles['note']}", ""]
    return lines + _pair_section(8, "", "", angles)[4:]


def ringing(section):
    lines = ["## 6. Quasi-static: the ringing ratio of every run", "",
             "The ringing ratio (docs/quasi_static.md): the RMS of the push force about its moving average over 1 cm "
             "of push, over max(its mean, 1 N), from the first contact to the end of the push, every sample weighted "
             "by the push it stands for, the 6 mm of push after each snap-through left out (at most a quarter of "
             f"the push). Quasi-static: below {section['limit']:g}. Rows of sweeps made before these rules are "
             "recomputed from their time series (`insertion/study/run_rules.py`; column `rules`).", ""]
    for name, s in section["sweeps"].items():
        lines += [f"### {name.capitalize()} sweep", ""] + carried_lines(s)
        if not s["ran"]:
            lines += [f"{NOT_RUN}.", ""]
            continue
        lines += [f"{s['passed']} of {s['runs']} finished runs below {section['limit']:g}; largest "
                  f"{num(s['largest'])} ({s['largest_run']}); median {num(s['median'])}.", "",
                  md_table(s["rows"], [("model", lambda r: r["segment"].upper()), ("scope", "scope"),
                                       ("inputs", "inputs"), ("ringing ratio", "ringing_ratio"),
                                       ("push force RMS / mean [N]", lambda r: f"{num(r['rms_N'])} / {num(r['mean_N'])}"),
                                       ("snap-throughs", lambda r: _snap_cell(r)),
                                       ("quasi-static", lambda r: verdict(r["quasi_static"])),
                                       ("rules", lambda r: r.get("rules") or "-")]), ""]
        failing = [r for r in s["rows"] if r["quasi_static"] is False]
        if failing:
            lines += ["Runs that fail, with the cause:", ""] + [
                f"- {r['segment'].upper()} {r['scope']} {r['inputs']}: {r.get('cause') or '-'}" for r in failing] + [""]
    return lines


def _snap_cell(row):
    n = row.get("snap_throughs")
    if n is None:
        return "-"
    return f"{n:g}" + (f" ({row['left_out_share']:.0%} left out)" if n else "")


def _scatter_alone(cubic):
    band = cubic.get("scatter_alone")
    if not band:
        return ""
    return (f" Scatter alone (independent runs about a smooth trend, Monte Carlo at these diameters) gives a largest "
            f"departure of {band['p05']:.2g} to {band['p95']:.2g} times its sd (5-95 %, median {band['p50']:.2g}).")


def smoothness(section):
    lines = ["## 9. Smooth across inputs", "",
             "Rough outputs make every surrogate fitted on them plateau (docs/model.md, \"Time integration and "
             "damping\"). Two checks on sweeps the repository defines (`benchmarks/sweeps/*.toml`), run with "
             "`colonsim sweep FILE --out DIR`.", "",
             "**Against scope diameter** (`smoothness.toml`: RSJ D36, mu 0, scope 9.0 to 13.5 mm in 0.5 mm steps): "
             "each output's largest departure from the least-squares cubic in the diameter, as a share of the "
             "output's range over the runs. Pass: the departure under max(2 % of the range, 2 x the runs' own "
             "scatter) (docs/quasi_static.md). A regime change a cubic cannot follow shows here as a "
             "failure, and the figure shows where; the largest deformation, the larger of A and C, is judged "
             "against the larger of their cubics too (the crease where one overtakes the other, docs/model.md "
             "\"What makes the outputs rough\"). Beside it, for scale, the departure against the runs' own "
             "scatter about a smooth trend (the noise sd the surrogate fitted on both GP sweeps estimates, table "
             "below): 2 % of a small range can lie below the scatter." + _scatter_alone(section["cubic"]), ""]
    cubic = section["cubic"]
    lines += carried_lines(cubic)
    if not cubic["ran"]:
        lines += [f"{NOT_RUN}: no --smoothness-sweep.", ""]
    else:
        scatter = {r["output"]: r.get("scatter") for r in section["surrogate"].get("rows") or []}

        def in_scatters(r):
            noise, departure = scatter.get(r.get("column")), r.get("departure_cm")
            return "-" if not noise or departure is None or not math.isfinite(departure) else f"{departure / noise:.2g}"

        lines += [md_table(cubic["rows"], [("output", "output"), ("runs", "runs"), ("range", "range"),
                                           ("largest departure / range", lambda r: percent(r["departure"])),
                                           ("at scope [mm]", "at_scope_mm"), ("departure", "departure_cm"),
                                           ("replicates' scatter", lambda r: num(r.get("replicate_scatter"))),
                                           ("scatter / range", lambda r: percent(r.get("scatter_share"))),
                                           ("bound", lambda r: num(r.get("bound"))),
                                           ("pass", lambda r: verdict(r["passed"])),
                                           ("departure / GP noise", in_scatters)]),
                  "", f"![outputs against scope diameter]({section['figure']})", ""]
    lines += ["**A surrogate's held-out error** (`gp_train.toml`, 20 runs, fits the project's surrogate; "
              "`gp_test.toml`, 30 independent runs in the same ranges, scores it): RSJ, scope 9-13.5 mm, D 20-40 mm, "
              "mu 0-0.1. RMSE of the predictions as a share of the held-out output's standard deviation; pass: the "
              "RMSE under max(5 % of that deviation, 1.25 x the replicates' scatter) (docs/quasi_static.md). Coverage: the share of held-out runs inside the predicted 95 % interval ('-': the model says "
              "its error is unknown and gives no interval, docs/surrogate.md 'Too few runs'). What limits the error: "
              "a surrogate fitted on both sweeps (50 runs) gives its leave-one-out RMSE and the noise sd it "
              "estimates, the runs' own scatter about a smooth trend (both as a share of the output's sd over both "
              "sweeps; of the largest deformation, modelled as the larger of points A and C (docs/surrogate.md), the "
              "larger of theirs). Held-out runs carry that scatter: where it is above 5 %, more training runs cannot "
              "pass the check; where it is well below and the error on both sweeps is too, 20 runs were too few.", ""]
    gp = section["surrogate"]
    lines += carried_lines(gp)
    if not gp["ran"]:
        lines += [f"{NOT_RUN}: no --gp-train-sweep and --gp-test-sweep.", ""]
    else:
        lines += [md_table(gp["rows"], [("output", "output"), ("train / test runs", lambda r: f"{r['train_runs']} / "
                                                                                              f"{r['test_runs']}"),
                                         ("RMSE", "rmse"), ("held-out sd", "spread"), ("RMSE / sd", lambda r: percent(r["share"])),
                                         ("95 % coverage", lambda r: percent(r["coverage95"])),
                                         ("replicates' scatter / sd", lambda r: percent(r.get("replicate_scatter_share"))),
                                         ("bound", lambda r: num(r.get("bound"))),
                                         ("pass", lambda r: verdict(r["passed"])),
                                         ("both sweeps: LOO RMSE / sd", lambda r: percent(r["pooled_loo_share"])),
                                         ("GP noise", "scatter"),
                                         ("GP noise / sd", lambda r: percent(r["scatter_share"]))]), ""]
    return lines
