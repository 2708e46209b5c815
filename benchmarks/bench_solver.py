"""Speed of the explicit solver on the issue's reference model.

A 60 cm straight tube (lumen D = 36 mm, wall 2 mm, 3 mm triangles, end rings fixed) with a
70 cm standard scope (12.8 mm, E = 16 MPa, 2944 kg/m^3, nodes every 5 mm) whose distal 25 cm lie
on the lumen floor under the scope's weight, guided by a sheath before the tube entry and pushed
at 60 cm/s with friction mu = 0.1. After a warm-up
(Numba compilation and the first candidate build) it times a number of steps and prints the
per-step time, element updates per second per core
((triangles + hinges + rod segments + contact candidates) * steps / wall / cores) and the
projected wall time of a 0.5 s simulated push at the solver's time step.

Run: ``python benchmarks/bench_solver.py [--steps 2000] [--threads 2] [--mesh 3e-3] [--rod-spacing 5e-3] [--repeat 1]``

On a shared machine single timings vary by +-15 %: ``--repeat 5`` times five runs of ``--steps``
steps each (one model, continuing in time) and reports the median.
"""

import argparse
import time

import numba
import numpy as np

from colonsim.insertion.engine.contact import RodShellContact
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH, load_material
from colonsim.insertion.engine.rod import Rod
from colonsim.insertion.engine.sheet_mesh import straight_tube
from colonsim.insertion.engine.shell import Shell
from colonsim.insertion.engine.constraints import FixedNodes, LineConstraint, NodalLoad, PrescribedVelocity
from colonsim.insertion.engine.solver import ExplicitSolver

LUMEN = 0.036
WALL = 2e-3
TUBE_LENGTH = 0.6
SCOPE_LENGTH = 0.7
SCOPE_D = 12.8e-3


def build(mesh_size=3e-3, rod_spacing=5e-3, friction=0.1):
    """The reference model: solver, shell, rod, contact."""
    nodes, tri, ring = straight_tube(TUBE_LENGTH, LUMEN + WALL, mesh_size)
    colon = Shell(nodes, tri, WALL, load_material(REFERENCE_MATERIAL_PATH), density=1040.0, name="colon")
    ends = np.flatnonzero((ring == 0) | (ring == ring.max()))
    # scope axis on the lumen floor, 0.1 mm into the contact layer so the contact is active
    reach = 0.5 * SCOPE_D + 0.5 * WALL
    y_axis = -(0.5 * (LUMEN + WALL) - reach + 1e-4)
    start = (0.25 - SCOPE_LENGTH, y_axis, 0.0)
    scope = Rod.straight(SCOPE_LENGTH, SCOPE_D, 16e6, 2944.0, spacing=rod_spacing, start=start)
    contact = RodShellContact(scope, colon, friction=friction)
    push = PrescribedVelocity(scope, [0], (0.6, 0.0, 0.0), ramp=0.02)
    sheath = LineConstraint(scope, start, (1.0, 0.0, 0.0), extent=(-1.0, -start[0] - 0.005))
    weight = NodalLoad(scope, np.arange(scope.n_nodes), np.outer(scope.mass * 9.81, (0.0, -1.0, 0.0)))
    sim = ExplicitSolver(
        [scope, colon],
        contacts=[contact],
        constraints=[FixedNodes(colon, ends), push, sheath],
        loads=[weight],
        damping={"colon": 20.0, "scope": 20.0},
    )
    return sim, colon, scope, contact


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=2000, help="timed steps")
    parser.add_argument("--threads", type=int, default=None, help="Numba threads (default: all)")
    parser.add_argument("--push", type=float, default=0.5, help="simulated push duration to project, s")
    parser.add_argument("--mesh", type=float, default=3e-3, help="wall triangle size, m")
    parser.add_argument("--rod-spacing", type=float, default=5e-3, help="scope node spacing, m")
    parser.add_argument("--repeat", type=int, default=1, help="timed runs of --steps steps; the median is reported")
    args = parser.parse_args()
    if args.threads:
        numba.set_num_threads(args.threads)
    cores = numba.get_num_threads()

    t0 = time.perf_counter()
    sim, colon, scope, contact = build(mesh_size=args.mesh, rod_spacing=args.rod_spacing)
    for _ in range(20):  # compile and build the candidate list
        sim.advance()
    warm = time.perf_counter() - t0

    elements = len(colon.triangles) + len(colon.hinges) + len(scope.segments)
    # time the wall's internal forces (membrane + hinges) inside the run
    shell_time = [0.0]
    shell_forces = colon.internal_forces

    def timed_shell_forces(x, f):
        t = time.perf_counter()
        energy = shell_forces(x, f)
        shell_time[0] += time.perf_counter() - t
        return energy

    colon.internal_forces = timed_shell_forces
    runs = []  # (wall, candidates, shell time) of each timed run
    for _ in range(max(args.repeat, 1)):
        cand = 0
        shell_time[0] = 0.0
        t0 = time.perf_counter()
        for _ in range(args.steps):
            sim.advance()
            cand += contact.n_candidates
        runs.append((time.perf_counter() - t0, cand, shell_time[0]))
    colon.internal_forces = shell_forces
    wall, cand, shell_wall = sorted(runs)[len(runs) // 2]
    shell_share = shell_wall / wall

    per_step = wall / args.steps
    updates = (elements * args.steps + cand) / wall / cores
    steps_push = args.push / sim.dt
    print(f"model: {len(colon.triangles)} triangles, {len(colon.hinges)} hinges, {len(scope.segments)} rod segments, "
          f"{contact.n_candidates} contact candidates ({contact.n_active} in contact), {cores} thread(s)")
    print(f"warm-up (compile + first steps): {warm:.1f} s")
    limits = {b.name: b.critical_time_step(sim.state[b.name].x) for b in sim.bodies}
    limits["contact"] = contact.critical_time_step()
    print(f"time step: {sim.dt:.3e} s  ->  {steps_push:.0f} steps for a {args.push} s push "
          f"(stable steps alone: " + ", ".join(f"{k} {v:.2e} s" for k, v in limits.items()) + ")")
    print(f"per step: {per_step * 1e3:.3f} ms over {args.steps} steps (simulated {sim.time:.4f} s); "
          f"wall internal forces ~{100 * shell_share:.0f} % of it")
    print(f"element updates per second per core: {updates / 1e6:.1f} M")
    print(f"projected wall time of a {args.push} s push: {steps_push * per_step:.0f} s")
    if len(runs) > 1:
        print(f"per step in each of the {len(runs)} runs (median reported above): "
              + ", ".join(f"{w / args.steps * 1e3:.3f}" for w, _, _ in runs) + " ms")
    print(f"candidate rebuilds: {contact.n_rebuilds}; tip at x = {sim.state['scope'].x[scope.tip_node, 0]:.4f} m")


if __name__ == "__main__":
    main()
