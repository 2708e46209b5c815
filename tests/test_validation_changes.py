"""The validation report's section on what moved since the previous report
(benchmarks/validation_changes.py): runs matched by what they are, not by key; a change is listed
only when it is one; a pass/fail that flipped is shown."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import validation_changes as changes  # noqa: E402


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
                                 "quantity": "final", "before": 0.071, "after": 0.002, "verdict": "FAIL -> pass"}]
    text = "\n".join(changes.markdown(section))
    assert "fixed THF run), 1 moved" in text and "FAIL -> pass" in text


def test_near_zero_deformations_are_compared_by_their_absolute_change():
    section = changes.changes(report(0.001, 1.83, 0.0, "a"), report(0.004, 1.83, 0.0, "a"))
    final = section["runs"][1]["quantities"][0]
    assert final["change"] is None and not final["moved"]  # +0.003 cm of a near-zero value: not a move
    section = changes.changes(report(0.001, 1.83, 0.0, "a"), report(0.02, 1.83, 0.0, "a"))
    assert section["runs"][1]["quantities"][0]["moved"]


def test_without_a_previous_report_the_section_says_not_run():
    assert "NOT RUN" in "\n".join(changes.markdown(changes.changes(None, report(1.0, 1.0, 0.0, "a"))))
