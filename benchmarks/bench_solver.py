"""Speed of the explicit solver on the issue's reference model.

A 60 cm straight tube (lumen D = 36 mm, wall 2 mm, 3 mm triangles, end rings fixed) with a
70 cm standard scope (12.8 mm, E = 16 MPa, 2944 kg/m^3, nodes every 5 mm) whose distal 25 cm lie
on the lumen floor under the scope's weight, guided by a sheath before the tube entry and pushed
at 60 cm/s with friction mu = 0.1. After a warm-up
(Numba compilation and the first candidate build) it times a number of steps and prints the
per-step time, element updates per second per core
((triangles + hinges + rod segments + contact candidates) * steps / wall / cores) and the
projected wall time of a 0.5 s simulated push at the solver's time step.

Run: ``python benchmarks/bench_solver.py [--steps 2000] [--threads 2] [--mesh 3e-3] [--rod-spacing 5e-3] [--repeat 1]
[--devices] [--engines] [--elements] [--baseline CHECKOUT | --baseline-python PYTHON]``

``--engines`` builds the model twice in this process, once with the wall's element-by-element
force kernel (the engine before the blocked kernel, ``Shell.force_kernel = "elementwise"``) and
once with today's, alternates their timed runs and prints both per-step times, their ratio and
whether the final positions are identical (they are: the two kernels do the same arithmetic).
``--elements`` prints the CPU time of one triangle and one hinge in each of the two kernels
(membrane and hinge passes timed apart, alternately, at the final positions).

``--devices`` gives the scope the insertion's quasi-static devices (docs/model.md, "Time
integration and damping": implicit axial and lateral damping instead of mass damping, the
sheath's lip), so the per-step time is that of today's insertions.

On a shared machine single timings vary by +-15 %: ``--repeat 5`` times five runs of ``--steps``
steps each (one model, continuing in time) and reports the median. ``--baseline`` builds the same
model with another checkout's engine in the same process and alternates their timed runs, so both
see the same machine load; it prints the ratio and whether the final positions are identical.
It needs the layout before the one-package restructure (two ``colonsim`` packages cannot share a
process): for a later checkout, ``--baseline-python`` names the Python of an environment where
that checkout is installed (``pip install -e CHECKOUT`` in a venv); this script then runs in it
as a child process that builds the same model and times its runs when told, alternating with
this process's runs, and the two compare the final positions through a file.
"""

import argparse
import importlib
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import numba
import numpy as np

# Where the engine's names live: this checkout, and the layout before the one-package restructure
# (top-level insertion/, commit 49ddc62 and earlier), which can be imported beside it for --baseline.
CURRENT = {"RodShellContact": "colonsim.insertion.engine.contact", "REFERENCE_MATERIAL_PATH": "colonsim.data",
           "load_material": "colonsim.insertion.engine.material", "Rod": "colonsim.insertion.engine.rod",
           "straight_tube": "colonsim.insertion.engine.sheet_mesh", "Shell": "colonsim.insertion.engine.shell",
           "FixedNodes": "colonsim.insertion.engine.constraints", "LineConstraint": "colonsim.insertion.engine.constraints",
           "NodalLoad": "colonsim.insertion.engine.constraints",
           "PrescribedVelocity": "colonsim.insertion.engine.constraints",
           "ExplicitSolver": "colonsim.insertion.engine.solver"}
BEFORE_PACKAGE = {"RodShellContact": "insertion.contact", "REFERENCE_MATERIAL_PATH": "insertion.material",
                  "load_material": "insertion.material", "Rod": "insertion.rod", "straight_tube": "insertion.sheet_mesh",
                  "Shell": "insertion.shell", "FixedNodes": "insertion.solver", "LineConstraint": "insertion.solver",
                  "NodalLoad": "insertion.solver", "PrescribedVelocity": "insertion.solver",
                  "ExplicitSolver": "insertion.solver"}


def engine(layout):
    """The engine's classes and functions, imported from ``layout`` (a name -> module map)."""
    return SimpleNamespace(**{name: getattr(importlib.import_module(module), name) for name, module in layout.items()})


def baseline_engine(checkout):
    """The engine of another checkout in the layout before the one-package restructure."""
    if not (Path(checkout) / "insertion" / "solver.py").is_file():
        sys.exit(f"--baseline {checkout}: not a checkout with insertion/solver.py (the layout before the colonsim "
                 "package; e.g. `git worktree add /tmp/base 49ddc62`)")
    sys.path.insert(0, str(checkout))
    return engine(BEFORE_PACKAGE)


LUMEN = 0.036
WALL = 2e-3
TUBE_LENGTH = 0.6
SCOPE_LENGTH = 0.7
SCOPE_D = 12.8e-3


def build(e, mesh_size=3e-3, rod_spacing=5e-3, friction=0.1, devices=False):
    """The reference model built with engine ``e``: solver, shell, rod, contact (``devices``: the
    scope with the insertion's quasi-static damping and the sheath's lip, which needs this checkout)."""
    nodes, tri, ring = e.straight_tube(TUBE_LENGTH, LUMEN + WALL, mesh_size)
    colon = e.Shell(nodes, tri, WALL, e.load_material(e.REFERENCE_MATERIAL_PATH), density=1040.0, name="colon")
    ends = np.flatnonzero((ring == 0) | (ring == ring.max()))
    # scope axis on the lumen floor, 0.1 mm into the contact layer so the contact is active
    reach = 0.5 * SCOPE_D + 0.5 * WALL
    y_axis = -(0.5 * (LUMEN + WALL) - reach + 1e-4)
    start = (0.25 - SCOPE_LENGTH, y_axis, 0.0)
    extra = {}
    if devices:
        from colonsim.insertion.case.insertion_case import InsertionCase

        case = InsertionCase()
        extra = {"damping_time": case.scope_axial_damping_s, "lateral_damping": case.scope_lateral_damping}
    scope = e.Rod.straight(SCOPE_LENGTH, SCOPE_D, 16e6, 2944.0, spacing=rod_spacing, start=start, **extra)
    contacts = [e.RodShellContact(scope, colon, friction=friction)]
    if devices:
        from colonsim.insertion.engine.sheath_lip import SheathLip

        contacts.append(SheathLip(scope, start, (1.0, 0.0, 0.0), -start[0] - 0.005))
    push = e.PrescribedVelocity(scope, [0], (0.6, 0.0, 0.0), ramp=0.02)
    sheath = e.LineConstraint(scope, start, (1.0, 0.0, 0.0), extent=(-1.0, -start[0] - 0.005))
    weight = e.NodalLoad(scope, np.arange(scope.n_nodes), np.outer(scope.mass * 9.81, (0.0, -1.0, 0.0)))
    sim = e.ExplicitSolver(
        [scope, colon],
        contacts=contacts,
        constraints=[e.FixedNodes(colon, ends), push, sheath],
        loads=[weight],
        damping={"colon": 20.0, "scope": 0.0 if devices else 20.0},
    )
    return sim, colon, scope, contacts[0]


class TimedModel:
    """The reference model of one engine, warmed up, timed in runs of a number of steps."""

    def __init__(self, e, args, force_kernel=None):
        t0 = time.perf_counter()
        self.sim, self.colon, self.scope, self.contact = build(e, mesh_size=args.mesh, rod_spacing=args.rod_spacing,
                                                               devices=args.devices)
        if force_kernel is not None:
            self.colon.force_kernel = force_kernel
        for _ in range(20):  # compile and build the candidate list
            self.sim.advance()
        self.warm = time.perf_counter() - t0
        self.runs = []  # (wall, candidates, shell time) of each timed run
        self._shell_time = 0.0
        shell_forces = self.colon.internal_forces

        def timed_shell_forces(x, f):  # the wall's internal forces (membrane + hinges) inside the run
            t = time.perf_counter()
            energy = shell_forces(x, f)
            self._shell_time += time.perf_counter() - t
            return energy

        self.colon.internal_forces = timed_shell_forces

    def run(self, steps):
        cand = 0
        self._shell_time = 0.0
        t0 = time.perf_counter()
        for _ in range(steps):
            self.sim.advance()
            cand += self.contact.n_candidates
        self.runs.append((time.perf_counter() - t0, cand, self._shell_time))

    def median(self):
        return sorted(self.runs)[len(self.runs) // 2]


def serve(model, args):
    """The child of ``--baseline-python``: time a run of N steps for every line "N" on stdin, print
    its wall time; at end of input, save the final positions to the file ``--serve`` names."""
    print("ready", flush=True)
    for line in sys.stdin:
        model.run(int(line))
        print(model.runs[-1][0], flush=True)
    np.savez(args.serve, colon=model.sim.state["colon"].x, scope=model.sim.state["scope"].x)


class ChildModel:
    """The reference model in a child process running another environment's engine."""

    def __init__(self, args):
        import subprocess
        import tempfile

        self._positions = Path(tempfile.mkdtemp()) / "baseline_positions.npz"
        command = [str(args.baseline_python), __file__, "--serve", str(self._positions), "--mesh", str(args.mesh),
                   "--rod-spacing", str(args.rod_spacing)] + (["--threads", str(args.threads)] if args.threads else []) \
            + (["--devices"] if args.devices else [])  # the same model on both sides
        self._child = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        if self._child.stdout.readline().strip() != "ready":
            sys.exit(f"--baseline-python {args.baseline_python}: the child did not start (see its error above)")
        self.runs = []

    def run(self, steps):
        self._child.stdin.write(f"{steps}\n")
        self._child.stdin.flush()
        self.runs.append(float(self._child.stdout.readline()))

    def finish(self):
        self._child.stdin.close()
        self._child.wait()
        x = np.load(self._positions)
        return sorted(self.runs)[len(self.runs) // 2], {"colon": x["colon"], "scope": x["scope"]}


def element_costs(colon, x, repeat=15, calls=20):
    """Median seconds per triangle and per hinge of the wall's membrane and hinge passes, for the
    element-by-element kernel and the blocked one, timed alternately in this process (CPU time,
    which a shared machine disturbs less than wall time) at the positions ``x``."""
    from colonsim.insertion.engine.shell_forces import internal_forces, triangle_reference

    tri, hinges, stiffness, theta0 = colon.triangles, colon.hinges, colon.hinge_stiffness, colon.theta0
    ref = triangle_reference(colon.dm_inv, colon.area0, colon.thickness)
    out = np.zeros((1,) + x.shape)
    energy = np.zeros((1, 2))
    count = np.zeros((1, 2), dtype=np.int64)

    def structure(blocked):
        def call(nt, nh):
            internal_forces(x, tri[:nt], ref[:, :nt], colon._law, colon._law_params, hinges[:nh], stiffness[:nh],
                            theta0[:nh], out, False, energy, count, blocked)
        return call

    passes = {"membrane": (len(tri), 0), "hinges": (0, len(hinges))}
    times = {(k, p): [] for k in ("elementwise", "blocked") for p in passes}
    for _ in range(repeat):
        for kernel_name, kernel in (("elementwise", structure(False)), ("blocked", structure(True))):
            for p, sizes in passes.items():
                kernel(*sizes)
                t0 = time.process_time()
                for _ in range(calls):
                    kernel(*sizes)
                times[kernel_name, p].append((time.process_time() - t0) / calls / max(sizes))
    return {key: float(np.median(v)) for key, v in times.items()}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=2000, help="timed steps")
    parser.add_argument("--threads", type=int, default=None, help="Numba threads (default: all)")
    parser.add_argument("--push", type=float, default=0.5, help="simulated push duration to project, s")
    parser.add_argument("--mesh", type=float, default=3e-3, help="wall triangle size, m")
    parser.add_argument("--rod-spacing", type=float, default=5e-3, help="scope node spacing, m")
    parser.add_argument("--repeat", type=int, default=1, help="timed runs of --steps steps; the median is reported")
    parser.add_argument("--devices", action="store_true", help="the scope with the insertion's quasi-static devices")
    parser.add_argument("--elements", action="store_true",
                        help="the cost of one triangle and one hinge in each wall kernel (one thread)")
    parser.add_argument("--engines", action="store_true",
                        help="also the wall's element-by-element force kernel (the engine before the blocked one), "
                             "timed run for run alternately in this process")
    parser.add_argument("--baseline-python", type=Path, default=None,
                        help="the Python of an environment with another (package-layout) checkout installed: it "
                             "runs the same model in a child process, timed run for run alternately")
    parser.add_argument("--serve", type=Path, default=None, help=argparse.SUPPRESS)  # the child of --baseline-python
    parser.add_argument("--baseline", type=Path, default=None,
                        help="a checkout in the layout before the colonsim package (e.g. commit 49ddc62): its "
                             "engine runs the same model in this process, timed run for run alternately")
    args = parser.parse_args()
    if args.threads:
        numba.set_num_threads(args.threads)
    cores = numba.get_num_threads()
    model = TimedModel(engine(CURRENT), args)
    if args.serve:
        return serve(model, args)
    base = TimedModel(baseline_engine(args.baseline), args) if args.baseline else None
    before = TimedModel(engine(CURRENT), args, force_kernel="elementwise") if args.engines else None
    child = ChildModel(args) if args.baseline_python else None
    for _ in range(max(args.repeat, 1)):
        model.run(args.steps)
        if base is not None:
            base.run(args.steps)
        if before is not None:
            before.run(args.steps)
        if child is not None:
            child.run(args.steps)
    sim, colon, scope, contact = model.sim, model.colon, model.scope, model.contact
    wall, cand, shell_wall = model.median()
    elements = len(colon.triangles) + len(colon.hinges) + len(scope.segments)
    per_step = wall / args.steps
    updates = (elements * args.steps + cand) / wall / cores
    steps_push = args.push / sim.dt
    print(f"model: {len(colon.triangles)} triangles, {len(colon.hinges)} hinges, {len(scope.segments)} rod segments, "
          f"{contact.n_candidates} contact candidates ({contact.n_active} in contact), {cores} thread(s)")
    print(f"warm-up (compile + first steps): {model.warm:.1f} s")
    limits = {b.name: b.critical_time_step(sim.state[b.name].x) for b in sim.bodies}
    limits["contact"] = contact.critical_time_step()
    print(f"time step: {sim.dt:.3e} s  ->  {steps_push:.0f} steps for a {args.push} s push "
          f"(stable steps alone: " + ", ".join(f"{k} {v:.2e} s" for k, v in limits.items()) + ")")
    print(f"per step: {per_step * 1e3:.3f} ms over {args.steps} steps (simulated {sim.time:.4f} s); "
          f"wall internal forces ~{100 * shell_wall / wall:.0f} % of it")
    print(f"element updates per second per core: {updates / 1e6:.1f} M")
    print(f"projected wall time of a {args.push} s push: {steps_push * per_step:.0f} s")
    if len(model.runs) > 1:
        print(f"per step in each of the {len(model.runs)} runs (median reported above): "
              + ", ".join(f"{w / args.steps * 1e3:.3f}" for w, _, _ in model.runs) + " ms")
    print(f"candidate rebuilds: {contact.n_rebuilds}; tip at x = {sim.state['scope'].x[scope.tip_node, 0]:.4f} m")
    if child is not None:
        child_wall, child_x = child.finish()
        same = np.array_equal(sim.state["colon"].x, child_x["colon"]) and np.array_equal(sim.state["scope"].x,
                                                                                           child_x["scope"])
        print(f"baseline {args.baseline_python}: per step {child_wall / args.steps * 1e3:.3f} ms (runs "
              + ", ".join(f"{w / args.steps * 1e3:.3f}" for w in child.runs) + " ms); this checkout / baseline = "
              f"{wall / child_wall:.3f}; final positions {'identical' if same else 'DIFFER'}")
    if base is not None:
        base_wall = base.median()[0]
        same = np.array_equal(sim.state["colon"].x, base.sim.state["colon"].x) and np.array_equal(
            sim.state["scope"].x, base.sim.state["scope"].x)
        print(f"baseline {args.baseline}: per step {base_wall / args.steps * 1e3:.3f} ms (runs "
              + ", ".join(f"{w / args.steps * 1e3:.3f}" for w, _, _ in base.runs) + " ms); this checkout / baseline = "
              f"{wall / base_wall:.3f}; final positions {'identical' if same else 'DIFFER'}")

    if before is not None:
        same = all(np.array_equal(sim.state[n].x, before.sim.state[n].x) for n in ("colon", "scope"))
        before_wall, _, before_shell = before.median()
        print(f"before the blocked wall kernel (elementwise): per step {before_wall / args.steps * 1e3:.3f} ms, wall "
              f"internal forces {before_shell / args.steps * 1e3:.3f} ms (runs "
              + ", ".join(f"{w / args.steps * 1e3:.3f}" for w, _, _ in before.runs) + " ms); today's: per step "
              f"{per_step * 1e3:.3f} ms, wall internal forces {shell_wall / args.steps * 1e3:.3f} ms; today / before = "
              f"{wall / before_wall:.3f} per step, {shell_wall / before_shell:.3f} wall forces; final positions "
              f"{'identical' if same else 'DIFFER'}")

    if args.elements:
        costs = element_costs(colon, sim.state["colon"].x)
        print("per element, CPU time, median: " + "; ".join(
            f"{kernel} {part} {costs[kernel, part] * 1e9:.1f} ns" for kernel, part in costs)
            + f"; blocked / elementwise: membrane {costs['blocked', 'membrane'] / costs['elementwise', 'membrane']:.3f}, "
            f"hinges {costs['blocked', 'hinges'] / costs['elementwise', 'hinges']:.3f}")


if __name__ == "__main__":
    main()
