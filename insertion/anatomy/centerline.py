"""Colon centerlines made of straight pieces and circular arcs, arc-length parametrised (SI, m).

A centerline is a chain of pieces, each tagged ``"fixed"`` (retroperitoneal, held in place) or
``"mobile"`` (intraperitoneal) and named after its colon segment. Pieces are given as
:class:`Straight`, :class:`Arc` and :class:`Kink`; a kink between two straight pieces becomes a
fillet arc of radius ``fillet_radius`` (**assumption**, docs/model.md "Colon models", so the tube has no crease),
trimming ``R_f tan(|angle|/2)`` off each neighbour.

Fillet rule (**assumption**): a fillet between two pieces of the same tag takes that tag; between
a fixed and a mobile piece it is split at its middle (the corner of the unrounded centerline,
where the fixation ends) and each half goes with its own neighbour, so a mobile segment keeps its
length and carries its half of the bend. (Tagging the whole fillet fixed, as an earlier version
did, put every bend of the RSF model in fixed tissue: the scope then passed the tilted sigmoid
without deforming it at any angle.) A fillet takes the neighbours' name when both share one (the
bottom of the transverse V) and ``"a-b fillet"`` else.

Frames are rotation-minimising (parallel transport): the normal ``n`` never spins about the
tangent, so rings of a tube mesh placed with ``(n, b)`` do not twist. On a planar centerline
``n`` stays in the plane and ``b = t x n`` is the plane normal. An arc bends towards
``cos(roll) n + sin(roll) b`` of the transported frame at its start (``roll = 0``: in the plane,
positive angle towards ``+n``), which is how a 3-D centerline is built.

The centerlines of the study's colon models are built from these pieces in
:mod:`colonsim.insertion.anatomy.colon_centerlines`. :class:`LabelledCenterline` is what the
mesher and the colon models use of any centerline (labelled ranges, frames, the self-clearance
check); a patient's measured centerline
(:class:`colonsim.insertion.anatomy.patient_centerline.PatientCenterline`) shares it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from colonsim.errors import ColonsimError

FLEXURE_RADIUS = 0.05  # m, the source's bend radius (flexures and the RSJ sigmoid arc)
FILLET_RADIUS = 0.05  # m, assumption: same as the flexures, the gentlest bend the anatomy shows
MAX_LENGTH = 2.0  # m, a whole adult colon is about 1.5 m; longer pieces are typing errors
TAGS = ("fixed", "mobile")


@dataclass(frozen=True)
class Straight:
    """Straight piece of ``length`` m."""

    length: float
    tag: str
    name: str


@dataclass(frozen=True)
class Arc:
    """Circular arc of ``radius`` m turning the tangent by ``angle`` rad (sign: side, see module)."""

    radius: float
    angle: float
    tag: str
    name: str
    roll: float = 0.0


@dataclass(frozen=True)
class Kink:
    """Change of direction by ``angle`` rad between two straight pieces, rounded by a fillet.

    ``fillet_radius`` None takes the centerline's default.
    """

    angle: float
    roll: float = 0.0
    fillet_radius: float | None = None


class TubeClash(ColonsimError):
    """A tube around a centerline would cut itself: two parts of it cross."""


def check_length(what, value, upper=MAX_LENGTH):
    if not (np.isfinite(value) and 0.0 < value <= upper):
        raise ColonsimError(f"{what} = {value!r} m must be a positive length up to {upper:g} m; fix it.")


def _check_tag(piece):
    if piece.tag not in TAGS:
        raise ColonsimError(f"piece {piece.name!r} has tag {piece.tag!r}; use 'fixed' or 'mobile'.")


def _unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def _rotate(v, axis, angle):
    """Rodrigues rotation of vectors ``v`` (k, 3) about unit ``axis`` (3,) by ``angle`` (k,) rad."""
    c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
    return v * c + np.cross(axis, v) * s + axis * (v @ axis)[:, None] * (1.0 - c)


def resolve_pieces(pieces, fillet_radius=FILLET_RADIUS):
    """Replace kinks by fillet arcs and trim the straight pieces next to them.

    Parameters
    ----------
    pieces : sequence of Straight, Arc, Kink
    fillet_radius : float
        Default fillet radius, m.

    Returns
    -------
    list of Straight and Arc
        Zero-angle kinks are dropped; straights trimmed to zero length are dropped.
    """
    check_length("fillet radius", fillet_radius)
    items = list(pieces)
    if not items:
        raise ColonsimError("a centerline needs at least one piece; give a Straight or an Arc.")
    for i, piece in enumerate(items):
        if isinstance(piece, Straight):
            _check_tag(piece)
            check_length(f"length of {piece.name}", piece.length)
        elif isinstance(piece, Arc):
            _check_tag(piece)
            check_length(f"radius of {piece.name}", piece.radius)
            if not (np.isfinite(piece.angle) and 0.0 < abs(piece.angle) <= 2.0 * np.pi):
                raise ColonsimError(
                    f"arc {piece.name!r} turns {np.degrees(piece.angle):g} deg; give a non-zero angle up to 360 deg."
                )
        elif isinstance(piece, Kink):
            if not (0 < i < len(items) - 1 and isinstance(items[i - 1], Straight)
                    and isinstance(items[i + 1], Straight)):
                raise ColonsimError("a Kink must sit between two Straight pieces; use an Arc next to an arc.")
            if not (np.isfinite(piece.angle) and abs(piece.angle) < np.pi):
                raise ColonsimError(
                    f"a kink of {np.degrees(piece.angle):g} deg folds the colon back on itself; "
                    "keep kinks below 180 deg."
                )
        else:
            raise ColonsimError(f"{piece!r} is not a centerline piece; use Straight, Arc or Kink.")

    # Trim lengths first: a straight between two kinks loses a tangent length at each end.
    trim = np.zeros(len(items))
    radius_of = {}
    for i, piece in enumerate(items):
        if isinstance(piece, Kink) and piece.angle != 0.0:
            rf = fillet_radius if piece.fillet_radius is None else piece.fillet_radius
            check_length(f"fillet radius at the kink after {items[i - 1].name}", rf)
            radius_of[i] = rf
            cut = rf * np.tan(0.5 * abs(piece.angle))
            trim[i - 1] += cut
            trim[i + 1] += cut
    for i, piece in enumerate(items):
        if isinstance(piece, Straight) and trim[i] > piece.length * (1.0 + 1e-12):
            raise ColonsimError(
                f"the fillets next to {piece.name} need {trim[i] * 100:.2f} cm of it but it is only "
                f"{piece.length * 100:.2f} cm long; reduce the fillet radius or the angle."
            )

    out = []
    for i, piece in enumerate(items):
        if isinstance(piece, Straight):
            length = piece.length - trim[i]
            if length > 1e-12:
                out.append(Straight(length, piece.tag, piece.name))
        elif isinstance(piece, Kink):
            if piece.angle == 0.0:
                continue
            before, after = items[i - 1], items[i + 1]
            name = before.name if before.name == after.name else f"{before.name}-{after.name} fillet"
            if before.tag == after.tag:
                out.append(Arc(radius_of[i], piece.angle, before.tag, name, piece.roll))
            else:  # the attachment is at the corner: each half of the bend goes with its own neighbour
                out.append(Arc(radius_of[i], 0.5 * piece.angle, before.tag, name, piece.roll))
                out.append(Arc(radius_of[i], 0.5 * piece.angle, after.tag, name, 0.0))
        else:
            out.append(piece)
    # Two straights with nothing between them (a zero kink) are one piece of the same segment.
    merged = []
    for piece in out:
        prev = merged[-1] if merged else None
        if (isinstance(piece, Straight) and isinstance(prev, Straight)
                and (prev.tag, prev.name) == (piece.tag, piece.name)):
            merged[-1] = Straight(prev.length + piece.length, piece.tag, piece.name)
        else:
            merged.append(piece)
    return merged


class LabelledCenterline:
    """What every centerline offers the mesher and the colon models: arc length ``s`` (m) from 0 to
    ``length``, :meth:`frame`, and labelled ranges ``pieces`` (each with ``.tag`` fixed/mobile and
    ``.name``) covering ``[s_start, s_end)``. Subclasses set ``pieces``, ``s_start``, ``s_end``,
    ``length`` and implement :meth:`frame`, :attr:`min_radius` and ``check_tube``.
    """

    def piece_index(self, s):
        """Index of the piece holding arc length ``s`` (pieces are [start, end); the end belongs to the last)."""
        s = np.asarray(s, dtype=float)
        return np.clip(np.searchsorted(self.s_end, s, side="right"), 0, len(self.pieces) - 1)

    def position(self, s):
        """Point at arc length ``s`` (m), shape (3,) or (k, 3)."""
        return self.frame(s)[0]

    def tangent(self, s):
        """Unit tangent at arc length ``s`` (m), shape (3,) or (k, 3)."""
        return self.frame(s)[1]

    def tag_at(self, s):
        """``"fixed"`` or ``"mobile"`` at arc length ``s`` (str, or array of str)."""
        tags = np.array([p.tag for p in self.pieces])[self.piece_index(s)]
        return tags if np.ndim(s) else str(tags)

    def name_at(self, s):
        """Name of the piece at arc length ``s`` (str, or array of str)."""
        names = np.array([p.name for p in self.pieces])[self.piece_index(s)]
        return names if np.ndim(s) else str(names)

    def bounds(self, name):
        """Arc-length interval (s0, s1), m, covered by the pieces called ``name``."""
        hits = [i for i, p in enumerate(self.pieces) if p.name == name]
        if not hits:
            known = ", ".join(dict.fromkeys(p.name for p in self.pieces))
            raise ColonsimError(f"no piece called {name!r} in this centerline; use one of: {known}.")
        return float(self.s_start[hits[0]]), float(self.s_end[hits[-1]])

    def first_clash(self, diameter_at):
        """Where a tube of diameter ``diameter_at(s)`` (m, vectorised) would cut itself, or None.

        Two cross-sections further apart along s than ``pi D / 2`` (the longest stretch over which
        a curve with bend radii >= D/2 can stay within D of its start; D the larger of the two)
        must be at least their mean diameter apart; checked on a sampled centerline.

        Returns
        -------
        (s_i, s_j, distance) or None
            Arc lengths of the first clashing pair found and the distance of their centres, m.
        """
        d_min = float(np.min(diameter_at(np.linspace(0.0, self.length, 201))))
        # Samples D/8 apart (capped, so a hair-thin tube on a long centerline stays affordable:
        # the check then only sees clashes deeper than the sample spacing).
        n = min(5_000, max(2, int(np.ceil(self.length / (0.125 * d_min))) + 1))
        s = np.linspace(0.0, self.length, n)
        p = self.position(s)
        d = diameter_at(s)
        for lo in range(0, n, 1000):  # blocks of rows bound the pairwise-distance memory
            dist = np.linalg.norm(p[lo:lo + 1000, None, :] - p[None, :, :], axis=-1)
            d_big = np.maximum(d[lo:lo + 1000, None], d[None, :])
            far = np.abs(s[lo:lo + 1000, None] - s[None, :]) > 0.5 * np.pi * d_big
            clash = far & (dist < 0.5 * (d[lo:lo + 1000, None] + d[None, :]) * (1.0 - 1e-9))
            if np.any(clash):
                i, j = np.argwhere(clash)[0]
                return float(s[lo + i]), float(s[j]), float(dist[i, j])
        return None


class Centerline(LabelledCenterline):
    """Arc-length parametrised chain of straight and arc pieces (m), with a parallel-transport frame.

    Parameters
    ----------
    pieces : sequence of Straight, Arc, Kink
        Kinks become fillet arcs (see :func:`resolve_pieces`).
    fillet_radius : float
        Default fillet radius, m.
    start : (3,) float
        Position at s = 0, m.
    tangent, normal : (3,) float
        Direction of travel and normal at s = 0; ``normal`` is made orthogonal to ``tangent``.

    Attributes
    ----------
    pieces : list of Straight and Arc
        The resolved pieces (fillets included).
    s_start, s_end : (np,) float
        Arc length at the start and end of each piece, m.
    length : float
        Total arc length, m.
    """

    def __init__(self, pieces, fillet_radius=FILLET_RADIUS, start=(0.0, 0.0, 0.0),
                 tangent=(0.0, 1.0, 0.0), normal=(-1.0, 0.0, 0.0)):
        self.pieces = resolve_pieces(pieces, fillet_radius)
        t = _unit(tangent)
        n = np.asarray(normal, dtype=float)
        n = _unit(n - (n @ t) * t)
        p = np.asarray(start, dtype=float).copy()
        s = 0.0
        # Per piece: start point, tangent, normal, bending direction d and rotation axis w = t x d.
        self._p0, self._t0, self._n0, self._d, self._w = [], [], [], [], []
        s_start, s_end = [], []
        for piece in self.pieces:
            b = np.cross(t, n)
            if isinstance(piece, Straight):
                length, d = piece.length, np.zeros(3)
            else:
                length = piece.radius * abs(piece.angle)
                d = np.sign(piece.angle) * (np.cos(piece.roll) * n + np.sin(piece.roll) * b)
            self._p0.append(p.copy())
            self._t0.append(t.copy())
            self._n0.append(n.copy())
            self._d.append(d)
            self._w.append(np.cross(t, d))
            s_start.append(s)
            s_end.append(s + length)
            p, t, n = self._local(len(s_start) - 1, np.array([length]))[:3]
            p, t, n = p[0], _unit(t[0]), n[0]
            n = _unit(n - (n @ t) * t)  # keep the frame orthonormal to round-off over many pieces
            s += length
        self.s_start = np.array(s_start)
        self.s_end = np.array(s_end)
        self.length = float(s)

    def _local(self, i, sigma):
        """Position, tangent and normal at distance ``sigma`` (k,) into piece ``i``."""
        piece = self.pieces[i]
        p0, t0, n0 = self._p0[i], self._t0[i], self._n0[i]
        if isinstance(piece, Straight):
            k = len(sigma)
            return p0 + sigma[:, None] * t0, np.tile(t0, (k, 1)), np.tile(n0, (k, 1))
        theta = sigma / piece.radius
        c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
        d = self._d[i]
        pos = p0 + piece.radius * (s * t0 + (1.0 - c) * d)
        tan = c * t0 + s * d
        # A planar circle has no torsion: parallel transport is the rotation about its binormal.
        nor = _rotate(np.tile(n0, (len(sigma), 1)), self._w[i], theta)
        return pos, tan, nor

    def frame(self, s):
        """Position, unit tangent, normal and binormal at arc length ``s``.

        Parameters
        ----------
        s : float or (k,) float
            Arc length, m, clipped to [0, length].

        Returns
        -------
        position, tangent, normal, binormal : (3,) or (k, 3) float
            ``(tangent, normal, binormal)`` is a right-handed orthonormal, rotation-minimising frame.
        """
        scalar = np.ndim(s) == 0
        s = np.clip(np.atleast_1d(np.asarray(s, dtype=float)), 0.0, self.length)
        idx = self.piece_index(s)
        pos, tan, nor = np.empty((len(s), 3)), np.empty((len(s), 3)), np.empty((len(s), 3))
        for i in np.unique(idx):
            mask = idx == i
            pos[mask], tan[mask], nor[mask] = self._local(i, s[mask] - self.s_start[i])
        binormal = np.cross(tan, nor)
        if scalar:
            return pos[0], tan[0], nor[0], binormal[0]
        return pos, tan, nor, binormal

    @property
    def min_radius(self):
        """Smallest bend radius, m (inf for a straight centerline)."""
        return min((p.radius for p in self.pieces if isinstance(p, Arc)), default=np.inf)

    def check_tube(self, diameter):
        """Raise ColonsimError if a tube of ``diameter`` (m) around this centerline would cut itself.

        Locally the wall folds at a bend when D/2 >= R. Globally, two cross-sections further apart
        along s than ``pi D / 2`` (the longest stretch over which a curve with bend radii >= D/2 can
        stay within D of its start) must be at least D apart; checked on a sampled centerline.
        """
        # 1-120 mm: from the thinnest lumen worth simulating to beyond any colon (caecum ~9 cm)
        if not (np.isfinite(diameter) and 1e-3 <= diameter <= 0.12):
            raise ColonsimError(f"tube diameter = {diameter!r} m must lie in 1-120 mm; fix the diameter.")
        if 0.5 * diameter >= self.min_radius:
            raise ColonsimError(
                f"a {diameter * 1e3:.0f} mm tube does not fit a bend of radius {self.min_radius * 100:.1f} cm "
                "(the wall folds at D/2 >= R); use a smaller diameter or a larger bend radius."
            )
        clash = self.first_clash(lambda s: np.full(np.shape(s), float(diameter)))
        if clash is not None:
            s_i, s_j, dist = clash
            raise TubeClash(
                f"a {diameter * 1e3:.0f} mm tube cuts itself between {self.name_at(s_i)} and "
                f"{self.name_at(s_j)} (centerlines {dist * 100:.1f} cm apart); "
                "use a smaller diameter or a smaller angle."
            )
