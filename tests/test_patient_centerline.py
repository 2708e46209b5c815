"""A patient's centerline: the CSV reader's one-line errors, the smoothed curve against analytic
curves, rotation-minimising frames, labelled ranges, diameter profiles and the tube around them."""

import numpy as np
import pytest
from centerline_files import hairpin, loop

from colonsim.data import data_path
from colonsim.errors import ColonsimError
from colonsim.insertion.anatomy.centerline_file import CenterlinePoints, read_centerline_points
from colonsim.insertion.anatomy.colon_geometry import tube_mesh
from colonsim.insertion.anatomy.colon_segments import colon_geometry
from colonsim.insertion.anatomy.patient_centerline import PatientCenterline, load_patient_centerline

EXAMPLE = data_path("anatomy", "sigmoid_loop.csv")
R_MM, STRAIGHT_MM = 50.0, 60.0


def _arc_and_straight(spacing_mm, noise_mm=0.0, seed=1):
    """A 6 cm straight along +y then a half circle of radius 5 cm turning to -x, sampled every ``spacing_mm``."""
    y = np.arange(0.0, STRAIGHT_MM, spacing_mm)
    theta = np.linspace(0.0, np.pi, int(round(np.pi * R_MM / spacing_mm)) + 1)
    p = np.vstack([np.column_stack([0 * y, y, 0 * y]),
                   np.column_stack([-R_MM + R_MM * np.cos(theta), STRAIGHT_MM + R_MM * np.sin(theta), 0 * theta])])
    p += np.random.default_rng(seed).normal(0.0, noise_mm, p.shape)
    labels = ("fixed",) * len(y) + ("mobile",) * len(theta)
    names = ("rectum",) * len(y) + ("sigmoid",) * len(theta)
    return CenterlinePoints("analytic", p, labels, names, None, tuple(range(2, len(p) + 2)))


def _write(tmp_path, text, name="c.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


GOOD = "x_mm,y_mm,z_mm,label\n" + "".join(f"0,{10 * i},0,{'fixed' if i == 0 else ('mobile' if i == 2 else '')}\n"
                                            for i in range(8))


# -- the reader's errors: one line, where, and the fix ------------------------------------------

@pytest.mark.parametrize("text,message", [
    ("x_mm,y_mm,z_mm,label\n0,0,0,fixed\n0,10,0,mobile\n0,20,0,\n0,30,0,\n", "4 point(s); a centerline needs at least 5"),
    ("x,y,z,label\n0,0,0,fixed\n", "column 'x' gives a coordinate without a unit; colonsim reads millimetres: name the "
                                   "columns x_mm, y_mm, z_mm"),
    ("x_cm,y_cm,z_cm,label\n0,0,0,fixed\n", "column 'x_cm' gives a coordinate in cm"),
    ("x [m],y [m],z [m],label\n0,0,0,fixed\n", "column 'x [m]' gives a coordinate in m"),
    ("x_mm,y_mm,z_mm\n0,0,0\n", "no column label"),
    ("x_mm,y_mm,z_mm,label,radius_mm\n0,0,0,fixed,3\n", "unknown column 'radius_mm'"),
    (GOOD.replace("0,30,0,", "0,3O,0,"), "line 5: y_mm = '3O' is not a number"),
    (GOOD.replace("0,30,0,", "0,nan,0,"), "line 5: y_mm = 'nan' is not a finite number"),
    (GOOD.replace("0,30,0,", "0,20,0,"), "lines 4 and 5 repeat the same point; delete one of them"),
    (GOOD.replace("0,20,0,mobile", "0,20,0,moblie"), "line 4: label 'moblie' is not fixed or mobile"),
    (GOOD.replace("0,0,0,fixed", "0,0,0,"), "line 2: the first point has no label"),
    (GOOD.replace("mobile", "fixed"), "no point is labelled mobile"),
    ("# only a comment\n", "holds no header"),
    (GOOD.replace("0,30,0,", "0,30,0,,7"), "line 5: 5 cells for 4 columns"),
    (GOOD.replace("0,30,0,", "0,3e7,0,"), "beyond 10000 mm"),
])
def test_bad_file_is_one_line_naming_the_fix(tmp_path, text, message):
    with pytest.raises(ColonsimError) as err:
        read_centerline_points(_write(tmp_path, text))
    assert message in str(err.value) and "\n" not in str(err.value)


def test_missing_file_and_bad_diameters(tmp_path):
    with pytest.raises(ColonsimError, match="not found"):
        read_centerline_points(tmp_path / "nope.csv")
    text = GOOD.replace("label\n", "label,diameter_mm\n")
    with pytest.raises(ColonsimError, match="diameter_mm column is empty"):
        read_centerline_points(_write(tmp_path, text))
    with pytest.raises(ColonsimError, match="line 3: diameter_mm = 2 is outside 5-120 mm"):
        read_centerline_points(_write(tmp_path, text.replace("0,10,0,\n", "0,10,0,,2\n")))


def test_comments_labels_names_and_blank_diameters(tmp_path):
    text = ("# from a CT colonography segmentation\n\nx_mm,y_mm,z_mm,label,diameter_mm,name\n"
            "0,0,0,fixed,40,rectum\n0,10,0,,,\n0,20,0,mobile,,\n0,30,0,,30,\n0,40,0,fixed,,\n0,50,0,,20,desc\n")
    pts = read_centerline_points(_write(tmp_path, text))
    assert pts.labels == ("fixed", "fixed", "mobile", "mobile", "fixed", "fixed")
    # a name continues from above; a range is a run of one (label, name)
    assert pts.names == ("rectum", "rectum", "rectum", "rectum", "rectum", "desc")
    assert pts.lines == (4, 5, 6, 7, 8, 9)
    assert np.allclose(pts.diameters_mm, np.interp([0, 10, 20, 30, 40, 50], [0, 30, 50], [40, 30, 20]))
    unnamed = read_centerline_points(_write(tmp_path, GOOD))
    assert sorted(set(unnamed.names)) == ["fixed 1", "mobile 2"]


def test_digest_is_of_the_content_not_the_text(tmp_path):
    a = read_centerline_points(_write(tmp_path, GOOD, "a.csv"))
    b = read_centerline_points(_write(tmp_path, "# a comment\r\n" + GOOD.replace("\n", "\r\n").replace(",10,", ",10.0,"),
                                      "b.csv"))
    c = read_centerline_points(_write(tmp_path, GOOD.replace("0,10,0", "0,11,0"), "c.csv"))
    assert a.digest() == b.digest() != c.digest()


# -- the smoothed curve ------------------------------------------------------------------------

def test_an_exact_arc_and_straight_are_recovered():
    """Noise-free points 5 mm apart, interpolated (tolerance 0): a cubic spline's error on a circle
    sampled at h is of order h^4 / R^3 (5e-3 mm here), so the length is exact to 0.05 mm, the bend
    radius in the middle of the arc to 1 %, and the label change sits at the junction."""
    c = PatientCenterline(_arc_and_straight(5.0), smoothing_mm=0.0)
    assert c.length * 1e3 == pytest.approx(STRAIGHT_MM + np.pi * R_MM, abs=0.05)
    middle = c.curvature_radius(np.linspace(0.085, 0.19, 40))
    assert np.allclose(middle * 1e3, R_MM, rtol=0.01)
    assert [(p.tag, p.name) for p in c.pieces] == [("fixed", "rectum"), ("mobile", "sigmoid")]
    assert c.s_start[1] * 1e3 == pytest.approx(STRAIGHT_MM, abs=0.05)
    assert c.tag_at(0.03) == "fixed" and c.tag_at(0.1) == "mobile" and c.bounds("sigmoid")[1] == c.length


def test_noisy_points_are_smoothed_within_the_tolerance():
    """Points 1 mm apart with 0.25 mm of noise per coordinate (a CT centerline): the default 1 mm
    RMS tolerance may cut the bend by up to about 1 mm, which shortens a half turn by up to
    pi x 1 mm; the bend radius stays within 10 % of 5 cm over the middle of the arc (the smoothing
    spreads the curvature step at the junction over a few cm, and a smoothing spline straightens
    towards a free end)."""
    c = PatientCenterline(_arc_and_straight(1.0, noise_mm=0.25))
    assert abs(c.length * 1e3 - (STRAIGHT_MM + np.pi * R_MM)) < np.pi * 1.0
    radius = c.curvature_radius(np.linspace(0.09, 0.17, 40)) * 1e3
    assert np.all(np.abs(radius - R_MM) < 0.1 * R_MM), (radius.min(), radius.max())
    # unsmoothed, the same noise makes bends of a few mm that no tube can follow
    assert PatientCenterline(_arc_and_straight(1.0, noise_mm=0.25), smoothing_mm=0.0).min_radius < 0.01


def test_frames_are_orthonormal_and_do_not_twist():
    # a helix of radius a and pitch 2 pi b: a rotation-minimising frame turns about the tangent by
    # nothing, so n(s + h) . b(s) = O(h^2)
    a, b = 40.0, 15.0
    t = np.linspace(0.0, 3 * np.pi, 150)
    p = np.column_stack([a * np.cos(t), a * np.sin(t), b * t])
    labels = ("mobile",) * len(t)
    c = PatientCenterline(CenterlinePoints("helix", p, labels, labels, None, tuple(range(len(t)))), 0.0)
    s = np.linspace(0.0, c.length, 400)
    x, tan, nor, bi = c.frame(s)
    frame = np.stack([tan, nor, bi], axis=1)
    assert np.allclose(frame @ frame.transpose(0, 2, 1), np.eye(3), atol=1e-12)
    assert np.allclose(np.linalg.det(frame), 1.0)
    h = 1e-4
    _, _, nor_h, _ = c.frame(s[:-1] + h)
    twist = np.einsum("ij,ij->i", nor_h, bi[:-1]) / h  # rotation rate about the tangent, rad/m
    assert np.abs(twist).max() < 0.05  # the helix's torsion is b / (a^2 + b^2) = 8.2 rad/m
    # on a planar curve the plane's normal (z) stays one of the frame's axes
    _, _, nor, bi = PatientCenterline(_arc_and_straight(5.0), 0.0).frame(np.linspace(0.0, 0.2, 300))
    assert any(np.allclose(np.abs(v[:, 2]), 1.0, atol=1e-9) for v in (nor, bi))


# -- the tube: bends, clashes, labelled nodes, diameter profile ----------------------------------

def test_a_bend_tighter_than_the_tube_names_where(tmp_path):
    c = load_patient_centerline(_write(tmp_path, hairpin()))
    with pytest.raises(ColonsimError, match=r"bends with radius .* mm at .* cm \(near line .*tighter than the colon "
                                            r"wall's outer surface.*raise the smoothing tolerance"):
        colon_geometry("patient", 0.036, 0.0, 0.004, 0.002, centerline=c)


def test_a_tube_cutting_itself_names_both_places(tmp_path):
    c = load_patient_centerline(_write(tmp_path, loop()))
    with pytest.raises(ColonsimError, match=r"the tube cuts itself: the centerline at .* cm \(near line \d+\) passes "
                                            r".* mm from itself at .* cm \(near line \d+\)"):
        colon_geometry("patient", 0.030, 0.0, 0.004, 0.002, centerline=c)


def test_labelled_ranges_become_fixed_and_mobile_nodes():
    c = PatientCenterline(_arc_and_straight(5.0), 0.0)
    mesh = tube_mesh(c, 0.036, 0.004)
    inner = ~mesh.end_ring
    expected_fixed = mesh.s < c.s_start[1]
    assert np.array_equal(mesh.fixed[inner], expected_fixed[inner])
    assert mesh.mobile.sum() > 0 and mesh.fixed[mesh.end_ring].all()


def test_a_diameter_profile_keeps_rings_and_near_equilateral_triangles():
    pts = _arc_and_straight(5.0)
    n = len(pts.points_mm)
    d = np.linspace(40.0, 25.0, n)
    c = PatientCenterline(CenterlinePoints("profile", pts.points_mm, pts.labels, pts.names, d, pts.lines), 0.0)
    h = 0.004
    mesh = tube_mesh(c, c.diameter_at, h)
    m = mesh.nodes_per_ring
    assert m == round(np.pi * 0.040 / h) and len(mesh.nodes) == m * mesh.n_rings  # sized on the widest ring
    # every ring lies at its profile's radius around its centre
    r = np.linalg.norm(mesh.nodes - c.position(mesh.s), axis=1)
    assert np.allclose(r, 0.5 * c.diameter_at(mesh.s), rtol=1e-9)
    assert np.allclose(mesh.ring_diameters, c.diameter_at(mesh.s[::m]))
    # edges: at most the element size (bend stretch aside), and near equilateral where it narrows
    tri = mesh.nodes[mesh.triangles]
    edges = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2)
    straight = mesh.s[mesh.triangles].max(axis=1) < 0.055
    assert edges[straight].max() < 1.05 * h
    assert (edges[straight].max(axis=1) / edges[straight].min(axis=1)).max() < 1.25


def test_the_bundled_example_reads_and_meshes():
    c = load_patient_centerline(EXAMPLE)
    assert [p.name for p in c.pieces] == ["rectum", "sigmoid", "descending"]
    assert [p.tag for p in c.pieces] == ["fixed", "mobile", "fixed"]
    assert 0.40 < c.length < 0.60 and c.median_diameter_mm is not None
    g = colon_geometry("patient", c.median_diameter_mm * 1e-3, 0.0, 0.006, 0.002, centerline=c)
    assert g.mobile.any() and g.summary()["lumen_diameter_mm"]["min"] == pytest.approx(40.0)
    with pytest.raises(ColonsimError, match="set the case's diameter_mm = 45"):
        colon_geometry("patient", 0.036, 0.0, 0.006, 0.002, centerline=c)
