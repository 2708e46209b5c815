"""A faster straightening push in RSF and THF: what it saves and what it moves, from one sweep.

    python benchmarks/bench_straighten.py DIR/straighten_speed
    python benchmarks/bench_straighten.py benchmarks/records/straighten_speed   # the runs of 2026-12-07

Reads a sweep (or its record) of ``benchmarks/sweeps/straighten_speed.toml`` (each case with
``straighten_speed_factor`` 1, 2 and 3) and prints, per case and factor above 1, the steps the run
took against the same case at factor 1 (each run's ``summary.json``; the push sets
the step count, so this is the saving at an unchanged cost per step), the wall time ratio (a
shared machine disturbs it), the ringing ratio and snap-throughs of both, and the rate check's
outputs as departures from factor 1 against the rate check's bounds (the report's
``validation.sections.PAIR_QUANTITIES``, every output in every model; ``BEYOND`` marks one outside
them). The straightening ends in a relax until the released system is at rest, so a faster
straightening should leave the final push's start, and every answer, where they were.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_paced import _cells, departures  # noqa: E402  (the rate check's outputs against its bounds)

CASE = ("segment", "scope", "angle_deg", "friction")
FACTOR = "straighten_speed_factor"


def steps_of(folder: Path, row) -> int:
    """Time steps of one run, from its ``summary.json`` (a sweep folder or a packed record)."""
    return int(json.loads((folder / row["timeseries_path"]).with_name("summary.json").read_text())["steps"])


def compare(folder: Path) -> tuple[list, int]:
    """One line per case and factor above 1, and the number of departures beyond the bounds."""
    table = pd.read_parquet(folder / "results.parquet")
    table = table[table["status"] == "ok"]
    if FACTOR not in table:
        raise SystemExit(f"bench_straighten: {folder} has no {FACTOR} column; run benchmarks/sweeps/straighten_speed.toml")
    table = table.assign(**{FACTOR: table[FACTOR].fillna(1.0)})
    lines, beyond = [], 0
    for case, runs in table.groupby(list(CASE), sort=True):
        base = runs[runs[FACTOR] == 1.0]
        if base.empty:
            continue
        base = base.iloc[0]
        base_steps = steps_of(folder, base)
        name = f"{case[0]} {case[1]} mm, angle {case[2]:g}, mu {case[3]:g}"
        for _, run in runs[runs[FACTOR] > 1.0].sort_values(FACTOR).iterrows():
            found = departures(run, base)
            beyond += sum(not ok for _, _, ok in found)
            steps = steps_of(folder, run)
            lines.append(f"{name}, x{run[FACTOR]:g}: steps {steps:,} / {base_steps:,} ({steps / base_steps - 1:+.1%}), "
                         f"wall time {run['wall_time_s'] / base['wall_time_s']:.2f}; ringing {run['ringing_ratio']:.3f} / "
                         f"{base['ringing_ratio']:.3f}, snap-throughs {run['snap_throughs']:g} / {base['snap_throughs']:g}; "
                         + _cells(found))
    return lines, beyond


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sweep", type=Path, help="the straighten_speed sweep folder (results.parquet, runs/)")
    args = parser.parse_args(argv)
    lines, beyond = compare(args.sweep)
    print("\n".join(lines))
    print(f"{len(lines)} faster straightenings; {beyond} departures beyond the rate bounds")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
