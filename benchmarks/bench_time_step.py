"""How far below the true stability limit the solver's time step lies (docs/model.md, "Time
integration and damping", "Cost").

The solver steps at ``time_step_factor`` (0.9) times a conservative estimate of the stable step:
per body 2 / omega_max with omega_max^2 bounded by element or Gershgorin bounds (the wall: the
membrane's element bound plus the hinges' row bound; the scope: its exact banded eigenvalue),
plus the contact and lip springs' bounds on the same body. This benchmark runs each case of the
insertion (the real run, its end rules and held push included) to a state in mid-push and there

- prints the pieces of the estimate (s): the scope alone, the wall's membrane and hinge bounds,
  the wall alone from a Lanczos eigenvalue of its linearised stiffness (central differences of
  its internal forces, held nodes out), the step the run was using, and the stable step of the
  global estimate (``time_step_estimate = "global"``, its power iteration run to convergence),
  and the same with the scope held still: the step the wall and its contact springs alone would
  stand, the most that subcycling the scope could give the wall (:func:`wall_without_scope`);
- runs copies of that state at fixed steps of k times the estimate (k = 1.0, 1.1, ... until one
  diverges, ``--steps`` steps each) and prints the largest k that stayed stable and the first
  that diverged (the solver's divergence guard: mechanical energy above 10 times what was put
  in). An instability just above the limit grows slowly, so "stable over N steps" brackets the
  limit from below only as far as N steps can tell.

Run: ``NUMBA_NUM_THREADS=1 python benchmarks/bench_time_step.py [--cases rsj rsf thf] [--steps 4000]
[--out bench_time_step.csv]`` (about 6 minutes for the three cases on one core).
"""

from __future__ import annotations

import argparse
import copy
import math
import time

import numpy as np
import pandas as pd

from colonsim.errors import ColonsimError
from colonsim.insertion.case import scenario
from colonsim.insertion.case.insertion_case import InsertionCase
from colonsim.insertion.engine.contact import RodShellContact
from colonsim.insertion.engine.global_time_step import GlobalTimeStep, stiffness_action

# each case and the simulated time (s) of its probed state: in the RSJ the tip rounds the sigmoid,
# in RSF and THF the mobile colon is free and the scope pushes through the flexure
CASES = {
    "rsj": ({"segment": "rsj", "scope": "13.3", "diameter_mm": 36.0}, 1.6),
    "rsf": ({"segment": "rsf", "scope": "13.3", "angle_deg": 45.0}, 5.0),
    "thf": ({"segment": "thf", "scope": "13.3", "angle_deg": 45.0}, 4.5),
}
MULTIPLES = [round(1.0 + 0.1 * i, 1) for i in range(11)]


class _Probed(Exception):
    """Raised from the progress callback to stop the run at the probed time."""


def state_at(fields: dict, t_probe: float):
    """The insertion of ``fields`` run by :func:`scenario.run_insertion` to the first chunk end at or
    after ``t_probe`` s; returns its model (bodies, contacts, solver)."""
    built = []
    build = scenario.build_insertion

    def capture(case):
        built.append(build(case))
        return built[-1]

    def stop(t, tip_arc, tip_end):
        if t >= t_probe:
            raise _Probed

    scenario.build_insertion = capture
    try:
        scenario.run_insertion(InsertionCase(**fields), progress=stop)
    except _Probed:
        return built[-1]
    finally:
        scenario.build_insertion = build
    raise ColonsimError(f"the run of {fields} ended before {t_probe} s; probe an earlier time")


def wall_lanczos(shell, x, free):
    """Largest eigenvalue of M^-1/2 K M^-1/2 of the wall's free nodes (rad^2/s^2), K from central
    differences of its internal forces."""
    from scipy.sparse.linalg import LinearOperator, eigsh

    msq = np.sqrt(shell.mass)[:, None]

    def matvec(flat):
        v = flat.reshape(x.shape).copy()
        v[~free] = 0.0
        kv = stiffness_action(shell, x, v / msq) / msq
        kv[~free] = 0.0
        return kv.ravel()

    n = x.size
    return float(eigsh(LinearOperator((n, n), matvec=matvec, dtype=float), k=1, which="LA", tol=1e-4,
                       maxiter=5000, v0=np.random.default_rng(0).standard_normal(n))[0][0])


def wall_without_scope(solver, scope):
    """Stable step (s) of the coupled system with every node of ``scope`` held still, by the global
    estimate's power iteration run to convergence: the wall and the contact springs it shares
    with the scope (grounded), the step a wall stepped apart from a subcycled scope would need."""
    state = solver.state[scope]
    fixed = state.fixed.copy()
    state.fixed[:] = 1
    try:
        return 2.0 / math.sqrt(GlobalTimeStep(first_iterations=500, tolerance=1e-8).omega2(solver))
    finally:
        state.fixed[:] = fixed


def stable_over(solver, step, n_steps):
    """True if a copy of ``solver`` runs ``n_steps`` fixed steps of ``step`` s without diverging."""
    probe = copy.deepcopy(solver)
    probe.fixed_time_step = step
    probe.dt = step
    try:
        for _ in range(n_steps):
            probe.advance()
    except ColonsimError:
        return False
    return True


def probe(name, n_steps):
    fields, t_probe = CASES[name]
    t0 = time.perf_counter()
    model = state_at(fields, t_probe)
    solver = model.solver
    wall_x = solver.state[model.shell.name].x
    estimate = solver.stable_time_step()
    membrane, hinges = model.shell.frequency_bounds(wall_x)
    true_wall = wall_lanczos(model.shell, wall_x, solver.state[model.shell.name].fixed == 0)
    contact = next(c for c in solver.contacts if isinstance(c, RodShellContact)).frequency_squared()
    scope_w2 = (2.0 / model.rod.critical_time_step(solver.state[model.rod.name].x)) ** 2
    global_w2 = GlobalTimeStep(first_iterations=500, tolerance=1e-8).omega2(solver, floor=scope_w2)
    wall_alone = wall_without_scope(solver, model.rod.name)
    stable, diverged = None, None
    for k in MULTIPLES:
        if stable_over(solver, k * estimate, n_steps):
            stable = k
        else:
            diverged = k
            break
    row = {
        "case": name, "time_s": solver.time, "step_in_use_s": solver.dt, "estimate_s": estimate,
        "scope_alone_s": model.rod.critical_time_step(solver.state[model.rod.name].x),
        "wall_bound_s": 2.0 / math.sqrt(membrane + hinges), "wall_membrane_bound_s": 2.0 / math.sqrt(membrane),
        "wall_hinge_bound_s": 2.0 / math.sqrt(hinges), "wall_lanczos_s": 2.0 / math.sqrt(true_wall),
        "wall_with_contact_bound_s": 2.0 / math.sqrt(membrane + hinges + contact[model.shell.name]),
        "wall_lanczos_with_contact_s": 2.0 / math.sqrt(true_wall + contact[model.shell.name]),
        "global_estimate_s": 2.0 / math.sqrt(global_w2), "wall_and_springs_scope_held_s": wall_alone,
        "largest_stable_multiple": stable, "first_diverged_multiple": diverged, "steps_per_trial": n_steps,
    }
    print(f"{name} at {solver.time:.3f} s (run and probed in {time.perf_counter() - t0:.0f} s): step in use "
          f"{solver.dt:.3e} s, estimate {estimate:.3e} s; scope alone {row['scope_alone_s']:.3e} s; wall bound "
          f"{row['wall_bound_s']:.3e} s (membrane {row['wall_membrane_bound_s']:.3e}, hinges "
          f"{row['wall_hinge_bound_s']:.3e}), wall alone by Lanczos {row['wall_lanczos_s']:.3e} s "
          f"(bound / Lanczos {row['wall_lanczos_s'] / row['wall_bound_s']:.2f} in the step); with the contact's wall "
          f"term {row['wall_with_contact_bound_s']:.3e} / {row['wall_lanczos_with_contact_s']:.3e} s", flush=True)
    print(f"  the global estimate (power iteration, converged): {row['global_estimate_s']:.3e} s = "
          f"{row['global_estimate_s'] / estimate:.2f} x the estimate; with the scope held still (the wall and "
          f"its contact springs: what a subcycled scope would leave to the wall): {wall_alone:.3e} s = "
          f"{wall_alone / row['scope_alone_s']:.2f} x the scope's own", flush=True)
    limit = "none diverged" if diverged is None else f"first diverged at {diverged:.1f} x ({diverged * estimate:.3e} s)"
    print(f"  fixed steps over {n_steps} steps: stable up to {stable} x the estimate "
          f"({(stable or 0.0) * estimate:.3e} s), {limit}; the step in use is "
          f"{solver.dt / estimate:.2f} x", flush=True)
    return row


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    parser.add_argument("--steps", type=int, default=4000, help="fixed steps per trial")
    parser.add_argument("--out", default=None, help="CSV of the table")
    args = parser.parse_args(argv)
    rows = [probe(name, args.steps) for name in args.cases]
    if args.out:
        pd.DataFrame(rows).to_csv(args.out, index=False)
        print(f"-> {args.out}")


if __name__ == "__main__":
    main()
