"""Rod against beam theory: cantilever tip deflection, Euler buckling, axial wave speed.

The problems are built and solved in :mod:`colonsim.insertion.study.verification` (which the validation report
also tabulates). The rod's hinge at the first free node owns the half cell behind it, so a rod
whose first two nodes are fixed is clamped at the middle of its first segment: the beam length is
measured from there (x = h/2) to the tip node.
"""

import math

import numpy as np
import pytest

from colonsim.insertion.engine.rod import Rod
from colonsim.insertion.study.verification import (SCOPE_D, SCOPE_E, SCOPE_RHO, axial_wave, cantilever, cantilever_tip_deflection,
                                    compressed_min_eigenvalue, euler_buckling_load, euler_load)

E, RHO, D = SCOPE_E, SCOPE_RHO, SCOPE_D  # the standard scope (catalogue diameter)


def test_cantilever_tip_load_matches_beam_theory():
    # Static deflection by dynamic relaxation (critical damping of the first mode).
    # Tolerance 1 %: the discrete moment-area sum is a midpoint rule, error ~ (h/L)^2/4 = 3e-4,
    # the relaxation residual is below 1e-4 after 16 time constants, and at delta/L = 0.5 % the
    # geometric nonlinearity is ~1e-5.
    c = cantilever_tip_deflection(length=0.3, spacing=0.01, deflection_ratio=0.005)
    assert c.measured == pytest.approx(c.analytic, rel=0.01)


def test_clamped_free_euler_buckling_load():
    # The critical load is where the tangent stiffness of the straight, compressed rod (dead
    # load, no load stiffness) first loses positive definiteness; the stiffness comes from the
    # rod's own forces by central differences. Tolerance 2 % (brief: 5 %): the discrete Euler
    # problem converges as (h/L)^2, about 0.1 % here.
    rod = cantilever(0.3, 0.01)
    assert compressed_min_eigenvalue(rod, 0.5 * euler_load(rod, 0.3)) > 0.0
    c = euler_buckling_load(length=0.3, spacing=0.01)
    assert c.measured == pytest.approx(c.analytic, rel=0.02)


def test_axial_wave_speed_and_impedance():
    # A velocity step at the free end of a long rod: the front (velocity v0/2) reaches a node at
    # distance d after d / c, c = sqrt(E / rho), and the force needed is the impedance
    # rho c A v0. Tolerance 2 %: the lattice front is spread over ~ (c t)^(1/3) h^(2/3) ~ 2 cm of
    # 0.5 m, and its half-height point travels at c.
    speed, force = axial_wave(length=1.0, spacing=5e-3, speed=0.01, probe=100)
    assert speed.analytic == pytest.approx(math.sqrt(E / RHO), rel=1e-12)
    assert speed.measured == pytest.approx(speed.analytic, rel=0.02)
    assert force.measured == pytest.approx(force.analytic, rel=0.02)


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
