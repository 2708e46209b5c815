"""Where a run's time goes: the steps of a sweep by phase of the manoeuvre, and a step by its parts.

    python benchmarks/bench_budget.py --sweep FOLDER [FOLDER ...]   # a sweep's steps, by phase
    python benchmarks/bench_budget.py --step [--at 0.6] [--threads 1] # one step of RSJ D36 13.3 mm, by part

``--sweep`` reads sweep folders as ``colonsim sweep`` writes them (``results.parquet`` and each run's
``timeseries.csv``; the committed records keep too few columns for this) and prints, per colon
model, the time steps spent in each phase of the manoeuvre (straighten, stop, relax, push, held
push, settle) and their shares of the whole sweep. Two upper bounds of what a push whose speed
follows the loading could save are printed beside them, each the most that candidate could buy
(the ramps between speeds and any slowing it would add are not counted):

- the held push at the full push speed wherever the tip keeps pace with the push (over the last
  centimetre of push it advanced along the lumen by at least 90 % of the push): half of those steps;
- the straightening at twice the push speed: half of its steps.

``--step`` builds the RSJ D36, 13.3 mm case at the default settings, runs it to ``--at`` seconds
(contact has begun by 0.3 s) and times, by CPU time over 2,000 calls each, the solver's whole
step, the wall's internal forces, the scope's, the contacts, and the time-step update (every
``time_step_interval`` steps, its cost per step); "the rest" is the nodal updates, the
constraints and the Python around them. CPU time, so a shared machine disturbs it less; one
process, so the parts are comparable.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pandas as pd

KEEPING_PACE = 0.9  # tip advance over push, over the last centimetre of push
PACE_WINDOW_CM = 1.0
PHASES = ("straighten", "stop", "relax", "push", "held push", "settle")


def run_budget(series: pd.DataFrame) -> dict:
    """Steps by phase of one run's time series (``time_s``, ``step``, ``phase``, ``depth_cm``,
    ``tip_arc_cm``), and the steps of its held push where the tip kept pace with the push."""
    steps = series["step"].diff().fillna(series["step"]).to_numpy()
    budget = {p: float(steps[series["phase"].to_numpy() == p].sum()) for p in PHASES}
    budget["total"] = float(series["step"].iloc[-1])
    held = (series["phase"] == "held push").to_numpy()
    depth, arc = series["depth_cm"].to_numpy(), series["tip_arc_cm"].to_numpy()
    back = np.searchsorted(depth, depth - PACE_WINDOW_CM)  # depth rises: the sample a centimetre of push before
    pushed = depth - depth[back]
    pace = (arc - arc[back]) / np.where(pushed > 0.0, pushed, np.inf)
    keeping = held & (pushed >= 0.9 * PACE_WINDOW_CM) & (pace >= KEEPING_PACE)
    budget["held, keeping pace"] = float(steps[keeping].sum())
    return budget


def sweep_budget(folders) -> pd.DataFrame:
    """One row per run of the sweep ``folders``: its colon model, wall time and steps by phase."""
    rows = []
    for folder in folders:
        table = pd.read_parquet(Path(folder) / "results.parquet")
        for _, row in table[table["status"] == "ok"].iterrows():
            series = pd.read_csv(Path(folder) / "runs" / row["key"] / "timeseries.csv",
                                 usecols=["time_s", "step", "phase", "depth_cm", "tip_arc_cm"])
            rows.append({"model": row["segment"], "wall_time_s": row["wall_time_s"], **run_budget(series)})
    if not rows:
        raise SystemExit("no finished runs in " + ", ".join(map(str, folders)))
    return pd.DataFrame(rows)


def print_sweep(frame: pd.DataFrame) -> None:
    by_model = frame.groupby("model").sum(numeric_only=True)
    by_model.loc["all"] = by_model.sum()
    total = by_model["total"]
    print(f"{len(frame)} runs; steps by phase (thousands) and their share of the model's steps")
    print(f"{'model':10s} {'runs':>5s} {'steps':>8s} " + " ".join(f"{p:>16s}" for p in PHASES))
    counts = frame.groupby("model").size()
    counts.loc["all"] = len(frame)
    for model, row in by_model.iterrows():
        cells = " ".join(f"{row[p] / 1e3:8.0f} ({row[p] / total[model]:5.1%})" for p in PHASES)
        print(f"{model:10s} {counts[model]:5d} {total[model] / 1e3:8.0f} {cells}")
    all_ = by_model.loc["all"]
    pace = 0.5 * all_["held, keeping pace"] / all_["total"]
    straighten = 0.5 * all_["straighten"] / all_["total"]
    print(f"upper bounds of the steps saved: the held push at full speed while the tip keeps pace "
          f"({KEEPING_PACE:.0%} of the push over {PACE_WINDOW_CM:g} cm): {pace:.1%}; the straightening at twice "
          f"the speed: {straighten:.1%}; both: {pace + straighten:.1%}")


def _cpu_us(call, n) -> float:
    t0 = time.process_time()
    for _ in range(n):
        call()
    return (time.process_time() - t0) / n * 1e6


def step_parts(at: float, n: int = 2000) -> dict:
    """CPU time per call, us, of a step and its parts (module docstring), at ``at`` s into the RSJ case."""
    from colonsim.insertion.case.scenario import InsertionCase, build_insertion

    model = build_insertion(InsertionCase(segment="rsj", scope="13.3", diameter_mm=36.0))
    solver = model.solver
    solver.run(at, record_interval=0.001, exact_end=False)
    state = solver.state
    wall, scope = state["colon"], state[model.rod.name]
    parts = {"step": _cpu_us(solver.advance, n),
             "wall internal forces": _cpu_us(lambda: wall.body.internal_forces(wall.x, wall.f_int), n),
             "scope internal forces": _cpu_us(lambda: scope.body.internal_forces(scope.x, scope.f_int), n)}
    for contact in solver.contacts:
        parts[f"contact: {type(contact).__name__}"] = _cpu_us(lambda c=contact: c.compute(state, solver.dt), n)
    parts["time-step update, per step"] = _cpu_us(solver._update_time_step, max(n // 40, 5)) / solver.time_step_interval
    parts["the rest (nodal updates, constraints, Python)"] = parts["step"] - sum(v for k, v in parts.items() if k != "step")
    return parts


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sweep", type=Path, nargs="+", help="sweep folders (results.parquet, runs/*/timeseries.csv)")
    parser.add_argument("--step", action="store_true", help="time one step of RSJ D36 13.3 mm by its parts")
    parser.add_argument("--at", type=float, default=0.6, help="simulated time of the step, s (default 0.6)")
    parser.add_argument("--threads", type=int, default=None, help="Numba threads (default: all)")
    args = parser.parse_args(argv)
    if not args.sweep and not args.step:
        parser.error("give --sweep FOLDER ... and/or --step")
    if args.sweep:
        print_sweep(sweep_budget(args.sweep))
    if args.step:
        if args.threads:
            import numba
            numba.set_num_threads(args.threads)
        parts = step_parts(args.at)
        for name, us in parts.items():
            print(f"{name:48s} {us:8.1f} us  {us / parts['step']:6.1%}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
