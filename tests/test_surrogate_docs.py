"""docs/surrogate.md runs: its commands, CSV, presets JSON and Python block, on a SYNTHETIC sweep
table (regression machinery, not physics); the recommend output it quotes is what the command prints."""

import json
import re
import shlex
import textwrap
from pathlib import Path

import pytest

from colonsim.cli import main
from colonsim.surrogate.patients import PatientPresets, patient_inputs
from colonsim.surrogate.synthetic import synthetic_sweep

DOC = Path(__file__).resolve().parents[1] / "docs" / "surrogate.md"


def blocks(kind):
    """The fenced code blocks of the document tagged ``kind`` ("" = untagged), dedented."""
    found, current, lang = [], None, None
    for line in DOC.read_text(encoding="utf-8").splitlines():
        if line.strip().startswith("```"):
            if current is None:
                current, lang = [], line.strip()[3:]
            else:
                if lang == kind:
                    found.append(textwrap.dedent("\n".join(current)) + "\n")
                current = None
        elif current is not None:
            current.append(line)
    return found


@pytest.fixture
def workdir(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    synthetic_sweep(design="grid", repeats=2).to_parquet(tmp_path / "results.parquet")  # the grid run twice
    synthetic_sweep(n_runs=30, n_failed=0, seed=7).to_parquet(tmp_path / "held_out.parquet")
    csv = next(b for b in blocks("") if b.startswith("segment,"))
    (tmp_path / "queries.csv").write_text(csv)
    return tmp_path


def test_doc_commands_run(workdir, capsys):
    commands = [line for line in blocks("console")[0].splitlines() if line.startswith("colonsim ")]
    assert len(commands) >= 8
    for command in commands:
        assert main(shlex.split(command)[1:]) == 0, command
    for name in ("model.json", "model.npz", "predictions.csv", "recommendation.json", "rsf_angle.png",
                 "reliability.png"):
        assert (workdir / name).is_file()
    capsys.readouterr()
    quoted = blocks("console")[1].splitlines()
    assert main(shlex.split(quoted[0].removeprefix("$ "))[1:]) == 0
    printed = capsys.readouterr().out.splitlines()
    assert printed[:2] == quoted[1:3]
    # the numbers may move in the last digit with another BLAS
    numbers = [[float(v) for v in re.findall(r"\d+\.?\d*", line)] for line in (printed[2], quoted[3])]
    assert numbers[0] == pytest.approx(numbers[1], abs=0.02)


def test_doc_python_block_runs(workdir):
    exec(compile(blocks("python")[0], str(DOC), "exec"), {})
    assert (workdir / "model.json").is_file()


def test_doc_presets_file_loads(tmp_path):
    path = tmp_path / "presets.json"
    path.write_text(blocks("json")[0])
    presets = PatientPresets.from_json(path)
    assert patient_inputs("rsf", sex="female", region="african", presets=presets) == {"angle_deg": 40.0, "diameter_mm": 38.0}
    assert json.loads(path.read_text())["age_friction"]["older"] == presets.age_friction["older"]
