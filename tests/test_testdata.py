"""Reading tensile test data: units, geometry, and a clear message for every bad input."""

import numpy as np
import pytest

from colonsim.errors import ColonsimError
from colonsim.identification.testdata import TensileCurve, mean_curve, read_curve, read_manifest, write_curve

GEOM = dict(length=0.1, width=0.025, thickness=0.002)
GOOD = "displacement [mm],force [N]\n0.5,0.10\n1.0,0.21\n1.5,0.33\n2.0,0.46\n"


def write(tmp_path, text, name="curve.csv", mode="w"):
    p = tmp_path / name
    if mode == "wb":
        p.write_bytes(text)
    else:
        p.write_text(text)
    return p


def test_reads_si_and_units_from_header(tmp_path):
    c = read_curve(write(tmp_path, "# machine export\nExtension (cm);Load (kN)\n0.1;0.001\n0.2;0.002\n0.3;0.004\n"), **GEOM)
    np.testing.assert_allclose(c.displacement, [1e-3, 2e-3, 3e-3])
    np.testing.assert_allclose(c.force, [1.0, 2.0, 4.0])
    assert c.name == "curve"


def test_unit_option_when_header_is_silent(tmp_path):
    c = read_curve(write(tmp_path, "displacement,force\n1,1\n2,2\n3,3\n"), **GEOM, displacement_unit="mm", force_unit="mN")
    assert c.displacement[-1] == pytest.approx(3e-3) and c.force[-1] == pytest.approx(3e-3)


def test_round_trip_through_write_curve(tmp_path):
    c = TensileCurve("s", np.array([1e-3, 2e-3, 3e-3]), np.array([0.1, 0.2, 0.35]), **GEOM)
    write_curve(tmp_path / "s.csv", c, comment="synthetic")
    back = read_curve(tmp_path / "s.csv", **GEOM)
    np.testing.assert_allclose(back.force, c.force)
    np.testing.assert_allclose(back.displacement, c.displacement)


@pytest.mark.parametrize("text,message", [
    ("", "the file is empty"),
    ("# only a comment\n", "the file is empty"),
    ("12345\n1\n2\n", "not a CSV with displacement and force columns"),
    ("time [s],force [N]\n1,1\n2,2\n3,3\n", "no displacement column"),
    ("displacement [mm],stress [MPa]\n1,1\n2,2\n3,3\n", "no force column"),
    ("displacement [furlong],force [N]\n1,1\n2,2\n3,3\n", "unknown displacement unit 'furlong'"),
    ("displacement [mm],force [pound]\n1,1\n2,2\n3,3\n", "unknown force unit 'pound'"),
    ("displacement,force [N]\n1,1\n2,2\n3,3\n", "the displacement unit is not stated"),
    ("displacement [mm],force [N]\n", "header but no data rows"),
    ("displacement [mm],force [N]\n1,1\n2,abc\n3,3\n", "data row 2 is not numeric"),
    ("displacement [mm],force [N]\n1,1\n2,nan\n3,3\n", "NaN or infinite value at data row 2"),
    ("displacement [mm],force [N]\n1,1\n2,2\n", "only 2 data rows"),
    ("displacement [mm],force [N]\n1,1\n2,2\n2,3\n4,4\n", "not strictly increasing at data row 3"),
    ("displacement [mm],force [N]\n1,1\n3,2\n2,3\n4,4\n", "not strictly increasing"),
])
def test_bad_curve_files(tmp_path, text, message):
    with pytest.raises(ColonsimError, match=message.replace("(", r"\(")):
        read_curve(write(tmp_path, text), **GEOM)


def test_binary_file_is_not_csv(tmp_path):
    with pytest.raises(ColonsimError, match="not a text CSV"):
        read_curve(write(tmp_path, b"\x89PNG\r\n\x1a\n\xff\xfe\x00", "plot.png", "wb"), **GEOM)


def test_missing_file(tmp_path):
    with pytest.raises(ColonsimError, match="not found"):
        read_curve(tmp_path / "nope.csv", **GEOM)


def test_conflicting_units(tmp_path):
    with pytest.raises(ColonsimError, match="header says displacement in 'mm' but the option says 'cm'"):
        read_curve(write(tmp_path, GOOD), **GEOM, displacement_unit="cm")


@pytest.mark.parametrize("key,value,message", [("thickness", 0.0, "thickness must be a positive number"),
                                               ("width", -0.02, "width must be a positive number"),
                                               ("length", float("nan"), "length must be a positive number"),
                                               ("thickness", None, "thickness is missing")])
def test_bad_geometry(tmp_path, key, value, message):
    with pytest.raises(ColonsimError, match=message):
        read_curve(write(tmp_path, GOOD), **{**GEOM, key: value})


def test_manifest_errors(tmp_path):
    write(tmp_path, GOOD, "a.csv")
    with pytest.raises(ColonsimError, match="manifest lacks the column"):
        read_manifest(write(tmp_path, "specimen,file,length_mm\na,a.csv,100\n", "m.csv"))
    with pytest.raises(ColonsimError, match="non-numeric thickness_mm"):
        read_manifest(write(tmp_path, "specimen,file,length_mm,width_mm,thickness_mm\na,a.csv,100,25,thick\n", "m.csv"))
    with pytest.raises(ColonsimError, match="thickness must be a positive number"):
        read_manifest(write(tmp_path, "specimen,file,length_mm,width_mm,thickness_mm\na,a.csv,100,25,-2\n", "m.csv"))
    with pytest.raises(ColonsimError, match="lists no specimens"):
        read_manifest(write(tmp_path, "specimen,file,length_mm,width_mm,thickness_mm\n", "m.csv"))


def test_mean_curve_averages_on_a_common_grid():
    d = np.linspace(0.0, 0.06, 241)
    a = TensileCurve("a", d, 100 * d, **GEOM)
    b = TensileCurve("b", d[:200], 300 * d[:200], **{**GEOM, "thickness": 0.004})
    m = mean_curve([a, b])
    assert m.max_displacement <= b.max_displacement
    np.testing.assert_allclose(m.force, 200 * m.displacement, rtol=1e-12)
    assert m.thickness == pytest.approx(0.003)
    with pytest.raises(ColonsimError, match="equal length and width"):
        mean_curve([a, TensileCurve("c", d, d, **{**GEOM, "width": 0.02})])
