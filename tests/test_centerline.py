"""Centerlines of the colon models: lengths, end points, smoothness, frames, tags, bad input."""

import numpy as np
import pytest

from colonsim.errors import ColonsimError
from colonsim.insertion.anatomy.centerline import FILLET_RADIUS, FLEXURE_RADIUS, Arc, Centerline, Kink, Straight
from colonsim.insertion.anatomy.colon_centerlines import EXIT_LENGTH, FLEXURE_ANGLE_DEG, rsf_centerline, rsj_centerline, thf_centerline, thf_fixed_centerline

R, RF = FLEXURE_RADIUS, FILLET_RADIUS


def test_default_exit_and_flexure_angle():
    # the model's documented defaults; every expected value below is derived from these
    assert EXIT_LENGTH == 0.10 and FLEXURE_ANGLE_DEG == 90.0


def _left_turn(p, t, radius, angle):
    """End point and tangent of an in-plane (x-y) arc turning counter-clockwise by ``angle`` from (p, t)."""
    left = np.cross([0.0, 0.0, 1.0], t)
    return (p + radius * np.sin(angle) * t + radius * (1 - np.cos(angle)) * left,
            np.cos(angle) * t + np.sin(angle) * left)


def _helix_like():
    """A 3-D chain: arcs rolled out of the plane, a kink with a roll."""
    return Centerline([Straight(0.05, "fixed", "a"), Arc(0.05, 1.2, "mobile", "b", roll=0.7),
                       Straight(0.04, "mobile", "c"), Kink(0.6, roll=-1.1), Straight(0.06, "fixed", "d"),
                       Arc(0.08, -2.0, "fixed", "e", roll=2.0)], fillet_radius=0.03)


MODELS = {
    "rsj": rsj_centerline,
    "rsf45": lambda: rsf_centerline(45.0),
    "rsf45-180": lambda: rsf_centerline(45.0, flexure_angle_deg=180.0),
    "thf30": lambda: thf_centerline(30.0),
    "thf45": lambda: thf_centerline(45.0),
    "thf45-180": lambda: thf_centerline(45.0, flexure_angle_deg=180.0),
    "3d": _helix_like,
}


@pytest.mark.parametrize("kwargs, exit_length", [({}, EXIT_LENGTH), ({"exit_length": 0.05}, 0.05),
                                                ({"exit_length": 0.0}, 0.0)])
def test_rsj_is_rectum_half_circle_then_fixed_exit(kwargs, exit_length):
    c = rsj_centerline(**kwargs)
    assert c.length == pytest.approx(0.04 + np.pi * R + exit_length, rel=1e-12)
    expected = [("rectum", "fixed"), ("sigmoid", "mobile")] + [("descending", "fixed")] * (exit_length > 0)
    assert [(p.name, p.tag) for p in c.pieces] == expected
    s1 = c.bounds("sigmoid")[1]
    assert s1 == pytest.approx(0.04 + np.pi * R, rel=1e-12)
    # the 180 deg arc ends 2R to the side (+n = -x), at the rectum's height, heading back down
    p, t, _, _ = c.frame(s1)
    assert p == pytest.approx([-2 * R, 0.04, 0.0], abs=1e-12)
    assert t == pytest.approx([0.0, -1.0, 0.0], abs=1e-12)
    # the exit carries straight on down from there
    p, t, _, _ = c.frame(c.length)
    assert p == pytest.approx([-2 * R, 0.04 - exit_length, 0.0], abs=1e-12)
    assert t == pytest.approx([0.0, -1.0, 0.0], abs=1e-12)
    if exit_length:
        assert c.bounds("descending") == pytest.approx((s1, c.length), rel=1e-12)
        assert c.tag_at(s1 + 1e-6) == "fixed" and c.name_at(c.length) == "descending"


@pytest.mark.parametrize("flexure", [90.0, 135.0, 180.0])
@pytest.mark.parametrize("alpha", [0.0, 30.0, 45.0])
def test_rsf_length_with_fillets_flexure_and_exit(alpha, flexure):
    a, phi = np.radians(alpha), np.radians(flexure)
    c = rsf_centerline(alpha, flexure_angle_deg=flexure)
    # each of the two fillets trims R_f tan(a/2) off both neighbours and adds an arc of R_f a;
    # the splenic flexure adds R phi and the fixed exit its own length
    expected = 0.04 + 0.20 + 0.10 - 4 * RF * np.tan(a / 2) + 2 * RF * a + R * phi + EXIT_LENGTH
    assert c.length == pytest.approx(expected, rel=1e-12)
    assert c.bounds("transverse") == pytest.approx((c.length - EXIT_LENGTH, c.length), rel=1e-12)
    assert [(p.name, p.tag) for p in c.pieces[-2:]] == [("splenic flexure", "fixed"), ("transverse", "fixed")]
    # the flexure starts where the unrounded descending colon ends (fillets do not move it), heading +y,
    # and turns medially (+n = -x) by phi
    f0, f1 = c.bounds("splenic flexure")
    start = np.array([0.20 * np.sin(a), 0.04 + 0.20 * np.cos(a) + 0.10, 0.0])
    assert c.position(f0) == pytest.approx(start, abs=1e-12)
    assert c.tangent(f0) == pytest.approx([0.0, 1.0, 0.0], abs=1e-12)
    p, t = _left_turn(start, np.array([0.0, 1.0, 0.0]), R, phi)
    assert t == pytest.approx([-np.sin(phi), np.cos(phi), 0.0], abs=1e-12)
    assert c.position(f1) == pytest.approx(p, abs=1e-12) and c.tangent(f1) == pytest.approx(t, abs=1e-12)
    assert c.position(c.length) == pytest.approx(p + EXIT_LENGTH * t, abs=1e-12)
    assert c.tangent(c.length) == pytest.approx(t, abs=1e-12)
    # exit 0: the tube ends at the flexure
    bare = rsf_centerline(alpha, flexure_angle_deg=flexure, exit_length=0.0)
    assert bare.length == pytest.approx(expected - EXIT_LENGTH, rel=1e-12)
    assert bare.pieces[-1].name == "splenic flexure"
    assert bare.position(bare.length) == pytest.approx(p, abs=1e-12)


def test_rsf_sigmoid_tilted_by_alpha_descending_parallel_to_rectum():
    c = rsf_centerline(30.0)
    s0, s1 = c.bounds("sigmoid")
    a = np.radians(30.0)
    assert c.tangent(0.5 * (s0 + s1)) == pytest.approx([np.sin(a), np.cos(a), 0.0], abs=1e-12)
    s0, s1 = c.bounds("descending")
    assert c.tangent(0.5 * (s0 + s1)) == pytest.approx([0.0, 1.0, 0.0], abs=1e-12)
    # unrounded corners: the descending colon is shifted sideways by L sin(alpha); fillets do not move it
    assert c.position(s0)[0] == pytest.approx(0.20 * np.sin(a), abs=1e-12)


@pytest.mark.parametrize("flexure", [90.0, 180.0])
@pytest.mark.parametrize("beta", [0.0, 30.0, 45.0])
def test_thf_length_span_depth_flexure_and_exit(beta, flexure):
    b, phi = np.radians(beta), np.radians(flexure)
    c = thf_centerline(beta, flexure_angle_deg=flexure)
    # two arms span/(2 cos b) - V fillet trims + fillet arc + hepatic flexure of phi + ascending exit
    expected = 0.20 / np.cos(b) - 2 * RF * np.tan(b) + RF * 2 * b + R * phi + EXIT_LENGTH
    assert c.length == pytest.approx(expected, rel=1e-12)
    # the scope enters the transverse colon directly along its first arm: no lead-in, no splenic flexure
    assert c.name_at(0.0) == "transverse" and c.tag_at(0.0) == "mobile"
    assert c.tangent(0.0) == pytest.approx([0.0, 1.0, 0.0], abs=1e-12)
    s_end = c.bounds("hepatic flexure")[0]
    assert c.bounds("transverse") == pytest.approx((0.0, s_end), abs=1e-15)
    assert len([p for p in c.pieces if p.name == "transverse"]) == (1 if beta == 0 else 3)
    start, end = c.position(0.0), c.position(s_end)
    chord = (end - start) / 0.20
    assert np.linalg.norm(end - start) == pytest.approx(0.20, rel=1e-12)
    # each arm lies at beta to the line joining the ends: that line heads beta clockwise of the first arm
    assert chord == pytest.approx([np.sin(b), np.cos(b), 0.0], abs=1e-12)
    s = np.linspace(0.0, s_end, 4001)
    # distance from that line, positive on its left (+n), where the V's bottom lies
    off = np.cross(chord, c.position(s) - start)[:, 2]
    assert off.min() > -1e-12
    # the sharp V sinks span tan(b)/2; the fillet at its bottom lifts it by R_f (1/cos b - 1);
    # sampling every 0.1 mm misses the exact bottom by at most (0.05 mm)^2 / (2 R_f) < 1e-7 m
    assert off.max() == pytest.approx(0.10 * np.tan(b) - RF * (1 / np.cos(b) - 1), abs=1e-7)
    # the hepatic flexure turns by phi counter-clockwise (the other way from the V-bottom kink) from
    # the second arm, heading -2 beta from +y, into the fixed ascending colon
    t2 = np.array([np.sin(2 * b), np.cos(2 * b), 0.0])
    assert c.tangent(s_end) == pytest.approx(t2, abs=1e-12)
    p, t = _left_turn(end, t2, R, phi)
    assert t == pytest.approx([-np.sin(phi - 2 * b), np.cos(phi - 2 * b), 0.0], abs=1e-12)
    a0, a1 = c.bounds("ascending")
    assert (a0, a1) == pytest.approx((c.length - EXIT_LENGTH, c.length), rel=1e-12)
    assert c.position(a0) == pytest.approx(p, abs=1e-12) and c.tangent(a0) == pytest.approx(t, abs=1e-12)
    assert c.position(c.length) == pytest.approx(p + EXIT_LENGTH * t, abs=1e-12)
    bare = thf_centerline(beta, flexure_angle_deg=flexure, exit_length=0.0)
    assert bare.length == pytest.approx(expected - EXIT_LENGTH, rel=1e-12)
    assert bare.pieces[-1].name == "hepatic flexure"
    assert bare.position(bare.length) == pytest.approx(p, abs=1e-12)
    fixed = thf_fixed_centerline(beta, flexure_angle_deg=flexure)
    assert fixed.length == c.length and {p.tag for p in fixed.pieces} == {"fixed"}
    assert fixed.position(fixed.length) == pytest.approx(c.position(c.length), abs=1e-15)


def test_thf_has_no_splenic_flexure_or_lead_in():
    c = thf_centerline(30.0)
    for name in ("splenic flexure", "descending"):
        with pytest.raises(ColonsimError, match=f"no piece called '{name}'"):
            c.bounds(name)


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


@pytest.mark.parametrize("name", ["rsj", "rsf45", "rsf45-180", "thf45", "thf45-180"])
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
    # RSF: everything after the sigmoid's far half-fillet is fixed, the exit included
    assert [(p.name, p.tag) for p in c.pieces] == [
        ("rectum", "fixed"), ("rectum-sigmoid fillet", "fixed"), ("rectum-sigmoid fillet", "mobile"),
        ("sigmoid", "mobile"), ("sigmoid-descending fillet", "mobile"), ("sigmoid-descending fillet", "fixed"),
        ("descending", "fixed"), ("splenic flexure", "fixed"), ("transverse", "fixed")]
    assert c.name_at(c.length) == "transverse"
    thf = thf_centerline(30.0)
    assert thf.tag_at(0.5 * np.add(*thf.bounds("transverse"))) == "mobile"
    # the V bottom between two mobile arms is mobile and belongs to the transverse colon; the
    # hepatic flexure and the ascending colon (the exit) are fixed
    assert [(p.name, p.tag) for p in thf.pieces] == [("transverse", "mobile")] * 3 + [
        ("hepatic flexure", "fixed"), ("ascending", "fixed")]
    assert list(thf.tag_at(np.array([0.0, thf.length]))) == ["mobile", "fixed"]
    assert {p.tag for p in thf_fixed_centerline(30.0).pieces} == {"fixed"}
    rsj = rsj_centerline()
    assert rsj.tag_at(0.1) == "mobile" and rsj.tag_at(rsj.length) == "fixed"


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
    (lambda: rsf_centerline(flexure_angle_deg=0.0), "splenic flexure angle"),
    (lambda: rsf_centerline(flexure_angle_deg=181.0), "splenic flexure angle"),
    (lambda: thf_centerline(flexure_angle_deg=200.0), "hepatic flexure angle"),
    (lambda: thf_centerline(flexure_angle_deg=float("nan")), "hepatic flexure angle"),
    (lambda: rsf_centerline(exit_length=-0.01), "length of transverse"),
    (lambda: thf_centerline(exit_length=float("nan")), "length of ascending"),
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
