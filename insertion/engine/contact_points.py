"""Where the contact samples the wall: its nodes, or points spread over its triangles.

The contact law (:mod:`colonsim.insertion.engine.contact`) acts between the scope's surface and a
set of **contact points** of the wall. A point is a fixed combination of up to three wall nodes,
p = sum_j w_j x_j, carrying a share s of one node's penalty and mass (docs/model.md, "Contact"):

- ``"nodes"``: every wall node is a point (weight 1, share 1): the contact of before.
- ``"faces"``: every triangle carries the centroids of its uniform subdivision into L^2
  sub-triangles (L = ``subdivision``), each standing for A / L^2 of the triangle's area A. Its
  share is that area over the mean lumped area of the triangle's three nodes, so a uniformly
  pressed wall takes the same penalty per unit area as with nodes, and a node's row of the
  contact stiffness (the time-step bound) stays what one node's spring gave; next to the wall's
  edge (an end ring) up to 1.3 times as much, as there a node takes a whole node's penalty on
  less area (``node_share``, which the bound reads).

Why faces: a node-sampled wall is felt only at its nodes, so a round scope lying across the
wall sinks between two node columns by about (1/r - 1/R) h^2 / 8 (r the scope's radius, R the
lumen's, h the node spacing: 0.1 mm for the 13.3 mm scope on the 3 mm mesh) and not at all where
it lies on a column. Sliding and rolling over the mesh, it therefore rises and sinks by a tenth of
a millimetre at the mesh's period, which shows as ringing and as a scatter of the outputs from run
to run. Sampled at spacing h / L over the faces, the sag falls as 1 / L^2.

A point is **held** when held nodes carry at least half its weight (the rigid fixed wall: it
pushes along the wall's rest normal, interpolated and normalised, and loads the scope alone);
otherwise it is free, and its force on any held node is taken by that node's constraint. On the
seam between the fixed and the mobile wall the points nearer the held nodes are so the rigid
wall's, as the held nodes are at ``nodes``: pushing along the axis-to-point line there, a tip
pressed into the crease would be pushed back along its own axis (docs/model.md, "Contact").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from colonsim.errors import ColonsimError

WALL_SAMPLINGS = ("nodes", "faces")
FACE_SUBDIVISIONS = range(1, 9)  # L: beyond 8 (64 points a triangle) the points cost more than they smooth


def valid_subdivision(subdivision) -> bool:
    """Is ``subdivision`` a whole number in :data:`FACE_SUBDIVISIONS`?"""
    return isinstance(subdivision, (int, np.integer)) and not isinstance(subdivision, bool) \
        and subdivision in FACE_SUBDIVISIONS


@dataclass(frozen=True)
class ContactPoints:
    """Contact points of a wall (arrays contiguous, for the kernels).

    nodes : (p, k) int64, the wall nodes each point rests on (k = 1 for nodes, 3 for faces)
    weights : (p, k) float64, their weights (summing to 1 per point)
    share : (p,) float64, the point's share of one node's penalty and mass
    held_normal : (p, 3) float64, the fixed wall's rest normal at the point (zeros: none given)
    node_share : (n,) float64, sum over the points of share x weight on each wall node: its
        penalty per node's penalty (1 for nodes; the time-step bound reads it)
    """

    nodes: np.ndarray
    weights: np.ndarray
    share: np.ndarray
    held_normal: np.ndarray
    node_share: np.ndarray

    def __len__(self):
        return len(self.share)

    def positions(self, x):
        """The points' positions (or velocities, displacements) from the nodes' x (n, 3)."""
        if self.nodes.shape[1] == 1:
            return x  # the nodes themselves (no copy: the node contact reads the state)
        return np.ascontiguousarray(np.einsum("pk,pkd->pd", self.weights, x[self.nodes]))


def node_points(n_nodes, held_normal) -> ContactPoints:
    """Every wall node a contact point (``held_normal`` (n, 3): the wall's rest normals, or zeros)."""
    return ContactPoints(np.arange(n_nodes, dtype=np.int64)[:, None], np.ones((n_nodes, 1)), np.ones(n_nodes),
                         held_normal, np.ones(n_nodes))


def subdivision_centroids(subdivision: int) -> np.ndarray:
    """Barycentric coordinates (L^2, 3) of the centroids of a triangle's uniform subdivision into
    L^2 sub-triangles (L = ``subdivision``): equal areas, so equal weights."""
    L = int(subdivision)
    points = []
    for i in range(L):
        for j in range(L - i):
            points.append(((i + 1.0 / 3.0) / L, (j + 1.0 / 3.0) / L))  # upward sub-triangle
            if i + j <= L - 2:
                points.append(((i + 2.0 / 3.0) / L, (j + 2.0 / 3.0) / L))  # downward one
    b = np.array(points)
    return np.column_stack([1.0 - b.sum(axis=1), b])


def face_points(x0, triangles, subdivision, held_normal) -> ContactPoints:
    """Contact points at the centroids of each triangle's subdivision (module docstring).

    Parameters
    ----------
    x0 : (n, 3) rest positions of the wall's nodes, m
    triangles : (t, 3) node indices
    subdivision : int >= 1, L: L^2 points per triangle, spaced about h / L
    held_normal : (n, 3) the wall's rest normals at its nodes (zeros: none)
    """
    if not valid_subdivision(subdivision):
        raise ColonsimError(f"contact face subdivision = {subdivision!r} must be a whole number from "
                            f"{FACE_SUBDIVISIONS.start} to {FACE_SUBDIVISIONS.stop - 1}; fix it.")
    x0 = np.asarray(x0, dtype=np.float64)
    tri = np.asarray(triangles, dtype=np.int64)
    area = 0.5 * np.linalg.norm(np.cross(x0[tri[:, 1]] - x0[tri[:, 0]], x0[tri[:, 2]] - x0[tri[:, 0]]), axis=1)
    lumped = np.zeros(len(x0))
    np.add.at(lumped, tri.ravel(), np.repeat(area / 3.0, 3))
    bary = subdivision_centroids(subdivision)
    per = len(bary)
    share_tri = area / per / lumped[tri].mean(axis=1)
    nodes = np.repeat(tri, per, axis=0)
    weights = np.tile(bary, (len(tri), 1))
    share = np.repeat(share_tri, per)
    normal = np.einsum("pk,pkd->pd", weights, held_normal[nodes])
    norm = np.linalg.norm(normal, axis=1)
    normal = normal / np.where(norm > 0.0, norm, 1.0)[:, None]
    node_share = np.zeros(len(x0))
    np.add.at(node_share, nodes.ravel(), (share[:, None] * weights).ravel())
    return ContactPoints(np.ascontiguousarray(nodes), np.ascontiguousarray(weights), np.ascontiguousarray(share),
                         np.ascontiguousarray(normal), node_share)
