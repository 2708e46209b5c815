"""The scikit-fem specimen model (docs/model.md): tangents, load stepping, bad input. The uniaxial
closed form, the grips and the mesh convergence are rows of the verification table
(tests/test_verification_table.py)."""

import numpy as np
import pytest

from colonsim.errors import ColonsimError
from colonsim.laws import get_law
from colonsim.identification.membrane import membrane_stress
from colonsim.identification.specimen import ClampedStripModel, FEConvergenceError
from colonsim.identification.verification import DISPLACEMENTS, REFERENCE, STRIP

L, W, T = STRIP
D = DISPLACEMENTS  # up to 60 % strain, the end of the test


@pytest.mark.parametrize("law,params", [("mooney_rivlin_3", REFERENCE), ("yeoh", (1e4, 5e4, 2e4))])
def test_membrane_tangent_matches_finite_differences(law, params):
    rng = np.random.default_rng(3)
    F = np.array([1.3, 0.1, -0.05, 0.85]) + 0.05 * rng.standard_normal((5, 4))
    P, A = membrane_stress(F, get_law(law), params)
    h = 1e-6
    for k in range(4):
        e = np.zeros(4)
        e[k] = h
        numeric = (membrane_stress(F + e, get_law(law), params, False) - membrane_stress(F - e, get_law(law), params, False)) / (2 * h)
        # central differences: error O(h^2 |P'''|) ~ 1e-10 relative; 1e-6 leaves room for round-off
        np.testing.assert_allclose(A[:, :, k], numeric, rtol=1e-6, atol=1e-6 * np.abs(A).max())


def test_force_at_each_displacement_independent_of_sampling():
    """Load stepping is an implementation detail: the force at 60 mm must not depend on it."""
    m = ClampedStripModel(L, W, T)
    one = m.solve(REFERENCE, [60e-3])
    many = m.solve(REFERENCE, np.linspace(1e-3, 60e-3, 20))
    assert one[0] == pytest.approx(many[-1], rel=1e-8)


def test_bad_geometry_and_unphysical_parameters():
    with pytest.raises(ColonsimError, match="thickness must be positive"):
        ClampedStripModel(L, W, 0.0)
    with pytest.raises(FEConvergenceError, match="shear modulus"):
        ClampedStripModel(L, W, T).solve([-1e4, 0.0, 0.0], D)


def test_assembled_tangent_matches_finite_differences_of_the_residual():
    """The global Newton matrix (free dofs) against central differences of the internal forces
    at a stretched, sheared state: O(h^2) truncation, 1e-6 relative leaves room for round-off."""
    m = ClampedStripModel(L, W, T, n_length=3, n_width=2)
    rng = np.random.default_rng(5)
    u = 3e-4 * rng.standard_normal(m.n_dofs)  # ~5 % strains on 8 mm elements, no inversion
    _, K = m._residual_tangent(u, REFERENCE)
    K = K.toarray()
    h = 1e-7
    free = m._free
    numeric = np.empty_like(K)
    for j, dof in enumerate(free):
        e = np.zeros(m.n_dofs)
        e[dof] = h
        numeric[:, j] = (m._residual_tangent(u + e, REFERENCE, False)[0][free]
                         - m._residual_tangent(u - e, REFERENCE, False)[0][free]) / (2 * h)
    np.testing.assert_allclose(K, numeric, rtol=1e-6, atol=1e-6 * np.abs(K).max())
