"""Centerlines of the colon models (SPEC.md 2.1): lengths, smoothness, frames, tags, bad input."""

import numpy as np
import pytest

from colonsim.errors import ColonsimError
from insertion.centerline import (FILLET_RADIUS, FLEXURE_RADIUS, Arc, Centerline, Kink, Straight, rsf_centerline,
                                  rsj_centerline, thf_centerline, thf_fixed_centerline)

R, RF = FLEXURE_RADIUS, FILLET_RADIUS


def _helix_like():
    """A 3-D chain: arcs rolled out of the plane, a kink with a roll."""
    return Centerline([Straight(0.05, "fixed", "a"), Arc(0.05, 1.2, "mobile", "b", roll=0.7),
                       Straight(0.04, "mobile", "c"), Kink(0.6, roll=-1.1), Straight(0.06, "fixed", "d"),
                       Arc(0.08, -2.0, "fixed", "e", roll=2.0)], fillet_radius=0.03)


MODELS = {
    "rsj": rsj_centerline,
    "rsf45": lambda: rsf_centerline(45.0),
    "thf30": lambda: thf_centerline(30.0),
    "thf45": lambda: thf_centerline(45.0),
    "3d": _helix_like,
}


def test_rsj_length_is_rectum_plus_half_circle():
    c = rsj_centerline()
    assert c.length == pytest.approx(0.04 + np.pi * R, rel=1e-12)
    # the 180 deg arc ends 2R to the side (+n = -x), at the rectum's height, heading back down
    p, t, _, _ = c.frame(c.length)
    assert p == pytest.approx([-2 * R, 0.04, 0.0], abs=1e-12)
    assert t == pytest.approx([0.0, -1.0, 0.0], abs=1e-12)


def test_rsj_exit_piece_continues_fixed_after_the_sigmoid():
    c = rsj_centerline(exit_length=0.05)
    assert c.length == pytest.approx(0.04 + np.pi * R + 0.05, rel=1e-12)
    assert c.bounds("sigmoid")[1] == pytest.approx(0.04 + np.pi * R, rel=1e-12)
    assert c.tag_at(c.length - 0.01) == "fixed" and c.name_at(c.length - 0.01) == "descending"
    # it carries on from the half circle's end, heading back down
    assert c.position(c.length) == pytest.approx([-2 * R, -0.01, 0.0], abs=1e-12)


@pytest.mark.parametrize("alpha", [0.0, 30.0, 45.0])
def test_rsf_length_with_fillets(alpha):
    a = np.radians(alpha)
    # each of the two fillets trims R_f tan(a/2) off both neighbours and adds an arc of R_f a
    expected = 0.04 + 0.20 + 0.10 - 4 * RF * np.tan(a / 2) + 2 * RF * a + R * np.pi / 2
    assert rsf_centerline(alpha).length == pytest.approx(expected, rel=1e-12)


def test_rsf_sigmoid_tilted_by_alpha_descending_parallel_to_rectum():
    c = rsf_centerline(30.0)
    s0, s1 = c.bounds("sigmoid")
    a = np.radians(30.0)
    assert c.tangent(0.5 * (s0 + s1)) == pytest.approx([np.sin(a), np.cos(a), 0.0], abs=1e-12)
    s0, s1 = c.bounds("descending")
    assert c.tangent(0.5 * (s0 + s1)) == pytest.approx([0.0, 1.0, 0.0], abs=1e-12)
    # unrounded corners: the descending colon is shifted sideways by L sin(alpha); fillets do not move it
    assert c.position(s0)[0] == pytest.approx(0.20 * np.sin(a), abs=1e-12)


@pytest.mark.parametrize("beta", [0.0, 30.0, 45.0])
def test_thf_length_span_and_depth(beta):
    b = np.radians(beta)
    c = thf_centerline(beta)
    # lead-in + two flexures of 90 + beta + two arms span/(2 cos b) - V fillet trims + fillet arc + ascending
    expected = 0.05 + 2 * R * (np.pi / 2 + b) + 0.20 / np.cos(b) - 2 * RF * np.tan(b) + RF * 2 * b + 0.10
    assert c.length == pytest.approx(expected, rel=1e-12)
    start = c.position(c.bounds("splenic flexure")[1])
    end = c.position(c.bounds("hepatic flexure")[0])
    assert np.linalg.norm(end - start) == pytest.approx(0.20, rel=1e-12)
    s = np.linspace(*c.bounds("transverse"), 4001)
    lowest = c.position(s)[:, 1].min()
    # the sharp V sinks span tan(b)/2; the fillet at its bottom lifts it by R_f (1/cos b - 1);
    # sampling every 0.1 mm misses the exact bottom by at most (0.05 mm)^2 / (2 R_f) < 1e-7 m
    assert start[1] - lowest == pytest.approx(0.10 * np.tan(b) - RF * (1 / np.cos(b) - 1), abs=1e-7)


def test_fillet_length_is_radius_times_angle():
    a = np.radians(40.0)
    c = Centerline([Straight(0.1, "fixed", "x"), Kink(a), Straight(0.1, "fixed", "y")], fillet_radius=0.02)
    # tangent-length correction: each straight loses R_f tan(a/2)
    assert c.length == pytest.approx(0.2 - 2 * 0.02 * np.tan(a / 2) + 0.02 * a, rel=1e-12)
    assert c.s_end[1] - c.s_start[1] == pytest.approx(0.02 * a, rel=1e-12)
    # the fillet's end points lie on the two unrounded lines
    corner = np.array([0.0, 0.1, 0.0])
    out_dir = np.array([-np.sin(a), np.cos(a), 0.0])
    assert c.position(c.length) == pytest.approx(corner + 0.1 * out_dir, abs=1e-12)


@pytest.mark.parametrize("name", MODELS)
def test_unit_tangent_is_derivative_of_position(name):
    c = MODELS[name]()
    h = 1e-5
    s = np.linspace(h, c.length - h, 997)
    t = c.tangent(s)
    assert np.abs(np.linalg.norm(t, axis=1) - 1) .max() < 1e-12
    fd = (c.position(s + h) - c.position(s - h)) / (2 * h)
    # central differences are exact on straights, off by (h/R)^2 / 6 ~ 1e-8 on arcs of R >= 3 cm;
    # across a junction the one-sided curvature adds at most h / (2 R) ~ 2e-4
    assert np.abs(fd - t).max() < 2e-4
    away = np.min(np.abs(s[:, None] - c.s_start[None, 1:]), axis=1) > 2 * h
    assert np.abs(fd - t)[away].max() < 1e-7


@pytest.mark.parametrize("name", MODELS)
def test_position_and_tangent_continuous_at_junctions(name):
    c = MODELS[name]()
    eps = 1e-9
    for s in c.s_start[1:]:
        p0, t0, n0, _ = c.frame(s - eps)
        p1, t1, n1, _ = c.frame(s + eps)
        # C1 (and a continuous frame): jumps no larger than the change over 2 eps on a bend of R >= 3 cm
        assert np.linalg.norm(p1 - p0) < 3 * eps
        assert np.linalg.norm(t1 - t0) < 2 * eps / 0.03 + 1e-12
        assert np.linalg.norm(n1 - n0) < 2 * eps / 0.03 + 1e-12


@pytest.mark.parametrize("name", MODELS)
def test_frame_orthonormal_and_rotation_minimising(name):
    c = MODELS[name]()
    s = np.linspace(0.0, c.length, 1501)
    _, t, n, b = c.frame(s)
    gram = np.stack([t, n, b], axis=1) @ np.stack([t, n, b], axis=2)
    assert np.abs(gram - np.eye(3)).max() < 1e-12
    assert np.abs(np.einsum("ij,ij->i", np.cross(t, n), b) - 1).max() < 1e-12
    # parallel transport: the normal never turns about the tangent, n' . b = 0
    h = 1e-6
    dn = (c.frame(s[1:-1] + h)[2] - c.frame(s[1:-1] - h)[2]) / (2 * h)
    assert np.abs(np.einsum("ij,ij->i", dn, b[1:-1])).max() < 1e-6


@pytest.mark.parametrize("name", ["rsj", "rsf45", "thf45"])
def test_planar_frame_does_not_twist(name):
    c = MODELS[name]()
    _, t, n, b = c.frame(np.linspace(0.0, c.length, 1001))
    # in the x-y plane the transported normal stays the in-plane left normal, b stays +z
    assert np.abs(b - [0.0, 0.0, 1.0]).max() < 1e-12
    assert np.abs(n - np.cross([0.0, 0.0, 1.0], t)).max() < 1e-12


def test_tags_and_names():
    c = rsf_centerline(30.0)
    mid = 0.5 * np.add(*c.bounds("sigmoid"))
    assert c.tag_at(mid) == "mobile" and c.name_at(mid) == "sigmoid"
    assert c.tag_at(0.01) == "fixed" and c.name_at(0.01) == "rectum"
    # fillet rule: between a fixed and a mobile piece, each half of the fillet goes with its neighbour,
    # split at the corner of the unrounded centerline, so the sigmoid keeps its 20 cm
    a = np.radians(30.0)
    rectum_end = c.bounds("rectum")[1]
    assert c.name_at(rectum_end + 1e-6) == "rectum-sigmoid fillet"
    assert c.tag_at(rectum_end + 1e-6) == "fixed"
    corner = rectum_end + 0.5 * FILLET_RADIUS * a
    assert list(c.tag_at(np.array([corner - 1e-6, corner + 1e-6]))) == ["fixed", "mobile"]
    mobile = [p for p in c.pieces if p.tag == "mobile"]
    mobile_length = sum(p.length if isinstance(p, Straight) else p.radius * abs(p.angle) for p in mobile)
    # sigmoid 20 cm minus two tangent trims R tan(a/2), plus two half fillets R a / 2
    assert mobile_length == pytest.approx(0.20 - 2 * FILLET_RADIUS * (np.tan(0.5 * a) - 0.5 * a), rel=1e-12)
    # the split point is the fillet's middle, R (1/cos(a/2) - 1) from the unrounded corner at y = 4 cm
    gap = np.linalg.norm(c.position(corner) - [0.0, 0.04, 0.0])
    assert gap == pytest.approx(FILLET_RADIUS * (1 / np.cos(0.5 * a) - 1), rel=1e-9)
    assert list(c.tag_at(np.array([0.0, mid, c.length]))) == ["fixed", "mobile", "fixed"]
    thf = thf_centerline(30.0)
    assert thf.tag_at(0.5 * np.add(*thf.bounds("transverse"))) == "mobile"
    # the V bottom between two mobile arms is mobile and belongs to the transverse colon
    assert {p.tag for p in thf.pieces if p.name == "transverse"} == {"mobile"}
    assert {p.tag for p in thf_fixed_centerline(30.0).pieces} == {"fixed"}
    assert rsj_centerline().tag_at(0.1) == "mobile"


def _clash():
    # a full circle comes back onto its own start: locally fine (D/2 < R), globally the wall overlaps
    Centerline([Straight(0.05, "fixed", "a"), Arc(0.03, 2 * np.pi, "mobile", "loop")]).check_tube(0.02)


BAD = [
    (lambda: rsf_centerline(-5.0), "alpha"),
    (lambda: rsf_centerline(90.0), "alpha"),
    (lambda: rsf_centerline(80.0), "reduce the fillet radius"),
    (lambda: rsf_centerline(45.0, fillet_radius=0.2), "reduce the fillet radius"),
    (lambda: rsf_centerline(30.0, fillet_radius=-0.01), "fillet radius"),
    (lambda: thf_centerline(70.0), "beta"),
    (lambda: thf_centerline(float("nan")), "beta"),
    (lambda: rsj_centerline(sigmoid_angle_deg=200.0), "sigmoid angle"),
    (lambda: rsj_centerline(sigmoid_angle_deg=0.0), "sigmoid angle"),
    (lambda: rsj_centerline(rectum_length=-0.01), "length of rectum"),
    (lambda: rsj_centerline(exit_length=-0.01), "length of descending"),
    (lambda: rsf_centerline(sigmoid_length=5.0), "length of sigmoid"),
    (lambda: rsj_centerline(sigmoid_radius=0.0), "radius of sigmoid"),
    (lambda: Centerline([]), "at least one piece"),
    (lambda: Centerline([Kink(0.3), Straight(0.1, "fixed", "a")]), "between two Straight"),
    (lambda: Centerline([Straight(0.1, "fixed", "a"), Kink(np.pi), Straight(0.1, "fixed", "b")]), "180 deg"),
    (lambda: Centerline([Straight(0.1, "loose", "a")]), "'fixed' or 'mobile'"),
    (lambda: Centerline([Arc(0.05, 0.0, "fixed", "a")]), "non-zero angle"),
    (lambda: rsj_centerline().check_tube(0.10), "does not fit a bend"),
    (lambda: rsj_centerline().check_tube(0.5), "tube diameter"),
    (_clash, "cuts itself"),
]


@pytest.mark.parametrize("make, fragment", BAD)
def test_bad_input_gives_one_line_actionable_error(make, fragment):
    with pytest.raises(ColonsimError) as err:
        make()
    message = str(err.value)
    print(message)
    assert fragment in message
    assert "\n" not in message and ";" in message  # problem; fix
