"""What a run costs: the wall time of the three representative cases (RSJ D36, RSF alpha 45, THF
beta 45; 13.3 mm scope, mu = 0) with the engine before the blocked wall kernel and today's, in one
process, with their outputs side by side.

"before" runs the wall's internal forces through the element-by-element kernel
(``Shell.force_kernel = "elementwise"``), "today" through the blocked one; everything else is the
same code. Each run's wall time and CPU time (which other processes on a shared machine disturb
less) are printed with the rate check's outputs (A, C, final and largest deformation, largest
lag, peak contact and push forces) and the steps taken; a last line per case gives the ratios
today / before and whether the two runs' recorded time series are identical (the two kernels
do the same arithmetic, so they are).

Run: ``python benchmarks/bench_cost.py [--quick] [--cases rsj,rsf,thf] [--engines before,today]
[--threads N] [--time-step-estimate bounds|global]``

``--quick`` runs the cases on a 6 mm wall mesh (a quarter of the triangles) pushed at 0.6 m/s
(the source's speed: a quarter of the steps) to compare the engines in minutes; its outputs are
not the cases' answers, and the wall's share of a step is smaller than on the cases' mesh. The
full cases take 40-400 s each. On a shared machine compare the two engines of one invocation (they alternate,
case by case), never figures from different days.
"""

import argparse
import math
import time

import numba

from colonsim.insertion.case.scenario import InsertionCase, run_insertion
from colonsim.insertion.engine.shell import Shell

CASES = {
    "rsj": {"segment": "rsj", "scope": "13.3", "diameter_mm": 36.0},
    "rsf": {"segment": "rsf", "scope": "13.3", "angle_deg": 45.0},
    "thf": {"segment": "thf", "scope": "13.3", "angle_deg": 45.0},
}
ENGINES = {"before": "elementwise", "today": "blocked"}  # engine -> Shell.force_kernel
QUICK = {"element_size_mm": 6.0, "push_speed": 0.6}  # --quick: coarse wall, fast push


def outputs(summary):
    """The rate check's outputs of a run (cm, N) and its steps."""
    points = summary["points_cm"]
    return {
        "A cm": points["A"]["deformation_cm"] if points.get("A") else math.nan,
        "C cm": points["C"]["deformation_cm"] if points.get("C") else math.nan,
        "final cm": summary["final_deformation_cm"],
        "largest cm": summary["max_deformation_cm"],
        "lag cm": summary["max_lag_cm"],
        "contact N": summary["peak_forces_sampled_N"]["contact"],
        "push N": summary["peak_forces_sampled_N"]["push"],
        "steps": summary["steps"],
    }


def run(name, engine, args):
    """(wall time s, CPU time s, outputs, time series) of case ``name`` with ``engine``."""
    settings = dict(CASES[name], time_step_estimate=args.time_step_estimate)
    if args.quick:
        settings.update(QUICK)
    Shell.force_kernel = ENGINES[engine]
    t0 = time.perf_counter()
    c0 = time.process_time()
    result = run_insertion(InsertionCase(**settings))
    return time.perf_counter() - t0, time.process_time() - c0, outputs(result.summary), result.timeseries


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="the cases on a {element_size_mm:g} mm wall mesh pushed at {push_speed:g} m/s".format(**QUICK))
    parser.add_argument("--cases", default=",".join(CASES), help="comma-separated, of " + ", ".join(CASES))
    parser.add_argument("--engines", default=",".join(ENGINES), help="comma-separated, of " + ", ".join(ENGINES))
    parser.add_argument("--threads", type=int, default=None, help="Numba threads (default: all)")
    parser.add_argument("--time-step-estimate", default=InsertionCase.time_step_estimate, help="bounds or global")
    args = parser.parse_args()
    names = [c for c in args.cases.split(",") if c]
    engines = [e for e in args.engines.split(",") if e]
    unknown = [c for c in names if c not in CASES] + [e for e in engines if e not in ENGINES]
    if unknown:
        parser.error(f"unknown case or engine {', '.join(unknown)}: cases {', '.join(CASES)}, engines "
                     f"{', '.join(ENGINES)}")
    if args.threads:
        numba.set_num_threads(args.threads)
    for engine in engines:  # compile (or load) both kernels before timing
        Shell.force_kernel = ENGINES[engine]
        run_insertion(InsertionCase(segment="straight", scope="sdc", element_size_mm=6.0))
    mesh = "--quick: {element_size_mm:g} mm wall mesh, push {push_speed:g} m/s".format(**QUICK) if args.quick \
        else "the cases' own wall mesh and push"
    print(f"{numba.get_num_threads()} Numba thread(s), {mesh}, time step {args.time_step_estimate}")
    columns = None
    for name in names:
        runs = {engine: run(name, engine, args) for engine in engines}
        if columns is None:
            columns = list(next(iter(runs.values()))[2])
            print(f"{'case':>5} {'engine':>7} {'wall s':>8} {'CPU s':>8} " + " ".join(f"{c:>10}" for c in columns))
        for engine, (wall, cpu, out, _) in runs.items():
            print(f"{name:>5} {engine:>7} {wall:8.1f} {cpu:8.1f} " + " ".join(f"{out[c]:10.4g}" for c in columns))
        if len(runs) == 2:
            (w0, c0, _, ts0), (w1, c1, _, ts1) = runs.values()
            same = ts0.shape == ts1.shape and ts0.equals(ts1)
            print(f"{name:>5} {'/'.join(reversed(runs))}: wall time ratio {w1 / w0:.3f}, CPU time ratio {c1 / c0:.3f}; "
                  f"time series {'identical' if same else 'DIFFER'}")


if __name__ == "__main__":
    main()
