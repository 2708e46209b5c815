"""The blocked internal-force kernels (one per wall law) give the element-by-element kernel's forces
and energies on a randomly deformed mesh, for every wall law, on one and two threads, with held
elements left out."""

import numpy as np
import pytest

from colonsim.errors import ColonsimError
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH, WallMaterial, load_material
from colonsim.insertion.engine.sheet_mesh import straight_tube
from colonsim.insertion.engine.shell import Shell
from colonsim.insertion.engine.shell_forces import BLOCK

# one material of each branch of the kernels (the reference file's law is Mooney-Rivlin's three-term)
MATERIALS = {
    "reference": load_material(REFERENCE_MATERIAL_PATH),
    "mooney_rivlin_2": WallMaterial("mooney_rivlin_2", (2.0e3, 1.0e3)),
    "neo_hookean": WallMaterial("neo_hookean", (3.0e3,)),
    "yeoh": WallMaterial("yeoh", (2.0e3, 5.0e3, 1.0e4)),
    "ogden_3": WallMaterial("ogden_3", (1.0e3, 2.0, 2.0e3, 10.0, -1.0e3, -2.0)),
}


def deformed_tube(material):
    """A short tube inflated by 3 % with 0.3 mm random node noise (h = 3 mm): stretches of a few
    percent and hinge angles up to ~0.3 rad."""
    nodes, tri, ring = straight_tube(0.03, 0.036, 0.003)
    tube = Shell(nodes, tri, 0.002, material, density=1040.0)
    rng = np.random.default_rng(7)
    x = np.ascontiguousarray(nodes * [1.0, 1.03, 1.03] + 3e-4 * rng.standard_normal(nodes.shape))
    return tube, x, ring


def forces(tube, x, kernel):
    """(forces added onto ones, energy) of the tube's internal forces through ``kernel``."""
    tube.force_kernel = kernel
    f = np.ones_like(x)  # the kernels add to what f holds
    energy = tube.internal_forces(x, f)
    return f - 1.0, energy


def assert_same_forces(tube, x):
    f_old, e_old = forces(tube, x, "elementwise")
    f_new, e_new = forces(tube, x, "blocked")
    assert np.abs(f_old).max() > 0.0 and e_old > 0.0
    assert np.abs(f_new - f_old).max() <= 1e-12 * np.abs(f_old).max()
    assert e_new == pytest.approx(e_old, rel=1e-12, abs=0.0)


@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_blocked_forces_equal_elementwise_on_one_thread(name, serial_kernels):
    tube, x, _ = deformed_tube(MATERIALS[name])
    # a last, partial block of triangles and of hinges is exercised
    assert len(tube.triangles) % BLOCK and len(tube.hinges) % BLOCK and len(tube.triangles) > 3 * BLOCK
    assert_same_forces(tube, x)


def test_blocked_forces_equal_elementwise_on_two_threads(two_threads):
    # two threads: one force array per thread over contiguous chunks of the elements, summed afterwards
    if two_threads:
        assert_same_forces(*deformed_tube(MATERIALS["reference"])[:2])


def test_blocked_forces_equal_elementwise_with_held_elements(serial_kernels):
    tube, x, ring = deformed_tube(MATERIALS["reference"])
    tube.hold(ring <= 2)  # the elements all of whose nodes lie in the first three rings drop out
    assert len(tube._active[0]) < len(tube.triangles)
    assert_same_forces(tube, x)


def test_blocked_forces_see_a_perturbation(serial_kernels):
    """The comparison can fail: moving one node changes the blocked forces well beyond 1e-12."""
    tube, x, _ = deformed_tube(MATERIALS["reference"])
    f_old, _ = forces(tube, x, "elementwise")
    x = x.copy()
    x[tube.triangles[100, 0], 0] += 1e-6
    f_new, _ = forces(tube, x, "blocked")
    assert np.abs(f_new - f_old).max() > 1e-6 * np.abs(f_old).max()


def test_blocked_forces_raise_on_collapsed_elements(serial_kernels):
    tube, x, _ = deformed_tube(MATERIALS["reference"])
    collapsed = x.copy()
    collapsed[tube.triangles[5]] = collapsed[tube.triangles[5, 0]]  # det C = 0 exactly
    with pytest.raises(ColonsimError, match="inverted or collapsed"):
        forces(tube, collapsed, "blocked")
    nan = x.copy()
    nan[tube.hinges[7, 3]] = np.nan  # fails the hinges' area check
    with pytest.raises(ColonsimError, match="collapsed triangle"):
        forces(tube, nan, "blocked")


def test_unknown_force_kernel_is_one_line(serial_kernels):
    tube, x, _ = deformed_tube(MATERIALS["reference"])
    with pytest.raises(ColonsimError, match="use 'blocked' or 'elementwise'"):
        forces(tube, x, "vectorised")


def test_a_law_index_without_a_blocked_kernel_is_refused(serial_kernels):
    tube, x, _ = deformed_tube(MATERIALS["reference"])
    tube._law = 99  # each law has a blocked kernel of its own (shell_forces.BLOCKED_KERNELS)
    with pytest.raises(ValueError, match="no wall law has the index 99"):
        forces(tube, x, "blocked")
