"""Sections of the validation report carried from the previous report (validation/carry.py):
a section whose sweep is not given comes from the previous report, marked with where it was computed;
a section whose sweep is given is never replaced; the Markdown says which is which. Read on the
landed report itself."""

import copy
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the validation package (a tool folder)

from validation import carry  # noqa: E402
from validation import report as validation_report  # noqa: E402
from validation.markdown import write_markdown  # noqa: E402



def computed(doc):
    """``doc`` as if every section had been computed by its own report: carried marks taken off."""
    if isinstance(doc, dict):
        return {k: computed(v) for k, v in doc.items() if k != "carried_from"}
    return [computed(v) for v in doc] if isinstance(doc, list) else doc


LANDED = computed(json.loads((ROOT / "docs" / "validation" / "report.json").read_text(encoding="utf-8")))
NOT_RUN = {"ran": False, "note": "no sweep given", "rows": [], "summary": ""}


def fresh_report():
    """The landed report as a report given only its main sweep would compute it: every section of another
    sweep NOT RUN, the header newer."""
    doc = copy.deepcopy(LANDED)
    doc["header"].update(date="2099-01-01T00:00:00+00:00", commit="f" * 40)
    doc["header"]["sweeps"]["validation"] = {"label": "validation", "folder": None, "ran": False}
    doc["mesh_pair"] = dict(NOT_RUN)
    doc["rate_check"] = {**NOT_RUN, "speeds": [0.15, 0.075], "angles": dict(NOT_RUN)}
    doc["flexure_sensitivity"] = {**NOT_RUN, "angles_deg": [], "figures": []}
    doc["ringing"]["sweeps"]["validation"] = {"ran": False}
    doc["run_ends"]["validation"] = {"sweep": {"label": "validation", "folder": None, "ran": False}, "runs": [],
                                     "counts": {}, "jams": 0}
    doc["smoothness"]["cubic"] = {"ran": False, "rows": []}
    doc["smoothness"]["surrogate"] = {"ran": False, "rows": []}
    doc["resistance"] = {"ran": False, "rows": [], "figures": []}
    return doc


def given(**ran):
    return {label: ran.get(label, False) for label in carry.SECTIONS}


def test_the_sections_of_sweeps_not_given_come_from_the_previous_report_marked_with_where_they_were_computed():
    doc = fresh_report()
    carried = carry.carry(doc, LANDED, given())
    assert carried == ["validation", "rate_angles", "smoothness", "gp_train", "gp_test", "resistance"]
    marks = {}
    for path in (("mesh_pair",), ("flexure_sensitivity",), ("resistance",), ("smoothness", "cubic"),
                 ("ringing", "sweeps", "validation"), ("run_ends", "validation")):
        section = copy.deepcopy(carry.section_at(doc, *path))
        marks[path] = mark = section.pop("carried_from")
        assert section == carry.section_at(LANDED, *path), path
        assert mark["date"] == LANDED["header"]["date"] and mark["commit"] == LANDED["header"]["commit"]
    # the validation sweep's rows name the code that made them, as the landed header does
    assert marks[("mesh_pair",)]["rows_code"] == LANDED["header"]["sweeps"]["validation"]["code"]
    # the main sweep's sections are never carried: they stay as this report computed them
    assert doc["header"]["commit"] == "f" * 40 and "carried_from" not in doc["rsj"]


def test_a_given_sweep_keeps_its_own_sections_and_the_rate_check_keeps_its_other_angles():
    doc = fresh_report()
    doc["rate_check"]["angles"] = {"ran": True, "rows": ["computed now"], "summary": "now"}
    doc["resistance"] = {"ran": True, "rows": ["computed now"], "figures": []}
    carried = carry.carry(doc, LANDED, given(rate_angles=True, resistance=True))
    assert "resistance" not in carried and "rate_angles" not in carried
    assert doc["resistance"]["rows"] == ["computed now"] and "carried_from" not in doc["resistance"]
    # the rate check's own pairs are the validation sweep's (carried); the other angles are this report's
    assert doc["rate_check"]["rows"] == LANDED["rate_check"]["rows"] and "carried_from" in doc["rate_check"]
    assert doc["rate_check"]["angles"]["rows"] == ["computed now"]


def test_carried_again_a_section_keeps_its_first_mark_and_a_section_that_never_ran_is_not_carried():
    first = fresh_report()
    carry.carry(first, LANDED, given())
    second = fresh_report()
    second["header"].update(date="2100-01-01T00:00:00+00:00", commit="e" * 40)
    carry.carry(second, first, given())
    assert second["mesh_pair"]["carried_from"]["date"] == LANDED["header"]["date"]
    never = fresh_report()
    assert carry.carry(never, fresh_report(), given()) == []
    assert never["mesh_pair"] == NOT_RUN


def test_the_markdown_says_under_each_carried_heading_that_it_was_carried_and_nowhere_else(tmp_path):
    doc = fresh_report()
    doc["header"]["carried"] = carry.carry(doc, LANDED, given(smoothness=True, gp_train=True, gp_test=True))
    doc["smoothness"]["cubic"] = {"ran": False, "rows": []}
    write_markdown(doc, tmp_path / "report.md")
    text = (tmp_path / "report.md").read_text(encoding="utf-8")
    note = f"*Carried from the report of {LANDED['header']['date']}"
    sections = {s.split("\n", 1)[0]: s for s in text.split("\n## ")}
    for heading in ("7. Mesh pair", "8. Rate check", "10. Flexure-angle", "14. Distal resistance"):
        assert note in next(s for h, s in sections.items() if h.startswith(heading)), heading
    for heading in ("3. RSJ against", "9. Smooth across inputs", "13. Run times"):
        assert note not in next(s for h, s in sections.items() if h.startswith(heading)), heading
    assert "sections carried from the previous report" in text and "validation sweep: carried from" in text


def test_carry_without_a_previous_report_is_a_one_line_error_before_anything_is_read(tmp_path, capsys):
    assert validation_report.main(["--sweep", str(tmp_path / "nowhere"), "--carry", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--previous OLD/report.json" in err
    assert not (tmp_path / "report.md").exists()


def test_the_report_page_is_what_its_builder_writes_from_report_json(tmp_path, capsys):
    """docs/validation/report.md is written by the builder from report.json (``--markdown-only``
    rewrites it without reading a sweep); the page shows the JSON's machine paths and commits as
    neither."""
    import shutil

    from validation import markdown

    page = ROOT / "docs" / "validation"
    shutil.copy(page / "report.json", tmp_path / "report.json")
    assert validation_report.main(["--markdown-only", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "report.md").read_text(encoding="utf-8") == (page / "report.md").read_text(encoding="utf-8")
    assert validation_report.main(["--markdown-only", "--out", str(tmp_path / "none")]) == 2
    assert "no report.json" in capsys.readouterr().err
    assert markdown.shown_path("/work/runs/thesis") == "DIR/thesis"
    assert markdown.shown_path(ROOT / "benchmarks" / "records" / "thesis") == "benchmarks/records/thesis"
    assert markdown.shown_folder("/elsewhere/thesis") == "`DIR/thesis` (record `benchmarks/records/thesis`)"
    assert markdown.shown_folder("/elsewhere/no_such_sweep") == "`DIR/no_such_sweep`"
    assert markdown.shown_command("python -m validation.report --sweep /a/b/thesis --out docs/validation") == \
        "python -m validation.report --sweep DIR/thesis --out docs/validation"
    assert markdown.commits({"a" * 40: 3, "b" * 40: 1}) == "rows made by 2 commits of the code"

