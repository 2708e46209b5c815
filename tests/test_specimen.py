"""The scikit-fem specimen model (docs/model.md): tangents, load stepping, bad input. The uniaxial
closed form, the grips and the mesh convergence are rows of the verification table
(tests/test_verification_table.py)."""

import numpy as np
import pytest

from colonsim.errors import ColonsimError
from colonsim.laws import get_law, get_wall_law
from colonsim.identification.membrane import membrane_stress
from colonsim.identification.specimen import ClampedStripModel, FEConvergenceError
from colonsim.identification.verification import DISPLACEMENTS, REFERENCE, STRIP

L, W, T = STRIP
D = DISPLACEMENTS  # up to 60 % strain, the end of the test


OGDEN_3 = (20e3, 2.0, 2e3, 10.0, -10e3, -2.0)
# a scaled rotation: equal stretches, where Ogden's flip stiffness takes its limit
EQUAL = np.array([[1.2 * np.cos(0.3), -1.2 * np.sin(0.3), 1.2 * np.sin(0.3), 1.2 * np.cos(0.3)]])


@pytest.mark.parametrize("law,params", [("mooney_rivlin_3", REFERENCE), ("yeoh", (1e4, 5e4, 2e4)),
                                        ("ogden_3", OGDEN_3), ("ogden_1", (2e4, 9.0))])
def test_membrane_tangent_matches_finite_differences(law, params):
    rng = np.random.default_rng(3)
    F = np.vstack([np.array([1.3, 0.1, -0.05, 0.85]) + 0.05 * rng.standard_normal((5, 4)), EQUAL])
    model = get_wall_law(law)
    P, A = membrane_stress(F, model, params)
    h = 1e-6
    for k in range(4):
        e = np.zeros(4)
        e[k] = h
        numeric = (membrane_stress(F + e, model, params, False) - membrane_stress(F - e, model, params, False)) / (2 * h)
        # central differences: error O(h^2 |P'''|) ~ 1e-10 relative; 1e-6 leaves room for round-off
        np.testing.assert_allclose(A[:, :, k], numeric, rtol=1e-6, atol=1e-6 * np.abs(A).max())


@pytest.mark.parametrize("ogden, params, invariant, same", [
    ("ogden_1", (86e3, 2.0), "neo_hookean", (43e3,)),
    ("ogden_2", (30e3, 2.0, -56e3, -2.0), "mooney_rivlin_2", (15e3, 28e3))])
def test_ogden_membrane_contains_the_invariant_laws(ogden, params, invariant, same):
    """Ogden's singular-value branch: stress and tangent of alpha = 2 (and -2) equal the neo-Hookean
    (two-parameter Mooney-Rivlin) law's to round-off, at equal stretches too; its stress is the
    derivative of its energy."""
    rng = np.random.default_rng(4)
    F = np.vstack([np.array([1.3, 0.1, -0.05, 0.85]) + 0.1 * rng.standard_normal((6, 4)), EQUAL, [[1.0, 0, 0, 1.0]]])
    P, A = membrane_stress(F, get_wall_law(ogden), params)
    P0, A0 = membrane_stress(F, get_law(invariant), same)
    assert np.abs(P - P0).max() < 1e-12 * np.abs(P0).max() and np.abs(A - A0).max() < 1e-12 * np.abs(A0).max()
    law, h = get_wall_law("ogden_3"), 1e-6

    def energy(G):
        stretches = np.linalg.svd(G.reshape(-1, 2, 2), compute_uv=False)
        return law.principal(stretches[:, 0], stretches[:, 1], OGDEN_3)[0]

    numeric = np.stack([(energy(F + h * e) - energy(F - h * e)) / (2 * h) for e in np.eye(4)], axis=-1)
    P3 = membrane_stress(F, law, OGDEN_3, False)
    np.testing.assert_allclose(P3, numeric, rtol=0, atol=1e-7 * np.abs(P3).max())


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
