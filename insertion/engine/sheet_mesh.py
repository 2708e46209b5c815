"""Triangle meshes of the colon wall mid-surface: a flat sheet, a straight tube, their hinges and
their open ends.

Both meshes use rows (rings) of nodes offset by half a step from one row to the next, so the
triangles are close to equilateral. That matters beyond looks: the discrete hinge bending energy
of :mod:`colonsim.insertion.engine.shell` is calibrated on near-equilateral meshes (on right-triangle meshes it
converges to a different, direction-dependent stiffness).
"""

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from colonsim.errors import ColonsimError


def _check_sizes(**sizes):
    for name, value in sizes.items():
        if not np.isfinite(value) or value <= 0.0:
            raise ColonsimError(f"mesh {name} = {value!r} m must be a positive length; fix it.")


def _zip_rows(lower, upper, lower_xy, upper_xy):
    """Triangulate the strip between two open rows of nodes sorted along the strip.

    Walks both rows at once, always closing the triangle with the shorter new diagonal.
    Triangles are counter-clockwise when ``upper`` lies to the left of ``lower``'s direction.
    """
    tris = []
    i, j = 0, 0
    while i < len(lower) - 1 or j < len(upper) - 1:
        if i == len(lower) - 1:
            advance_lower = False
        elif j == len(upper) - 1:
            advance_lower = True
        else:
            d_lower = np.sum((lower_xy[i + 1] - upper_xy[j]) ** 2)
            d_upper = np.sum((upper_xy[j + 1] - lower_xy[i]) ** 2)
            advance_lower = d_lower <= d_upper
        if advance_lower:
            tris.append((lower[i], lower[i + 1], upper[j]))
            i += 1
        else:
            tris.append((lower[i], upper[j + 1], upper[j]))
            j += 1
    return tris


def flat_sheet(length, width, h):
    """Rectangular sheet [0, length] x [0, width] in the z = 0 plane, near-equilateral triangles.

    Rows of nodes run along x, spaced ``h sqrt(3)/2`` in y; odd rows are shifted by half a step
    and closed by half triangles, so all four edges are straight.

    Parameters
    ----------
    length, width : float
        Sheet size along x and y, m.
    h : float
        Target edge length, m.

    Returns
    -------
    nodes : (n, 3) float64
    triangles : (nt, 3) int64
        Counter-clockwise seen from +z (normals point to +z).
    """
    _check_sizes(length=length, width=width, h=h)
    nx = max(1, int(round(length / h)))
    ny = max(1, int(round(width / (h * np.sqrt(3.0) / 2.0))))
    dx = length / nx
    rows, coords = [], []
    start = 0
    for j in range(ny + 1):
        if j % 2 == 0:
            xs = np.arange(nx + 1) * dx
        else:
            xs = np.concatenate(([0.0], (np.arange(nx) + 0.5) * dx, [length]))
        y = width * j / ny
        rows.append(np.arange(start, start + len(xs)))
        coords.append(np.column_stack((xs, np.full(len(xs), y), np.zeros(len(xs)))))
        start += len(xs)
    nodes = np.vstack(coords)
    tris = []
    for j in range(ny):
        tris += _zip_rows(rows[j], rows[j + 1], nodes[rows[j], :2], nodes[rows[j + 1], :2])
    return nodes, np.asarray(tris, dtype=np.int64)


def straight_tube(length, diameter, h):
    """Cylindrical tube along +x from x = 0, mid-surface diameter ``diameter``, triangles of ~h.

    Nodes lie on rings of ``m = round(pi diameter / h)`` nodes, rings spaced so the triangles are
    near-equilateral, every other ring rotated by half a step.

    Parameters
    ----------
    length, diameter : float
        Tube length and mid-surface diameter, m.
    h : float
        Target edge length, m.

    Returns
    -------
    nodes : (n, 3) float64
    triangles : (nt, 3) int64
        Oriented so that triangle normals point out of the lumen.
    ring : (n,) int64
        Ring index of each node, 0 at x = 0 up to ``ring.max()`` at x = length.
    """
    _check_sizes(length=length, diameter=diameter, h=h)
    radius = 0.5 * diameter
    m = max(3, int(round(np.pi * diameter / h)))
    step = np.pi * diameter / m
    n_rings = max(1, int(round(length / (step * np.sqrt(3.0) / 2.0)))) + 1
    xs = np.linspace(0.0, length, n_rings)
    k = np.repeat(np.arange(n_rings), m)
    j = np.tile(np.arange(m), n_rings)
    phi = 2.0 * np.pi * (j + 0.5 * (k % 2)) / m
    nodes = np.column_stack((xs[k], radius * np.cos(phi), radius * np.sin(phi)))

    centres = np.column_stack((xs[k], np.zeros(len(k)), np.zeros(len(k))))
    triangles = orient_outward(nodes, ring_triangles(n_rings, m), centres)
    return nodes, triangles, k.astype(np.int64)


def ring_triangles(n_rings, m):
    """Triangles between ``n_rings`` rings of ``m`` nodes (node ``k m + j``: ring k, position j),
    odd rings rotated by half a step, so every strip is a zig-zag of near-equilateral triangles.
    Orientation is not yet consistent: pass the result through :func:`orient_outward`."""
    jj = np.arange(m)
    jn = (jj + 1) % m
    tris = []
    for ring in range(n_rings - 1):
        lo, up = ring * m, (ring + 1) * m
        if ring % 2 == 0:  # upper node jj sits between lower jj and jj + 1
            tris.append(np.column_stack((lo + jj, lo + jn, up + jj)))
            tris.append(np.column_stack((up + jj, lo + jn, up + jn)))
        else:  # lower node jj sits between upper jj and jj + 1
            tris.append(np.column_stack((lo + jj, up + jn, up + jj)))
            tris.append(np.column_stack((lo + jj, lo + jn, up + jn)))
    return np.vstack(tris).astype(np.int64)


def orient_outward(nodes, triangles, centres):
    """Flip triangles so their normals point away from the ring centres of their nodes
    (``centres`` (n, 3): the centerline point of each node's ring)."""
    triangles = triangles.copy()
    p = nodes[triangles]
    normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    radial = p.mean(axis=1) - centres[triangles].mean(axis=1)
    flip = np.einsum("ij,ij->i", normal, radial) < 0.0
    triangles[flip] = triangles[flip][:, [0, 2, 1]]
    return triangles


def _edge_groups(triangles):
    """The directed edges of ``triangles`` grouped by the edge they run along: ``(tail, head,
    opp, order, starts, counts)``, the directed edges (one per triangle side, the opposite node of
    each), the order that sorts them by undirected edge, and where each edge's group starts in
    that order and how many directed edges it holds (1 on a boundary, 2 inside a manifold)."""
    tri = np.ascontiguousarray(triangles, dtype=np.int64)
    if tri.ndim != 2 or tri.shape[1] != 3:
        raise ColonsimError(f"triangles must be an (nt, 3) array, got shape {tri.shape}; fix the mesh.")
    tail = tri[:, [0, 1, 2]].ravel()
    head = tri[:, [1, 2, 0]].ravel()
    opp = tri[:, [2, 0, 1]].ravel()
    n = int(tri.max()) + 1 if len(tri) else 0
    key = np.minimum(tail, head) * n + np.maximum(tail, head)
    order = np.argsort(key, kind="stable")
    key_sorted = key[order]
    starts = np.flatnonzero(np.r_[True, key_sorted[1:] != key_sorted[:-1]])
    counts = np.diff(np.r_[starts, len(key_sorted)])
    return tail, head, opp, order, starts, counts


def boundary_loops(triangles):
    """The open ends of a triangle mesh: its boundary edges (the edges of one triangle) as
    ``(k, 2)`` node pairs in their triangle's direction, and for each the index of the boundary
    loop (the connected chain of boundary edges) it lies on, from 0 (a tube: its two ends)."""
    tail, head, _, order, starts, counts = _edge_groups(triangles)
    one = order[starts[counts == 1]]
    edges = np.column_stack((tail[one], head[one]))
    if not len(edges):
        return edges, np.zeros(0, dtype=np.int64)
    n = int(edges.max()) + 1
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    _, component = connected_components(graph, directed=False)
    _, loop = np.unique(component[edges[:, 0]], return_inverse=True)
    return edges, loop.ravel()


def hinges(triangles):
    """Interior edges with their two opposite nodes.

    Parameters
    ----------
    triangles : (nt, 3) int array
        Consistently oriented manifold triangle mesh.

    Returns
    -------
    (nh, 4) int64
        ``[a, b, c, d]``: the edge ``a-b``, ``c`` opposite in the triangle that runs ``a -> b``
        (ordered ``(a, b, c)``), ``d`` opposite in the triangle that runs ``b -> a``.

    Raises
    ------
    ColonsimError
        An edge shared by more than two triangles, or two triangles with opposite orientation.
    """
    tail, head, opp, order, starts, counts = _edge_groups(triangles)
    n = int(max(tail.max(), head.max())) + 1 if len(tail) else 0
    key_sorted = (np.minimum(tail, head) * n + np.maximum(tail, head))[order]
    if np.any(counts > 2):
        bad = key_sorted[starts[counts > 2][0]]
        raise ColonsimError(
            f"edge ({bad // n}, {bad % n}) is shared by more than two triangles; "
            "the wall mesh must be a manifold surface."
        )
    pair = starts[counts == 2]
    first = order[pair]
    second = order[pair + 1]
    if np.any(tail[first] != head[second]):
        e = first[tail[first] != head[second]][0]
        raise ColonsimError(
            f"triangles around edge ({tail[e]}, {head[e]}) have opposite orientation; "
            "orient all triangles consistently."
        )
    return np.column_stack((tail[first], head[first], opp[first], opp[second])).astype(np.int64)
