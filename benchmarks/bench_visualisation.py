"""What the wall-stretch map and the animation add to a run's wall time (docs/visualisation.md).

One case run twice in one process, alternately: without (the stretch record switched off, no
snapshots, the run's files without map or movie: the run as it was before them) and with (the
record, snapshots every 0.02 s, the map's files and ``insertion.gif``). Both write the run's
other files. Wall time and this process's CPU time of run + files, each pair measured after a
warm-up run at the smoke size (compiled kernels, imported plotting)::

    python benchmarks/bench_visualisation.py --out /tmp/bench_vis            # RSJ UTC at the defaults
    python benchmarks/bench_visualisation.py --smoke --out /tmp/bench_vis_smoke  # the smoke size
"""

from __future__ import annotations

import argparse
import json
import time
from contextlib import contextmanager
from pathlib import Path

from colonsim.catalog import SMOKE_ELEMENT_MM, SMOKE_PUSH_SPEED, SMOKE_SCOPE_SPACING_MM
from colonsim.insertion.case import results, run_summary, stretch_map
from colonsim.insertion.case.scenario import InsertionCase, run_insertion


@contextmanager
def without_visualisation():
    """The stretch record, its summary entries and its files switched off."""
    saved = (stretch_map.WallStretch.sample, run_summary.wall_stretch_summary, results.map_arrays)
    stretch_map.WallStretch.sample = lambda self, stretches, deformation, wall_contact_force=None: None
    run_summary.wall_stretch_summary = lambda model, ts: {}
    results.map_arrays = lambda result: None
    try:
        yield
    finally:
        stretch_map.WallStretch.sample, run_summary.wall_stretch_summary, results.map_arrays = saved


def timed(case, out, visualise):
    wall, cpu = time.perf_counter(), time.process_time()
    if visualise:
        r = run_insertion(case, snapshot_interval=0.02)
        run_s = time.perf_counter() - wall
        results.write_insertion(r, out, animate=True)
    else:
        with without_visualisation():
            r = run_insertion(case)
            run_s = time.perf_counter() - wall
            results.write_insertion(r, out)
    return {"wall_s": time.perf_counter() - wall, "cpu_s": time.process_time() - cpu, "run_s": run_s,
            "files_s": time.perf_counter() - wall - run_s, "steps": r.summary["steps"],
            "snapshots": len(r.snapshots)}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--smoke", action="store_true", help="the smoke size (5 mm wall, 10 mm scope nodes, 0.6 m/s)")
    parser.add_argument("--pairs", type=int, default=1, help="pairs of runs (without, with)")
    args = parser.parse_args(argv)
    import numba

    numba.set_num_threads(1)
    smoke = dict(element_size_mm=SMOKE_ELEMENT_MM, scope_spacing_mm=SMOKE_SCOPE_SPACING_MM, push_speed=SMOKE_PUSH_SPEED)
    case = InsertionCase(segment="rsj", scope="utc", **(smoke if args.smoke else {}))
    timed(InsertionCase(segment="rsj", scope="utc", **smoke), args.out / "warm", True)  # kernels, imports, fonts
    rows = []
    for k in range(args.pairs):
        for visualise in (False, True):
            row = {"pair": k, "visualised": visualise, **timed(case, args.out / f"{k}_{visualise}", visualise)}
            rows.append(row)
            print(json.dumps(row), flush=True)
    base = [r for r in rows if not r["visualised"]]
    with_ = [r for r in rows if r["visualised"]]
    for key in ("wall_s", "cpu_s"):
        plain, more = sum(r[key] for r in base), sum(r[key] for r in with_)
        print(f"{key}: without {plain:.1f}, with {more:.1f}: {100 * (more / plain - 1):+.1f} %")


if __name__ == "__main__":
    main()
