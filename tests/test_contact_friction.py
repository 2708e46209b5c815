"""Regularised Coulomb friction: a rod on a wall sticks below mu N and slides above it."""

import math

import numpy as np
import pytest

from insertion.solver import ExplicitSolver, FixedNodes, NodalLoad
from test_contact_rest import rod_on_sheet

MU = 0.3
N = 1.0  # total normal load, N


def slide(tangential):
    """Settle the rod under N, then pull it along its axis with ``tangential`` (N) for 5 ms.

    Returns the rod's mean axial velocity at 2, 5 ms after the pull starts, the slid distance,
    the rod mass and the contact."""
    wall, rod, contact, under = rod_on_sheet(friction=MU)
    share = rod.mass / rod.mass.sum()
    normal = NodalLoad(rod, np.arange(rod.n_nodes), np.column_stack((0 * share, 0 * share, -N * share)))
    omega = math.sqrt(len(under) * contact.held_stiffness / rod.mass.sum())
    t1 = 30.0 / omega  # contact springs critically damped: settled after 30 time constants
    pull = NodalLoad(rod, np.arange(rod.n_nodes), np.column_stack((tangential * share, 0 * share, 0 * share)),
                     start=t1)
    sim = ExplicitSolver([rod, wall], contacts=[contact], constraints=[FixedNodes(wall, np.arange(wall.n_nodes))],
                         loads=[normal, pull])
    sim.run(t1)
    x_start = sim.state["scope"].x[:, 0] @ share
    d0 = contact.friction_dissipated
    sim.run(2e-3)
    v2, t2 = sim.state["scope"].v[:, 0].mean(), sim.time
    sim.run(3e-3)
    v5, t5 = sim.state["scope"].v[:, 0].mean(), sim.time
    # the work sums of a step pair its forces with the mid-step velocity, so they cover the
    # motion up to half a step before the positions: compare with the slide up to there
    slid = sim.state["scope"].x[:, 0] @ share - x_start - 0.5 * sim.dt * v5
    return v2, v5, t5 - t2, slid, contact.friction_dissipated - d0, rod.mass.sum(), contact


def test_sticks_below_mu_n():
    # Below mu N the regularised law holds the rod at the creep speed v_reg F_t / (mu N)
    # (reached after M v_reg / (mu N) = 0.07 ms). Tolerance 1 %: the creep is steady, the only
    # deviation is the O(mu f_n dt / m) lag of the explicit viscous update.
    ft = 0.5 * MU * N
    v2, v5, _, slid, _, _, contact = slide(ft)
    creep = contact.slip_velocity * ft / (MU * N)
    assert v5 == pytest.approx(creep, rel=0.01)
    assert v2 == pytest.approx(creep, rel=0.01)
    assert slid < 1.1 * creep * 5e-3  # a few micrometres: stuck for practical purposes


def test_slides_above_mu_n():
    # Above mu N the rod accelerates at (F_t - mu N) / M and friction dissipates mu N per unit
    # slid distance. Tolerance 1 %: friction is saturated once |v| > v_reg (after ~0.1 ms, before
    # the 2 ms measuring start), the normal force stays N to 1e-4 and the part of the slide below
    # v_reg is ~1e-8 m of 2e-4 m.
    ft = 2.0 * MU * N
    v2, v5, dt, slid, dissipated, mass, _ = slide(ft)
    assert (v5 - v2) / dt == pytest.approx((ft - MU * N) / mass, rel=0.01)
    assert dissipated == pytest.approx(MU * N * slid, rel=0.01)
