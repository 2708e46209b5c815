"""The colon models of the study as simulation-ready geometry (docs/model.md, "Colon models").

A thin layer over :mod:`colonsim.insertion.anatomy.centerline` (the centerlines, their fixed/mobile tags and their
readings, in the builders' docstrings) and :mod:`colonsim.insertion.anatomy.colon_geometry` (the tube mesh). It
adds what an insertion run needs from a model (**assumptions** where marked):

- the wall is meshed at its mid-surface, diameter D + t, because contact acts half a thickness
  inside the mid-surface;
- every model continues past its last mobile piece into a fixed exit (``exit_length``, 10 cm by
  default), so the scope is held at both ends of the mobile part;
- RSJ: the run ends when the tip is ``PAST_JUNCTION`` (2 cm) past the sigmoid's junction with
  the fixed exit;
- RSF: the sigmoid tilts by alpha towards the patient's left, away from the side the splenic
  flexure turns to (:func:`colonsim.insertion.anatomy.centerline.rsf_centerline`); alpha = 0 is one straight line;
- THF / fixed THF: the scope enters the transverse colon directly;
- RSF, THF: straightening ends where the mobile part ends (``straighten_depth``); while
  straightening, each mobile node may only move along the straight piece it belongs to
  (``mobile_axes``): the sigmoid, or each transverse arm, each with its half of the V-bottom
  fillet. After it the push goes on until the scope's available length is used or the tip
  reaches the model's far end (``end_depth`` = the centerline's length).

:func:`colon_geometry` returns a :class:`ColonGeometry`. A straight tube (``"straight"``) is
kept for sanity checks.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from colonsim.errors import ColonsimError
from colonsim.insertion.anatomy.centerline import Straight
from colonsim.insertion.anatomy.colon_centerlines import EXIT_LENGTH, FLEXURE_ANGLE_DEG, rsf_centerline, rsj_centerline, thf_centerline, thf_fixed_centerline
from colonsim.insertion.anatomy.colon_geometry import tube_mesh
from colonsim.insertion.engine.sheet_mesh import straight_tube

ANGLE_LIMIT_DEG = 60.0  # RSF alpha and THF beta; the source used 0, 30, 45
EXIT_LIMIT = 0.3  # m, fixed exit piece
PAST_JUNCTION = 0.02  # m, an RSJ run ends when the tip is this far past the sigmoid's fixed end


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
    # arc length of the plane (normal to the centerline) whose crossing by the tip ends the run;
    # default: the far end ring
    end_depth: float | None = None
    # arc length where the mobile part ends (None: no mobile part)
    mobile_end: float | None = None

    def __post_init__(self):
        if self.end_depth is None:
            self.end_depth = self.centerline_length

    def summary(self) -> dict:
        return {"segment": self.name, "wall_nodes": int(len(self.nodes)), "wall_triangles": int(len(self.triangles)),
                "fixed_nodes": int(self.fixed.sum()), "mobile_nodes": int(self.mobile.sum()),
                "end_ring_nodes": int(self.end_ring.sum()), "centerline_length_cm": self.centerline_length * 100,
                "mobile_end_cm": None if self.mobile_end is None else self.mobile_end * 100}


def _mobile_axes(centerline, mesh, name):
    """(direction (3,), node indices) per mobile straight piece called ``name``: its mobile nodes
    and those of the mobile arcs (fillets) next to it, which may only move along the straight.

    An arc between two such straights (the bottom of the THF V) is split at its middle, each half
    going with its own straight; an arc next to one only goes with it whole; other arcs stay free.
    (Giving the whole V-bottom fillet to the first arm held the nodes of its second half to a
    direction across their own tube at beta = 45 deg: the scope then crushed them against the
    constraint and two THF runs diverged.)
    """
    pieces = centerline.pieces
    own = {i: [mesh.mobile & (mesh.piece == i)] for i, p in enumerate(pieces)
           if isinstance(p, Straight) and p.tag == "mobile" and p.name == name}
    for i, piece in enumerate(pieces):
        if piece.tag != "mobile" or isinstance(piece, Straight):
            continue
        nodes = mesh.mobile & (mesh.piece == i)
        before, after = i - 1 in own, i + 1 in own
        if before and after:
            first = nodes & (mesh.s < 0.5 * (centerline.s_start[i] + centerline.s_end[i]))
            own[i - 1].append(first)
            own[i + 1].append(nodes & ~first)
        elif before or after:
            own[i - 1 if before else i + 1].append(nodes)
    axes = [(centerline.tangent(centerline.s_start[i]), np.flatnonzero(np.logical_or.reduce(masks)))
            for i, masks in own.items()]
    return [(d, nodes) for d, nodes in axes if nodes.size]


def mobile_end(centerline):
    """Arc length where the last mobile piece ends, m (None when every piece is fixed)."""
    ends = [end for piece, end in zip(centerline.pieces, centerline.s_end) if piece.tag == "mobile"]
    return float(ends[-1]) if ends else None


def _geometry(name, centerline, diameter, element_size, wall_thickness, mobile_piece=None,
              end_depth=None) -> ColonGeometry:
    if 0.5 * diameter + wall_thickness >= centerline.min_radius:
        raise ColonsimError(f"a {diameter * 1e3:.0f} mm colon does not fit around a bend of radius "
                            f"{centerline.min_radius * 100:.0f} cm (the wall would fold); use a smaller --diameter")
    mesh = tube_mesh(centerline, diameter + wall_thickness, element_size)
    axes = [] if mobile_piece is None else _mobile_axes(centerline, mesh, mobile_piece)
    end_mobile = mobile_end(centerline)
    return ColonGeometry(name, mesh.nodes, mesh.triangles, mesh.fixed & ~mesh.end_ring, mesh.mobile, mesh.end_ring,
                         entry_point=centerline.position(0.0), entry_axis=centerline.tangent(0.0),
                         centerline_length=centerline.length,
                         centerline_points=lambda s: centerline.position(np.atleast_1d(s)),
                         straighten_depth=end_mobile if mobile_piece is not None else None, mobile_axes=axes,
                         end_depth=end_depth, mobile_end=end_mobile)


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


def colon_geometry(segment, diameter, angle_deg, element_size, wall_thickness, exit_length=EXIT_LENGTH,
                   flexure_angle_deg=FLEXURE_ANGLE_DEG) -> ColonGeometry:
    """The geometry of ``segment`` ("rsj", "rsf", "thf", "thf-fixed", or "straight").

    Parameters
    ----------
    segment : str
    diameter, wall_thickness, element_size : float
        Lumen diameter D, wall thickness t and triangle size, m; the wall is meshed at D + t.
    angle_deg : float
        RSF alpha or THF beta, 0-60 deg (ignored for RSJ and straight).
    exit_length : float
        m, the fixed straight every model continues into after its last mobile piece (10 cm).
    flexure_angle_deg : float
        Turn of the splenic (RSF) or hepatic (THF) flexure, deg (90).
    """
    if segment == "straight":
        return straight_colon(0.20, diameter, element_size, wall_thickness)
    if segment not in ("rsj", "rsf", "thf", "thf-fixed"):
        raise ColonsimError(f"{segment!r} is not a colon model; use rsj, rsf, thf, thf-fixed or straight")
    if segment in ("rsf", "thf", "thf-fixed") and not (0.0 <= angle_deg <= ANGLE_LIMIT_DEG):
        raise ColonsimError(f"--angle {angle_deg:g} deg is outside 0-{ANGLE_LIMIT_DEG:g} deg, the range this geometry "
                            "builds (the source used 0, 30, 45)")
    if not (np.isfinite(exit_length) and 0.0 <= exit_length <= EXIT_LIMIT):
        raise ColonsimError(f"exit length {exit_length * 1e3:g} mm must lie in 0-{EXIT_LIMIT * 1e3:g} mm")
    if segment == "rsj":
        c = rsj_centerline(exit_length=exit_length)
        end = min(c.bounds("sigmoid")[1] + PAST_JUNCTION, c.length)
        return _geometry("rsj", c, diameter, element_size, wall_thickness, end_depth=end)
    if segment == "rsf":
        c = rsf_centerline(angle_deg, flexure_angle_deg=flexure_angle_deg, exit_length=exit_length)
        return _geometry("rsf", c, diameter, element_size, wall_thickness, mobile_piece="sigmoid")
    build = thf_fixed_centerline if segment == "thf-fixed" else thf_centerline
    c = build(angle_deg, flexure_angle_deg=flexure_angle_deg, exit_length=exit_length)
    return _geometry(segment, c, diameter, element_size, wall_thickness,
                     mobile_piece=None if segment == "thf-fixed" else "transverse")
