"""The validation report's section on what moved since the previous report
(validation/changes.py): runs matched by what they are, not by key; a change is listed
only when it is one; a pass/fail that flipped is shown."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the validation package

from validation import changes  # noqa: E402


def report(final_rsf, max_rsf, rate_change, key):
    rsj = {"case": "UTC D36", "status": "ok", "A_cm": 1.17, "C_cm": 1.33, "final_cm": 1.33, "max_cm": 1.33}
    rsf = {"segment": "rsf", "role": "utc", "scope": "UTC (9.2 mm)", "inputs": "alpha 0 deg", "key": key,
           "status": "ok", "final_deformation_cm": final_rsf, "max_deformation_cm": max_rsf,
           "peak_contact_force_N": 15.0, "peak_push_force_N": 5.0}
    pair = {"segment": "rsf", "scope": "UTC (9.2 mm)", "inputs": "alpha 45 deg, push 0.15 m/s",
            "quantities": [{"quantity": "final", "change": rate_change, "passed": abs(rate_change) < 0.05}]}
    return {"header": {"date": "d", "commit": "c" * 40, "sweeps": {}}, "rsj": {"rows": [rsj]},
            "flexure_models": {"rows": [rsf]}, "rate_check": {"rows": [pair]}, "mesh_pair": {"rows": []}}


def test_a_moved_run_and_a_flipped_verdict_are_listed_and_an_unmoved_run_is_not():
    before, after = report(0.96, 1.83, 0.071, "86cc17389552"), report(1.54, 1.834, 0.002, "0f0f0f0f0f0f")
    section = changes.changes(before, after)
    assert len(section["runs"]) == 2  # matched across the new key
    assert [r["run"] for r in section["moved"]] == ["RSF UTC (9.2 mm) alpha 0 deg"]
    final, largest = section["moved"][0]["quantities"][:2]
    assert final["moved"] and abs(final["change"] - 0.6042) < 1e-3
    assert not largest["moved"]  # +0.2 %: below the 1 % that counts as moved
    assert section["flips"] == [{"check": "rate", "run": "RSF UTC (9.2 mm) alpha 45 deg, push 0.15 m/s",
                                 "quantity": "final", "before": 0.071, "after": 0.002, "verdict": "FAIL -> pass",
                                 "rule": "its numbers moved"}]
    text = "\n".join(changes.markdown(section))
    assert "and 0 of the distal resistance sweep), 1 moved" in text and "FAIL -> pass" in text


def test_near_zero_deformations_are_compared_by_their_absolute_change():
    section = changes.changes(report(0.001, 1.83, 0.0, "a"), report(0.004, 1.83, 0.0, "a"))
    final = section["runs"][1]["quantities"][0]
    assert final["change"] is None and not final["moved"]  # +0.003 cm of a near-zero value: not a move
    section = changes.changes(report(0.001, 1.83, 0.0, "a"), report(0.02, 1.83, 0.0, "a"))
    assert section["runs"][1]["quantities"][0]["moved"]


def test_without_a_previous_report_the_section_says_not_run():
    assert "NOT RUN" in "\n".join(changes.markdown(changes.changes(None, report(1.0, 1.0, 0.0, "a"))))


def resisted(final_10n, rate_change, thin_claim):
    """A report with a distal resistance section: one RSF run at 10 N, its rate pair, two claims."""
    run = {"segment": "rsf", "role": "utc", "where": "alpha 45 deg", "level_N": 10.0, "scope": "UTC (9.2 mm)",
           "final_deformation_cm": final_10n, "max_deformation_cm": 3.6, "peak_contact_force_N": 70.0,
           "peak_push_force_N": 11.0, "max_lag_cm": 11.9, "ended_by": "length_used"}
    rate = {"segment": "rsf", "scope": "SDC (13.3 mm)", "where": "alpha 45 deg", "level_N": 10.0,
            "changes": {"final_deformation_cm": {"change": rate_change, "limit": 0.05,
                                                 "passed": abs(rate_change) < 0.05}}}
    claims = [{"name": "a", "levels": {"10": {"verdict": "REPRODUCED"}}},
              {"name": "b", "levels": {"10": {"verdict": "REPRODUCED" if thin_claim else "NOT REPRODUCED"}}}]
    doc = report(1.54, 1.83, 0.0, "a")
    doc["resistance"] = {"rows": [run], "rate": [rate], "claims": claims, "claims_largest": claims,
                         "quasi_static": {"below": 120, "largest": 0.2}}
    return doc


def test_the_distal_resistance_runs_their_rate_pairs_and_claims_are_compared():
    section = changes.changes(resisted(3.06, 0.012, False), resisted(3.52, 0.071, True))
    moved = [r for r in section["moved"] if r.get("sweep") == "resistance"]
    assert [r["run"] for r in moved] == ["RSF UTC (9.2 mm) alpha 45 deg, 10 N"]
    assert abs(moved[0]["quantities"][0]["change"] - (3.52 / 3.06 - 1)) < 1e-9
    assert section["flips"] == [{"check": "rate (resistance sweep)", "run": "RSF SDC (13.3 mm) alpha 45 deg, 10 N",
                                 "quantity": "final_deformation_cm", "before": 0.012, "after": 0.071,
                                 "verdict": "pass -> FAIL", "rule": "its numbers moved"}]
    claims = {r["what"]: (r["before"], r["after"]) for r in section["summaries"] if "claims" in r["what"]}
    assert claims["resistance sweep: the source's claims reproduced on the final deformation at 10 N"] == (1, 2)
    text = "\n".join(changes.markdown(section))
    assert "and 1 of the distal resistance sweep), 1 moved" in text and "3.06 -> 3.52 (+15.0 %)" in text
    # unmoved: the same run at the same numbers is matched and not listed
    same = changes.changes(resisted(3.06, 0.012, False), resisted(3.06, 0.012, False))
    assert len(same["runs"]) == 3 and not same["moved"] and not same["flips"]


def test_a_claim_whose_verdict_flipped_is_listed_and_counted_and_an_unchanged_one_is_not():
    before, after = report(0.96, 1.83, 0.0, "a"), report(0.96, 1.83, 0.0, "a")
    before["claims"] = [{"name": "x", "statement": "Thin scopes deform less.", "verdict": "NOT REPRODUCED"},
                        {"name": "y", "statement": "Friction matters less.", "verdict": "REPRODUCED"}]
    after["claims"] = [{"name": "x", "statement": "Thin scopes deform less.", "verdict": "REPRODUCED"},
                       {"name": "y", "statement": "Friction matters less.", "verdict": "REPRODUCED"}]
    section = changes.changes(before, after)
    assert section["claim_flips"] == [{"claim": "Thin scopes deform less.", "before": "NOT REPRODUCED",
                                       "after": "REPRODUCED"}]
    assert {"what": "main sweep: the source's claims reproduced", "before": 1, "after": 2} in section["summaries"]
    assert "| Thin scopes deform less. | NOT REPRODUCED | REPRODUCED |" in "\n".join(changes.markdown(section))
    assert changes.changes(before, before)["claim_flips"] == []


def test_each_previous_sweep_is_named_with_its_code_or_as_not_run_and_its_carried_sections_are_named():
    """The section's JSON keeps the previous report's commits; its page names none of them (a test of
    the site scans the pages for commits), only the sweeps that did not run there."""
    before, after = report(0.96, 1.83, 0.071, "86cc17389552"), report(1.54, 1.834, 0.002, "0f0f0f0f0f0f")
    before["header"]["sweeps"] = {"main": {"code": {"a" * 40: 39}}, "resistance": {"code": {}}}
    section = changes.changes(before, after)
    assert section["previous"]["commit"] == "c" * 40 and section["previous"]["sweeps"]["main"] == {"a" * 40: 39}
    text = "\n".join(changes.markdown(section))
    assert "a" * 7 not in text and "c" * 7 not in text and "`changes.previous` in report.json" in text
    assert "sweeps not run there: resistance)" in text and "carried" not in text
    before["header"]["sweeps"]["resistance"] = {"code": {"b" * 40: 1}}
    assert "not run there" not in "\n".join(changes.markdown(changes.changes(before, after)))
    before["header"]["carried"] = ["resistance"]
    text = "\n".join(changes.markdown(changes.changes(before, after)))
    assert "; sections it carried from an earlier report: resistance)" in text


def test_a_quantity_below_its_floor_is_not_counted_as_compared():
    before, after = report(0.96, 1.83, 0.071, "86cc17389552"), report(1.54, 1.834, 0.002, "0f0f0f0f0f0f")
    for doc in (before, after):
        doc["rate_check"]["rows"][0]["quantities"].append({"quantity": "max", "change": None, "passed": None})
    counts = changes.changes(before, after)["pair_counts"]
    assert counts["before"]["rate"] == (0, 1) and counts["after"]["rate"] == (1, 1)


def test_a_verdict_changed_by_a_rule_names_the_rule():
    """A quantity a rule leaves unjudged now, and one judged only since the rules, say why; a quantity
    whose values moved says that instead."""
    def doc(quantities):
        return {"rate_check": {"rows": [{"segment": "thf", "scope": "SDC (13.3 mm)", "inputs": "beta 45 deg",
                                          "quantities": quantities}]}}

    why = "final deformation of a loop behind a tip held at mu 0: a nearly neutral end state"
    before = doc([{"quantity": "final", "change": 0.08, "passed": False},
                  {"quantity": "max", "change": 0.01, "passed": True}])
    after = doc([{"quantity": "final", "change": 0.08, "passed": None, "why": why},
                 {"quantity": "max", "change": 0.06, "passed": False, "why": ""},
                 {"quantity": "lag", "change": 0.01, "passed": True, "why": ""}])
    flips = {f["quantity"]: (f["verdict"], f["rule"]) for f in changes.changes(before, after)["flips"]}
    assert flips == {"final": ("FAIL -> not judged", why), "max": ("pass -> FAIL", "its numbers moved"),
                     "lag": ("not judged -> pass", "judged since the rules of 2026-12-07: the largest lag")}
