"""A patient's centerline through the case, the sweep file and the command line: validation, keys
that follow the file's content, one-line errors with exit code 2 and nothing written."""

import json
import shutil

import numpy as np
import pandas as pd
import pytest
from centerline_files import PLAIN, hairpin, loop

from colonsim.catalog import SMOKE_ELEMENT_MM, SMOKE_PUSH_SPEED, SMOKE_SCOPE_SPACING_MM
from colonsim.cli import main
from colonsim.data import data_path
from colonsim.errors import ColonsimError
from colonsim.insertion.case.scenario import InsertionCase
from colonsim.insertion.study.sweep_spec import parse_sweep

EXAMPLE = data_path("anatomy", "sigmoid_loop.csv")
HEADER = "x_mm,y_mm,z_mm,label,diameter_mm\n"


def _rsj_like(diameters=("", "", "")):
    """A 4 cm fixed rectum, a mobile half turn of radius 5 cm and a 6 cm fixed exit, points ~1 cm apart."""
    rows = [(0.0, y, 0.0, "fixed" if y == 0 else "", diameters[0] if y == 0 else "") for y in range(0, 40, 10)]
    theta = np.linspace(0.0, np.pi, 16)
    rows += [(-50 + 50 * np.cos(a), 40 + 50 * np.sin(a), 0.0, "mobile" if i == 0 else "", diameters[1] if i == 0 else "")
             for i, a in enumerate(theta)]
    rows += [(-100.0, 40 - y, 0.0, "fixed" if y == 10 else "", diameters[2] if y == 10 else "") for y in range(10, 70, 10)]
    if not any(diameters):
        return PLAIN + "".join(f"{x:.3f},{y:.3f},{z},{label}\n" for x, y, z, label, _ in rows)
    return HEADER + "".join(f"{x:.3f},{y:.3f},{z},{label},{d}\n" for x, y, z, label, d in rows)


@pytest.fixture
def files(tmp_path):
    texts = {"good.csv": _rsj_like(), "profile.csv": _rsj_like(("40", "30", "40")),
             "narrow.csv": _rsj_like(("30", "12", "30")), "hairpin.csv": hairpin(), "loop.csv": loop(),
             "few.csv": PLAIN + "0,0,0,mobile\n0,10,0,\n",
             "no_units.csv": "x,y,z,label\n0,0,0,mobile\n", "cm.csv": "x_cm,y_cm,z_cm,label\n0,0,0,mobile\n",
             "fixed_only.csv": _rsj_like().replace("mobile", "fixed"),
             "bad_number.csv": _rsj_like().replace("0.000,10.000", "0.000,1O.000")}
    for name, text in texts.items():
        (tmp_path / name).write_text(text)
    return tmp_path


@pytest.mark.parametrize("args,message", [
    (["--centerline", "{d}/missing.csv"], "not found"),
    (["--centerline", "{d}/few.csv"], "2 point(s); a centerline needs at least 5"),
    (["--centerline", "{d}/no_units.csv"], "name the columns x_mm, y_mm, z_mm"),
    (["--centerline", "{d}/cm.csv"], "gives a coordinate in cm"),
    (["--centerline", "{d}/fixed_only.csv"], "no point is labelled mobile"),
    (["--centerline", "{d}/bad_number.csv"], "line 3: y_mm = '1O.000' is not a number"),
    (["--centerline", "{d}/hairpin.csv"], "tighter than the colon wall's outer surface"),
    (["--centerline", "{d}/loop.csv", "--diameter", "30"], "the tube cuts itself"),
    (["--centerline", "{d}/narrow.csv", "--scope", "sdc"], "does not fit the narrowest lumen"),
    (["--centerline", "{d}/profile.csv", "--diameter", "36"], "set the case's diameter_mm = 36.6"),
    (["--centerline", "{d}/good.csv", "--segment", "rsj"], "drop --segment rsj"),
    (["--centerline", "{d}/good.csv", "--centerline-smoothing", "-1"], "centerline smoothing -1.0 mm is outside"),
    (["--segment", "patient"], "give the file (--centerline FILE"),
    (["--centerline-smoothing", "2"], "--centerline-smoothing goes with --centerline"),
])
def test_bad_centerline_is_one_line_exit_2_and_nothing_written(files, args, message, capsys):
    out = files / "out"
    code = main(["insert", *[a.replace("{d}", str(files)) for a in args], "--no-progress", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("colonsim: error: "), err
    assert message in err[0], err[0]
    assert not out.exists()


def test_a_patient_runs_from_the_command_line(files, capsys):
    out = files / "run"
    assert main(["insert", "--centerline", str(files / "profile.csv"), "--scope", "utc", "--element-size",
                 str(SMOKE_ELEMENT_MM), "--scope-spacing", str(SMOKE_SCOPE_SPACING_MM), "--push-speed",
                 str(SMOKE_PUSH_SPEED), "--no-progress", "--out", str(out)]) == 0
    summary = json.loads((out / "patient_UTC" / "summary.json").read_text())
    # the diameters at the ranges' first points (40, 30, 40 mm) interpolated along the points: median 36.6
    assert summary["inputs"]["segment"] == "patient" and summary["inputs"]["diameter_mm"] == 36.6
    assert summary["inputs"]["centerline"] == str((files / "profile.csv").resolve())
    assert summary["mesh"]["lumen_diameter_mm"]["min"] == pytest.approx(30.0)
    assert summary["mesh"]["lumen_diameter_mm"]["max"] == pytest.approx(40.0)
    assert summary["ended_by"] in ("far_end", "length_used", "jam") and summary["max_deformation_cm"] > 0.0
    # the scope is sized to the anatomy: centerline + 20 cm + the 2 cm kept in the sheath
    assert summary["scope"]["length_cm"] == pytest.approx(summary["mesh"]["centerline_length_cm"] + 22.0, abs=0.01)
    table = pd.read_csv(out / "comparison.csv")
    assert table["colon_diameter_mm"].tolist() == [36.6]


def test_case_checks_and_keys(files):
    assert InsertionCase(time_step_estimate="bounds").key() == "d1aafd84d442"  # ... and at the global time-step
    assert InsertionCase().key() == "fecd8bb9070e"  # estimate, the default since 2026-12-07 (the bounds' keep theirs)  # the quasi-static defaults (0.15 m/s), the 5 N distal resistance, the held push and the end at rest, the defaults of 2026-11-28; see test_material_samples
    assert InsertionCase(segment="rsf", scope="utc", angle_deg=30, friction=0.05,
                         time_step_estimate="bounds").key() == "cbf520e7eee8"
    assert InsertionCase(segment="rsf", scope="utc", angle_deg=30, friction=0.05).key() == "7e90c80d1d57"
    with pytest.raises(ColonsimError, match="use segment 'patient'"):
        InsertionCase(segment="rsj", centerline=str(files / "good.csv")).validate()
    case = InsertionCase(segment="patient", centerline=str(files / "good.csv"), scope="utc")
    case.validate()
    # the key follows the content: a copy elsewhere keeps it, an edit or a new tolerance changes it
    shutil.copy(files / "good.csv", files / "copy.csv")
    same = InsertionCase(segment="patient", centerline=str(files / "copy.csv"), scope="utc")
    assert same.key() == case.key() != InsertionCase(segment="patient", centerline=str(files / "profile.csv"),
                                                     scope="utc", diameter_mm=36.6).key()
    assert InsertionCase(segment="patient", centerline=str(files / "good.csv"), scope="utc",
                         centerline_smoothing_mm=0.5).key() != case.key()
    (files / "copy.csv").write_text(_rsj_like().replace("-100.000,30.000", "-100.000,31.000"))
    assert same.key() != case.key()


def test_sweep_files_take_a_centerline_relative_to_their_folder(files):
    (files / "sub").mkdir()
    shutil.copy(EXAMPLE, files / "sub" / "anatomy.csv")
    text = ('[fixed]\nsegment = "patient"\ncenterline = "anatomy.csv"\ndiameter_mm = 45\nelement_size_mm = 10\n'
            '[[grid]]\nscope = ["utc", "sdc"]\n')
    spec = parse_sweep(text, base=files / "sub")
    assert [c.centerline for c in spec.cases] == [str((files / "sub" / "anatomy.csv").resolve())] * 2
    with pytest.raises(ColonsimError, match="set the case's diameter_mm = 45"):
        parse_sweep(text.replace("= 45", "= 36"), base=files / "sub")
    with pytest.raises(ColonsimError, match="centerline = 3; give the path of a centerline CSV"):
        parse_sweep(text.replace('"anatomy.csv"', "3"), base=files / "sub")
