"""Energy accounting of the explicit solver: conservation without damping, balance with it."""

import math

import numpy as np
import pytest

from insertion.material import REFERENCE_MATERIAL_PATH, load_material
from insertion.rod import Rod
from insertion.sheet_mesh import flat_sheet
from insertion.shell import Shell
from insertion.solver import ExplicitSolver, FixedNodes, NodalLoad, PrescribedVelocity

E = 16e6
RHO = 2944.0
D = 12.8e-3


def test_undamped_free_vibration_conserves_energy():
    # Cantilever rod and a clamped wall patch vibrating freely (no damping, no loads): total
    # energy kinetic + strain must stay within 1 % of its initial value over 5 periods of the
    # rod's first mode. Central differences conserve a shadow energy; the measured energy
    # oscillates by O((omega dt)^2) of the excited modes, far below 1 % at these amplitudes.
    rod = Rod.straight(0.1, D, E, RHO, spacing=5e-3)
    s = rod.x0[:, 0] / 0.1
    v_rod = np.zeros_like(rod.x0)
    v_rod[:, 2] = 0.05 * s**2
    v_rod[:2] = 0.0
    nodes, tri = flat_sheet(0.04, 0.04, 4e-3)
    wall = Shell(nodes, tri, 2e-3, load_material(REFERENCE_MATERIAL_PATH), name="wall")
    on_edge = (np.minimum(nodes[:, 0], 0.04 - nodes[:, 0]) < 1e-9) | (np.minimum(nodes[:, 1], 0.04 - nodes[:, 1]) < 1e-9)
    edge = np.flatnonzero(on_edge)
    r = np.hypot(nodes[:, 0] - 0.02, nodes[:, 1] - 0.02)
    v_wall = np.zeros_like(nodes)
    v_wall[:, 2] = 0.05 * np.clip(1.0 - r / 0.02, 0.0, None)
    v_wall[edge] = 0.0
    sim = ExplicitSolver(
        [rod, wall],
        constraints=[FixedNodes(rod, [0, 1]), FixedNodes(wall, edge)],
        initial_velocity={"scope": v_rod, "wall": v_wall},
    )
    omega1 = 1.875**2 * math.sqrt(rod.flexural_rigidity / (RHO * rod.area * 0.1**4))
    hist = sim.run(5 * 2 * math.pi / omega1, record_interval=1e-3)
    for name in ("scope", "wall"):
        b = hist.bodies[name]
        total = b["kinetic"] + b["internal"]
        assert np.all(b["external_work"] == 0.0)
        assert np.max(np.abs(total - total[0])) < 0.01 * total[0]


def test_damped_pushed_rod_energy_balance():
    # Damping, a prescribed velocity with a ramp and a switched load: kinetic + strain +
    # dissipated - external work stays at its initial value (zero) to 1 % of the work put in.
    # The accounting is exact for kinetic energy; the residual is the O(dt^2) quadrature error
    # of the strain energy (trapezoid vs. exact), far below 1 %.
    rod = Rod.straight(0.2, D, E, RHO, spacing=5e-3)
    push = PrescribedVelocity(rod, [0], (0.5, 0.0, 0.0), ramp=2e-3, end=8e-3)
    hold = FixedNodes(rod, [0], start=8e-3)
    load = NodalLoad(rod, [rod.tip_node], (-20.0, 5.0, 0.0), start=2e-3)
    sim = ExplicitSolver([rod], constraints=[push, hold], loads=[load], damping=200.0)
    hist = sim.run(0.03, record_interval=1e-4)
    b = hist.bodies["scope"]
    balance = hist.total_energy_balance()
    work = np.max(np.abs(b["external_work"]))
    assert work > 1e-3
    assert np.max(np.abs(balance)) < 0.01 * work
    assert b["dissipated"][-1] > 0.0
    # the push force is the reaction of the prescribed-velocity constraint; after the push the
    # fixed node takes over the reaction
    assert np.any(np.abs(hist.reactions[0][:, 0]) > 0.0)
    assert np.all(hist.reactions[0][hist.time > 8.5e-3] == 0.0)
    # the pushed node moved by the integral of the ramped velocity, 0.5 (8 ms - 1 ms), up to the
    # one step in which the window ends
    assert sim.state["scope"].x[0, 0] == pytest.approx(0.5 * (8e-3 - 1e-3), abs=0.5 * sim.dt)
