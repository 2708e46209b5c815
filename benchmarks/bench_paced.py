"""The paced held push against the unpaced one and at half its speed: its rate check from sweep tables.

    python benchmarks/bench_paced.py --paced DIR/paced_rate [--unpaced benchmarks/records/thesis]

``--paced``: the sweep of ``benchmarks/sweeps/paced_rate.toml`` (``held_push_pace`` = 0.9, each
case at the default push speed and at half of it); ``--unpaced``: a sweep or record of the same
cases at the default speed without the pace (default: the record ``thesis``, the
`thesis` preset at the defaults). Prints, per case at the default speed,
its steps (simulated time, as the push sets the step count) against the unpaced run's, and the
rate check's outputs (A, C, final and largest deformation, largest lag, peak contact and push
forces: the report's ``validation.sections.PAIR_QUANTITIES``) as departures from the unpaced run
and from its own half-speed pair, each against the rate check's bounds (deformations 5 % above
0.1 cm, peak forces 10 % above 0.5 N), every output in every model and without the report's rules
for snap-throughs and neutral end states (the counts are printed beside); ``BEYOND`` marks a
departure outside them.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from colonsim.insertion.case.insertion_case import InsertionCase

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the validation package beside benchmarks/
from validation.sections import PAIR_QUANTITIES  # noqa: E402  (the rate check's outputs, floors and bounds)
from validation.sweeps import relative_change  # noqa: E402

RECORD = Path(__file__).resolve().parent / "records" / "thesis"
CASE = ("segment", "scope", "angle_deg", "diameter_mm", "friction", "distal_resistance_N")


def _table(folder) -> pd.DataFrame:
    table = pd.read_parquet(Path(folder) / "results.parquet")
    return table[table["status"] == "ok"].reset_index(drop=True)


def _key(row) -> tuple:
    return tuple(round(float(row[c]), 6) if c not in ("segment", "scope") else str(row[c]) for c in CASE)


def departures(new, old) -> list:
    """(output, relative departure of ``new`` from ``old``, within the bounds) of each of the rate
    check's outputs (:data:`validation.sections.PAIR_QUANTITIES`, every one in every model) that is
    measurable (above its floor) in either run."""
    out = []
    for column, name, floor, bound in PAIR_QUANTITIES:
        change = relative_change(float(old[column]), float(new[column]), floor)
        if not math.isnan(change):
            out.append((name, change, abs(change) <= bound))
    return out


def _cells(found) -> str:
    shown = [f"{n} {c:+.1%}{'' if ok else ' BEYOND'}" for n, c, ok in found if abs(c) >= 5e-4 or not ok]
    return ", ".join(shown) or "equal (all within 0.05 %)"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--paced", type=Path, required=True, help="the paced_rate sweep folder (results.parquet)")
    parser.add_argument("--unpaced", type=Path, default=RECORD, help="unpaced runs of the same cases at the default "
                                                                     "speed (default: the record thesis)")
    args = parser.parse_args(argv)
    paced, unpaced = _table(args.paced), _table(args.unpaced)
    speed = InsertionCase.push_speed
    fast = paced[np.isclose(paced["push_speed"], speed)]
    slow = {_key(r): r for _, r in paced[np.isclose(paced["push_speed"], 0.5 * speed)].iterrows()}
    plain = {_key(r): r for _, r in unpaced[np.isclose(unpaced["push_speed"], speed)].iterrows()}
    beyond = 0
    for _, row in fast.iterrows():
        key = _key(row)
        name = f"{row['segment']} {row['scope']}" + (f" angle {row['angle_deg']:g}" if row["angle_deg"] else "") + \
            f" D {row['diameter_mm']:g} {row['distal_resistance_N']:g} N"
        line = [name]
        if key in plain:
            base = plain[key]
            line.append(f"simulated {row['simulated_time_s']:.2f} s against {base['simulated_time_s']:.2f} s unpaced "
                        f"({row['simulated_time_s'] / base['simulated_time_s'] - 1:+.1%})")
            found = departures(row, base)
            beyond += sum(not ok for _, _, ok in found)
            line.append("against unpaced: " + _cells(found) + f" (snap-throughs {row['snap_throughs']:g}, unpaced "
                        f"{base['snap_throughs']:g})")
        if key in slow:
            found = departures(slow[key], row)
            beyond += sum(not ok for _, _, ok in found)
            line.append(f"half speed: {_cells(found)} (snap-throughs {slow[key]['snap_throughs']:g})")
        print("; ".join(line))
    print(f"{len(fast)} paced cases at {speed:g} m/s, {len(slow)} at {0.5 * speed:g} m/s; {beyond} departures beyond "
          "the rate bounds")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
