"""Colon models as simulation-ready geometry: what colon_segments adds to the centerlines
(tests/test_centerline.py) and the tube mesh (tests/test_colon_geometry.py)."""

import numpy as np
import pytest

from colonsim.errors import ColonsimError
from colonsim.insertion.anatomy.centerline import FILLET_RADIUS, FLEXURE_RADIUS
from colonsim.insertion.anatomy.colon_centerlines import EXIT_LENGTH, rsf_centerline, rsj_centerline, thf_centerline, thf_fixed_centerline
from colonsim.insertion.anatomy.colon_geometry import tube_mesh
from colonsim.catalog import PAST_JUNCTION
from colonsim.insertion.anatomy.colon_segments import colon_geometry

R, RF = FLEXURE_RADIUS, FILLET_RADIUS
D, T, H = 0.036, 2e-3, 3e-3

MODELS = {  # segment, angle, flexure angle, the centerline it must be built on
    "rsj": ("rsj", 0.0, 90.0, rsj_centerline),
    "rsf30": ("rsf", 30.0, 90.0, lambda: rsf_centerline(30.0)),
    "rsf45-180": ("rsf", 45.0, 180.0, lambda: rsf_centerline(45.0, flexure_angle_deg=180.0)),
    "thf0": ("thf", 0.0, 90.0, lambda: thf_centerline(0.0)),
    "thf30": ("thf", 30.0, 90.0, lambda: thf_centerline(30.0)),
    "thf45-180": ("thf", 45.0, 180.0, lambda: thf_centerline(45.0, flexure_angle_deg=180.0)),
    "thf-fixed45": ("thf-fixed", 45.0, 90.0, lambda: thf_fixed_centerline(45.0)),
}


def _model(name):
    segment, angle, flexure, make = MODELS[name]
    return colon_geometry(segment, D, angle, H, T, flexure_angle_deg=flexure), make()


def test_documented_constants():
    assert PAST_JUNCTION == 0.02 and EXIT_LENGTH == 0.10


@pytest.mark.parametrize("kwargs, exit_length", [({}, EXIT_LENGTH), ({"exit_length": 0.0}, 0.0)])
def test_rsj_length_is_rectum_half_circle_and_exit(kwargs, exit_length):
    g = colon_geometry("rsj", 0.023, 0.0, H, T, **kwargs)
    assert g.centerline_length == pytest.approx(0.04 + np.pi * R + exit_length, rel=1e-12)


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
    # every model ends in a fixed exit: its nodes exist (at least ten rings) and are all held
    exit_piece = mesh.piece == len(c.pieces) - 1
    assert names[exit_piece][0] == {"rsj": "descending", "rsf": "transverse"}.get(g.name, "ascending")
    assert exit_piece.sum() >= 10 * round(np.pi * (D + T) / H)
    assert not g.mobile[exit_piece].any()
    # the mobile part is one run of rings, ending where the last mobile piece ends
    if g.mobile_end is not None:
        first = c.s_start[[p.tag for p in c.pieces].index("mobile")]
        assert np.array_equal(g.mobile, (mesh.s >= first) & (mesh.s < g.mobile_end) & ~g.end_ring)


# Wall node counts at the default mesh (3 mm triangles, D = 36 mm unless given, t = 2 mm, 10 cm
# fixed exits, 90 deg flexures), pinned as a regression check, next to the source's counts, which
# are only documented (its exits, its mesher and its reading of the models differ from ours):
#   model         ours   source  ratio   ours without the exit (exit_length = 0)
#   RSJ D23       2990    2064   1.45    1976 (0.96)
#   RSJ D36       4640    2792   1.66    3080 (1.10)
#   RSF alpha 0   8080    6632   1.22    6520 (0.98)
#   THF beta 0    5880    4086   1.44    4360 (1.07)
#   THF beta 30   6280    5324   1.18    4760 (0.89)
#   THF beta 45   6840    5977   1.14    5320 (0.89)
# Ours mesh the wall's mid-surface (D + t = 38 mm: 40 nodes per ring). The source's THF grows by
# 1891 nodes from beta 0 to 45, ours by 960 (the V's arms, span / (2 cos beta), add 6.1 cm of
# filleted tube).
NODE_COUNTS = {("rsj", 0.023, 0.0): 2990, ("rsj", 0.036, 0.0): 4640, ("rsf", 0.036, 0.0): 8080,
               ("thf", 0.036, 0.0): 5880, ("thf", 0.036, 30.0): 6280, ("thf", 0.036, 45.0): 6840}


@pytest.mark.parametrize("segment, diameter, angle", NODE_COUNTS)
def test_node_counts_at_the_default_mesh(segment, diameter, angle):
    g = colon_geometry(segment, diameter, angle, H, T)
    # the tube mesh's rule: round(pi (D + t) / h) nodes per ring, rings ~h sqrt(3)/2 apart along s
    m = round(np.pi * (diameter + T) / H)
    rings = round(g.centerline_length / (np.pi * (diameter + T) / m * np.sqrt(3) / 2)) + 1
    assert len(g.nodes) == m * rings == NODE_COUNTS[segment, diameter, angle]
    assert len(g.triangles) == 2 * m * (rings - 1)


@pytest.mark.parametrize("exit_length", [EXIT_LENGTH, 0.05, 0.01, 0.0])
def test_rsj_run_ends_past_the_junction_capped_at_the_far_end(exit_length):
    g = colon_geometry("rsj", D, 0.0, H, T, exit_length=exit_length)
    junction = 0.04 + np.pi * R  # the sigmoid's end, where the fixed exit starts
    assert g.centerline_length == pytest.approx(junction + exit_length, rel=1e-12)
    assert g.end_depth == pytest.approx(min(junction + PAST_JUNCTION, junction + exit_length), rel=1e-12)
    assert g.mobile_end == pytest.approx(junction, rel=1e-12)
    assert g.summary()["mobile_end_cm"] == pytest.approx(junction * 100, rel=1e-12)
    # the scope is pushed straight through: no straightening phase
    assert g.straighten_depth is None and g.mobile_axes == []


@pytest.mark.parametrize("flexure", [90.0, 135.0, 180.0])
@pytest.mark.parametrize("alpha", [0.0, 30.0, 45.0])
def test_rsf_straightens_to_the_sigmoid_end_and_runs_to_the_far_end(alpha, flexure):
    g = colon_geometry("rsf", D, alpha, H, T, flexure_angle_deg=flexure)
    a, phi = np.radians(alpha), np.radians(flexure)
    assert g.centerline_length == pytest.approx(
        0.04 + 0.20 + 0.10 - 4 * RF * np.tan(a / 2) + 2 * RF * a + R * phi + EXIT_LENGTH, rel=1e-12)
    assert g.end_depth == g.centerline_length  # the far end of the fixed exit
    # the mobile part ends at the middle of the sigmoid-descending fillet: rectum and sigmoid less
    # three tangent trims R_f tan(a/2), plus one and a half fillet arcs R_f a; the flexure plays no part
    end = 0.04 + 0.20 - 3 * RF * np.tan(a / 2) + 1.5 * RF * a
    assert g.mobile_end == pytest.approx(end, rel=1e-12) and g.straighten_depth == g.mobile_end
    assert g.mobile_end == pytest.approx(rsf_centerline(alpha).bounds("sigmoid")[1] + 0.5 * RF * a, rel=1e-12)
    assert g.summary()["mobile_end_cm"] == pytest.approx(end * 100, rel=1e-12)


@pytest.mark.parametrize("flexure", [90.0, 180.0])
@pytest.mark.parametrize("beta", [0.0, 30.0, 45.0])
def test_thf_straightens_to_the_transverse_end_and_runs_to_the_far_end(beta, flexure):
    b, phi = np.radians(beta), np.radians(flexure)
    transverse = 0.20 / np.cos(b) - 2 * RF * np.tan(b) + 2 * RF * b  # the whole V, from the entry
    g = colon_geometry("thf", D, beta, H, T, flexure_angle_deg=flexure)
    assert g.centerline_length == pytest.approx(transverse + R * phi + EXIT_LENGTH, rel=1e-12)
    assert g.end_depth == g.centerline_length
    assert g.mobile_end == pytest.approx(transverse, rel=1e-12) and g.straighten_depth == g.mobile_end
    assert g.summary()["mobile_end_cm"] == pytest.approx(transverse * 100, rel=1e-12)
    fixed = colon_geometry("thf-fixed", D, beta, H, T, flexure_angle_deg=flexure)
    assert fixed.end_depth == fixed.centerline_length == g.centerline_length
    assert fixed.straighten_depth is None and fixed.mobile_end is None and fixed.summary()["mobile_end_cm"] is None
    assert fixed.mobile_axes == [] and not fixed.mobile.any()


@pytest.mark.parametrize("alpha", [0.0, 30.0, 45.0])
def test_rsf_straightens_the_sigmoid_along_its_axis(alpha):
    g = colon_geometry("rsf", D, alpha, H, T)
    c = rsf_centerline(alpha)
    [(direction, nodes)] = g.mobile_axes
    a = np.radians(alpha)
    # tilted towards +x, away from the side the splenic flexure turns to (-x, the exit's heading)
    assert direction == pytest.approx([np.sin(a), np.cos(a), 0.0], abs=1e-12)
    assert c.tangent(c.length) == pytest.approx([-1.0, 0.0, 0.0], abs=1e-12)
    assert np.array_equal(nodes, np.flatnonzero(g.mobile))


@pytest.mark.parametrize("beta", [30.0, 45.0])
def test_thf_straightens_each_transverse_arm(beta):
    g = colon_geometry("thf", D, beta, H, T)
    c = thf_centerline(beta)
    assert g.straighten_depth == pytest.approx(c.bounds("hepatic flexure")[0], rel=1e-12)
    b = np.radians(beta)
    (d1, n1), (d2, n2) = g.mobile_axes
    # the first arm along the entry axis, the second turned by the V's 2 beta
    assert d1 == pytest.approx([0.0, 1.0, 0.0], abs=1e-12)
    assert d2 == pytest.approx([np.sin(2 * b), np.cos(2 * b), 0.0], abs=1e-12)
    assert np.array_equal(np.sort(np.concatenate([n1, n2])), np.flatnonzero(g.mobile))
    # the V-bottom fillet is split at its middle: each half goes with its own arm, so no node is held
    # to a direction more than beta off its own tube's axis
    fillet = [i for i, p in enumerate(c.pieces) if p.name == "transverse" and hasattr(p, "radius")]
    s0, s1 = c.s_start[fillet[0]], c.s_end[fillet[0]]
    near = lambda s: np.argmin(np.linalg.norm(g.nodes - c.position(s), axis=1))  # noqa: E731
    assert near(s0 + 0.1 * (s1 - s0)) in n1 and near(s1 - 0.1 * (s1 - s0)) in n2
    for d, nodes in g.mobile_axes:
        tangents = c.tangent(_node_arc(c, g.nodes[nodes]))
        assert np.degrees(np.arccos(np.clip(np.abs(tangents @ d), 0.0, 1.0))).max() <= beta + 1.0


def test_straight_transverse_is_one_axis_and_fixed_thf_has_none():
    [(direction, nodes)] = colon_geometry("thf", D, 0.0, H, T).mobile_axes
    assert direction == pytest.approx([0.0, 1.0, 0.0], abs=1e-12) and nodes.size
    fixed = colon_geometry("thf-fixed", D, 30.0, H, T)
    assert fixed.mobile_axes == [] and not fixed.mobile.any() and fixed.straighten_depth is None
    rsj = colon_geometry("rsj", D, 0.0, H, T)
    assert rsj.straighten_depth is None and rsj.mobile_axes == []


def test_rsj_exit_piece_continues_fixed():
    g = colon_geometry("rsj", D, 0.0, H, T)
    bare = colon_geometry("rsj", D, 0.0, H, T, exit_length=0.0)
    assert g.fixed.sum() > bare.fixed.sum()
    # sigmoid nodes lie at y >= 4 cm (ring planes on the half circle); the exit piece's below are all held
    exit_nodes = (g.nodes[:, 0] < -R) & (g.nodes[:, 1] < 0.04 - 1e-9)
    assert exit_nodes.sum() > 30 * round(np.pi * (D + T) / H) and not g.mobile[exit_nodes].any()
    assert g.nodes[:, 1].min() == pytest.approx(0.04 - EXIT_LENGTH, abs=1e-12)


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


@pytest.mark.parametrize("segment", ["rsj", "rsf", "thf"])
@pytest.mark.parametrize("exit_length", [-0.01, 0.41, float("nan")])
def test_exit_length_out_of_range(segment, exit_length):
    with pytest.raises(ColonsimError, match="exit length .* must lie in 0-400 mm"):
        colon_geometry(segment, D, 0.0, H, T, exit_length=exit_length)


@pytest.mark.parametrize("segment, name", [("rsf", "splenic"), ("thf", "hepatic"), ("thf-fixed", "hepatic")])
@pytest.mark.parametrize("flexure", [0.0, 181.0])
def test_flexure_angle_out_of_range(segment, name, flexure):
    with pytest.raises(ColonsimError, match=f"{name} flexure angle") as err:
        colon_geometry(segment, D, 0.0, H, T, flexure_angle_deg=flexure)
    assert "\n" not in str(err.value)


def test_a_model_whose_tube_cuts_itself_is_refused():
    # sigmoid at 45 deg, the flexure turned back by 180 deg, a 30 cm exit: the exit runs back down
    # at x = 0.2 sin(45 deg) - 2R = 4.1 cm and its last centimetres lie on the sigmoid
    with pytest.raises(ColonsimError, match="cuts itself between .*sigmoid.* and transverse") as err:
        colon_geometry("rsf", D, 45.0, H, T, exit_length=0.30, flexure_angle_deg=180.0)
    assert "\n" not in str(err.value)
    colon_geometry("rsf", D, 45.0, H, T, exit_length=0.10, flexure_angle_deg=180.0)  # a 10 cm exit fits


def test_a_lengthened_exit_that_would_cut_the_tube_folds_out_of_the_plane():
    """The same 30 cm exit folded after its first 10 cm: a quarter turn of the flexure radius
    out of the model's plane (+z), so it never comes back across the sigmoid; the exit (where the
    distal resistance engages) still begins where the flexure ends, and its length is unchanged."""
    straight = colon_geometry("rsf", D, 45.0, H, T, exit_length=0.10, flexure_angle_deg=180.0)
    folded = colon_geometry("rsf", D, 45.0, H, T, exit_length=0.30, flexure_angle_deg=180.0, exit_fold_after=0.10)
    c = folded.tube.centerline
    assert [(type(p).__name__, p.name) for p in c.pieces[-3:]] == [
        ("Straight", "transverse"), ("Arc", "transverse"), ("Straight", "transverse")]
    assert folded.centerline_length == pytest.approx(straight.centerline_length + 0.20, abs=1e-9)
    assert folded.exit_start == pytest.approx(straight.exit_start, abs=1e-9)
    assert folded.exit_start == pytest.approx(c.s_start[-3], abs=1e-9)
    z = c.position(np.array([folded.exit_start + 0.10, c.length]))[:, 2]  # in the plane up to the fold
    assert z[0] == pytest.approx(0.0, abs=1e-9)
    assert z[1] == pytest.approx(FLEXURE_RADIUS + (0.20 - 0.5 * np.pi * FLEXURE_RADIUS), abs=1e-6)
    assert np.allclose(c.tangent(c.length), [0.0, 0.0, 1.0], atol=1e-9)
    # a 90 deg flexure's exit does not cross the colon: without a fold it stays one straight piece
    plain = colon_geometry("rsf", D, 45.0, H, T, exit_length=0.30)
    assert type(plain.tube.centerline.pieces[-1]).__name__ == "Straight" and plain.tube.centerline.pieces[-2].name != "transverse"


def _node_arc(centerline, points):
    """Arc length of the centerline point closest to each of ``points`` (sampled every 0.5 mm)."""
    s = np.linspace(0.0, centerline.length, int(centerline.length / 5e-4) + 1)
    p = centerline.position(s)
    return s[np.argmin(((points[:, None, :] - p[None, :, :]) ** 2).sum(axis=2), axis=1)]


def test_an_rsf_insertion_with_its_flexure_turned_back_builds():
    """RSF at alpha 45 deg with the splenic flexure turned by 180 deg: the exit lengthened to take
    the scope's available length folds out of the plane instead of crossing the sigmoid."""
    from colonsim.insertion.case.scenario import InsertionCase, build_insertion

    model = build_insertion(InsertionCase(segment="rsf", scope="9.2", angle_deg=45.0, flexure_angle_deg=180.0,
                                          element_size_mm=6.0))
    pieces = model.geometry.tube.centerline.pieces
    assert type(pieces[-2]).__name__ == "Arc" and pieces[-2].name == "transverse"
    assert model.geometry.exit_start == pytest.approx(rsf_centerline(45.0, flexure_angle_deg=180.0, exit_length=0.0).length)
