"""Sweep throughput: runs per hour and wall time of a preset on this machine (local process pool).

Run: python benchmarks/bench_sweep.py [--preset thesis|smoke] [--workers N] [--limit N] [--out DIR]
(default: the full thesis preset, 39 insertions at the study's 3 mm mesh, one worker per core;
--limit N runs N cases spread over the preset and extrapolates the full preset's wall time).
Each run starts fresh unless --out names a folder that already holds results (it then resumes,
and only the runs done now are counted).
"""

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")  # this process only waits and writes files

from colonsim.insertion.study.sweep import run_sweep  # noqa: E402
from colonsim.insertion.study.sweep_spec import PRESETS, load_sweep  # noqa: E402
from colonsim.workflows import available_cores  # noqa: E402


def spread(cases, n):
    """``n`` cases spread evenly over the list (so a subset mixes the segments of the preset)."""
    if n >= len(cases):
        return list(cases)
    step = len(cases) / n
    return [cases[int(i * step)] for i in range(n)]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--preset", default="thesis", choices=sorted(PRESETS))
    parser.add_argument("--workers", type=int, default=available_cores())
    parser.add_argument("--limit", type=int, default=None, help="run only N cases spread over the preset")
    parser.add_argument("--out", type=Path, default=None, help="sweep folder (default: a temporary folder)")
    args = parser.parse_args(argv)

    spec = load_sweep(preset=args.preset)
    cases = spread(spec.cases, args.limit) if args.limit else spec.cases
    with tempfile.TemporaryDirectory(prefix="bench_sweep_") as tmp:
        out = args.out or Path(tmp)
        print(f"preset {args.preset}: {len(cases)} of {len(spec.cases)} runs, {args.workers} worker process(es), "
              f"{available_cores()} cores, load average {os.getloadavg()[0]:.1f} at start", flush=True)
        t0 = time.perf_counter()
        report = run_sweep(cases, out, workers=args.workers, spec=spec)
        wall = time.perf_counter() - t0
        table = report.table
    if report.ran == 0:
        print("nothing ran (every case already finished in --out)")
        return 0
    rate = 3600.0 * report.ran / wall
    print(f"{report.ran} runs ({report.ok} ok, {report.failed} failed) in {wall:.1f} s wall: {rate:.0f} runs/hour")
    done = table.dropna(subset=["wall_time_s"])
    for segment, group in done.groupby("segment", sort=False):
        print(f"  {segment:>9}: {len(group)} runs, {group['wall_time_s'].mean():.1f} s per run in a worker "
              f"(min {group['wall_time_s'].min():.1f}, max {group['wall_time_s'].max():.1f})")
    serial = done["wall_time_s"].sum()
    print(f"  sum of run times {serial:.1f} s -> parallel efficiency {serial / (wall * args.workers):.0%} "
          f"on {args.workers} workers (startup, warm-up and file writing included in the wall time)")
    if len(cases) < len(spec.cases):
        print(f"full preset ({len(spec.cases)} runs) estimated at {len(spec.cases) / rate * 60:.0f} min wall "
              f"(from this subset's rate; segments differ in cost)")
    else:
        print(f"full preset {args.preset}: {wall / 60:.1f} min wall")
    for _, row in table[table["status"] == "failed"].iterrows():
        print(f"  failed {row['key']} {row['segment']} {row['scope']}: {row['error']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
