"""The command line: results on disk, one-line errors with exit code 2, nothing half written."""

import json
import subprocess
import sys

import pytest

from colonsim.data import TENSILE_DIR
from colonsim.cli import main

SPECIMEN = ["--curve", str(TENSILE_DIR / "specimen_01.csv"), "--length", "100", "--width", "25", "--thickness", "1.7786"]


def test_calibrate_one_curve_analytic(tmp_path, capsys):
    out = tmp_path / "cal"
    assert main(["calibrate", *SPECIMEN, "--analytic", "--quick", "--no-progress", "--out", str(out)]) == 0
    doc = json.loads((out / "material.json").read_text())
    assert doc["model"]["model"].startswith("homogeneous")
    # the closed form fitted, the clamped FE evaluated at the same parameters: FE is stiffer
    assert doc["model_comparison"]["fe_over_closed_form_minus_1_at_end"] > 0.01
    text = capsys.readouterr().out
    assert "clamped FE vs closed form" in text and "C11" in text


def test_calibrate_per_specimen_population(tmp_path):
    manifest = tmp_path / "manifest.csv"
    manifest.write_text("specimen,file,length_mm,width_mm,thickness_mm\n"
                        f"a,{TENSILE_DIR / 'specimen_01.csv'},100,25,1.7786\nb,{TENSILE_DIR / 'specimen_02.csv'},100,25,1.9365\n")
    out = tmp_path / "pop"
    assert main(["calibrate", "--manifest", str(manifest), "--per-specimen", "--analytic", "--quick",
                 "--workers", "2", "--no-progress", "--out", str(out)]) == 0
    pop = json.loads((out / "population.json").read_text())
    assert [s["specimen"] for s in pop["specimens"]] == ["a", "b"]
    assert pop["population"]["C11"]["n"] == 2
    assert (out / "a" / "material.json").is_file() and (out / "population.png").is_file()


@pytest.mark.parametrize("args,message", [
    (["--curve", "missing.csv", "--length", "100", "--width", "25", "--thickness", "2"], "not found"),
    (["--curve", str(TENSILE_DIR / "specimen_01.csv"), "--length", "100", "--width", "25"], "thickness is missing"),
    (["--curve", str(TENSILE_DIR / "specimen_01.csv"), "--length", "100", "--width", "25", "--thickness", "-1"],
     "thickness must be a positive number"),
    (["--manifest", str(TENSILE_DIR / "manifest.csv"), "--thickness", "2"], "go with --curve"),
    (["--law", "ogden"], "unknown hyperelastic law"),
])
def test_bad_input_is_one_line_and_exit_2(args, message, capsys, tmp_path):
    assert main(["calibrate", *args, "--out", str(tmp_path / "x"), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1 and err.startswith("colonsim: error:")
    assert not (tmp_path / "x").exists()


def test_console_script_has_no_traceback(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("displacement [mm],force [N]\n1,1\n2,nan\n3,3\n")
    proc = subprocess.run([sys.executable, "-m", "colonsim.cli", "calibrate", "--curve", str(bad), "--length", "100",
                           "--width", "25", "--thickness", "2", "--out", str(tmp_path / "o")],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr and "NaN or infinite value at data row 2" in proc.stderr


def test_failed_run_keeps_earlier_results(tmp_path):
    """A second calibration into the same folder that fails on input leaves the first intact."""
    out = tmp_path / "cal"
    assert main(["calibrate", *SPECIMEN, "--analytic", "--quick", "--no-progress", "--out", str(out)]) == 0
    before = (out / "material.json").read_bytes()
    assert main(["calibrate", "--curve", str(tmp_path / "nope.csv"), "--length", "100", "--width", "25",
                 "--thickness", "2", "--out", str(out), "--no-progress"]) == 2
    assert (out / "material.json").read_bytes() == before
