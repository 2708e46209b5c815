"""Rod resting on a wall: penetration F / k, energy balance, broad phase against all pairs."""

import math

import numpy as np
import pytest

from insertion.contact import RodShellContact
from insertion.material import REFERENCE_MATERIAL_PATH, load_material
from insertion.rod import Rod
from insertion.sheet_mesh import flat_sheet, straight_tube
from insertion.shell import Shell
from insertion.solver import ExplicitSolver, FixedNodes, LineConstraint, NodalLoad

E = 16e6
RHO = 2944.0
D = 12.8e-3
T = 2e-3  # wall thickness


def rod_on_sheet(friction=0.0):
    """A fixed flat wall (rigid support) and a rod lying along one row of its nodes.

    The row has nodes every 5 mm along x; the rod spans x in [22.5, 77.5] mm, so exactly the 11
    row nodes at 25..75 mm lie under it (the neighbour rows are 4.4 mm aside, 1.2 mm clear of
    the capsule, and the row nodes beyond the rod ends 0.4 mm clear of the end caps).
    """
    nodes, tri = flat_sheet(0.1, 0.04, 5e-3)
    wall = Shell(nodes, tri, T, load_material(REFERENCE_MATERIAL_PATH), name="wall")
    y_row = 0.04 * 4 / 9
    under = np.flatnonzero((np.abs(nodes[:, 1] - y_row) < 1e-9) & (nodes[:, 0] > 0.0225) & (nodes[:, 0] < 0.0775))
    z = 0.5 * D + 0.5 * T
    rod = Rod.straight(0.055, D, E, RHO, spacing=5e-3, start=(0.0225, y_row, z))
    contact = RodShellContact(rod, wall, damping_ratio=1.0, friction=friction)
    return wall, rod, contact, under


def test_rod_resting_on_wall_penetrates_f_over_k():
    # A load F spread over the rod like its weight, 11 contact springs k in parallel: at rest
    # the mean penetration is F / (11 k) exactly (vertical force balance). Tolerance 0.5 %: the
    # relaxation residual (contact springs critically damped, 30 time constants); measured 2e-10.
    wall, rod, contact, under = rod_on_sheet()
    F = 1.0
    per_node = F * rod.mass / rod.mass.sum()
    load = NodalLoad(rod, np.arange(rod.n_nodes), np.column_stack((0 * per_node, 0 * per_node, -per_node)))
    sim = ExplicitSolver([rod, wall], contacts=[contact], constraints=[FixedNodes(wall, np.arange(wall.n_nodes))],
                         loads=[load], damping={"scope": 0.0})
    omega = math.sqrt(len(under) * contact.held_stiffness / rod.mass.sum())
    hist = sim.run(30.0 / omega, record_interval=1.0 / omega)
    assert contact.n_active == len(under) == 11
    xr = sim.state["scope"].x
    pen = 0.5 * D + 0.5 * T - (xr[:, 2].mean())
    expected = F / (len(under) * contact.held_stiffness)
    assert pen == pytest.approx(expected, rel=0.005)
    assert contact.normal_force == pytest.approx(F, rel=0.005)
    assert contact.force_on_rod[2] == pytest.approx(F, rel=0.005)
    # energy: kinetic + strain + contact penalty + dissipated - work of the load is conserved
    # to 2 % of the work (the contact damping power is evaluated at the half-step velocity)
    balance = hist.total_energy_balance()
    work = hist.bodies["scope"]["external_work"][-1]
    assert np.max(np.abs(balance)) < 0.02 * work
    assert hist.contacts[0]["energy"][-1] == pytest.approx(0.5 * F * expected, rel=0.01)


def test_broad_phase_finds_every_contact_of_all_pairs():
    # A bent rod pressed into a tube wall: the cell-hash candidates must give exactly the
    # contact forces of a brute-force search over all (node, segment) pairs.
    nodes, tri, _ = straight_tube(0.15, 0.036, 4e-3)
    wall = Shell(nodes, tri, T, load_material(REFERENCE_MATERIAL_PATH), name="wall")
    s = np.linspace(0.0, 0.12, 41)
    centre = np.column_stack((0.01 + s, 0.011 * np.sin(30 * s), 0.011 * np.cos(20 * s)))
    rod = Rod(centre, D, E, RHO)
    contact = RodShellContact(rod, wall, friction=0.2)
    state = {"scope": _State(rod), "wall": _State(wall)}
    rng = np.random.default_rng(1)
    state["scope"].v[:] = rng.normal(size=state["scope"].v.shape) * 0.01
    contact.compute(state, 1e-6)
    assert contact.n_active > 20
    assert contact.n_candidates < 0.05 * len(nodes) * len(rod.segments)
    # brute force: every wall node against every segment
    xs, xr = state["wall"].x, state["scope"].x
    a, b = xr[:-1], xr[1:]
    e = b - a
    w = xs[:, None, :] - a[None]
    t = np.clip(np.einsum("nsk,sk->ns", w, e) / np.einsum("sk,sk->s", e, e), 0.0, 1.0)
    dist = np.linalg.norm(w - t[..., None] * e[None], axis=2)
    in_contact = dist.min(axis=1) < rod.radius + 0.5 * T
    near = np.flatnonzero(dist.min(axis=1) < contact.cutoff)
    assert np.array_equal(np.sort(contact._nodes), near)
    assert contact.n_candidates == int((dist < contact.cutoff).sum())
    got = np.linalg.norm(state["wall"].f_con, axis=1) > 0.0
    assert np.array_equal(got, in_contact)
    # action = reaction
    assert np.allclose(state["wall"].f_con.sum(axis=0), -state["scope"].f_con.sum(axis=0), atol=1e-12)


class _State:
    def __init__(self, body):
        self.x = body.x0.copy()
        self.v = np.zeros_like(self.x)
        self.f_con = np.zeros_like(self.x)
        self.fixed = np.zeros(len(self.x), dtype=np.uint8)


def test_threaded_narrow_phase_matches_serial():
    # Large contact sets run the narrow phase on threads; it must give the serial result
    # (same arithmetic per candidate, only the order of the scalar sums differs: 1e-12).
    wall, rod, contact, under = rod_on_sheet(friction=0.2)
    xr = rod.x0.copy()
    xr[:, 2] -= 1e-4  # press the rod into the wall
    out = []
    for threshold in (10**9, 0):
        contact.parallel_min_candidates = threshold
        state = {"scope": _State(rod), "wall": _State(wall)}
        state["scope"].x[:] = xr
        state["scope"].v[:, 0] = 0.01
        contact.compute(state, 1e-6)
        out.append((state["wall"].f_con.copy(), state["scope"].f_con.copy(), contact.energy))
    assert np.allclose(out[0][0], out[1][0], rtol=0, atol=1e-12)
    assert np.allclose(out[0][1], out[1][1], rtol=0, atol=1e-12)
    assert out[0][2] == pytest.approx(out[1][2], rel=1e-12)


def test_hemispherical_tip_pressed_on_a_node_penetrates_f_over_k():
    # A short rod standing tip-down over one wall node, guided along its axis (a sheath over
    # its whole length) and pushed with F: only the node under the tip touches (its neighbours,
    # 5 mm aside, are 1.5 mm clear of the 7.4 mm sphere), so the tip sinks F / k into it.
    # Tolerance 0.5 %: relaxation residual of the critically damped contact spring.
    nodes, tri = flat_sheet(0.1, 0.04, 5e-3)
    wall = Shell(nodes, tri, T, load_material(REFERENCE_MATERIAL_PATH), name="wall")
    below = int(np.argmin(np.hypot(nodes[:, 0] - 0.05, nodes[:, 1] - 0.04 * 4 / 9)))
    reach = 0.5 * D + 0.5 * T
    top = nodes[below] + (0.0, 0.0, reach + 0.03)
    rod = Rod.straight(0.03, D, E, RHO, spacing=5e-3, start=top, direction=(0.0, 0.0, -1.0))
    contact = RodShellContact(rod, wall, damping_ratio=1.0)
    F = 0.2
    sim = ExplicitSolver(
        [rod, wall], contacts=[contact],
        constraints=[FixedNodes(wall, np.arange(wall.n_nodes)), LineConstraint(rod, top, (0.0, 0.0, -1.0))],
        loads=[NodalLoad(rod, [0], (0.0, 0.0, -F))],
    )
    omega = math.sqrt(contact.held_stiffness / rod.mass.sum())
    sim.run(30.0 / omega, record_interval=1.0 / omega)
    assert contact.n_active == 1
    tip = sim.state["scope"].x[rod.tip_node]
    assert reach - (tip[2] - nodes[below, 2]) == pytest.approx(F / contact.held_stiffness, rel=0.005)
