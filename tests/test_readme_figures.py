"""The README's figures of the shipped predictor come from the committed records: its held-out
table is the one ``benchmarks/bench_predictor.py`` prints from ``predictor_heldout.json``, row for
row, and the patient models it says the predictor covers are those the shipped model holds."""

import json
import sys
from pathlib import Path

import pytest

from colonsim.surrogate import predictor
from colonsim.surrogate.predictor import load_shipped

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
import bench_predictor  # noqa: E402

README = (ROOT / "README.md").read_text(encoding="utf-8")
shipped_only = pytest.mark.skipif(not predictor.shipped_exists() or not bench_predictor.RECORD.exists(),
                                  reason="no predictor is shipped yet (the patient-space sweeps have not been run)")


@shipped_only
def test_the_readme_quotes_the_committed_held_out_table_row_for_row():
    rows = json.loads(bench_predictor.RECORD.read_text(encoding="utf-8"))["rows"]
    table = [line for line in bench_predictor.format_table(rows).splitlines() if line.startswith("|")]
    lines = README.splitlines()
    starts = [i for i, line in enumerate(lines) if line.startswith("| model | output | held-out runs")]
    assert len(starts) == 1, "the README quotes the held-out table once"
    assert lines[starts[0]:starts[0] + len(table)] == table


@shipped_only
def test_the_readme_names_the_patient_models_the_shipped_predictor_covers():
    names = [m.upper() for m in load_shipped().domains_]
    covered = names[0] if len(names) == 1 else f"{', '.join(names[:-1])} and {names[-1]}"
    assert f"answers for {covered} patients" in README
