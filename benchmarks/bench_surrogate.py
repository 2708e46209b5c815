"""Speed of the surrogate against the issue's targets.

On a SYNTHETIC table of ``--runs`` runs (default 500) of one segment with five varying inputs
(scope diameter, colon diameter, angle, friction, wall thickness; colonsim.surrogate.synthetic plus a wall
term), it times:

- the fit of every default output (7 GPs, closed-form leave-one-out CV included)  target < 30 s
- one query (mean and std of one output, domain check included), median of many   target < 1 ms
- 10,000 queries in one call (mean and std of one output)                         target < 1 s

and, for information, saving and loading the model files.

Run: ``NUMBA_NUM_THREADS=1 python benchmarks/bench_surrogate.py [--runs 500] [--queries 10000] [--restarts 2]``
(on a shared machine timings vary by +-20 %).
"""

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from colonsim.surrogate.model import SweepSurrogate
from colonsim.surrogate.store import load_surrogate, save_surrogate
from colonsim.surrogate.synthetic import synthetic_outputs, synthetic_sweep


def five_input_table(n_runs, seed=0):
    """SYNTHETIC runs of one segment where all five inputs vary."""
    rng = np.random.default_rng(seed)
    table = synthetic_sweep(n_runs=n_runs, segments=("rsf",), n_failed=0, seed=seed)
    table["diameter_mm"] = rng.uniform(23.0, 36.0, n_runs)
    table["wall_thickness_mm"] = rng.uniform(1.6, 2.4, n_runs)
    out = synthetic_outputs("rsj", table["scope_diameter_mm"], table["diameter_mm"], table["angle_deg"], table["friction"])
    for name, values in out.items():  # all seven outputs defined (points A and C as in RSJ)
        wall = 0.3 * (table["wall_thickness_mm"] - 2.0) if name.endswith("_cm") else 0.0
        table[name] = np.asarray(values) + wall + rng.normal(0.0, 0.02, n_runs)
    return table


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=500)
    parser.add_argument("--queries", type=int, default=10_000)
    parser.add_argument("--restarts", type=int, default=2, help="optimizer restarts per GP (the CLI default, 2)")
    args = parser.parse_args()

    table = five_input_table(args.runs)
    t0 = time.perf_counter()
    model = SweepSurrogate(n_restarts=args.restarts).fit(table)
    fit_s = time.perf_counter() - t0
    n_models = len(model.models_["rsf"])
    print(f"fit: {args.runs} runs, 5 inputs, {n_models} outputs, LOO CV: {fit_s:.2f} s "
          f"({fit_s / n_models:.2f} s per output)   target < 30 s  {'OK' if fit_s < 30 else 'MISSED'}")

    with tempfile.TemporaryDirectory() as folder:
        t0 = time.perf_counter()
        save_surrogate(model, Path(folder) / "model")
        save_s = time.perf_counter() - t0
        t0 = time.perf_counter()
        model = load_surrogate(Path(folder) / "model.json")
        load_s = time.perf_counter() - t0
    print(f"save {1e3 * save_s:.0f} ms, load {1e3 * load_s:.0f} ms (JSON + NPZ, no pickle)")

    query = {"scope": "pdc", "diameter_mm": 30.0, "angle_deg": 30.0, "friction": 0.05, "wall_thickness_mm": 2.0}
    for _ in range(50):
        model.predict(query, "rsf", return_std=True)
    times = []
    for _ in range(2000):
        t0 = time.perf_counter()
        model.predict(query, "rsf", return_std=True)
        times.append(time.perf_counter() - t0)
    one = np.median(times)
    print(f"one query (mean + std, {args.runs} training runs): median {1e3 * one:.3f} ms, "
          f"95th percentile {1e3 * np.percentile(times, 95):.3f} ms   target < 1 ms  {'OK' if one < 1e-3 else 'MISSED'}")

    rng = np.random.default_rng(1)
    n = args.queries
    domain = model.domains_["rsf"]  # queries inside the training domain: no warning
    batch = dict(zip(domain.inputs, rng.uniform(domain.low, domain.high, (n, len(domain.inputs))).T))
    runs = []
    for _ in range(3):
        t0 = time.perf_counter()
        model.predict(batch, "rsf", return_std=True)
        runs.append(time.perf_counter() - t0)
    many = min(runs)
    print(f"{n} queries in one call (mean + std of one output): {many:.3f} s (best of 3)   "
          f"target < 1 s  {'OK' if many < 1.0 else 'MISSED'}")


if __name__ == "__main__":
    main()
