"""Triangle mesh of a tube around a centerline (:class:`colonsim.insertion.anatomy.centerline.Centerline`
or :class:`colonsim.insertion.anatomy.patient_centerline.PatientCenterline`).

Rings of ``m = round(pi D / h)`` nodes sit every ``~h sqrt(3)/2`` of arc length, every other ring
rotated by half a node spacing, so the triangles are close to equilateral with edges of about h
(on a bend they are compressed on the inner side and stretched on the outer side by ``1 -/+ D/(2R)``).

A diameter that varies along the centerline (a patient's profile, a callable ``D(s)``) keeps
``m`` nodes on every ring, sized on the widest ring (``m = round(pi D_max / h)``): no triangle is
larger than asked, and narrower rings get proportionally smaller ones (**assumption**,
docs/model.md, "A patient's centerline": sizing on the median would leave the widest rings
coarser than the element size the user chose; the price is a time step smaller by up to
D_min / D_max). The rings are then spaced ``(pi D(s) / m) sqrt(3)/2`` apart, so the triangles stay
near equilateral where the tube narrows.
Rings are placed in the centerline's parallel-transport frame, so the mesh does not twist and a
node keeps its angular position along the tube. Node tags come from the centerline pieces; the
first and last ring are the end rings, held fixed in every model (docs/model.md, "Colon models").

``diameter`` is the diameter of the meshed surface: pass the lumen diameter D for a contact
surface, or D + t for the wall's mid-surface of a shell of thickness t.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from colonsim.errors import ColonsimError
from colonsim.insertion.anatomy.centerline import Centerline
from colonsim.insertion.engine.sheet_mesh import orient_outward, ring_triangles

MAX_NODES = 2_000_000  # beyond this the explicit solver would run for days: an element size typo


@dataclass
class TubeMesh:
    """Tube wall mesh with tags (SI units).

    Attributes
    ----------
    nodes : (n, 3) float64
        Node positions, m.
    triangles : (nt, 3) int64
        Consistently oriented, normals pointing out of the lumen.
    ring : (n,) int64
        Ring index of each node, 0 at s = 0.
    s : (n,) float64
        Arc length of each node's ring, m.
    fixed : (n,) bool
        Held in place: nodes on fixed pieces and the end rings.
    mobile : (n,) bool
        ``~fixed``: nodes on mobile pieces, end rings excluded.
    end_ring : (n,) bool
        Nodes of the first and last ring.
    piece : (n,) int64
        Index into ``centerline.pieces`` of each node's ring.
    diameter, element_size : float
        Meshed diameter (the largest, for a profile) and requested element size, m.
    nodes_per_ring : int
    centerline : Centerline or PatientCenterline
    ring_diameters : (n_rings,) float64 or None
        Meshed diameter of each ring for a diameter profile, m (None: constant ``diameter``).
    """

    nodes: np.ndarray
    triangles: np.ndarray
    ring: np.ndarray
    s: np.ndarray
    fixed: np.ndarray
    mobile: np.ndarray
    end_ring: np.ndarray
    piece: np.ndarray
    diameter: float
    element_size: float
    nodes_per_ring: int
    centerline: Centerline
    ring_diameters: np.ndarray | None = None

    @property
    def n_rings(self):
        return int(self.ring.max()) + 1

    def ring_centres(self):
        """Centerline point of each node's ring, (n, 3) m."""
        return self.centerline.position(self.s)

    def summary(self):
        """Counts and sizes for printing next to the source's meshes."""
        return {
            "nodes": int(len(self.nodes)),
            "triangles": int(len(self.triangles)),
            "rings": self.n_rings,
            "nodes_per_ring": self.nodes_per_ring,
            "fixed_nodes": int(self.fixed.sum()),
            "mobile_nodes": int(self.mobile.sum()),
            "end_ring_nodes": int(self.end_ring.sum()),
            "centerline_length_m": self.centerline.length,
            "diameter_m": self.diameter,
            "element_size_m": self.element_size,
        }


def tube_mesh(centerline: Centerline, diameter, element_size=3e-3) -> TubeMesh:
    """Mesh a tube of ``diameter`` around ``centerline`` with near-equilateral triangles of ~``element_size``.

    Parameters
    ----------
    centerline : Centerline or PatientCenterline
    diameter : float or callable
        Diameter of the meshed surface, m (1 mm <= D <= 120 mm, D/2 below every bend radius), or
        for a :class:`PatientCenterline` a profile ``D(s)`` (vectorised in s, m).
    element_size : float
        Target edge length h, m; at least 6 nodes per ring (h <= pi D / 6).

    Returns
    -------
    TubeMesh

    Raises
    ------
    ColonsimError
        Diameter or element size out of range, the tube cutting itself, or a mesh too large.
    """
    centerline.check_tube(diameter)
    profile = callable(diameter)
    if profile:  # the widest ring sizes the elements (module docstring)
        s_fine = np.linspace(0.0, centerline.length, max(2, int(np.ceil(centerline.length / 5e-4)) + 1))
        d_fine = diameter(s_fine)
        widest = float(d_fine.max())
    else:
        widest = diameter
    if not (np.isfinite(element_size) and 0.0 < element_size <= np.pi * widest / 6.0):
        raise ColonsimError(
            f"element size {element_size!r} m must be positive and at most pi D / 6 = "
            f"{np.pi * widest / 6 * 1e3:.1f} mm (6 nodes per ring); fix the element size."
        )
    m = int(round(np.pi * widest / element_size))
    step = np.pi * widest / m
    if profile:
        # ring index as a function of s: rings (pi D(s) / m) sqrt(3)/2 apart
        density = 1.0 / (np.pi * d_fine / m * np.sqrt(3.0) / 2.0)
        count = np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * np.diff(s_fine))])
        n_rings = max(1, int(round(count[-1]))) + 1
    else:
        # Ring spacing of an equilateral zig-zag whose base is the actual node spacing on the ring.
        n_rings = max(1, int(round(centerline.length / (step * np.sqrt(3.0) / 2.0)))) + 1
    if n_rings * m > MAX_NODES:
        raise ColonsimError(
            f"element size {element_size * 1e3:g} mm gives {n_rings * m} nodes (limit {MAX_NODES}); "
            "use a larger element size."
        )
    if profile:
        s_ring = np.interp(np.linspace(0.0, count[-1], n_rings), count, s_fine)
        s_ring[[0, -1]] = 0.0, centerline.length
        ring_diameters = diameter(s_ring)
    else:
        s_ring = np.linspace(0.0, centerline.length, n_rings)
        ring_diameters = None
    centre, _, normal, binormal = centerline.frame(s_ring)

    ring = np.repeat(np.arange(n_rings), m)
    j = np.tile(np.arange(m), n_rings)
    phi = 2.0 * np.pi * (j + 0.5 * (ring % 2)) / m
    radius = 0.5 * diameter if not profile else 0.5 * ring_diameters[ring][:, None]
    nodes = centre[ring] + radius * (np.cos(phi)[:, None] * normal[ring] + np.sin(phi)[:, None] * binormal[ring])
    triangles = orient_outward(nodes, ring_triangles(n_rings, m), centre[ring])

    piece_of_ring = centerline.piece_index(s_ring)
    ring_fixed = np.array([centerline.pieces[i].tag == "fixed" for i in piece_of_ring])
    end_ring = (ring == 0) | (ring == n_rings - 1)
    fixed = ring_fixed[ring] | end_ring
    return TubeMesh(nodes=nodes, triangles=triangles.astype(np.int64), ring=ring.astype(np.int64),
                    s=s_ring[ring], fixed=fixed, mobile=~fixed, end_ring=end_ring,
                    piece=piece_of_ring[ring].astype(np.int64), diameter=float(widest),
                    element_size=float(element_size), nodes_per_ring=m, centerline=centerline,
                    ring_diameters=ring_diameters)


def enclosed_volume(mesh: TubeMesh):
    """Volume of the tube closed by flat fans at its end rings, m^3 (divergence theorem).

    Positive when the normals point out of the lumen.
    """
    p = mesh.nodes
    tri = mesh.triangles
    vol = np.einsum("ij,ij->i", p[tri[:, 0]], np.cross(p[tri[:, 1]], p[tri[:, 2]])).sum() / 6.0
    m = mesh.nodes_per_ring
    for k, outward in ((0, -1.0), (mesh.n_rings - 1, 1.0)):
        ids = np.arange(k * m, (k + 1) * m)
        centre = p[ids].mean(axis=0)
        a, b = p[ids], p[np.roll(ids, -1)]
        fan = np.einsum("ij,ij->i", np.broadcast_to(centre, a.shape), np.cross(a, b)).sum() / 6.0
        # The fan (centre, a, b) is counter-clockwise about the ring's (n, b) plane, normal +t.
        vol += outward * fan
    return float(vol)
