"""The global time-step estimate (insertion/engine/global_time_step.py) against the largest
eigenvalue of the assembled coupled system: a scope pressed on a tube's wall, touching it at a
few nodes, and held at the sheath's lip."""

import numpy as np
import pytest

from colonsim.insertion.engine.constraints import FixedNodes
from colonsim.insertion.engine.contact import RodShellContact
from colonsim.insertion.engine.global_time_step import GlobalTimeStep
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH, load_material
from colonsim.insertion.engine.rod import Rod
from colonsim.insertion.engine.sheath_lip import SheathLip
from colonsim.insertion.engine.sheet_mesh import straight_tube
from colonsim.insertion.engine.shell import Shell
from colonsim.insertion.engine.solver import ExplicitSolver

PENETRATION = 5e-5  # m: small, so the springs' geometric stiffness (force / distance) is 0.3 % of k


def _model(global_estimate=None, damping_ratio=0.0):
    nodes, tri, ring = straight_tube(0.1, 0.038, 6e-3)
    wall = Shell(nodes, tri, 2e-3, load_material(REFERENCE_MATERIAL_PATH), name="colon")
    lumen = 0.019 - 1e-3  # mid-surface radius less half the wall
    scope = Rod.straight(0.15, 12.8e-3, 16e6, 2944.0, spacing=5e-3,
                         start=(-0.08, 0.0, -(lumen - 6.4e-3 + PENETRATION)))
    contact = RodShellContact(scope, wall, damping_ratio=damping_ratio)
    lip = SheathLip(scope, (-0.08, 0.0, -(lumen - 6.4e-3 + PENETRATION)), (1.0, 0.0, 0.0), 0.02,
                    damping_ratio=damping_ratio)
    solver = ExplicitSolver([scope, wall], contacts=[contact, lip],
                            constraints=[FixedNodes(wall, np.flatnonzero((ring == 0) | (ring == ring.max())))],
                            global_estimate=global_estimate)
    solver.advance()  # the contacts find their springs, the held nodes are marked
    return solver, scope, wall, contact, lip


def _assembled_top_eigenvalue(solver, scope, wall):
    """Largest eigenvalue of M^-1/2 K M^-1/2 over the rod's and the free wall nodes' DOFs, K by
    central differences of every force (internal, contact, lip) at zero velocity."""
    state = solver.state
    for s in state.values():
        s.v[:] = 0.0
    free_wall = np.flatnonzero(state["colon"].fixed == 0)
    dofs = [("scope", i, k) for i in range(len(scope.x0)) for k in range(3)]
    dofs += [("colon", i, k) for i in free_wall for k in range(3)]

    def forces():
        out = {}
        for b in solver.bodies:
            s = state[b.name]
            s.f_int[:] = 0.0
            s.f_con[:] = 0.0
            b.internal_forces(s.x, s.f_int)
        for c in solver.contacts:
            c.compute(state, 1e-5)
        for b in solver.bodies:
            s = state[b.name]
            out[b.name] = s.f_int + s.f_con
        return np.array([out[n][i, k] for n, i, k in dofs])

    eps = 1e-9
    k = np.empty((len(dofs), len(dofs)))
    for j, (n, i, a) in enumerate(dofs):
        state[n].x[i, a] += eps
        fp = forces()
        state[n].x[i, a] -= 2 * eps
        fm = forces()
        state[n].x[i, a] += eps
        k[:, j] = -(fp - fm) / (2 * eps)
    masses = {"scope": scope.mass, "colon": wall.mass}
    d = np.array([1.0 / np.sqrt(masses[n][i]) for n, i, _ in dofs])
    a = d[:, None] * k * d[None, :]
    return float(np.linalg.eigvalsh(0.5 * (a + a.T)).max())


@pytest.mark.parametrize("rod_stiffness_scale", [1.0, 0.02])
def test_power_iteration_finds_the_coupled_systems_largest_eigenvalue(rod_stiffness_scale):
    """Converged, the estimate is the assembled system's largest eigenvalue within 1 % (the springs'
    geometric stiffness, 0.3 % of k, is left out). With the scope 50 times softer its own modes no
    longer dominate, so the contact springs and the lip (stiffnesses set from the stiff scope) make
    the top of the spectrum: the products must include them to agree."""
    solver, scope, wall, contact, lip = _model()
    assert contact.n_active > 0 and int(lip._out[0]) >= 0  # springs are active
    scope.axial_stiffness *= rod_stiffness_scale
    scope.bending_stiffness *= rod_stiffness_scale
    exact = _assembled_top_eigenvalue(solver, scope, wall)
    estimate = GlobalTimeStep(first_iterations=3000, tolerance=1e-12).omega2(solver)
    assert estimate == pytest.approx(exact, rel=1e-2)
    if rod_stiffness_scale < 1.0:  # without the springs the estimate would be far below
        assert (2.0 / scope.critical_time_step(np.ascontiguousarray(solver.state["scope"].x))) ** 2 < 0.5 * exact


def test_the_global_step_is_longer_than_the_bounds_and_stable():
    """The same model stepped by the bounds and by the global estimate: the global step is the
    longer (the bounds add every spring where the stiffest mode is), and 2000 steps of it stay
    stable (the divergence guard would stop them)."""
    bounds, *_ = _model(damping_ratio=0.5)
    coupled, *_ = _model(GlobalTimeStep(), damping_ratio=0.5)
    dt_bounds = bounds.stable_time_step()
    dt_global = coupled.stable_time_step()
    assert dt_global > 1.05 * dt_bounds
    for _ in range(2000):
        coupled.advance()
    assert coupled.dt > 1.05 * bounds.time_step_factor * dt_bounds


def test_the_estimate_enters_a_cases_key_only_when_global():
    """At "bounds" the key is that of the runs made before the field existed (the RSJ 13.3 mm run
    of the thesis record made at the bounds, in git history before the records' rerun), so every
    record of before stays valid; "global" is another run."""
    from colonsim.insertion.case.insertion_case import InsertionCase

    bounds = InsertionCase(segment="rsj", scope="13.3", time_step_estimate="bounds")
    assert bounds.key() == "289196816b34"  # the thesis record of before the rerun
    assert InsertionCase(segment="rsj", scope="13.3", time_step_estimate="global").key() != bounds.key()
