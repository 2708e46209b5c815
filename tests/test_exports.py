"""Testing-machine exports read as written: preamble, units row, decimal comma, tabs, code pages,
summary rows; geometry from the preamble, the caller's value winning with a warning."""

import json
from pathlib import Path

import numpy as np
import pytest

from colonsim.data import TENSILE_DIR
from colonsim.cli import main
from colonsim.errors import ColonsimError
from colonsim.identification.testdata import CurveWarning, TensileCurve, read_curve, read_manifest

ROOT = Path(__file__).resolve().parents[1]
EXPORTS = ROOT / "tests" / "data" / "exports"
GEOM = dict(length=0.1, width=0.025, thickness=0.00178)
FROM_FILE = dict(length=0.1, width=0.025, thickness=0.00178)


@pytest.fixture(scope="module")
def reference():
    """Every export in the corpus holds bundled specimen_01, every 10th sample (mm, N)."""
    c = read_curve(TENSILE_DIR / "specimen_01.csv", **GEOM)
    return c.displacement[::10], c.force[::10]


# file, geometry the caller must give, expected layout (delimiter, decimal mark, encoding, units row, rows ignored)
CORPUS = [
    ("instron_preamble.csv", {}, ("comma", ".", "utf-8", False, 0)),
    ("bluehill3_units_row.csv", {}, ("comma", ".", "utf-8", True, 0)),
    ("bluehill_universal_results_first.csv", {"length": 0.1}, ("comma", ".", "utf-8", True, 0)),
    ("testxpert_de_semicolon_decimal_comma.csv", {}, ("semicolon", ",", "cp1252", True, 0)),
    ("testxpert_en_tab_bom.txt", {}, ("tab", ".", "utf-8", True, 0)),
    ("trapezium_blocks.csv", {}, ("comma", ".", "utf-8", True, 0)),
    ("mts_testsuite_kN.csv", GEOM, ("comma", ".", "utf-8", True, 0)),
    ("summary_rows_after_data.csv", GEOM, ("comma", ".", "utf-8", False, 4)),
]


@pytest.mark.parametrize("name,given,layout", CORPUS, ids=[c[0] for c in CORPUS])
def test_corpus_reads_the_same_curve(name, given, layout, reference):
    c = read_curve(EXPORTS / name, **given)
    np.testing.assert_allclose(c.displacement, reference[0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(c.force, reference[1], rtol=0, atol=1e-6)
    assert (c.length, c.width, c.thickness) == pytest.approx(tuple(FROM_FILE.values()), rel=1e-12)
    found = c.meta["layout"]
    assert (found["delimiter"], found["decimal_mark"], found["encoding"], found["units_row"],
            found["rows_after_data_ignored"]) == layout
    for quantity, source in c.meta["geometry_from"].items():
        assert source.startswith("preamble") == (quantity not in given), (quantity, source)


def test_grip_separation_preferred_to_gauge_length(tmp_path):
    p = tmp_path / "both.csv"
    p.write_text('"Gauge length (mm)","50"\n"Grip separation (mm)","100"\n"Width (mm)","25"\n"Thickness (mm)","2"\n'
                 "\nextension (mm),load (N)\n1,1\n2,2\n3,3\n")
    c = read_curve(p)
    assert c.length == pytest.approx(0.1) and "Grip separation" in c.meta["geometry_from"]["length"]


def test_preamble_spellings_and_units(tmp_path):
    p = tmp_path / "spellings.csv"
    p.write_text("Specimen width: 0.984 in\nSpecimen thickness [mm];1,8\nClamping length = 10 cm\n"
                 "Extensometer gauge length;25;mm\n\nWeg [mm];Kraft [N]\n1,0;1,0\n2,0;2,0\n3,0;3,5\n")
    c = read_curve(p)
    assert c.width == pytest.approx(0.984 * 0.0254) and c.thickness == pytest.approx(1.8e-3)
    assert c.length == pytest.approx(0.1)  # the extensometer's gauge length is not the grips'
    np.testing.assert_allclose(c.force, [1.0, 2.0, 3.5])


def test_given_geometry_wins_and_a_disagreement_names_both(tmp_path):
    with pytest.warns(CurveWarning, match=r"thickness given 2 mm disagrees with the file's 'Thickness \(mm\)' = 1.78 mm"):
        c = read_curve(EXPORTS / "instron_preamble.csv", thickness=0.002)
    assert c.thickness == 0.002 and c.meta["geometry_from"]["thickness"] == "thickness given"


def test_cli_reports_the_disagreement_and_records_the_preamble(tmp_path, capsys):
    out = tmp_path / "cal"
    assert main(["calibrate", "--curve", str(EXPORTS / "instron_preamble.csv"), "--thickness", "2", "--analytic",
                 "--quick", "--no-progress", "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert "colonsim: warning:" in captured.err and "--thickness 2 mm disagrees" in captured.err \
        and "1.78 mm" in captured.err
    doc = json.loads((out / "material.json").read_text())
    source = doc["provenance"]["source_files"][0]
    assert source["preamble"][:2] == ["Specimen,S7", "Width (mm),25.0"]
    assert source["geometry_from"]["thickness"] == "--thickness"
    assert doc["specimen"]["thickness_mm"] == 2.0 and doc["specimen"]["width_mm"] == 25.0


def test_export_with_preamble_calibrates_from_the_file_alone(tmp_path, capsys):
    """The issue's export: `colonsim calibrate --curve FILE` with no geometry flags."""
    out = tmp_path / "cal"
    assert main(["calibrate", "--curve", str(EXPORTS / "instron_preamble.csv"), "--analytic", "--quick",
                 "--no-progress", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "width from the preamble 'Width (mm)' = 25 mm (line 2)" in text
    doc = json.loads((out / "material.json").read_text())
    assert (doc["specimen"]["length_mm"], doc["specimen"]["width_mm"], doc["specimen"]["thickness_mm"]) == \
        pytest.approx((100.0, 25.0, 1.78))
    assert doc["provenance"]["source_files"][0]["layout"]["header_line"] == 7


def test_manifest_leaves_blank_geometry_to_the_preamble(tmp_path):
    m = tmp_path / "manifest.csv"
    m.write_text("specimen,file,length_mm,width_mm,thickness_mm\n"
                 f"a,{EXPORTS / 'trapezium_blocks.csv'},,,\nb,{EXPORTS / 'instron_preamble.csv'},100,25,2\n")
    with pytest.warns(CurveWarning, match="manifest.csv thickness_mm 2 mm disagrees"):
        a, b = read_manifest(m)
    assert a.thickness == pytest.approx(1.78e-3) and b.thickness == pytest.approx(2e-3)


@pytest.mark.parametrize("text,given,message", [
    ('"Width","25"\n"Thickness (mm)","2"\n"Grip separation (mm)","100"\n\nextension (mm),load (N)\n1,1\n2,2\n3,3\n', {},
     r"gives 'Width' = 25 \(line 1\) without a unit"),
    ('"Width (mm)","25"\n"Width (mm)","20"\n"Thickness (mm)","2"\n"Grip separation (mm)","100"\n\n'
     "extension (mm),load (N)\n1,1\n2,2\n3,3\n", {}, "gives the width differently"),
    ('"Name","Thickness","Width","Gauge Length"\n"","mm","mm","mm"\n"A","1.8","25","100"\n"B","1.9","25","100"\n\n'
     "extension (mm),load (N)\n1,1\n2,2\n3,3\n", {}, "lists 2 test pieces"),
    ('"Width (%)","25"\n"Thickness (mm)","2"\n"Grip separation (mm)","100"\n\nextension (mm),load (N)\n1,1\n2,2\n3,3\n',
     {}, "is in '%', not a length unit"),
    ("extension (mm),load (N)\n1,1\n2,2\n3,3\n\nSpecimen 2\nextension (mm),load (N)\n1,1\n2,2\n", GEOM,
     "holds a second curve"),
    ("extension (mm),load (N)\n1,1\n2,2\nMean,1.5,1.5\n3,3\n", GEOM, r"data row 3 is not numeric or is short \(line 4"),
    ('"Specimen","S7"\n"Rate","10 mm/min"\n\n"Time (s)","Strain (%)","Load (N)"\n0.1,0.1,1\n0.2,0.2,2\n', GEOM,
     r"no displacement column among \['Time \(s\)', 'Strain \(%\)', 'Load \(N\)'\] \(line 4"),
    ("extension;load\n(mm);(furlong)\n1;1\n2;2\n3;3\n", GEOM, "unknown force unit 'furlong'"),
    ("extension (mm);load (N)\n(cm);(N)\n1;1\n2;2\n3;3\n", GEOM, "header says displacement in 'mm' but the units row says 'cm'"),
])
def test_bad_exports(tmp_path, text, given, message):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(ColonsimError, match=message):
        read_curve(p, **given)


def test_code_pages_and_bom(tmp_path):
    latin = tmp_path / "latin1.csv"
    latin.write_bytes("Weg [µm];Kraft [N]\n10;1,5\n20;2,5\n30;3,5\n".encode("latin-1"))
    c = read_curve(latin, **GEOM)
    np.testing.assert_allclose(c.displacement, [1e-5, 2e-5, 3e-5])
    np.testing.assert_allclose(c.force, [1.5, 2.5, 3.5])
    wide = tmp_path / "utf16.txt"
    wide.write_bytes("Time (s)\tPosition (mm)\tLoad (kN)\n0\t1\t0.001\n1\t2\t0.002\n2\t3\t0.003\n".encode("utf-16"))
    c = read_curve(wide, **GEOM)
    np.testing.assert_allclose(c.force, [1.0, 2.0, 3.0])
    thousands = tmp_path / "thousands.csv"
    thousands.write_text('Time,Extension,Load\n(s),(mm),(N)\n"999.5","1.5","1.0"\n"1,000.5","2.5","1,001.25"\n'
                         '"1,001.5","3.5","1,002.5"\n')
    np.testing.assert_allclose(read_curve(thousands, **GEOM).force, [1.0, 1001.25, 1002.5])


def test_machine_coordinates_read_as_compression(tmp_path):
    """MTS frames record tension as negative: say so instead of fitting nonsense."""
    lines = (EXPORTS / "mts_testsuite_kN.csv").read_text().splitlines()
    data = lines.index('"sec","mm","kN"') + 1
    negated = [",".join([a, b, f'"{-float(c.strip(chr(34))):.7f}"']) for a, b, c in (r.split(",") for r in lines[data:])]
    p = tmp_path / "mts_negative.csv"
    p.write_text("\n".join(lines[:data] + negated) + "\n")
    with pytest.raises(ColonsimError, match="forces are compressive.*negate the force column"):
        read_curve(p, **GEOM)


@pytest.mark.parametrize("force,message", [(np.zeros(4), "force is zero throughout"),
                                           (-np.arange(1.0, 5.0), "forces are compressive")])
def test_a_tensile_curve_pulls(force, message):
    with pytest.raises(ColonsimError, match=message):
        TensileCurve("c", np.arange(1.0, 5.0) * 1e-3, force, **GEOM)


def test_geometry_errors_quote_mm_and_folders_are_not_missing_files(tmp_path):
    with pytest.raises(ColonsimError, match="thickness must be a positive number of mm, got -1 mm"):
        read_curve(EXPORTS / "mts_testsuite_kN.csv", length=0.1, width=0.025, thickness=-1e-3)
    with pytest.raises(ColonsimError, match="is a folder, not a file"):
        read_curve(tmp_path, **GEOM)
    with pytest.raises(ColonsimError, match="is a folder, not a file"):
        read_manifest(tmp_path)


@pytest.mark.parametrize("header", ["stretch,nominal_stress_MPa", "stretch,nominal_stress [MPa]", "Stretch,Nominal_Stress_mpa"])
def test_a_stress_curve_with_the_unit_after_an_underscore_and_the_unloaded_state_first(tmp_path, header):
    """The layout of published data sets: ``stretch,nominal_stress_MPa`` and a first row at stretch 1, stress 0."""
    from colonsim.identification.stress_curves import read_stress_curve

    p = tmp_path / "uniaxial.csv"
    p.write_text(f"{header}\n1,0\n1.5,0.3\n2,0.7\n3,2.2\n")
    c = read_stress_curve(p, "uniaxial")
    np.testing.assert_allclose(c.stretch, [1.0, 1.5, 2.0, 3.0])
    np.testing.assert_allclose(c.stress, [0.0, 3e5, 7e5, 2.2e6])
    p.write_text("stretch,nominal_stress_furlong\n1,0\n1.5,0.3\n2,0.7\n")
    with pytest.raises(ColonsimError, match="the stress unit is not stated"):
        read_stress_curve(p, "uniaxial")
