"""The colon models of the catalog as simulation-ready geometry (docs/model.md, "Colon models").

A thin layer over :mod:`colonsim.insertion.anatomy.centerline` (the centerlines, their fixed/mobile
tags and their readings, in the builders' docstrings) and
:mod:`colonsim.insertion.anatomy.colon_geometry` (the tube mesh). Which models exist, and each
one's angle, manoeuvre and end rule, is :data:`colonsim.catalog.COLON_MODELS`; this module holds
their builders and applies those rules. It adds what an insertion run needs from a model
(**assumptions** where marked):

- the wall is meshed at its mid-surface, diameter D + t, because contact acts half a thickness
  inside the mid-surface;
- every model continues past its last mobile piece into a fixed exit (``exit_length``, 10 cm by
  default), so the scope is held at both ends of the mobile part;
- RSF: the sigmoid tilts by alpha towards the patient's left, away from the side the splenic
  flexure turns to (:func:`colonsim.insertion.anatomy.centerline.rsf_centerline`); alpha = 0 is one straight line;
- THF / fixed THF: the scope enters the transverse colon directly;
- a model whose manoeuvre straightens ends straightening where the mobile part ends
  (``straighten_depth``); while straightening, each mobile node may only move along the straight
  piece it belongs to (``mobile_axes``): the sigmoid, or each transverse arm, each with its half of
  the V-bottom fillet;
- the end rule sets ``end_depth``: ``PAST_JUNCTION`` (2 cm) past the fixed end of the mobile piece
  (RSJ), else the centerline's far end;
- a patient's centerline (``patient``) is the file's shape as it is: no exit is added, no angle
  applies, and the lumen follows the file's diameter profile when it has one.

:func:`colon_geometry` returns a :class:`ColonGeometry`. A straight tube (``"straight"``) is
kept for sanity checks.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass, field

import numpy as np

from colonsim.catalog import PAST_JUNCTION, PAST_MOBILE_END, colon_model
from colonsim.input_ranges import INPUT_RANGES
from colonsim.errors import ColonsimError
from colonsim.insertion.anatomy.centerline import Straight
from colonsim.insertion.anatomy.colon_centerlines import (EXIT_LENGTH, FLEXURE_ANGLE_DEG, rsf_centerline, rsj_centerline,
                                                          thf_centerline, thf_fixed_centerline)
from colonsim.insertion.anatomy.colon_geometry import tube_mesh
from colonsim.insertion.engine.sheet_mesh import straight_tube

EXIT_LIMIT = 1e-3 * INPUT_RANGES["exit_length_mm"][1]  # m, fixed exit piece (RSF takes about 31 cm)
STRAIGHT_LENGTH = 0.20  # m, the straight sanity tube


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
    # arc length where the fixed exit begins: the last piece, when it is fixed and follows another
    # (the plane past which the distal resistance holds the tip back; None: no exit)
    exit_start: float | None = None
    # the wall's tube mesh with its centerline (None for the straight tube)
    tube: object = None
    # lumen diameter (min, median, max), m, of a diameter profile (None: constant diameter)
    lumen_diameters: tuple | None = None

    def __post_init__(self):
        if self.end_depth is None:
            self.end_depth = self.centerline_length

    def summary(self) -> dict:
        return {"segment": self.name, "wall_nodes": int(len(self.nodes)), "wall_triangles": int(len(self.triangles)),
                "fixed_nodes": int(self.fixed.sum()), "mobile_nodes": int(self.mobile.sum()),
                "end_ring_nodes": int(self.end_ring.sum()), "centerline_length_cm": self.centerline_length * 100,
                "mobile_end_cm": None if self.mobile_end is None else self.mobile_end * 100,
                "exit_start_cm": None if self.exit_start is None else self.exit_start * 100,
                **({} if self.lumen_diameters is None else
                   {"lumen_diameter_mm": dict(zip(("min", "median", "max"), (d * 1e3 for d in self.lumen_diameters)))})}


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


def exit_start(centerline):
    """Arc length where the fixed exit begins, m: the start of the last piece when it is fixed and
    is not the only piece (None otherwise)."""
    if len(centerline.pieces) < 2 or centerline.pieces[-1].tag != "fixed":
        return None
    return float(centerline.s_start[-1])


def _tube_geometry(centerline, diameter, element_size, wall_thickness, exit_length=None) -> ColonGeometry:
    """The wall of ``centerline`` meshed at its mid-surface, with the mesh kept for the catalog's rules.

    ``diameter`` is the lumen diameter, m, or a patient's profile ``D(s)``: the wall's outer
    surface must clear every bend (D/2 + t below the bend radius). ``exit_length`` (m): the length
    of an exit made of several pieces (a folded one), which then begins that far before the end;
    None: the exit is the last piece (:func:`exit_start`)."""
    if callable(diameter):
        centerline.check_bend(lambda s: 0.5 * diameter(s) + wall_thickness, "the colon wall's outer surface")
        mesh = tube_mesh(centerline, lambda s: diameter(s) + wall_thickness, element_size)
    elif 0.5 * diameter + wall_thickness >= centerline.min_radius:
        raise ColonsimError(f"a {diameter * 1e3:.0f} mm colon does not fit around a bend of radius "
                            f"{centerline.min_radius * 100:.0f} cm (the wall would fold); use a smaller --diameter")
    else:
        mesh = tube_mesh(centerline, diameter + wall_thickness, element_size)
    return ColonGeometry("", mesh.nodes, mesh.triangles, mesh.fixed & ~mesh.end_ring, mesh.mobile, mesh.end_ring,
                         entry_point=centerline.position(0.0), entry_axis=centerline.tangent(0.0),
                         centerline_length=centerline.length,
                         centerline_points=lambda s: centerline.position(np.atleast_1d(s)),
                         mobile_end=mobile_end(centerline),
                         exit_start=exit_start(centerline) if exit_length is None else centerline.length - exit_length,
                         tube=mesh)


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


# The builders the catalog names (colonsim.catalog.ColonModel.builder): one signature, SI units;
# ``exit_fold_after`` (m): a longer exit folds out of the model's plane after that much
# (colonsim.insertion.anatomy.colon_centerlines.exit_pieces; None: straight).

def _flexure_geometry(centerline_of, diameter, angle_deg, element_size, wall_thickness, exit_length,
                      flexure_angle_deg, exit_fold_after):
    """The tube of a model whose flexure leads into a lengthened exit: ``centerline_of`` (one of
    the centerline builders) at the angle, flexure and exit given. A folded exit has several
    pieces, so :func:`_tube_geometry` is told its length; a straight one is the last piece."""
    c = centerline_of(angle_deg, flexure_angle_deg=flexure_angle_deg, exit_length=exit_length,
                      exit_fold_after=exit_fold_after)
    folded = exit_fold_after is not None and exit_length > exit_fold_after
    return _tube_geometry(c, diameter, element_size, wall_thickness, exit_length if folded else None)


def rsj_geometry(diameter, angle_deg, element_size, wall_thickness, exit_length, flexure_angle_deg,
                 exit_fold_after=None):
    """RSJ (:func:`colonsim.insertion.anatomy.centerline.rsj_centerline`); no angle, no flexure, and
    a straight exit (the RSJ's is never lengthened)."""
    return _tube_geometry(rsj_centerline(exit_length=exit_length), diameter, element_size, wall_thickness)


def rsf_geometry(diameter, angle_deg, element_size, wall_thickness, exit_length, flexure_angle_deg,
                 exit_fold_after=None):
    """RSF with the sigmoid tilted by alpha = ``angle_deg``."""
    return _flexure_geometry(rsf_centerline, diameter, angle_deg, element_size, wall_thickness, exit_length,
                             flexure_angle_deg, exit_fold_after)


def thf_geometry(diameter, angle_deg, element_size, wall_thickness, exit_length, flexure_angle_deg,
                 exit_fold_after=None):
    """THF with the transverse V at beta = ``angle_deg``."""
    return _flexure_geometry(thf_centerline, diameter, angle_deg, element_size, wall_thickness, exit_length,
                             flexure_angle_deg, exit_fold_after)


def thf_fixed_geometry(diameter, angle_deg, element_size, wall_thickness, exit_length, flexure_angle_deg,
                       exit_fold_after=None):
    """Fixed THF: the THF centerline with the transverse colon fixed too."""
    return _flexure_geometry(thf_fixed_centerline, diameter, angle_deg, element_size, wall_thickness, exit_length,
                             flexure_angle_deg, exit_fold_after)


def straight_geometry(diameter, angle_deg, element_size, wall_thickness, exit_length, flexure_angle_deg,
                      exit_fold_after=None):
    """The 20 cm straight tube, mobile throughout; no angle, no exit."""
    return straight_colon(STRAIGHT_LENGTH, diameter, element_size, wall_thickness)


def _patient_lumen(centerline, diameter):
    """The lumen diameter ``D(s)`` (m) of a case on ``centerline``: the file's profile when it has
    one (``diameter``, m, must then be its median), else ``diameter`` everywhere."""
    centerline.check_case_diameter(diameter)
    if centerline.diameter_profile is not None:
        return centerline.diameter_at
    return lambda s: np.full(np.shape(s), float(diameter))


def check_patient_tube(centerline, diameter, wall_thickness):
    """Raise unless a colon of lumen ``diameter`` (m; the file's profile when it has one) and wall
    ``wall_thickness`` (m) fits ``centerline``: the diameter the case states, every bend cleared by
    the wall's outer surface, no two parts of the tube's mid-surface crossing (the checks
    :func:`patient_geometry` makes while meshing, without the mesh)."""
    lumen = _patient_lumen(centerline, diameter)
    centerline.check_bend(lambda s: 0.5 * lumen(s) + wall_thickness, "the colon wall's outer surface")
    centerline.check_tube(lambda s: lumen(s) + wall_thickness)


def patient_geometry(diameter, angle_deg, element_size, wall_thickness, exit_length, flexure_angle_deg,
                     exit_fold_after=None, centerline=None):
    """A patient's centerline (:class:`colonsim.insertion.anatomy.patient_centerline.PatientCenterline`)
    as it is: angle, flexure and exit do not apply; the lumen is the file's diameter profile when
    it has one (``diameter`` must then be its median), else ``diameter``. The wall's bend and
    self-clearance checks are those of meshing (:func:`_tube_geometry`, :func:`tube_mesh`)."""
    geometry = _tube_geometry(centerline, _patient_lumen(centerline, diameter), element_size, wall_thickness)
    if centerline.diameter_profile is not None:
        d = centerline.diameter_profile[1]
        geometry.lumen_diameters = (float(d.min()), float(np.median(d)), float(d.max()))
    return geometry


def _builder(model):
    module, _, function = model.builder.partition(":")
    try:
        return getattr(importlib.import_module(module), function)
    except (ImportError, AttributeError):
        raise ColonsimError(f"colon model {model.name!r}: builder {model.builder!r} not found; fix its catalog "
                            "entry (colonsim/catalog.py)") from None


def colon_geometry(segment, diameter, angle_deg, element_size, wall_thickness, exit_length=EXIT_LENGTH,
                   flexure_angle_deg=FLEXURE_ANGLE_DEG, centerline=None, exit_fold_after=None) -> ColonGeometry:
    """The geometry of the catalog's colon model ``segment`` (:data:`colonsim.catalog.COLON_MODELS`).

    Builds it with the model's builder, then applies the model's rules: the mobile piece a
    straighten-relax-push straightens (``mobile_axes``, ``straighten_depth``) and the end rule
    (``end_depth``).

    Parameters
    ----------
    segment : str
    diameter, wall_thickness, element_size : float
        Lumen diameter D, wall thickness t and triangle size, m; the wall is meshed at D + t.
    angle_deg : float
        RSF alpha or THF beta, within the model's limits (ignored by models without an angle).
    exit_length : float
        m, the fixed straight every model continues into after its last mobile piece (10 cm).
    flexure_angle_deg : float
        Turn of the splenic (RSF) or hepatic (THF) flexure, deg (90).
    exit_fold_after : float or None
        m: an exit longer than this folds out of the model's plane after it (the models whose exit
        takes the whole available length, where a straight one would cut the tube; None: straight).
    centerline : PatientCenterline or None
        The user's centerline, for (and only for) a model that reads one (``reads_centerline``:
        ``patient``), from :func:`colonsim.insertion.anatomy.patient_centerline.load_patient_centerline`.
    """
    model = colon_model(segment)
    if model.reads_centerline != (centerline is not None):
        raise ColonsimError(f"colon model {model.name!r} {'needs' if model.reads_centerline else 'takes no'} "
                            "centerline file; " + ("give one (--centerline FILE)" if model.reads_centerline else
                                                   "drop it, or use --segment patient (--centerline implies it)"))
    model.check_angle(angle_deg)
    if not (np.isfinite(exit_length) and 0.0 <= exit_length <= EXIT_LIMIT):
        raise ColonsimError(f"exit length {exit_length * 1e3:g} mm must lie in 0-{EXIT_LIMIT * 1e3:g} mm")
    extra = {"centerline": centerline} if model.reads_centerline else {}
    geometry = _builder(model)(diameter, angle_deg, element_size, wall_thickness, exit_length, flexure_angle_deg,
                               exit_fold_after=exit_fold_after, **extra)
    geometry.name = model.name
    if model.straightens or model.end_rule == PAST_MOBILE_END:
        if geometry.tube is None:
            raise ColonsimError(f"colon model {model.name!r}: its rules need a centerline mesh, and its builder "
                                f"{model.builder!r} returns none; fix its catalog entry (colonsim/catalog.py)")
        centerline = geometry.tube.centerline
    if model.straightens:
        geometry.mobile_axes = _mobile_axes(centerline, geometry.tube, model.mobile_piece)
        geometry.straighten_depth = geometry.mobile_end
    if model.end_rule == PAST_MOBILE_END:
        geometry.end_depth = min(centerline.bounds(model.mobile_piece)[1] + PAST_JUNCTION, centerline.length)
    return geometry
