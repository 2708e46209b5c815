"""Insertion end to end: wall time of one RSJ D = 36 mm SDC insertion, and the RSJ table of
SPEC.md 2.5 (points A and C, 3 scopes x 2 diameters, mu = 0) side by side with the source.

Run: python benchmarks/bench_insertion.py [--quick] [--threads N]
(--quick: only the timed SDC run). Target of issue 4: one RSJ D36 SDC insertion under 60 s wall
on the 2-core machine (the source: 100 minutes with LS-DYNA on 4 cores).
"""

import argparse
import time

import numba

from insertion.scenario import InsertionCase, run_insertion

REFERENCE = {  # SPEC.md 2.5, colon deformation in cm at points A and C (final = C), mu = 0
    ("utc", 23): (1.353, 2.575), ("utc", 36): (1.319, 2.389),
    ("pdc", 23): (2.155, 3.384), ("pdc", 36): (1.992, 3.077),
    ("sdc", 23): (3.218, 4.234), ("sdc", 36): (2.651, 3.824),
}


def fmt(v):
    return "  -  " if v is None else f"{v:5.2f}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--threads", type=int, default=None)
    parser.add_argument("--exit-length", type=float, default=0.0, help="RSJ fixed exit piece, mm (0: SPEC.md's model)")
    args = parser.parse_args()
    if args.threads:
        numba.set_num_threads(args.threads)
    print(f"numba threads: {numba.get_num_threads()}")
    run_insertion(InsertionCase(segment="straight", scope="sdc", element_size_mm=6.0))  # compile / cache warm-up
    t0 = time.perf_counter()
    r = run_insertion(InsertionCase(segment="rsj", scope="sdc", diameter_mm=36.0, exit_length_mm=args.exit_length))
    wall = time.perf_counter() - t0
    s = r.summary
    print(f"RSJ D36 SDC end to end: {wall:.1f} s wall (build {s['build_time_s']:.1f} s, {s['steps']} steps, "
          f"{1e3 * s['wall_time_s'] / s['steps']:.2f} ms/step, mesh {s['mesh']['wall_nodes']} nodes / "
          f"{s['mesh']['wall_triangles']} triangles)   (target < 60 s; source 100 min)")
    if args.quick:
        return
    print(f"\nRSJ colon deformation [cm], mu = 0, exit length {args.exit_length:g} mm: this project vs the source (LS-DYNA)")
    print(f"{'case':>9} | {'A ours':>6} {'A src':>6} | {'C ours':>6} {'C src':>6} | {'final':>6} {'max':>6} | C>A  quasi-static(colon/scope)")
    for (scope, d), (a_ref, c_ref) in REFERENCE.items():
        s = r.summary if (scope, d) == ("sdc", 36) else run_insertion(InsertionCase(segment="rsj", scope=scope, diameter_mm=d,
                                                                                       exit_length_mm=args.exit_length)).summary
        p = s["points_cm"]
        a = p["A"]["deformation_cm"] if p["A"] else None
        c = p["C"]["deformation_cm"] if p["C"] else None
        qs = s["quasi_static"]["fraction_below_10pct"]
        c_gt_a = "-" if a is None or c is None else ("yes" if c > a else "no")
        print(f"{scope.upper()} D{d:>3} | {fmt(a):>6} {a_ref:6.3f} | {fmt(c):>6} {c_ref:6.3f} | {s['final_deformation_cm']:6.2f} "
              f"{s['max_deformation_cm']:6.2f} | {c_gt_a:>3}  {100 * qs['colon']:.0f} % / {100 * qs['scope']:.0f} %")


if __name__ == "__main__":
    main()
