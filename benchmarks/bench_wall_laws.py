"""What each wall law costs the shell: internal forces and stable time step per call.

Run: NUMBA_NUM_THREADS=1 python benchmarks/bench_wall_laws.py

A flat 30 x 10 cm sheet of 3 mm triangles (the colon models' default size), stretched 10 % and
slightly crumpled, made of each law's verification material
(:data:`colonsim.insertion.study.law_checks.CHECK_MATERIALS`); best of 5 repetitions of 100
force evaluations (membrane and hinges, one fused kernel) and of 20 time-step estimates, on the
threads numba has. The invariant laws cost about the same; Ogden's law pays for its powers
``l^alpha_p`` (three per term and triangle).
"""

import time

import numpy as np

from colonsim.insertion.engine.sheet_mesh import flat_sheet
from colonsim.insertion.engine.shell import Shell
from colonsim.insertion.study.law_checks import CHECK_MATERIALS


def best_time(call, repeat, reps=5):
    """Shortest mean time of ``repeat`` calls over ``reps`` tries, s."""
    best = np.inf
    for _ in range(reps):
        t0 = time.perf_counter()
        for _ in range(repeat):
            call()
        best = min(best, (time.perf_counter() - t0) / repeat)
    return best


def main():
    nodes, tri = flat_sheet(0.3, 0.1, 3e-3)
    print(f"{len(tri)} triangles, {len(nodes)} nodes")
    for law, material in CHECK_MATERIALS.items():
        shell = Shell(nodes, tri, 0.002, material)
        x = np.ascontiguousarray(shell.x0 * [1.1, 0.95, 1.0]
                                 + 1e-4 * np.random.default_rng(1).standard_normal(shell.x0.shape))
        f = np.zeros_like(x)
        shell.internal_forces(x, f)  # compile
        shell.critical_time_step(x)
        forces = best_time(lambda: shell.internal_forces(x, f), 100)
        step = best_time(lambda: shell.critical_time_step(x), 20)
        print(f"{law:>16}: internal forces {forces * 1e3:.3f} ms, stable time step {step * 1e3:.3f} ms")


if __name__ == "__main__":
    main()
