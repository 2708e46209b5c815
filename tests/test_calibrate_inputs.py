"""Bad input to `colonsim calibrate`: one line naming the problem, exit 2, no traceback, and an
earlier good output folder left byte-identical."""

import os
from pathlib import Path

import pytest

from colonsim.data import TENSILE_DIR
from colonsim.cli import main

ROOT = Path(__file__).resolve().parents[1]
SPECIMEN = TENSILE_DIR / "specimen_01.csv"
EXPORT = ROOT / "tests" / "data" / "exports" / "instron_preamble.csv"
GEOMETRY = ["--length", "100", "--width", "25", "--thickness", "1.8"]
QUICK = ["--analytic", "--quick", "--no-progress"]


def specimen_rows():
    lines = SPECIMEN.read_text().splitlines()[2:]
    return [tuple(float(v) for v in line.split(",")) for line in lines]


def curve_file(folder, name, force=lambda f: f, header="displacement [mm],force [N]"):
    path = folder / name
    path.write_text(header + "\n" + "".join(f"{d:.4f},{force(f)!r}\n" for d, f in specimen_rows()))
    return path


def text_file(folder, name, text, mode="w"):
    path = folder / name
    path.write_bytes(text) if mode == "wb" else path.write_text(text)
    return path


@pytest.fixture(scope="module")
def good_output(tmp_path_factory):
    """A folder holding a good calibration, and a snapshot of its bytes."""
    out = tmp_path_factory.mktemp("good") / "calibration"
    assert main(["calibrate", "--curve", str(SPECIMEN), *GEOMETRY, *QUICK, "--out", str(out)]) == 0
    return out, {p: p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()}


# (arguments built in tmp, expected words); "OUT" stands for the good output folder.
CASES = {
    "all-zero force": (lambda t: ["--curve", curve_file(t, "zero.csv", lambda f: 0.0), *GEOMETRY],
                       "force is zero throughout"),
    "forces x 1e30": (lambda t: ["--curve", curve_file(t, "big.csv", lambda f: f * 1e30), *GEOMETRY],
                      "times the most a 25 x 1.8 mm strip"),
    "forces x 1e-7": (lambda t: ["--curve", curve_file(t, "tiny.csv", lambda f: f * 1e-7), *GEOMETRY],
                      "far below any soft tissue"),
    "forces negated": (lambda t: ["--curve", curve_file(t, "neg.csv", lambda f: -f), *GEOMETRY],
                       "forces are compressive"),
    "thickness typed in metres": (lambda t: ["--curve", SPECIMEN, "--length", "100", "--width", "25",
                                             "--thickness", "0.0018"], "25 x 0.0018 mm strip"),
    "negative thickness": (lambda t: ["--curve", SPECIMEN, "--length", "100", "--width", "25", "--thickness", "-1"],
                           "thickness must be a positive number of mm, got -1 mm"),
    "workers -3": (lambda t: ["--curve", SPECIMEN, *GEOMETRY, "--per-specimen", "--workers", "-3"],
                   "--workers: -3 must be at least 1"),
    "curve is a folder": (lambda t: ["--curve", t, *GEOMETRY], "is a folder, not a file"),
    "manifest is a folder": (lambda t: ["--manifest", t], "is a folder, not a file"),
    "curve missing": (lambda t: ["--curve", t / "nope.csv", *GEOMETRY], "not found; check the path"),
    "binary curve": (lambda t: ["--curve", text_file(t, "plot.png", b"\x89PNG\r\n\x1a\n\x00\x00", "wb"), *GEOMETRY],
                     "not a text CSV file"),
    "preamble width without unit": (lambda t: ["--curve", text_file(t, "w.csv", '"Width","25"\n"Thickness (mm)","2"\n'
                                                                    '"Gauge length (mm)","100"\n\n' + EXPORT.read_text()
                                                                    .split("\n\n", 1)[1])], "without a unit"),
    "export without displacement": (lambda t: ["--curve", text_file(t, "strain.csv", EXPORT.read_text().replace(
        "Extension (mm)", "Strain (%)")), *GEOMETRY], "no displacement column among ['Time (s)', 'Strain (%)'"),
    "second curve in the file": (lambda t: ["--curve", text_file(t, "two.csv", EXPORT.read_text() + "\n" +
                                                                 EXPORT.read_text().split("\n\n", 1)[1])],
                                 "holds a second curve"),
    "broken data row": (lambda t: ["--curve", text_file(t, "row.csv", "displacement [mm],force [N]\n1,1\n2,x\n3,3\n"),
                                   *GEOMETRY], "data row 2 is not numeric"),
    "unknown unit in the units row": (lambda t: ["--curve", text_file(t, "u.csv", "Extension;Load\n(mm);(stone)\n"
                                                                      "1;1\n2;2\n3;3\n"), *GEOMETRY],
                                      "unknown force unit 'stone'"),
    "compare-laws with --law": (lambda t: ["--curve", SPECIMEN, *GEOMETRY, "--compare-laws", "--law", "yeoh"],
                                "drop --law yeoh"),
    "compare-laws per specimen": (lambda t: ["--compare-laws", "--per-specimen"], "drop --per-specimen"),
}


@pytest.mark.parametrize("case", CASES)
def test_bad_calibrate_input(case, good_output, tmp_path, capsys):
    out, snapshot = good_output
    build, words = CASES[case]
    args = [str(a) for a in build(tmp_path)]
    capsys.readouterr()
    assert main(["calibrate", *args, *QUICK, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    errors = [line for line in err if line.startswith("colonsim: error:")]
    assert len(errors) == 1 and words in errors[0], err
    assert not any("Traceback" in line for line in err)
    assert {p: p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()} == snapshot


@pytest.mark.parametrize("target,words", [("file", "is an existing file, not a folder"),
                                          ("below a file", "is a file, not a folder")])
def test_out_that_cannot_be_a_folder(target, words, tmp_path, capsys):
    existing = tmp_path / "results.csv"
    existing.write_text("keep me\n")
    out = existing if target == "file" else existing / "calibration"
    assert main(["calibrate", "--curve", str(SPECIMEN), *GEOMETRY, *QUICK, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and len(err.splitlines()) == 1
    assert existing.read_text() == "keep me\n" and sorted(tmp_path.iterdir()) == [existing]


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes anywhere")
def test_out_without_permission(tmp_path, capsys):
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o555)
    assert main(["calibrate", "--curve", str(SPECIMEN), *GEOMETRY, *QUICK, "--out", str(locked / "x")]) == 2
    assert "cannot write in" in capsys.readouterr().err

