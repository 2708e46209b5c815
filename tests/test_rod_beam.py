"""Rod properties: section, time step, tangent stiffness. The rod against beam theory
(cantilever, Euler load, axial waves) is checked by the verification table
(tests/test_verification_table.py)."""

import math

import numpy as np
import pytest

from colonsim.insertion.engine.rod import Rod
from colonsim.insertion.study.verification import SCOPE_D, SCOPE_E, SCOPE_RHO
from colonsim.insertion.study.verification_rod import cantilever, compressed_min_eigenvalue, euler_load

E, RHO, D = SCOPE_E, SCOPE_RHO, SCOPE_D  # the standard scope (catalogue diameter)


def test_compressed_rod_is_stable_at_half_the_euler_load():
    # The Euler check (verification table) finds where the tangent stiffness of the straight
    # compressed rod first loses positive definiteness; its root bracket starts at half the load,
    # where the rod must still be stable. The rod's hinge at the first free node owns the half
    # cell behind it, so the clamp is at the middle of the first segment (x = h/2).
    rod = cantilever(0.3, 0.01)
    assert compressed_min_eigenvalue(rod, 0.5 * euler_load(rod, 0.3)) > 0.0
    assert rod.x0[rod.tip_node, 0] == pytest.approx(0.3, rel=1e-12) and rod.x0[1, 0] == -rod.x0[0, 0]


def test_hollow_section_properties():
    # Annulus: A = pi (D^2 - d^2) / 4, I = pi (D^4 - d^4) / 64; lumped masses sum to rho A L.
    rod = Rod.straight(0.5, D, E, RHO, spacing=5e-3, inner_diameter=4e-3)
    assert rod.area == pytest.approx(math.pi / 4 * (D**2 - 4e-3**2), rel=1e-14)
    assert rod.second_moment == pytest.approx(math.pi / 64 * (D**4 - 4e-3**4), rel=1e-14)
    assert rod.mass.sum() == pytest.approx(RHO * rod.area * 0.5, rel=1e-12)
    assert rod.radius == 0.5 * D and rod.tip_node == rod.n_nodes - 1


def test_highest_frequency_sets_the_time_step():
    # A free straight rod's highest modes are the lattice limits: bending 4 sqrt(EI / rho A) / h^2
    # (the [1, -4, 6, -4, 1] stencil) and axial 2 c / h (the alternating mode, exact for a free
    # chain). Tolerance 0.5 %: a finite chain's top bending mode sits ~(pi / n)^2 below the limit.
    # The Gershgorin bound must lie above; the stable step is 2 / omega_max.
    c = math.sqrt(E / RHO)
    for h in (5e-3, 2e-2):
        rod = Rod.straight(0.3, D, E, RHO, spacing=h)
        r_g = math.sqrt(rod.second_moment / rod.area)
        lattice = max(2.0 * c / h, 4.0 * r_g * c / h**2)
        omega = rod.max_frequency(rod.x0)
        assert omega == pytest.approx(lattice, rel=0.005)
        assert rod.frequency_bound(rod.x0) >= omega
        assert rod.critical_time_step(rod.x0) == pytest.approx(2.0 / omega, rel=1e-12)


def test_banded_frequency_matches_dense_eigensolver_on_a_bent_rod():
    # Random bent, stretched rod: the banded colouring must rebuild the full tangent stiffness;
    # the dense eigenvalue of the finite-difference Hessian agrees to 1e-6 (difference noise).
    rng = np.random.default_rng(0)
    nodes = np.cumsum(rng.normal(size=(20, 3)) * 0.003 + np.array([0.005, 0.0, 0.0]), axis=0)
    rod = Rod(nodes, D, E, RHO)
    x = np.ascontiguousarray(nodes + rng.normal(size=nodes.shape) * 5e-4)
    n = 3 * len(x)
    k = np.zeros((n, n))
    eps = 1e-8
    for j in range(n):
        xp = x.copy()
        xm = x.copy()
        xp.flat[j] += eps
        xm.flat[j] -= eps
        fp = np.zeros_like(x)
        fm = np.zeros_like(x)
        rod.internal_forces(xp, fp)
        rod.internal_forces(xm, fm)
        k[:, j] = -(fp - fm).ravel() / (2 * eps)
    d = np.repeat(1.0 / np.sqrt(rod.mass), 3)
    dense = math.sqrt(np.linalg.eigvalsh(0.5 * (k + k.T) * d[:, None] * d[None, :]).max())
    assert rod.max_frequency(x) == pytest.approx(dense, rel=1e-6)
    assert rod.frequency_bound(x) >= dense
