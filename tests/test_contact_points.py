"""Where the contact samples the wall (insertion/engine/contact_points.py): the points on the
faces stand for the wall's area as the nodes do, and the nodes' contact is the contact of before."""

import numpy as np
import pytest

from colonsim.errors import ColonsimError
from colonsim.insertion.engine.contact_kernel import point_held
from colonsim.insertion.engine.contact_points import face_points, node_points, subdivision_centroids
from colonsim.insertion.engine.sheet_mesh import flat_sheet


@pytest.mark.parametrize("L", [1, 2, 3, 5])
def test_subdivision_centroids_sample_the_triangle_evenly(L):
    b = subdivision_centroids(L)
    assert b.shape == (L * L, 3)
    assert np.allclose(b.sum(axis=1), 1.0) and np.all(b > 0.0)
    # equal areas: their mean is the centroid, and a coordinate's mean square over the triangle
    # (1/6) is that of the centroids plus what each sub-triangle holds about its own centroid (the
    # triangle's variance 1/6 - 1/9, scaled by 1 / L^2)
    assert np.allclose(b.mean(axis=0), 1.0 / 3.0)
    exact = 1.0 / 6.0
    own = (1.0 / 6.0 - 1.0 / 9.0) / L**2
    assert np.allclose((b**2).mean(axis=0) + own, exact)
    assert len({tuple(np.round(p, 12)) for p in b}) == L * L


def test_face_points_carry_the_wall_like_its_nodes():
    nodes, tri = flat_sheet(0.03, 0.02, 3e-3)
    normals = np.tile((0.0, 0.0, -1.0), (len(nodes), 1))
    pts = face_points(nodes, tri, 2, normals)
    assert len(pts) == 4 * len(tri)
    assert np.allclose(pts.weights.sum(axis=1), 1.0)
    edge = np.minimum(np.minimum(nodes[:, 0], 0.03 - nodes[:, 0]), np.minimum(nodes[:, 1], 0.02 - nodes[:, 1]))
    # a uniformly pressed node takes one node's penalty (the time-step bound reads this) away from
    # the wall's edge; next to it more, as a node there takes a whole node's on less area
    assert np.allclose(pts.node_share[edge > 6e-3], 1.0)
    assert np.all((pts.node_share > 0.99) | (edge < 1e-9)) and pts.node_share.max() < 1.5
    # the shares add up to the wall's area in nodes' areas: as many as there are nodes, edges aside
    area = 0.5 * np.linalg.norm(np.cross(nodes[tri[:, 1]] - nodes[tri[:, 0]], nodes[tri[:, 2]] - nodes[tri[:, 0]]), axis=1)
    assert pts.share.sum() == pytest.approx(pts.node_share.sum())
    assert np.all(pts.share > 0.0) and area.sum() > 0.0
    assert np.allclose(pts.held_normal, (0.0, 0.0, -1.0))
    x = nodes + 1e-3
    assert np.allclose(pts.positions(x), np.einsum("pk,pkd->pd", pts.weights, x[pts.nodes]))


def test_node_points_are_the_nodes():
    nodes, _ = flat_sheet(0.01, 0.01, 3e-3)
    pts = node_points(len(nodes), np.zeros_like(nodes))
    assert pts.positions(nodes) is nodes  # the node contact reads the state itself
    assert np.all(pts.weights == 1.0) and np.all(pts.share == 1.0) and np.all(pts.node_share == 1.0)


@pytest.mark.parametrize("bad", [0, 9, 2.0, "2", True])
def test_a_bad_subdivision_is_one_line(bad):
    nodes, tri = flat_sheet(0.01, 0.01, 3e-3)
    with pytest.raises(ColonsimError, match="must be a whole number from 1 to 8"):
        face_points(nodes, tri, bad, np.zeros_like(nodes))


@pytest.mark.parametrize("held_nodes, held_points", [
    ((), set()),
    ((0,), {"corner 0"}),  # weight 2/3 on node 0; the others carry 1/6 or 1/3 of it
    ((0, 1), {"corner 0", "corner 1", "middle"}),  # 5/6, 5/6 and 2/3; corner 2 only 1/3
    ((0, 1, 2), {"corner 0", "corner 1", "corner 2", "middle"}),
])
def test_a_face_point_is_held_when_held_nodes_carry_half_its_weight(held_nodes, held_points):
    """The seam between the fixed and the mobile wall (docs/model.md, "Contact"): the points
    nearer the held nodes are the rigid wall's, as the held nodes are in the node contact (the
    rule before c15e92d, every node held, would leave all four free until the third is held)."""
    nodes = np.array([[0.0, 0.0, 0.0], [3e-3, 0.0, 0.0], [0.0, 3e-3, 0.0]])
    pts = face_points(nodes, np.array([[0, 1, 2]]), 2, np.tile((0.0, 0.0, -1.0), (3, 1)))
    fixed = np.zeros(3, dtype=np.uint8)
    fixed[list(held_nodes)] = 1
    names = {}
    for q in range(len(pts)):
        w = dict(zip(pts.nodes[q], pts.weights[q]))
        heaviest = max(w, key=w.get)
        names[q] = "middle" if np.isclose(max(w.values()), 1.0 / 3.0) else f"corner {heaviest}"
    assert sorted(names.values()) == ["corner 0", "corner 1", "corner 2", "middle"]
    held = {names[q] for q in range(len(pts)) if point_held(fixed, pts.nodes, pts.weights, q)}
    assert held == held_points


def test_a_node_point_is_held_when_its_node_is():
    pts = node_points(4, np.zeros((4, 3)))
    fixed = np.array([0, 1, 0, 1], dtype=np.uint8)
    assert [point_held(fixed, pts.nodes, pts.weights, q) for q in range(4)] == [False, True, False, True]
