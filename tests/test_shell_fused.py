"""The fused internal-force kernel equals the separate membrane and hinge kernels, and the
Cephes arctangent used by the hinges equals math.atan2 to a few ulps."""

import math

import numpy as np
import pytest

from shell_reference import bending_forces, membrane_forces

from colonsim.errors import ColonsimError
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH, load_material
from colonsim.insertion.engine.sheet_mesh import straight_tube
from colonsim.insertion.engine.shell import Shell
from colonsim.insertion.engine.shell_hinges import fast_atan2

MATERIAL = load_material(REFERENCE_MATERIAL_PATH)


@pytest.fixture(scope="module")
def deformed_tube():
    """A short tube inflated by 3 % with 0.3 mm random node noise (h = 3 mm): stretches of a
    few percent and hinge angles up to ~0.3 rad, so every term of both kernels is exercised."""
    nodes, tri, _ = straight_tube(0.03, 0.036, 0.003)
    tube = Shell(nodes, tri, 0.002, MATERIAL, density=1040.0)
    rng = np.random.default_rng(3)
    x = np.ascontiguousarray(nodes * [1.0, 1.03, 1.03] + 3e-4 * rng.standard_normal(nodes.shape))
    return tube, x


def _fused_equals_separate(tube, x):
    """Same sums in a different order: equal to 1e-12 of the largest nodal force and of the
    energy (round-off is ~1e-16 per term, a node sums ~20 terms)."""
    f_sep = np.zeros_like(x)
    e_sep = membrane_forces(tube, x, f_sep) + bending_forces(tube, x, f_sep)
    f_fused = np.full_like(x, 0.5)  # forces are added to what f holds
    e_fused = tube.internal_forces(x, f_fused)
    assert e_fused == pytest.approx(e_sep, rel=1e-12)
    assert np.abs(f_fused - 0.5 - f_sep).max() <= 1e-12 * np.abs(f_sep).max()


def test_fused_forces_equal_separate_kernels_on_one_thread(deformed_tube, serial_kernels):
    _fused_equals_separate(*deformed_tube)


def test_fused_forces_equal_separate_kernels_on_two_threads(deformed_tube, two_threads):
    # two threads: the kernel adds into one force array per thread, summed afterwards
    if two_threads:
        _fused_equals_separate(*deformed_tube)


def test_fused_forces_raise_on_collapsed_triangle(deformed_tube):
    tube, x = deformed_tube
    x = x.copy()
    x[tube.triangles[5]] = x[tube.triangles[5, 0]]  # det C = 0 exactly
    with pytest.raises(ColonsimError, match="inverted or collapsed"):
        tube.internal_forces(x, np.zeros_like(x))


def test_fused_forces_raise_on_nan_position(deformed_tube):
    """A NaN position fails the hinges' area check (NaN > 0 is False): reported, not propagated."""
    tube, x = deformed_tube
    x = x.copy()
    x[tube.hinges[7, 3]] = np.nan
    with pytest.raises(ColonsimError, match="collapsed triangle"):
        tube.internal_forces(x, np.zeros_like(x))


def test_atan2_matches_libm():
    """Within 2 ulps of math.atan2 in all four quadrants, on the axes and for tiny/huge ratios
    (Cephes atan is accurate to ~1 ulp; the pi shift of the left half-plane adds half an ulp)."""
    rng = np.random.default_rng(0)
    angles = np.r_[rng.uniform(-np.pi, np.pi, 20000), np.linspace(-np.pi, np.pi, 17)]
    radii = 10.0 ** rng.uniform(-8, 8, angles.size)
    ys = radii * np.sin(angles)
    xs = radii * np.cos(angles)
    ys = np.r_[ys, 1e-300, -1e-300, 1.0, -1.0, 0.0, 1.0, -1.0]
    xs = np.r_[xs, 1.0, -1.0, 1e-300, 1e-300, 1.0, 0.0, 0.0]
    for y, x in zip(ys, xs):
        ref = math.atan2(y, x)
        assert abs(fast_atan2(y, x) - ref) <= 2 * np.spacing(abs(ref)) + 1e-320, (y, x)
    assert math.isnan(fast_atan2(math.nan, 1.0)) and math.isnan(fast_atan2(1.0, math.nan))
