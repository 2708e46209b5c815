"""validation/quasi_static_checks.py: one line per quasi-static criterion, and the mesh pair, the rate
check and the smoothness checks of any sweeps as the validation report's own (on the committed
records of the report's sweeps, the verdicts of docs/validation/report.json); a missing or
half-given sweep is one line, exit 2."""

import contextlib
import io
import json
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the validation package (a tool folder)

from validation import quasi_static_checks  # noqa: E402
from validation import sweep_records as records  # noqa: E402

REPORT = json.loads((ROOT / "docs" / "validation" / "report.json").read_text(encoding="utf-8"))


def _run(*argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = quasi_static_checks.main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


def _verdicts(out, first_column):
    """{first cell: passed} of the table rows whose first cell is among ``first_column``."""
    found = {}
    for line in out.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if line.startswith("|") and cells[0] in first_column:
            found[cells[0]] = cells[[i for i, c in enumerate(cells) if c in ("pass", "**FAIL**")][0]] == "pass"
    return found


def test_the_records_give_the_report_verdicts(tmp_path):
    """On the committed records, one line per criterion, and the report's own tables and verdicts."""
    code, out, _ = _run("--records", "--figures", tmp_path / "figures")
    assert code == 0
    assert (tmp_path / "figures" / "smoothness.png").is_file()
    lines = out.splitlines()
    for label in ("thesis", "validation", "resistance"):
        line = next(x for x in lines if x.startswith(f"ringing ({label}): "))
        ringing = REPORT["ringing"]["sweeps"].get({"thesis": "main"}.get(label, label))
        if ringing:  # the report's count of quasi-static runs
            assert f": {ringing['passed']} of {ringing['runs']} runs quasi-static" in line
    for criterion in ("mesh (3 vs 2 mm): ", "rate (half the push speed): ", "smooth against scope diameter: ",
                      "surrogate held-out error: ", "runs' own scatter (replicates): ", "time step: "):
        assert sum(x.startswith(criterion) for x in lines) == 1, criterion
    summaries = [line for line in lines if "pairs pass" in line and line[0].isdigit()]
    assert summaries == [REPORT["mesh_pair"]["summary"], REPORT["rate_check"]["summary"]]
    failing = [line for line in lines if line.startswith("|") and line.rstrip().endswith("**FAIL** |")]
    assert len(failing) == sum(not r["passed"] for key in ("mesh_pair", "rate_check") for r in REPORT[key]["rows"]
                               if r["passed"] is not None)
    smooth = REPORT["smoothness"]
    for key in ("cubic", "surrogate"):
        expected = {r["output"]: r["passed"] for r in smooth[key]["rows"] if r["passed"] is not None}
        assert _verdicts(out, expected) == expected


@pytest.mark.parametrize("argv, words", [
    (("--base", "{none}", "--variants", "{none}"), "no results.parquet in"),
    (("--base", "{none}",), "no results.parquet in"),
    ((), "the sweeps to check"),
])
def test_a_missing_or_half_given_sweep_is_one_line(tmp_path, argv, words):
    code, out, err = _run(*[a.format(none=tmp_path / "none") for a in argv])
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and words in err


def test_a_base_without_its_variants_is_named(tmp_path):
    records.unpack(ROOT / "benchmarks" / "records" / "smoothness", tmp_path / "smooth")
    code, _, err = _run("--base", tmp_path / "smooth")
    assert code == 2 and re.search(r"give --base with --variants", err)
