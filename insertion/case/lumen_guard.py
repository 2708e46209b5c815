"""Has the scope left the colon through its wall? (docs/model.md, "Contact")

The contact holds the scope back from the wall's nodes, not from its faces: a scope thin next to
the wall's elements, pushed hard against a stretched wall, can slip between three nodes and go on
outside the colon. Nothing in the contact then notices (the nodes it passed are behind it), and
the run would go on reporting the displaced wall as colon deformation. This module recognises
that state from the geometry alone, so a run can stop with the fix instead of results.

The test: each scope node, measured from its nearest wall node along that node's outward normal
(the deformed wall's, area-weighted over its triangles; tube meshes are oriented out of the
lumen). Inside the colon the scope's axis lies at least its radius plus half the wall thickness
inside the wall (the contact's gap, less a penetration of a fraction of a millimetre). A scope
whose axis lies more than :data:`OUTSIDE_MARGIN` scope radii beyond the wall's mid-surface plus
half its thickness is outside: its whole cross-section is beyond the wall's outer surface, which
no contact state reaches (a margin of one radius on top of the geometry leaves room for the
nearest node's normal being tilted on a coarse or folded wall). Only the scope nodes past the
entry plane are measured: those behind it are in the sheath, outside the model by design (the
proximal end lies a scope's length back, where the nearest wall may well face it).

The nearest node's normal can mislead where the wall is folded hard against itself (a THF loop
pressing a 13 mm scope into a 29 mm colon: the node nearest a scope node inside the lumen had a
normal pointing at the scope, and the test put the scope 6.5 mm beyond the wall). So a scope node
the test puts outside is outside only if the wall, closed over its open ends, does not enclose
it: its winding number with respect to that closed surface (the solid angle its triangles
subtend, over 4 pi) is 1 inside and 0 outside, whatever the folds, and is taken at below 1/2.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from colonsim.errors import ColonsimError

OUTSIDE_MARGIN = 1.0  # scope radii beyond the wall's outer surface: the scope's axis is then outside the colon


def depth_outside_wall(scope_x, wall_x, wall_normals, half_thickness):
    """How far each scope node lies beyond the wall's outer surface, m (negative: inside the lumen
    or the wall), measured from its nearest wall node along that node's outward normal.

    Parameters
    ----------
    scope_x : (k, 3) scope node positions, m.
    wall_x, wall_normals : (n, 3) wall node positions (mid-surface), m, and unit outward normals.
    half_thickness : float, m.
    """
    _, nearest = cKDTree(wall_x).query(scope_x)
    return np.einsum("ij,ij->i", scope_x - wall_x[nearest], wall_normals[nearest]) - half_thickness


def closed_surface(x, triangles, open_ends):
    """The surface ``triangles`` at positions ``x`` closed over each of its open ends: every
    boundary edge joined to the centroid of its boundary loop, in the orientation that continues
    its triangle's. ``open_ends``: the boundary edges and the loop of each
    (:func:`colonsim.insertion.engine.sheet_mesh.boundary_loops`). Returns (points, triangles) with
    the centroids appended to ``x``."""
    boundary, loop = open_ends
    if not len(boundary):
        return x, triangles
    centroids = np.array([x[np.unique(boundary[loop == i])].mean(axis=0) for i in range(int(loop.max()) + 1)])
    caps = np.c_[boundary[:, 1], boundary[:, 0], len(x) + loop]
    return np.vstack([x, centroids]), np.vstack([triangles, caps])


def winding_number(point, x, triangles):
    """The winding number of the closed, outward-oriented surface ``triangles`` (at ``x``) about
    ``point``: the solid angle its triangles subtend there over 4 pi (Van Oosterom and Strackee's
    formula), 1 inside and 0 outside."""
    a, b, c = (x[triangles[:, i]] - point for i in range(3))
    la, lb, lc = (np.linalg.norm(v, axis=1) for v in (a, b, c))
    det = np.einsum("ij,ij->i", a, np.cross(b, c))
    dot = (la * lb * lc + np.einsum("ij,ij->i", a, b) * lc + np.einsum("ij,ij->i", b, c) * la
           + np.einsum("ij,ij->i", c, a) * lb)
    return float(np.sum(2.0 * np.arctan2(det, dot)) / (4.0 * np.pi))


def check_scope_inside(model, depth_m):
    """Raise :class:`ColonsimError` when the scope of the built insertion ``model`` has left the
    colon through its wall (see the module docstring); ``depth_m`` is the push so far, for the
    message."""
    wall_x = model.solver.state["colon"].x
    scope_x = model.solver.state[model.rod.name].x
    inserted = np.flatnonzero((scope_x - model.entry_point) @ model.entry_axis > 0.0)
    if not inserted.size:
        return
    outside = depth_outside_wall(scope_x[inserted], wall_x, model.shell.node_normals(wall_x),
                                 0.5 * model.shell.thickness)
    flagged = np.flatnonzero(outside > OUTSIDE_MARGIN * model.rod.radius)
    if not flagged.size:
        return
    points, triangles = closed_surface(wall_x, model.shell.triangles, model.shell.open_ends())
    beyond = [j for j in flagged if winding_number(scope_x[inserted[j]], points, triangles) < 0.5]
    if beyond:  # the worst of the nodes the wall does not enclose
        k = max(beyond, key=lambda j: outside[j])
        case = model.case
        raise ColonsimError(
            f"the scope left the colon through its wall {depth_m * 100:.1f} cm into the push "
            f"(scope node {inserted[k]} is {outside[k] * 1e3:.1f} mm beyond the wall): the "
            f"{case.element_size_mm:g} mm wall mesh is too coarse for a {2e3 * model.rod.radius:.1f} mm scope; "
            "use a finer --element-size (the default is 3 mm)")
