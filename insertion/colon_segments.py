"""The colon models of the study as simulation-ready geometry (SPEC.md 2.1).

The centerline is planar (x-y plane) and built like a turtle walk from straight pieces and
circular arcs; a kink between two straight pieces gets a fillet arc of radius 5 cm
(**assumption**, so the tube has no crease); a kink next to a flexure is absorbed into the
flexure's turning angle. Each piece is fixed or mobile; fillets take the fixed tag when either
neighbour is fixed, so the mobile part is exactly the named intraperitoneal piece. Readings of
SPEC.md 2.1 made here (**assumptions**):

- RSJ: 4 cm rectum along +y, then a 180 deg arc of R = 5 cm (the mobile sigmoid angulation).
- RSF: 4 cm rectum along +y, 20 cm sigmoid tilted by alpha from the rectum axis, 10 cm
  descending colon parallel to the rectum again, splenic flexure turning 90 deg (the model ends
  after the flexure). alpha = 0 makes rectum, sigmoid and descending colon one straight line.
- THF: a 5 cm straight lead-in (end of the descending colon, along +y) for the scope's entry,
  splenic flexure turning 90 deg + beta, transverse colon as a V of two straight arms at
  -/+ beta spanning 20 cm (each arm 10 / cos(beta) cm, longer and deeper with beta), hepatic
  flexure turning 90 deg + beta, 10 cm ascending colon along -y.
- fixed THF: THF with the transverse colon fixed too.

:func:`colon_geometry` returns a :class:`ColonGeometry`: the wall mesh at the mid-surface (the
lumen diameter D plus one wall thickness, because contact acts half a thickness inside the
mid-surface), the node tags (fixed, mobile, end rings), the entry point and axis of the scope,
the centerline, and what the manoeuvre needs (where straightening ends, the axes of the
straight mobile pieces). A straight tube (``"straight"``) is kept for sanity checks.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from colonsim.errors import ColonsimError
from insertion.sheet_mesh import orient_outward, ring_triangles, straight_tube

FLEXURE_RADIUS = 0.05  # m, SPEC.md 2.1
FILLET_RADIUS = 0.05  # m, assumption: junctions between straight pieces at an angle


@dataclass
class ColonGeometry:
    """Wall mesh and tags of one colon model (SI units)."""

    name: str
    nodes: np.ndarray
    triangles: np.ndarray
    fixed: np.ndarray
    mobile: np.ndarray
    end_ring: np.ndarray
    entry_point: np.ndarray
    entry_axis: np.ndarray
    centerline_length: float
    centerline_points: object  # callable s -> (n, 3)
    straighten_depth: float | None = None
    mobile_axes: list = field(default_factory=list)
    end_depth: float | None = None  # pushed depth at which the run ends (tip past the fixed end)

    def __post_init__(self):
        if self.end_depth is None:
            self.end_depth = self.centerline_length - 0.5 * self._diameter()

    def _diameter(self):
        return 2.0 * float(np.linalg.norm(self.nodes[0] - self.entry_point))

    def summary(self) -> dict:
        return {"segment": self.name, "wall_nodes": int(len(self.nodes)), "wall_triangles": int(len(self.triangles)),
                "fixed_nodes": int(self.fixed.sum()), "mobile_nodes": int(self.mobile.sum()),
                "end_ring_nodes": int(self.end_ring.sum()), "centerline_length_cm": self.centerline_length * 100}


def _fillet_tangent(turn, radius):
    return radius * np.tan(0.5 * abs(turn))


def plan_pieces(pieces, fillet_radius=FILLET_RADIUS):
    """Insert fillets between straight pieces at an angle; return (kind, length_or_radius, turn, tag, name).

    ``pieces``: sequence of ("straight", length, heading_change_before, tag, name) or
    ("arc", radius, turn, tag, name); a straight piece's ``heading_change_before`` is the kink
    from the previous straight piece (fillet inserted, both straights trimmed by R tan(kink/2)).
    """
    out = []
    for piece in pieces:
        kind, size, turn, tag, name = piece
        if kind == "straight" and turn != 0.0:
            if not out or out[-1][0] != "straight":
                raise ColonsimError(f"a kink before {name} needs a straight piece before it")
            cut = _fillet_tangent(turn, fillet_radius)
            prev = out[-1]
            if prev[1] - cut <= 0 or size - cut <= 0:
                raise ColonsimError(
                    f"the {np.degrees(abs(turn)):.0f} deg kink between {prev[4]} and {name} needs "
                    f"{cut * 100:.1f} cm of straight on both sides; reduce the angle"
                )
            out[-1] = (prev[0], prev[1] - cut, 0.0, prev[3], prev[4])
            fillet_tag = "fixed" if "fixed" in (prev[3], tag) else "mobile"
            out.append(("arc", fillet_radius, turn, fillet_tag, f"fillet {prev[4]}-{name}"))
            out.append((kind, size - cut, 0.0, tag, name))
        else:
            out.append(piece)
    return out


class Centerline:
    """A planar centerline of straight and arc pieces, arc-length parametrised (m)."""

    def __init__(self, pieces, start=(0.0, 0.0), heading=np.pi / 2):
        self.pieces = []
        p = np.asarray(start, dtype=float)
        phi = float(heading)
        s = 0.0
        for kind, size, turn, tag, name in pieces:
            length = size if kind == "straight" else size * abs(turn)
            self.pieces.append({"kind": kind, "size": size, "turn": turn, "tag": tag, "name": name,
                                "s0": s, "s1": s + length, "p0": p.copy(), "phi0": phi})
            p, phi = self._walk(self.pieces[-1], length)
            s += length
        self.length = s

    @staticmethod
    def _walk(piece, ds):
        p0, phi0 = piece["p0"], piece["phi0"]
        if piece["kind"] == "straight":
            return p0 + ds * np.array([np.cos(phi0), np.sin(phi0)]), phi0
        R, sign = piece["size"], np.sign(piece["turn"])
        dphi = sign * ds / R
        centre = p0 + sign * R * np.array([-np.sin(phi0), np.cos(phi0)])
        phi = phi0 + dphi
        return centre + sign * R * np.array([np.sin(phi), -np.cos(phi)]), phi

    def piece_at(self, s):
        for piece in self.pieces:
            if s <= piece["s1"] + 1e-12:
                return piece
        return self.pieces[-1]

    def frame(self, s):
        """Position (3,), unit tangent (3,) and in-plane unit normal (3,) at arc length s."""
        piece = self.piece_at(s)
        p, phi = self._walk(piece, s - piece["s0"])
        t = np.array([np.cos(phi), np.sin(phi), 0.0])
        return np.array([p[0], p[1], 0.0]), t, np.array([-t[1], t[0], 0.0])

    def points(self, s):
        return np.array([self.frame(si)[0] for si in np.atleast_1d(s)])

    def ends(self, name):
        """Arc-length interval of the named piece."""
        for piece in self.pieces:
            if piece["name"] == name:
                return piece["s0"], piece["s1"]
        raise KeyError(name)


def tube_mesh(centerline: Centerline, diameter, element_size):
    """Rings of ``round(pi diameter / h)`` nodes around the centerline, about h sqrt(3)/2 apart.

    Returns nodes (n, 3), outward-oriented triangles, and the arc length and ring of each node.
    """
    radius = 0.5 * diameter
    m = max(3, int(round(np.pi * diameter / element_size)))
    step = np.pi * diameter / m
    n_rings = max(2, int(round(centerline.length / (step * np.sqrt(3.0) / 2.0))) + 1)
    s = np.linspace(0.0, centerline.length, n_rings)
    nodes, centres = [], []
    ez = np.array([0.0, 0.0, 1.0])
    for k, sk in enumerate(s):
        c, _, n = centerline.frame(sk)
        phi = 2.0 * np.pi * (np.arange(m) + 0.5 * (k % 2)) / m
        nodes.append(c + radius * (np.cos(phi)[:, None] * n + np.sin(phi)[:, None] * ez))
        centres.append(np.repeat(c[None], m, axis=0))
    nodes = np.vstack(nodes)
    triangles = orient_outward(nodes, ring_triangles(n_rings, m), np.vstack(centres))
    ring = np.repeat(np.arange(n_rings), m)
    return nodes, triangles, s[ring], ring


def _tags(centerline, node_s):
    tags = np.array([centerline.piece_at(si)["tag"] for si in node_s])
    return tags == "fixed", tags == "mobile"


def _geometry(name, centerline, diameter, element_size, wall_thickness, entry_axis, straighten_depth=None,
              mobile_pieces=(), end_depth=None):
    if diameter / 2 + wall_thickness >= min([p["size"] for p in centerline.pieces if p["kind"] == "arc"], default=np.inf):
        raise ColonsimError(f"a {diameter * 1e3:.0f} mm colon does not fit around a bend of radius "
                            f"{FLEXURE_RADIUS * 100:.0f} cm (the wall would fold); use a smaller --diameter")
    nodes, triangles, node_s, ring = tube_mesh(centerline, diameter + wall_thickness, element_size)
    fixed, mobile = _tags(centerline, node_s)
    end_ring = (ring == 0) | (ring == ring.max())
    axes = []
    for names in mobile_pieces:
        # nodes of these pieces may only move along the direction of the first (a straight piece)
        s0 = min(centerline.ends(n)[0] for n in names)
        s1 = max(centerline.ends(n)[1] for n in names)
        nodes_in = np.flatnonzero(mobile & (node_s >= s0 - 1e-9) & (node_s <= s1 + 1e-9))
        if nodes_in.size:
            axes.append((centerline.frame(centerline.ends(names[0])[0] + 1e-9)[1], nodes_in))
    return ColonGeometry(name, nodes, triangles, fixed & ~end_ring, mobile & ~end_ring, end_ring,
                         entry_point=centerline.frame(0.0)[0], entry_axis=np.asarray(entry_axis, float),
                         centerline_length=centerline.length, centerline_points=centerline.points,
                         straighten_depth=straighten_depth, mobile_axes=axes, end_depth=end_depth)


def straight_colon(length, diameter, element_size, wall_thickness, fixed_length=0.0) -> ColonGeometry:
    """A straight tube along +x, mobile between ``fixed_length`` from each end (the sanity case)."""
    nodes, triangles, ring = straight_tube(length, diameter + wall_thickness, element_size)
    x = nodes[:, 0]
    end_ring = (ring == 0) | (ring == ring.max())
    fixed = (x < fixed_length) | (x > length - fixed_length)
    return ColonGeometry(
        "straight", nodes, triangles, fixed & ~end_ring, ~fixed & ~end_ring, end_ring,
        entry_point=np.zeros(3), entry_axis=np.array([1.0, 0.0, 0.0]), centerline_length=float(length),
        centerline_points=lambda s: np.column_stack([np.asarray(s, float), np.zeros(np.size(s)), np.zeros(np.size(s))]),
    )


def rsj_centerline(rectum=0.04, radius=FLEXURE_RADIUS, angle_deg=180.0, exit_length=0.0):
    pieces = [("straight", rectum, 0.0, "fixed", "rectum"),
              ("arc", radius, np.radians(angle_deg), "mobile", "sigmoid")]
    if exit_length > 0.0:
        pieces.append(("straight", exit_length, 0.0, "fixed", "descending"))
    return Centerline(pieces)


def rsf_centerline(alpha_deg=0.0, rectum=0.04, sigmoid=0.20, descending=0.10, radius=FLEXURE_RADIUS):
    a = np.radians(alpha_deg)
    return Centerline(plan_pieces([("straight", rectum, 0.0, "fixed", "rectum"),
                                   ("straight", sigmoid, a, "mobile", "sigmoid"),
                                   ("straight", descending, -a, "fixed", "descending"),
                                   ("arc", radius, np.pi / 2, "fixed", "splenic flexure")]))


def thf_centerline(beta_deg=0.0, lead_in=0.05, span=0.20, ascending=0.10, radius=FLEXURE_RADIUS, fixed_transverse=False):
    b = np.radians(beta_deg)
    tag = "fixed" if fixed_transverse else "mobile"
    arm = 0.5 * span / np.cos(b)
    pieces = [("straight", lead_in, 0.0, "fixed", "descending"),
              ("arc", radius, np.pi / 2 + b, "fixed", "splenic flexure"),
              ("straight", arm, 0.0, tag, "transverse 1"),
              ("straight", arm, -2 * b, tag, "transverse 2"),
              ("arc", radius, np.pi / 2 + b, "fixed", "hepatic flexure"),
              ("straight", ascending, 0.0, "fixed", "ascending")]
    return Centerline(plan_pieces(pieces))


ANGLE_LIMIT_DEG = 60.0


def colon_geometry(segment, diameter, angle_deg, element_size, wall_thickness, exit_length=0.0) -> ColonGeometry:
    """The geometry of ``segment`` ("rsj", "rsf", "thf", "thf-fixed", or "straight").

    ``exit_length`` (m, RSJ only, default 0 = SPEC.md's model) continues the colon after the
    sigmoid with a fixed straight piece (the start of the descending colon), so the tip passing
    the fixed end enters fixed colon instead of leaving the tube.
    """
    if segment == "straight":
        return straight_colon(0.20, diameter, element_size, wall_thickness)
    if segment not in ("rsj", "rsf", "thf", "thf-fixed"):
        raise ColonsimError(f"{segment!r} is not a colon model; use rsj, rsf, thf, thf-fixed or straight")
    if segment in ("rsf", "thf", "thf-fixed") and not (0.0 <= angle_deg <= ANGLE_LIMIT_DEG):
        raise ColonsimError(f"--angle {angle_deg:g} deg is outside 0-{ANGLE_LIMIT_DEG:g} deg, the range this geometry "
                            "builds (the source used 0, 30, 45)")
    up = np.array([0.0, 1.0, 0.0])
    if not (np.isfinite(exit_length) and 0.0 <= exit_length <= 0.3):
        raise ColonsimError(f"exit length {exit_length * 1e3:g} mm must lie in 0-300 mm")
    if segment == "rsj":
        c = rsj_centerline(exit_length=exit_length)
        end = c.ends("sigmoid")[1] + 0.5 * diameter if exit_length > 0 else None
        return _geometry("rsj", c, diameter, element_size, wall_thickness, up, end_depth=end)
    if segment == "rsf":
        c = rsf_centerline(angle_deg)
        return _geometry("rsf", c, diameter, element_size, wall_thickness, up,
                         straighten_depth=c.ends("splenic flexure")[0], mobile_pieces=[("sigmoid",)])
    c = thf_centerline(angle_deg, fixed_transverse=segment == "thf-fixed")
    mobile = [] if segment == "thf-fixed" else [("transverse 1",), ("transverse 2",)]
    if angle_deg > 0 and segment == "thf":
        # the V-bottom fillet goes with the first arm
        mobile = [("transverse 1", "fillet transverse 1-transverse 2"), ("transverse 2",)]
    # THF ends when the tip has passed the hepatic flexure (the ascending colon only closes the tube)
    return _geometry(segment, c, diameter, element_size, wall_thickness, up,
                     straighten_depth=c.ends("hepatic flexure")[0], mobile_pieces=mobile,
                     end_depth=c.ends("hepatic flexure")[1] + 0.5 * diameter)
