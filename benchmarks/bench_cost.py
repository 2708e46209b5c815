"""What a run costs: the wall time of the three representative cases (RSJ D36, RSF alpha 45, THF
beta 45; 13.3 mm scope, mu = 0) with the engine before the blocked wall kernel and today's, in one
process, with their outputs side by side.

"before" runs the wall's internal forces through the element-by-element kernel
(``Shell.force_kernel = "elementwise"``), "today" through the blocked one; everything else is the
same code. Each run's wall time and CPU time (which other processes on a shared machine disturb
less) are printed with the rate check's outputs (A, C, final and largest deformation, largest
lag, peak contact and push forces) and the steps taken; a line per other engine gives the
ratios today / that engine and whether the two runs' recorded time series are identical (the
engines do the same arithmetic, so they are).

Run: ``python benchmarks/bench_cost.py [--quick] [--cases rsj,rsf,thf] [--engines before,today]
[--baseline-python PYTHON] [--threads N] [--time-step-estimate bounds|global]``

"before" differs from "today" by the wall's force kernel only. "paced" is today's engine with
the loading-following held push (``held_push_pace`` = 0.9, off by default): it changes the
answers, so its line also says whether its outputs lie within the rate check's bounds of
today's (deformations and lag 5 %, peak forces 10 %). ``--half-speed`` runs every case at half
its push speed: with it, the rate check of each engine is two invocations. ``--baseline-python`` names the
Python of an environment where an earlier checkout is installed (``pip install -e CHECKOUT`` in a
venv): each case then also runs there, in a child process (this script under that Python), as
engine "baseline": the whole engine of that checkout.

``--quick`` runs the cases on a 6 mm wall mesh (a quarter of the triangles) pushed at 0.6 m/s
(the source's speed: a quarter of the steps) to compare the engines in minutes; its outputs are
not the cases' answers, and the wall's share of a step is smaller than on the cases' mesh. The
full cases take 40-400 s each. On a shared machine compare the engines of one invocation (they
alternate, case by case), never figures from different days.
"""

import argparse
import json
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba

from colonsim.insertion.case.outcomes import DEFORMATION_TOLERANCE, FORCE_FLOOR_N, FORCE_TOLERANCE
from colonsim.insertion.case.scenario import InsertionCase, run_insertion
from colonsim.insertion.study.claims import NO_DEFORMATION_CM
from colonsim.insertion.engine.shell import Shell

CASES = {
    "rsj": {"segment": "rsj", "scope": "13.3", "diameter_mm": 36.0},
    "rsf": {"segment": "rsf", "scope": "13.3", "angle_deg": 45.0},
    "thf": {"segment": "thf", "scope": "13.3", "angle_deg": 45.0},
}
ENGINES = {"before": "elementwise", "today": "blocked", "paced": "blocked"}  # engine -> Shell.force_kernel
# engine -> settings it changes: "paced" is today's engine with the loading-following held push
# (InsertionCase.held_push_pace; docs/model.md, "Distal resistance"), which changes the answers,
# so its outputs are compared with today's against the rate check's bounds
PACED = 0.9
ENGINE_SETTINGS = {"paced": {"held_push_pace": PACED}}
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


def settings(name, args, engine=None):
    """The InsertionCase settings of case ``name`` under the command line's options (and ``engine``'s)."""
    out = dict(CASES[name], time_step_estimate=args.time_step_estimate, **ENGINE_SETTINGS.get(engine, {}))
    if args.quick:
        out.update(QUICK)
    if args.half_speed:
        out["push_speed"] = 0.5 * out.get("push_speed", InsertionCase.push_speed)
    return out


def within_rate_bounds(new, old) -> list:
    """The rate check's outputs where ``new`` departs from ``old`` by more than its bounds
    (deformations and lag 5 % above 0.1 cm, peak forces 10 % above 0.5 N), with the departure."""
    beyond = []
    for column in ("A cm", "C cm", "final cm", "largest cm", "lag cm", "contact N", "push N"):
        force = column.endswith("N")
        floor, bound = (FORCE_FLOOR_N, FORCE_TOLERANCE) if force else (NO_DEFORMATION_CM, DEFORMATION_TOLERANCE)
        a, b = new[column], old[column]
        if math.isnan(a) and math.isnan(b) or max(abs(a), abs(b)) < floor:
            continue
        change = (a - b) / max(abs(b), floor)
        if not abs(change) <= bound:
            beyond.append(f"{column.split()[0]} {change:+.1%}")
    return beyond


def run(name, engine, args):
    """(wall time s, CPU time s, outputs, time series as CSV text) of case ``name`` with ``engine``
    (None: this environment's engine as it comes, for the child of ``--baseline-python``)."""
    if engine is not None:
        Shell.force_kernel = ENGINES[engine]
    t0 = time.perf_counter()
    c0 = time.process_time()
    result = run_insertion(InsertionCase(**settings(name, args, engine)))
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    return wall, cpu, outputs(result.summary), result.timeseries.to_csv(index=False)


def options(args):
    """The options a child process needs to run the same cases."""
    return (["--quick"] if args.quick else []) + (["--half-speed"] if args.half_speed else []) + (
        ["--threads", str(args.threads)] if args.threads else []) + [
        "--time-step-estimate", args.time_step_estimate]


def run_baseline(name, args, folder):
    """Case ``name`` run by ``--baseline-python``'s environment in a child process (this script
    with ``--serve``), its figures read back from ``folder``."""
    command = [str(args.baseline_python), __file__, "--serve", name, "--out", str(folder)] + options(args)
    child = subprocess.run(command, capture_output=True, text=True)
    if child.returncode != 0:
        sys.exit(f"--baseline-python {args.baseline_python}: the child failed on {name}:\n{child.stderr[-3000:]}")
    figures = json.loads((Path(folder) / f"{name}.json").read_text())
    return figures["wall"], figures["cpu"], figures["outputs"], (Path(folder) / f"{name}.csv").read_text()


def serve(args):
    """The child of ``--baseline-python``: warm up, run one case, write its figures to ``--out``."""
    run_insertion(InsertionCase(segment="straight", scope="sdc", element_size_mm=6.0))
    wall, cpu, out, csv = run(args.serve, None, args)
    (args.out / f"{args.serve}.csv").write_text(csv)
    (args.out / f"{args.serve}.json").write_text(json.dumps({"wall": wall, "cpu": cpu, "outputs": out}))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="the cases on a {element_size_mm:g} mm wall mesh pushed at {push_speed:g} m/s".format(**QUICK))
    parser.add_argument("--cases", default=",".join(CASES), help="comma-separated, of " + ", ".join(CASES))
    parser.add_argument("--engines", default=",".join(ENGINES), help="comma-separated, of " + ", ".join(ENGINES))
    parser.add_argument("--baseline-python", type=Path, default=None,
                        help="the Python of an environment with an earlier checkout installed: each case also runs "
                             "there, in a child process, after this process's runs (engine 'baseline')")
    parser.add_argument("--half-speed", action="store_true",
                        help="every case at half its push speed (the rate check's other run)")
    parser.add_argument("--threads", type=int, default=None, help="Numba threads (default: all)")
    parser.add_argument("--time-step-estimate", default=InsertionCase.time_step_estimate, help="bounds or global")
    parser.add_argument("--serve", default=None, help=argparse.SUPPRESS)  # the child of --baseline-python
    parser.add_argument("--out", type=Path, default=None, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.threads:
        numba.set_num_threads(args.threads)
    if args.serve:
        return serve(args)
    names = [c for c in args.cases.split(",") if c]
    engines = [e for e in args.engines.split(",") if e]
    unknown = [c for c in names if c not in CASES] + [e for e in engines if e not in ENGINES]
    if unknown:
        parser.error(f"unknown case or engine {', '.join(unknown)}: cases {', '.join(CASES)}, engines "
                     f"{', '.join(ENGINES)}")
    for engine in engines:  # compile (or load) both kernels before timing
        Shell.force_kernel = ENGINES[engine]
        run_insertion(InsertionCase(segment="straight", scope="sdc", element_size_mm=6.0))
    mesh = "--quick: {element_size_mm:g} mm wall mesh, push {push_speed:g} m/s".format(**QUICK) if args.quick \
        else "the cases' own wall mesh and push"
    print(f"{numba.get_num_threads()} Numba thread(s), {mesh}, time step {args.time_step_estimate}")
    columns = list(outputs({"points_cm": {}, "final_deformation_cm": 0, "max_deformation_cm": 0, "max_lag_cm": 0,
                            "peak_forces_sampled_N": {"contact": 0, "push": 0}, "steps": 0}))
    print(f"{'case':>5} {'engine':>8} {'wall s':>8} {'CPU s':>8} " + " ".join(f"{c:>10}" for c in columns))
    with tempfile.TemporaryDirectory() as folder:
        for name in names:
            runs = {engine: run(name, engine, args) for engine in engines}
            if args.baseline_python:
                runs["baseline"] = run_baseline(name, args, folder)
            for engine, (wall, cpu, out, _) in runs.items():
                print(f"{name:>5} {engine:>8} {wall:8.1f} {cpu:8.1f} " + " ".join(f"{out[c]:10.4g}" for c in columns))
            if "today" in runs:
                w1, c1, _, ts1 = runs["today"]
                for other, (w0, c0, out0, ts0) in runs.items():
                    if other == "today":
                        continue
                    same = "identical" if ts0 == ts1 else "DIFFER"
                    if other in ENGINE_SETTINGS:  # another model setting: judged by the rate check's bounds
                        beyond = within_rate_bounds(out0, runs["today"][2])
                        same += "; outputs " + ("within the rate bounds" if not beyond else "BEYOND the rate "
                                                "bounds: " + ", ".join(beyond))
                    print(f"{name:>5} today/{other}: wall time ratio {w1 / w0:.3f}, CPU time ratio "
                          f"{c1 / c0:.3f}; time series {same}")


if __name__ == "__main__":
    main()
