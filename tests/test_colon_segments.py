"""Colon models as simulation-ready geometry (SPEC.md 2.1): what colon_segments adds to the
centerlines (tests/test_centerline.py) and the tube mesh (tests/test_colon_geometry.py)."""

import numpy as np
import pytest

from colonsim.errors import ColonsimError
from insertion.centerline import FLEXURE_RADIUS, rsf_centerline, rsj_centerline, thf_centerline, thf_fixed_centerline
from insertion.colon_geometry import tube_mesh
from insertion.colon_segments import colon_geometry

R = FLEXURE_RADIUS
D, T, H = 0.036, 2e-3, 3e-3

MODELS = {  # segment, angle, the centerline it must be built on
    "rsj": ("rsj", 0.0, rsj_centerline),
    "rsf30": ("rsf", 30.0, lambda: rsf_centerline(30.0)),
    "thf0": ("thf", 0.0, lambda: thf_centerline(0.0)),
    "thf30": ("thf", 30.0, lambda: thf_centerline(30.0)),
    "thf-fixed45": ("thf-fixed", 45.0, lambda: thf_fixed_centerline(45.0)),
}


def _model(name):
    segment, angle, make = MODELS[name]
    return colon_geometry(segment, D, angle, H, T), make()


def test_rsj_length_is_rectum_plus_half_circle():
    assert colon_geometry("rsj", 0.023, 0.0, H, T).centerline_length == pytest.approx(0.04 + np.pi * R, rel=1e-12)


@pytest.mark.parametrize("name", MODELS)
def test_centerline_length_and_points_are_the_builders_and_c1(name):
    g, c = _model(name)
    assert g.centerline_length == c.length
    s = np.linspace(0.0, c.length, 1001)
    assert np.array_equal(g.centerline_points(s), c.position(s))
    assert g.centerline_points(0.1).shape == (1, 3)
    # C1 at every junction: one-sided difference quotients agree to the change over h on a bend of R >= 5 cm
    h = 1e-6
    for sj in c.s_start[1:]:
        p = g.centerline_points(np.array([sj - h, sj, sj + h]))
        assert np.linalg.norm((p[2] - p[1]) - (p[1] - p[0])) / h < 2 * h / R


@pytest.mark.parametrize("name", MODELS)
def test_wall_is_the_tube_mesh_at_the_mid_surface_with_its_tags(name):
    g, c = _model(name)
    mesh = tube_mesh(c, D + T, H)  # contact acts half a thickness inside the mid-surface
    assert np.array_equal(g.nodes, mesh.nodes) and np.array_equal(g.triangles, mesh.triangles)
    assert np.linalg.norm(g.nodes - c.position(mesh.s), axis=1) == pytest.approx(0.5 * (D + T), abs=1e-12)
    # every node is exactly one of fixed, mobile, end ring; the end rings are the first and last ring
    assert np.array_equal(g.fixed.astype(int) + g.mobile + g.end_ring, np.ones(len(g.nodes), int))
    assert g.end_ring.sum() == 2 * round(np.pi * (D + T) / H)
    names = np.array([p.name for p in c.pieces])[mesh.piece]
    # RSF: the sigmoid and the mobile halves of the fillets at its ends
    mobile_names = {"rsj": {"sigmoid"}, "rsf": {"sigmoid", "rectum-sigmoid fillet", "sigmoid-descending fillet"}}
    mobile_name = mobile_names.get(g.name, {"transverse"})
    assert g.mobile.any() == (g.name != "thf-fixed")
    assert set(names[g.mobile]) <= mobile_name
    mobile_piece = np.array([c.pieces[i].tag == "mobile" for i in mesh.piece])
    assert np.array_equal(g.mobile, np.isin(names, list(mobile_name)) & mobile_piece & ~g.end_ring)
    assert np.array_equal(g.entry_point, [0.0, 0.0, 0.0]) and np.array_equal(g.entry_axis, [0.0, 1.0, 0.0])


def test_mesh_sizes_next_to_the_source():
    """Source: RSJ D23 2064 nodes, RSJ D36 2792, RSF 6632, THF 4086 (its THF did not include our
    5 cm lead-in, the flexures' full arcs and the 10 cm ascending colon)."""
    sizes = {(s, d): len(colon_geometry(s, d, 0.0, H, T).nodes)
             for s, d in (("rsj", 0.023), ("rsj", 0.036), ("rsf", 0.036), ("thf", 0.036))}
    for (seg, d), source in {("rsj", 0.023): 2064, ("rsj", 0.036): 2792, ("rsf", 0.036): 6632}.items():
        assert 0.8 < sizes[seg, d] / source < 1.2, (seg, d, sizes[seg, d])
    assert 1.0 < sizes["thf", 0.036] / 4086 < 2.5


@pytest.mark.parametrize("alpha", [0.0, 30.0, 45.0])
def test_rsf_straightens_the_sigmoid_along_its_axis_up_to_the_splenic_flexure(alpha):
    g = colon_geometry("rsf", D, alpha, H, T)
    c = rsf_centerline(alpha)
    assert g.straighten_depth == pytest.approx(c.bounds("splenic flexure")[0])
    [(direction, nodes)] = g.mobile_axes
    a = np.radians(alpha)
    # tilted towards +x, away from the side the splenic flexure turns to (-x)
    assert direction == pytest.approx([np.sin(a), np.cos(a), 0.0], abs=1e-12)
    assert c.tangent(c.length) == pytest.approx([-1.0, 0.0, 0.0], abs=1e-12)
    assert np.array_equal(nodes, np.flatnonzero(g.mobile))


@pytest.mark.parametrize("beta", [30.0, 45.0])
def test_thf_straightens_each_transverse_arm_up_to_the_hepatic_flexure(beta):
    g = colon_geometry("thf", D, beta, H, T)
    c = thf_centerline(beta)
    assert g.straighten_depth == pytest.approx(c.bounds("hepatic flexure")[0])
    b = np.radians(beta)
    (d1, n1), (d2, n2) = g.mobile_axes
    assert d1 == pytest.approx([-np.cos(b), -np.sin(b), 0.0], abs=1e-12)
    assert d2 == pytest.approx([-np.cos(b), np.sin(b), 0.0], abs=1e-12)
    assert np.array_equal(np.sort(np.concatenate([n1, n2])), np.flatnonzero(g.mobile))
    # the V-bottom fillet goes with the first arm
    fillet = [i for i, p in enumerate(c.pieces) if p.name == "transverse" and hasattr(p, "radius")]
    s_fillet = 0.5 * (c.s_start[fillet[0]] + c.s_end[fillet[0]])
    bottom = np.argmin(np.linalg.norm(g.nodes - c.position(s_fillet), axis=1))
    assert bottom in n1 and bottom not in n2


def test_straight_transverse_is_one_axis_and_fixed_thf_has_none():
    [(direction, nodes)] = colon_geometry("thf", D, 0.0, H, T).mobile_axes
    assert direction == pytest.approx([-1.0, 0.0, 0.0], abs=1e-12) and nodes.size
    fixed = colon_geometry("thf-fixed", D, 30.0, H, T)
    assert fixed.mobile_axes == [] and not fixed.mobile.any()
    assert fixed.straighten_depth == pytest.approx(thf_fixed_centerline(30.0).bounds("hepatic flexure")[0])
    rsj = colon_geometry("rsj", D, 0.0, H, T)
    assert rsj.straighten_depth is None and rsj.mobile_axes == []


def test_end_depth_is_the_plane_the_tip_must_cross():
    # default: the far end ring (the tip has passed the fixed end when it crosses it)
    rsj = colon_geometry("rsj", D, 0.0, H, T)
    assert rsj.end_depth == pytest.approx(0.04 + np.pi * R, rel=1e-12) == rsj.centerline_length
    thf = colon_geometry("thf", D, 30.0, H, T)
    assert thf.end_depth == pytest.approx(thf_centerline(30.0).bounds("hepatic flexure")[1] + 0.5 * D, rel=1e-12)


def test_rsj_exit_piece_continues_fixed_and_moves_the_end_of_the_run():
    g = colon_geometry("rsj", D, 0.0, H, T, exit_length=0.05)
    assert g.centerline_length == pytest.approx(0.04 + np.pi * R + 0.05, rel=1e-12)
    assert g.end_depth == pytest.approx(0.04 + np.pi * R + 0.5 * D, rel=1e-12)  # tip past the sigmoid's end
    assert g.fixed.sum() > colon_geometry("rsj", D, 0.0, H, T).fixed.sum()
    # sigmoid nodes lie at y >= 4 cm (ring planes on the half circle); the exit piece's below are all held
    exit_nodes = (g.nodes[:, 0] < -R) & (g.nodes[:, 1] < 0.04 - 1e-9)
    assert exit_nodes.sum() > 10 * round(np.pi * (D + T) / H) and not g.mobile[exit_nodes].any()


def test_straight_sanity_tube_along_x():
    g = colon_geometry("straight", D, 0.0, H, T)
    assert np.array_equal(g.entry_axis, [1.0, 0.0, 0.0]) and g.centerline_length == 0.20
    assert g.nodes[:, 0].min() == 0.0 and g.nodes[:, 0].max() == pytest.approx(0.20)
    assert g.end_depth == pytest.approx(0.20) and not g.fixed.any()


@pytest.mark.parametrize("args,message", [(("rsf", D, 75.0), "outside 0-60 deg"),
                                          (("thf", D, -5.0), "outside 0-60 deg"),
                                          (("thf-fixed", D, 61.0), "outside 0-60 deg"),
                                          (("rsj", 0.100, 0.0), "does not fit around a bend"),
                                          (("rsj", 0.097, 0.0), "does not fit around a bend"),
                                          (("sigmoid", D, 0.0), "not a colon model")])
def test_geometry_errors(args, message):
    with pytest.raises(ColonsimError, match=message) as err:
        colon_geometry(*args, H, T)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("exit_length", [-0.01, 0.31, float("nan")])
def test_exit_length_out_of_range(exit_length):
    with pytest.raises(ColonsimError, match="exit length .* must lie in 0-300 mm"):
        colon_geometry("rsj", D, 0.0, H, T, exit_length=exit_length)
