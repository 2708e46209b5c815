"""The wall's quiet held nodes left out of the nodal updates, and its held elements' time-step
bounds kept: both must leave a run the same to the last bit (insertion/engine/body_state.py,
insertion/engine/shell_bounds.py)."""

import numpy as np
import pytest

from colonsim.insertion.engine.constraints import FixedNodes, NodalLoad, PrescribedVelocity
from colonsim.insertion.engine.contact import RodShellContact
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH, load_material
from colonsim.insertion.engine.rod import Rod
from colonsim.insertion.engine.sheet_mesh import straight_tube
from colonsim.insertion.engine.shell import Shell
from colonsim.insertion.engine._scatter import gather
from colonsim.insertion.engine.shell_bounds import SplitBounds
from colonsim.insertion.engine.shell_hinges import hinge_rowsum_kernel, max_row_over_mass
from colonsim.insertion.engine.shell_membrane import membrane_omega2_kernel
from colonsim.insertion.engine.solver import ExplicitSolver
from colonsim.insertion.study.verification import SCOPE_D, SCOPE_E, SCOPE_RHO, WALL_T

LENGTH, DIAMETER, MESH = 0.12, 0.036, 6e-3
STEPS = 600


def _tube():
    nodes, tri, _ = straight_tube(LENGTH, DIAMETER, MESH)
    return Shell(nodes, tri, WALL_T, load_material(REFERENCE_MATERIAL_PATH), name="colon")


def _run(leave_out=True, contact_reach=None, late_load=False):
    """A scope pushed along the tube and pressed into its wall on both sides of the line where the
    wall's far half is held (the contact reaches held nodes and free ones); returns the solver
    after ``STEPS`` steps and the held part's constraint reaction at every step. ``late_load``: a
    force on a held node far from the scope, added half-way."""
    wall = _tube()
    x0 = wall.x0[:, 0].min()
    held = np.flatnonzero(wall.x0[:, 0] > x0 + 0.5 * LENGTH)
    offset = 0.5 * DIAMETER - 0.5 * SCOPE_D - 0.4 * WALL_T  # the scope presses into the wall at y > 0
    rod = Rod.straight(0.1, SCOPE_D, SCOPE_E, SCOPE_RHO, spacing=5e-3, start=(x0 + 0.01, offset, 0.0))
    contact = RodShellContact(rod, wall)
    if not leave_out:
        contact.nodes_on = lambda body: None  # a contact that cannot say: nothing is left out
    elif contact_reach is not None:
        contact.nodes_on = contact_reach
    fixed = FixedNodes(wall, held)
    push = PrescribedVelocity(rod, [0], (0.5, 0.2, 0.0))
    sim = ExplicitSolver([rod, wall], contacts=[contact], constraints=[fixed, push], damping={"colon": 50.0})
    reactions = []
    for step in range(STEPS):
        if late_load and step == STEPS // 2:
            far = held[np.argmax(wall.x0[held, 0])]
            sim.loads.append(NodalLoad(wall, [far], (0.0, 0.0, 1.0)))
        sim.advance()
        reactions.append(fixed.reaction.copy())
    return sim, np.array(reactions)


@pytest.fixture(scope="module")
def both():
    return _run(leave_out=True), _run(leave_out=False)


def test_leaving_quiet_nodes_out_changes_nothing(both):
    (sim, reactions), (ref, ref_reactions) = both
    wall = sim.state["colon"]
    # most of the held half is left out, and the contact did reach held nodes
    assert len(wall.moving) < 0.7 * len(wall.x) and len(ref.state["colon"].moving) == len(wall.x)
    assert np.abs(ref_reactions[-1]).max() > 0.0
    for name in ("colon", "scope"):
        a, b = sim.state[name], ref.state[name]
        assert np.array_equal(a.x, b.x) and np.array_equal(a.v, b.v)
        assert (a.work_internal, a.work_contact, a.work_reaction, a.dissipated_damping) == \
            (b.work_internal, b.work_contact, b.work_reaction, b.dissipated_damping)
    assert np.array_equal(reactions, ref_reactions)
    assert sim.dt == ref.dt


def test_a_contact_node_wrongly_left_out_is_seen():
    # the contact's candidates kept in the update is what keeps the held part's reaction: a
    # contact that claimed to reach no wall node would lose the reaction of the held nodes it presses
    _, reactions = _run(contact_reach=lambda body: np.zeros(0, dtype=np.int64))
    _, ref_reactions = _run(leave_out=False)
    assert not np.array_equal(reactions, ref_reactions)


def _every_element(wall, x, scale):
    """The two bounds with every triangle and hinge evaluated at x."""
    omega2 = np.zeros(len(wall.triangles))
    membrane_omega2_kernel(x, wall.triangles, wall.dm_inv, wall.thickness, wall.density, wall._law, wall._law_params,
                           scale, omega2)
    buf = np.zeros((len(wall.hinges), 4, 3))
    hinge_rowsum_kernel(x, wall.hinges, wall.hinge_stiffness, wall.theta0, buf)
    rows = np.zeros_like(x)
    gather(buf, wall._hinge_ptr, wall._hinge_slots, rows)
    return float(omega2.max()), max_row_over_mass(rows, wall.mass)


def test_a_load_added_later_is_seen():
    # a load on the wall puts every node back in the update: the held node it pulls has its reaction
    sim, reactions = _run(late_load=True)
    _, ref_reactions = _run(leave_out=False, late_load=True)
    assert len(sim.state["colon"].moving) == len(sim.state["colon"].x)
    assert np.array_equal(reactions, ref_reactions)
    assert reactions[-1, 2] == pytest.approx(ref_reactions[STEPS // 2 - 1, 2] - 1.0, abs=0.5)


def test_split_bounds_equal_every_element_evaluated():
    wall = _tube()
    rng = np.random.default_rng(3)
    held = wall.x0[:, 0] > wall.x0[:, 0].min() + 0.5 * LENGTH
    x = wall.x0 * np.array([1.0, 1.03, 1.03]) + rng.normal(scale=2e-4, size=wall.x0.shape)
    x[held] = wall.x0[held]
    scale = np.ones(len(x))
    whole = SplitBounds(wall, np.ones(len(wall.triangles), bool), np.ones(len(wall.hinges), bool))
    split = SplitBounds(wall, ~held[wall.triangles].all(axis=1), ~held[wall.hinges].all(axis=1))
    free_sets_it = _every_element(wall, x, scale)
    assert split.bounds(x, scale) == whole.bounds(x, scale) == free_sets_it
    # the held part stretched further (it then sets the membrane bound): the kept part is evaluated again
    x[held] = wall.x0[held] * np.array([1.0, 1.3, 1.3])
    assert split.bounds(x, scale) == whole.bounds(x, scale) == _every_element(wall, x, scale)
    assert split.bounds(x, scale)[0] > free_sets_it[0]
    # a held node's mass factor is seen too
    scale[np.flatnonzero(held)[0]] = 0.5
    assert split.bounds(x, scale) == _every_element(wall, x, scale) != free_sets_it
