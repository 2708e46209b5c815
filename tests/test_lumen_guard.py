"""The check that the scope is still inside the colon (insertion/case/lumen_guard.py).

The depth beyond the wall against the tube's closed form, a scope placed outside flagged and one
inside not, a tube's two open ends and a sheet's one, the wall closed over its ends enclosing the
lumen and nothing else, a scope inside that a misleading wall normal puts outside not stopped, and
a thin scope on a coarse wall mesh that really slips out through the wall: the run stops with the
fix instead of reporting the displaced wall as colon deformation.
"""

import numpy as np
import pytest

from colonsim.errors import ColonsimError
from colonsim.insertion.case.lumen_guard import (OUTSIDE_MARGIN, check_scope_inside, closed_surface,
                                                 depth_outside_wall, winding_number)
from colonsim.insertion.case.scenario import InsertionCase, build_insertion, run_insertion
from colonsim.insertion.engine.sheet_mesh import boundary_loops, flat_sheet, straight_tube

D_MM, T_MM = 36.0, 2.0


@pytest.fixture(scope="module")
def straight():
    return build_insertion(InsertionCase(segment="straight", scope="9.2", diameter_mm=D_MM, wall_thickness_mm=T_MM,
                                         element_size_mm=3.0))


def test_depth_beyond_the_wall_is_the_radial_distance_past_its_outer_surface(straight):
    shell = straight.shell
    x = shell.x0
    normals = shell.node_normals(x)
    middle = np.flatnonzero(np.abs(x[:, 0] - 0.5 * x[:, 0].max()) < 2e-3)[:4]  # nodes away from the tube's ends
    radial = x[middle] - np.c_[x[middle, 0], np.zeros((len(middle), 2))]
    radial /= np.linalg.norm(radial, axis=1)[:, None]
    outer = 0.5 * D_MM * 1e-3 + T_MM * 1e-3  # the mesh is the mid-surface at (D + t) / 2
    for rho in (0.0, 0.010, 0.5 * D_MM * 1e-3, outer + 0.004):  # axis, lumen, the lumen's surface, outside
        points = np.c_[x[middle, 0], np.zeros((len(middle), 2))] + rho * radial
        depth = depth_outside_wall(points, x, normals, 0.5 * T_MM * 1e-3)
        # exact on a node's own ray up to the normal's tilt on the polygon (cos(pi/m) ~ 1 - 1e-3)
        np.testing.assert_allclose(depth, rho - outer, atol=2e-5)


def test_a_scope_outside_the_tube_is_flagged_and_one_inside_is_not(straight):
    scope = straight.solver.state[straight.rod.name].x
    check_scope_inside(straight, 0.0)  # straight in its sheath on the axis: inside
    inside = scope.copy()
    outer = 0.5 * D_MM * 1e-3 + T_MM * 1e-3
    radius = straight.rod.radius
    scope[-1] = [0.10, outer + 0.5 * OUTSIDE_MARGIN * radius, 0.0]  # half the margin beyond: not yet
    check_scope_inside(straight, 0.05)
    scope[0] = [-0.02, outer + 3.0 * radius, 0.0]  # behind the entry plane: the sheath's part, not measured
    check_scope_inside(straight, 0.05)
    scope[-1] = [0.10, outer + 1.5 * OUTSIDE_MARGIN * radius, 0.0]  # the tip's whole section outside
    with pytest.raises(ColonsimError, match=r"left the colon through its wall 5\.0 cm into the push.*finer --element-size"):
        check_scope_inside(straight, 0.05)
    scope[:] = inside


def test_a_tube_has_two_open_ends_and_a_sheet_one():
    nodes, triangles, ring = straight_tube(0.1, 0.038, 6e-3)
    edges, loop = boundary_loops(triangles)
    assert loop.max() == 1
    ends = {frozenset(np.flatnonzero(ring == end).tolist()) for end in (0, ring.max())}
    assert {frozenset(edges[loop == i].ravel().tolist()) for i in (0, 1)} == ends  # each loop an end ring
    for i in (0, 1):  # a closed chain: every node a tail once and a head once
        assert np.array_equal(np.sort(edges[loop == i][:, 0]), np.sort(edges[loop == i][:, 1]))
    _, sheet = flat_sheet(0.1, 0.05, 5e-3)
    assert boundary_loops(sheet)[1].max() == 0


def test_the_wall_closed_over_its_open_ends_encloses_the_lumen_and_nothing_else(straight):
    x, triangles = straight.shell.x0, straight.shell.triangles
    points, closed = closed_surface(x, triangles, boundary_loops(triangles))
    assert len(points) == len(x) + 2  # one centroid per open end
    length = x[:, 0].max() - x[:, 0].min()
    outer = 0.5 * D_MM * 1e-3 + T_MM * 1e-3
    for p in ([0.5 * length, 0.0, 0.0], [2e-3, 0.0, 0.0], [length - 2e-3, 0.01, 0.0],  # lumen, by either end
              [0.5 * length, 0.5 * D_MM * 1e-3 - 1e-3, 0.0]):  # near the wall
        assert winding_number(np.array(p), points, closed) == pytest.approx(1.0, abs=1e-6)
    for p in ([0.5 * length, outer + 5e-3, 0.0], [-0.01, 0.0, 0.0], [length + 0.01, 0.0, 0.0]):  # outside, beyond the ends
        assert winding_number(np.array(p), points, closed) == pytest.approx(0.0, abs=1e-6)


def test_a_misleading_wall_normal_does_not_stop_a_scope_inside_the_lumen(straight, monkeypatch):
    # a wall folded hard against itself can give the node nearest a scope node a normal that
    # points at the scope (a THF loop, 13 mm scope in a 29 mm colon): every node's normal reversed
    # puts the scope on the axis beyond the wall by the nearest-node test, but the wall encloses it
    shell = straight.shell
    normals = shell.node_normals(shell.x0)
    monkeypatch.setattr(shell, "node_normals", lambda x: -normals)
    scope = straight.solver.state[straight.rod.name].x
    tip = scope[-1:]
    assert depth_outside_wall(tip, shell.x0, -normals, 0.5 * T_MM * 1e-3)[0] > OUTSIDE_MARGIN * straight.rod.radius
    check_scope_inside(straight, 0.05)  # no error: the winding number says inside


@pytest.mark.slow
def test_a_thin_scope_slipping_out_through_a_coarse_wall_stops_the_run():
    # RSF alpha 45 on the 7.5 mm wall: the 9.2 mm scope goes on straight through the wall at the
    # rectum-sigmoid bend (its tip ~8 cm in); without the check the run ended by wall stretch with
    # the displaced wall reported as 2 cm of colon deformation
    case = InsertionCase(segment="rsf", scope="9.2", angle_deg=45.0, element_size_mm=7.5)
    with pytest.raises(ColonsimError, match=r"the 7\.5 mm wall mesh is too coarse for a 9\.2 mm scope"):
        run_insertion(case)
