"""Rod against beam theory: cantilever tip deflection, Euler buckling, axial wave speed.

The rod's hinge at the first free node owns the half cell behind it, so a rod whose first two
nodes are fixed is clamped at the middle of its first segment: the beam length is measured from
there (x = h/2) to the tip node.
"""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from insertion.rod import Rod
from insertion.solver import ExplicitSolver, FixedNodes, NodalLoad, PrescribedVelocity

E = 16e6  # Pa, scope (SPEC 2.2)
RHO = 2944.0  # kg/m^3
D = 12.8e-3  # m, standard scope


def cantilever(length, spacing):
    """Rod whose clamp (middle of segment 0) lies at x = 0 and whose tip is at x = length."""
    n_seg = int(round(length / spacing))
    h = length / (n_seg + 0.5)
    x = (np.arange(n_seg + 2) - 0.5) * h
    nodes = np.column_stack((x, np.zeros_like(x), np.zeros_like(x)))
    return Rod(nodes, D, E, RHO)


def test_cantilever_tip_load_matches_beam_theory():
    # Static deflection by dynamic relaxation (critical damping of the first mode).
    # Tolerance 1 %: the discrete moment-area sum is a midpoint rule, error ~ (h/L)^2/4 = 3e-4,
    # the relaxation residual is below 1e-4 after 16 time constants, and at delta/L = 0.5 % the
    # geometric nonlinearity is ~1e-5.
    L = 0.3
    rod = cantilever(L, 0.01)
    EI = rod.flexural_rigidity
    delta = 0.005 * L
    P = 3.0 * EI * delta / L**3
    omega1 = 1.875**2 * math.sqrt(EI / (RHO * rod.area * L**4))
    sim = ExplicitSolver(
        [rod],
        constraints=[FixedNodes(rod, [0, 1])],
        loads=[NodalLoad(rod, [rod.tip_node], (0.0, 0.0, -P))],
        damping=2.0 * omega1,
    )
    sim.run(16.0 / omega1, record_interval=0.1)
    tip = sim.state["scope"].x[rod.tip_node]
    assert -tip[2] == pytest.approx(P * L**3 / (3.0 * EI), rel=0.01)


def test_clamped_free_euler_buckling_load():
    # The critical load is where the tangent stiffness of the straight, compressed rod (dead
    # load, no load stiffness) first loses positive definiteness; the stiffness comes from the
    # rod's own forces by central differences. Tolerance 2 % (brief: 5 %): the discrete Euler
    # problem converges as (h/L)^2, about 0.1 % here.
    L = 0.3
    rod = cantilever(L, 0.01)
    EI = rod.flexural_rigidity
    free = np.arange(2, rod.n_nodes)

    def min_eig(P):
        x = rod.x0.copy()
        shortened = rod.rest_length[1:] - P / rod.axial_stiffness[1:]
        x[2:, 0] = x[1, 0] + np.cumsum(shortened)
        k = np.zeros((len(free), len(free)))
        eps = 1e-7
        for j, node in enumerate(free):
            fp = np.zeros_like(x)
            fm = np.zeros_like(x)
            xp = x.copy()
            xp[node, 1] += eps
            xm = x.copy()
            xm[node, 1] -= eps
            rod.internal_forces(xp, fp)
            rod.internal_forces(xm, fm)
            k[:, j] = -(fp[free, 1] - fm[free, 1]) / (2 * eps)
        return np.linalg.eigvalsh(0.5 * (k + k.T)).min()

    p_euler = math.pi**2 * EI / (4.0 * L**2)
    assert min_eig(0.5 * p_euler) > 0.0
    p_cr = brentq(min_eig, 0.5 * p_euler, 1.5 * p_euler, xtol=1e-6 * p_euler)
    assert p_cr == pytest.approx(p_euler, rel=0.02)


def test_axial_wave_speed_and_impedance():
    # A velocity step at the free end of a long rod: the front (velocity v0/2) reaches a node at
    # distance d after d / c, c = sqrt(E / rho), and the force needed is the impedance
    # rho c A v0. Tolerance 2 %: the lattice front is spread over ~ (c t)^(1/3) h^(2/3) ~ 2 cm of
    # 0.5 m, and its half-height point travels at c.
    rod = Rod.straight(1.0, D, E, RHO, spacing=5e-3)
    c = math.sqrt(E / RHO)
    v0 = 0.01
    push = PrescribedVelocity(rod, [0], (v0, 0.0, 0.0))
    sim = ExplicitSolver([rod], constraints=[push])
    probe = 100  # 0.5 m from the pushed end
    d = rod.x0[probe, 0]
    arrival = None
    force = []
    while sim.time < 1.2 * d / c:
        v_before = sim.state["scope"].v[probe, 0]
        t_before = sim.time
        sim.advance()
        v_after = sim.state["scope"].v[probe, 0]
        # velocities live at mid-steps
        if arrival is None and v_after >= 0.5 * v0:
            frac = (0.5 * v0 - v_before) / (v_after - v_before)
            arrival = t_before - 0.5 * sim.dt + frac * sim.dt if t_before > 0 else t_before
        if sim.time > 0.3 * d / c:
            force.append(push.reaction[0])
    assert d / arrival == pytest.approx(c, rel=0.02)
    assert np.mean(force) == pytest.approx(RHO * c * rod.area * v0, rel=0.02)


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
