"""Colon model geometry (SPEC.md 2.1): centerline lengths, smoothness, tags, mesh quality."""

import numpy as np
import pytest

from colonsim.errors import ColonsimError
from insertion.colon_segments import FILLET_RADIUS, FLEXURE_RADIUS, colon_geometry, rsf_centerline, rsj_centerline, thf_centerline

R, RF = FLEXURE_RADIUS, FILLET_RADIUS


def test_rsj_length_is_rectum_plus_half_circle():
    assert rsj_centerline().length == pytest.approx(0.04 + np.pi * R, rel=1e-12)


@pytest.mark.parametrize("alpha", [0.0, 30.0, 45.0])
def test_rsf_length_with_fillets(alpha):
    a = np.radians(alpha)
    # two fillets, each trims R_f tan(a/2) off both neighbours and adds an arc R_f a; flexure 90 deg
    expected = 0.04 + 0.20 + 0.10 - 4 * RF * np.tan(a / 2) + 2 * RF * a + R * np.pi / 2
    assert rsf_centerline(alpha).length == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("make", [lambda: rsf_centerline(45.0), lambda: thf_centerline(30.0), lambda: rsj_centerline()])
def test_centerline_is_c1_at_every_junction(make):
    c = make()
    for piece in c.pieces[1:]:
        s = piece["s0"]
        p0, t0, _ = c.frame(s - 1e-9)
        p1, t1, _ = c.frame(s + 1e-9)
        assert np.linalg.norm(p1 - p0) < 1e-7 and np.linalg.norm(t1 - t0) < 1e-6, piece["name"]


def test_rsf_descending_colon_parallel_to_the_rectum_and_sigmoid_tilted():
    c = rsf_centerline(30.0)
    s0, s1 = c.ends("sigmoid")
    assert c.frame(0.5 * (s0 + s1))[1] == pytest.approx([-0.5, np.sqrt(3) / 2, 0.0], abs=1e-12)
    s0, s1 = c.ends("descending")
    assert c.frame(0.5 * (s0 + s1))[1] == pytest.approx([0.0, 1.0, 0.0], abs=1e-12)


@pytest.mark.parametrize("beta", [0.0, 30.0, 45.0])
def test_thf_transverse_spans_20_cm_and_droops_with_beta(beta):
    c = thf_centerline(beta)
    start = c.frame(c.ends("splenic flexure")[1])[0]
    end = c.frame(c.ends("hepatic flexure")[0])[0]
    assert np.linalg.norm(end - start) == pytest.approx(0.20, rel=1e-9)
    s = np.linspace(c.ends("splenic flexure")[1], c.ends("hepatic flexure")[0], 2001)
    lowest = min(c.frame(si)[0][1] for si in s)
    # the sharp V would sink 10 tan(beta) cm; the fillet at its bottom lifts it by R_f (1/cos(beta) - 1)
    b = np.radians(beta)
    assert start[1] - lowest == pytest.approx(0.10 * np.tan(b) - RF * (1 / np.cos(b) - 1), abs=1e-6)


def test_mesh_tags_normals_and_sizes():
    g = colon_geometry("rsf", 0.036, 30.0, 3e-3, 2e-3)
    c = rsf_centerline(30.0)
    # mobile nodes: exactly the sigmoid's rings
    s0, s1 = c.ends("sigmoid")
    assert g.mobile.sum() > 0 and not np.any(g.mobile & g.fixed)
    assert g.end_ring.sum() == 2 * round(np.pi * 0.038 / 3e-3)
    # outward normals: away from the centerline at every triangle
    p = g.nodes[g.triangles]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    area = 0.5 * np.linalg.norm(n, axis=1)
    # triangles near-equilateral at 3 mm; compressed to R_in/R = 0.6 on the inside of a bend
    # and stretched to 1.4 on the outside
    target = np.sqrt(3) / 4 * (np.pi * 0.038 / round(np.pi * 0.038 / 3e-3)) ** 2
    assert 0.5 < area.min() / target and area.max() / target < 1.6
    assert g.straighten_depth == pytest.approx(c.ends("splenic flexure")[0])


def test_mesh_sizes_next_to_the_source():
    """Source: RSJ D23 2064 nodes, RSJ D36 2792, RSF 6632, THF 4086 (its THF did not include our
    5 cm lead-in, the flexures' full arcs and the 10 cm ascending colon)."""
    sizes = {(s, d): len(colon_geometry(s, d, 0.0, 3e-3, 2e-3).nodes)
             for s, d in (("rsj", 0.023), ("rsj", 0.036), ("rsf", 0.036), ("thf", 0.036))}
    for (seg, d), source in {("rsj", 0.023): 2064, ("rsj", 0.036): 2792, ("rsf", 0.036): 6632}.items():
        assert 0.8 < sizes[seg, d] / source < 1.2, (seg, d, sizes[seg, d])
    assert 1.0 < sizes["thf", 0.036] / 4086 < 2.5


@pytest.mark.parametrize("args,message", [(("rsf", 0.036, 75.0), "outside 0-60 deg"),
                                          (("thf", 0.036, -5.0), "outside 0-60 deg"),
                                          (("rsj", 0.100, 0.0), "does not fit around a bend"),
                                          (("sigmoid", 0.036, 0.0), "not a colon model")])
def test_geometry_errors(args, message):
    with pytest.raises(ColonsimError, match=message):
        colon_geometry(*args, 3e-3, 2e-3)


def test_rsj_exit_piece_continues_fixed_and_moves_the_end_of_the_run():
    g = colon_geometry("rsj", 0.036, 0.0, 3e-3, 2e-3, exit_length=0.05)
    c = rsj_centerline(exit_length=0.05)
    assert c.length == pytest.approx(0.04 + np.pi * R + 0.05, rel=1e-12)
    assert g.end_depth == pytest.approx(0.04 + np.pi * R + 0.018, rel=1e-12)  # tip past the sigmoid's end
    assert g.fixed.sum() > colon_geometry("rsj", 0.036, 0.0, 3e-3, 2e-3).fixed.sum()
