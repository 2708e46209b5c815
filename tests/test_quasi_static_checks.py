"""benchmarks/quasi_static_checks.py: the mesh pair, the rate check and the smoothness checks of any
sweeps come out as the validation report's own (on the committed records of the report's sweeps,
the verdicts of docs/validation/report.json), and a missing or half-given sweep is one line, exit 2."""

import contextlib
import io
import json
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import quasi_static_checks  # noqa: E402
import sweep_records as records  # noqa: E402

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


def test_the_report_sweeps_give_the_report_verdicts(tmp_path):
    for name in ("thesis", "validation", "smoothness", "gp_train", "gp_test"):
        records.unpack(ROOT / "benchmarks" / "records" / name, tmp_path / name)
    code, out, _ = _run("--base", tmp_path / "thesis", "--variants", tmp_path / "validation",
                        "--smoothness", tmp_path / "smoothness", "--gp-train", tmp_path / "gp_train",
                        "--gp-test", tmp_path / "gp_test", "--figures", tmp_path / "figures")
    assert code == 0
    assert (tmp_path / "figures" / "smoothness.png").is_file()
    summaries = [line for line in out.splitlines() if "pairs pass" in line]
    assert summaries == [REPORT["mesh_pair"]["summary"], REPORT["rate_check"]["summary"]]
    failing = [line for line in out.splitlines() if line.startswith("|") and line.rstrip().endswith("**FAIL** |")]
    assert len(failing) == sum(not r["passed"] for key in ("mesh_pair", "rate_check") for r in REPORT[key]["rows"])
    smooth = REPORT["smoothness"]
    for key in ("cubic", "surrogate"):
        expected = {r["output"]: r["passed"] for r in smooth[key]["rows"]}
        assert _verdicts(out, expected) == expected


@pytest.mark.parametrize("argv, words", [
    (("--base", "{none}", "--variants", "{none}"), "no results.parquet in"),
    (("--base", "{none}",), "no results.parquet in"),
    ((), "give the sweeps to check"),
])
def test_a_missing_or_half_given_sweep_is_one_line(tmp_path, argv, words):
    code, out, err = _run(*[a.format(none=tmp_path / "none") for a in argv])
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and words in err


def test_a_base_without_its_variants_is_named(tmp_path):
    records.unpack(ROOT / "benchmarks" / "records" / "smoothness", tmp_path / "smooth")
    code, _, err = _run("--base", tmp_path / "smooth")
    assert code == 2 and re.search(r"give --base with --variants", err)
