"""Kinematic constraints of the explicit solver: sheath (line), time windows, mass scaling."""

import math

import numpy as np
import pytest

from colonsim.insertion.engine.rod import Rod
from colonsim.insertion.engine.constraints import FixedNodes, LineConstraint, NodalLoad
from colonsim.insertion.engine.solver import ExplicitSolver

E = 16e6
RHO = 2944.0
D = 12.8e-3


def test_sheath_clamps_the_rod_where_it_ends():
    # A rod guided by a rigid sheath (line constraint) over x <= 0.1 m and loaded laterally at
    # the tip is a cantilever clamped at the sheath exit: nodes inside stay on the line, and the
    # tip deflects P L^3 / 3EI with L from the middle of the last guided segment (where the
    # first free hinge's half cell begins) to the tip. Tolerance 1 % as for the cantilever test
    # (midpoint-rule discretization ~ (h/L)^2 / 4, relaxation residual < 1e-4).
    h = 0.01
    rod = Rod.straight(0.4, D, E, RHO, spacing=h)
    inside = rod.x0[:, 0] <= 0.1 + 1e-9
    last_inside = np.flatnonzero(inside).max()
    L = rod.x0[rod.tip_node, 0] - (rod.x0[last_inside, 0] - 0.5 * h)
    EI = rod.flexural_rigidity
    P = 3.0 * EI * 0.005 * L / L**3
    omega1 = 1.875**2 * math.sqrt(EI / (RHO * rod.area * L**4))
    sheath = LineConstraint(rod, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), extent=(-1.0, 0.1 + 1e-9))
    sim = ExplicitSolver(
        [rod],
        constraints=[sheath, FixedNodes(rod, [0])],
        loads=[NodalLoad(rod, [rod.tip_node], (0.0, -P, 0.0))],
        damping=2.0 * omega1,
    )
    sim.run(16.0 / omega1, record_interval=0.1)
    x = sim.state["scope"].x
    assert np.all(x[inside, 1] == 0.0) and np.all(x[inside, 2] == 0.0)
    assert -x[rod.tip_node, 1] == pytest.approx(P * L**3 / (3.0 * EI), rel=0.01)
    # the sheath carries the lateral load: its reaction balances P (static equilibrium; 0.5 %
    # covers the inertia of the residual relaxation motion, measured 0.09 %)
    assert sheath.reaction[1] == pytest.approx(P, rel=5e-3)


def test_constraint_released_at_the_end_of_its_window():
    # A free rod held at both ends by a fixed-node constraint that dies at t1 = 1 ms, pulled
    # axially by F on its tip: nothing moves before t1; afterwards the rod's centre of mass
    # accelerates at F / M (momentum balance, exact for the scheme up to one step of timing).
    rod = Rod.straight(0.1, D, E, RHO, spacing=5e-3)
    F = 2.0
    hold = FixedNodes(rod, [0, rod.tip_node], end=1e-3)
    sim = ExplicitSolver([rod], constraints=[hold], loads=[NodalLoad(rod, [rod.tip_node], (F, 0.0, 0.0))])
    sim.run(1e-3)
    assert np.array_equal(sim.state["scope"].x, rod.x0)
    t1 = sim.time
    sim.run(2e-3)
    m = rod.mass
    com = (m[:, None] * (sim.state["scope"].x - rod.x0)).sum(axis=0) / m.sum()
    dt = sim.dt
    assert com[0] == pytest.approx(0.5 * F / m.sum() * (sim.time - t1) ** 2, rel=2 * dt / (sim.time - t1))
    assert abs(com[1]) < 1e-15 and abs(com[2]) < 1e-15


def test_mass_scaling_reaches_the_target_time_step():
    # Uniform mass scaling by (target / dt)^2 lowers every frequency by target / dt, so the
    # stable step becomes the target; the solver then steps at time_step_factor x target.
    rod = Rod.straight(0.1, D, E, RHO, spacing=5e-3)
    dt0 = rod.critical_time_step(rod.x0)
    m0 = rod.mass.sum()
    sim = ExplicitSolver([rod], mass_scaling=4.0 * dt0, time_step_factor=0.9)
    sim.advance()
    assert sim.dt == pytest.approx(0.9 * 4.0 * dt0, rel=1e-9)
    assert sim.added_mass["scope"] == pytest.approx(15.0 * m0, rel=1e-9)


def test_threaded_nodal_updates_match_serial(two_threads):
    # Large bodies update their nodes on threads; a small run must give the serial result
    # (identical per-node arithmetic; only the order of the energy sums differs: 1e-12).
    if not two_threads:
        return  # checked on two threads in a child process (the fixture)
    results = []
    for threshold in (10**9, 0):
        rod = Rod.straight(0.1, D, E, RHO, spacing=5e-3)
        sim = ExplicitSolver([rod], constraints=[FixedNodes(rod, [0, 1])], damping=5.0, parallel_min_nodes=threshold,
                             loads=[NodalLoad(rod, [rod.tip_node], (0.0, 1.0, 0.5))])
        hist = sim.run(2e-3)
        results.append((sim.state["scope"].x.copy(), hist.bodies["scope"]["kinetic"][-1]))
    assert np.array_equal(results[0][0], results[1][0])
    assert results[0][1] == pytest.approx(results[1][1], rel=1e-12)


def test_a_constraint_born_and_dying_holds_its_nodes_exactly_over_its_window():
    # The solver asks the constraints' windows again only where one starts or ends: a hold born at
    # 1 ms and dying at 2 ms keeps its nodes still exactly over that window and not outside it.
    rod = Rod.straight(0.1, D, E, RHO, spacing=5e-3)
    hold = FixedNodes(rod, [rod.tip_node], start=1e-3, end=2e-3)
    sim = ExplicitSolver([rod], constraints=[hold], loads=[NodalLoad(rod, [rod.tip_node], (2.0, 0.0, 0.0))])
    tips = []
    while sim.time < 3e-3:
        sim.advance()
        tips.append((sim.time, sim.state["scope"].x[rod.tip_node, 0]))
    t, x = np.array(tips).T
    held = (t > 1e-3 + sim.dt) & (t < 2e-3)  # from the first step that starts inside the window
    assert np.ptp(x[held]) == 0.0 and held.sum() > 5
    assert np.all(np.diff(x[t < 1e-3]) > 0.0) and np.all(np.diff(x[t > 2e-3 + sim.dt]) > 0.0)
