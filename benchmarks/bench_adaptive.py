"""Adaptive sweep against Latin hypercubes: runs needed for a given surrogate error (RSJ, coarse mesh).

Run: python benchmarks/bench_adaptive.py [--out DIR] [--budget 40] [--first 10] [--batch 2]
     [--criteria variance,error] [--target final_deformation_cm] [--lhs 10,15,20,30,40] [--test 30]
     [--workers 2] [--element-size 5] [--scope-spacing 10]

Domain: RSJ, scope_diameter_mm 9-13.5, diameter_mm 20-40, friction 0-0.1, on a coarse wall mesh
(the smoke size of colonsim.catalog: element 5 mm, scope spacing 10 mm; on 6 mm the thinner
scopes leave the colon through its wall, docs/model.md "Contact"; a benchmark of the designs, not
of the physics). Designs, each a sweep folder under --out (a rerun reuses every finished run):

- ``adaptive`` (criterion variance) and ``adaptive_error``: ``colonsim sweep --adaptive``'s loop,
  a first hypercube of --first runs (the same for both), then batches of --batch chosen by each
  criterion of --criteria, to --budget runs;
- ``lhs_N``: an independent Latin hypercube of N runs for each N of --lhs;
- ``test``: an independent hypercube of --test runs, used only to measure errors.

Two errors of the target (--target, default final_deformation_cm), per design and size: the surrogate's leave-one-out RMSE
(closed form, what the adaptive sweep stops on) and the RMSE of its predictions at the held-out
test runs. The LOO RMSE of an adaptive design is measured on runs chosen where the model was
unsure, so it is pessimistic next to an LHS's; the held-out RMSE compares the designs on equal
terms. For each LHS size N the script reports the runs the adaptive sweep needed to reach the
same error (the first round at or below it) and the ratio to N (the issue's goal: at most 0.5).
Writes bench_adaptive[_TARGET].json, .csv and .png into --out (the suffix for another target; the
adaptive folders then carry it too, the hypercubes and the test runs serve every target).
"""

import argparse
import json
import os
import sys
import time
import warnings
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")  # this process only waits, fits and writes files

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from colonsim.catalog import SMOKE_ELEMENT_MM, SMOKE_SCOPE_SPACING_MM  # noqa: E402
from colonsim.errors import ColonsimWarning  # noqa: E402
from colonsim.insertion.study.adaptive_sweep import AdaptiveSettings, fit_round, run_adaptive_sweep  # noqa: E402
from colonsim.insertion.study.sweep import run_sweep  # noqa: E402
from colonsim.insertion.study.sweep_spec import parse_sweep  # noqa: E402

DEFAULT_TARGET = "final_deformation_cm"
INPUTS = ["scope_diameter_mm", "diameter_mm", "friction"]
SPEC = """
[sweep]
name = "{name}"
seed = {seed}
description = "bench_adaptive: RSJ, element {element} mm, scope spacing {spacing} mm"

[fixed]
segment = "rsj"
element_size_mm = {element}
scope_spacing_mm = {spacing}

[lhs]
samples = {samples}
scope_diameter_mm = [9, 13.5]
diameter_mm = [20, 40]
friction = [0, 0.1]
"""
# Seeds of the designs: each its own hypercube (the adaptive sweep's first round is not one of the LHS).
SEEDS = {"adaptive": 1, "test": 999}


MESH = {"element": SMOKE_ELEMENT_MM, "spacing": SMOKE_SCOPE_SPACING_MM}  # mm (--element-size, --scope-spacing)


def spec(name, seed, samples):
    return parse_sweep(SPEC.format(name=name, seed=seed, samples=samples, **MESH), origin=f"bench_adaptive {name}")


def errors(table, test, target):
    """(LOO RMSE, held-out RMSE, runs, scatter sd, spread) of the surrogate of ``target`` fitted on
    ``table``'s ok runs; the scatter sd is the GP's run-to-run noise, the floor of any held-out
    RMSE, the spread the target's standard deviation over the runs."""
    model, cv = fit_round(table, target, 0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ColonsimWarning)  # test runs outside the box of a small design
        predicted = model.predict(test[INPUTS], "rsj", target)
    held_out = float(np.sqrt(np.mean((predicted - test[target].to_numpy()) ** 2)))
    ok = table["status"] == "ok"
    return (cv["rsj"]["rmse"], held_out, int(ok.sum()), model.models_["rsj"][target].noise_std,
            float(table.loc[ok, target].std()))


def runs_to_reach(curve, level):
    """Fewest runs of the adaptive curve [(runs, error)] at or below ``level`` (None: not within budget)."""
    return next((n for n, e in curve if e <= level), None)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=Path("bench_adaptive_runs"))
    p.add_argument("--budget", type=int, default=40)
    p.add_argument("--first", type=int, default=10)
    p.add_argument("--batch", type=int, default=2)
    p.add_argument("--criteria", default="variance,error")
    p.add_argument("--target", default=DEFAULT_TARGET)
    p.add_argument("--lhs", default="10,15,20,30,40")
    p.add_argument("--test", type=int, default=30)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--element-size", type=float, default=MESH["element"], help="wall element size, mm")
    p.add_argument("--scope-spacing", type=float, default=MESH["spacing"], help="scope node spacing, mm")
    args = p.parse_args(argv)
    MESH.update(element=args.element_size, spacing=args.scope_spacing)
    sizes = [int(s) for s in args.lhs.split(",")]
    target = args.target
    suffix = "" if target == DEFAULT_TARGET else f"_{target}"
    t0 = time.perf_counter()
    kw = dict(workers=args.workers, progress=sys.stderr.isatty(), log=lambda *a: None)

    test = run_sweep(spec("test", SEEDS["test"], args.test).cases, args.out / "test", spec=spec("test", SEEDS["test"], args.test), **kw).table
    test = test[test["status"] == "ok"]
    print(f"test set: {len(test)} ok runs ({time.perf_counter() - t0:.0f} s so far)", flush=True)

    lhs = {}
    for n in sizes:
        s = spec(f"lhs_{n}", 100 + n, n)
        lhs[n] = errors(run_sweep(s.cases, args.out / f"lhs_{n}", spec=s, **kw).table, test, target)
        print(f"LHS {n}: LOO {lhs[n][0]:.4f}, held-out {lhs[n][1]:.4f} ({time.perf_counter() - t0:.0f} s so far)",
              flush=True)

    rows, stopped = [], {}
    for criterion in args.criteria.split(","):
        s = spec("adaptive", SEEDS["adaptive"], args.first)
        folder = args.out / (("adaptive" if criterion == "variance" else f"adaptive_{criterion}") + suffix)
        report = run_adaptive_sweep(s, folder, AdaptiveSettings(args.budget, None, args.batch, target, criterion), **kw)
        stopped[criterion] = report.stopped
        table = report.table.set_index("key")
        chosen = []
        for rnd in report.rounds:  # refit on the runs of the rounds so far: the surrogate the sweep had then
            chosen += [r["key"] for r in rnd["chosen"]]
            loo, held_out, ok, scatter, spread = errors(table.loc[chosen].reset_index(), test, target)
            rows.append({"design": f"adaptive-{criterion}", "runs": len(chosen), "ok": ok, "loo_rmse": loo,
                         "held_out_rmse": held_out, "scatter_sd": scatter, "spread_sd": spread})
        print(f"adaptive ({criterion}): {len(chosen)} runs ({time.perf_counter() - t0:.0f} s so far)", flush=True)
    rows += [{"design": "lhs", "runs": n, "ok": ok, "loo_rmse": loo, "held_out_rmse": ho, "scatter_sd": sd,
              "spread_sd": spread} for n, (loo, ho, ok, sd, spread) in lhs.items()]
    frame = pd.DataFrame(rows)

    comparison = []
    for design, adaptive in frame[frame["design"] != "lhs"].groupby("design", sort=False):
        for n, (loo, held_out, *_) in lhs.items():
            entry = {"design": design, "lhs_runs": n}
            for name, level in (("loo", loo), ("held_out", held_out)):
                need = runs_to_reach(list(zip(adaptive["runs"], adaptive[f"{name}_rmse"])), level)
                entry.update({f"{name}_level": level, f"{name}_adaptive_runs": need,
                              f"{name}_ratio": None if need is None else need / n})
            comparison.append(entry)
    comparison = pd.DataFrame(comparison)

    pd.set_option("display.width", 160)
    print(f"\nerror by design and runs ({target}):")
    print(frame.to_string(index=False, float_format=lambda v: f"{v:.4f}"))
    print("\nadaptive runs needed to reach each LHS's error, and the ratio to the LHS's runs:")
    print(comparison.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    args.out.mkdir(parents=True, exist_ok=True)
    name = f"bench_adaptive{suffix}"
    frame.to_csv(args.out / f"{name}.csv", index=False)
    (args.out / f"{name}.json").write_text(json.dumps({
        "command": "python benchmarks/bench_adaptive.py " + " ".join(argv if argv is not None else sys.argv[1:]),
        "errors": frame.to_dict("records"), "comparison": comparison.astype(object).where(comparison.notna(), None).to_dict("records"),
        "stopped": stopped, "wall_time_s": time.perf_counter() - t0}, indent=1))
    figure(frame, target).savefig(args.out / f"{name}.png", dpi=120)
    print(f"\nwrote {args.out}/{name}.json, .csv, .png ({time.perf_counter() - t0:.0f} s)")


def figure(frame, target):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9, 3.8))
    axes = fig.subplots(1, 2, sharey=True)
    for ax, col, title in zip(axes, ("loo_rmse", "held_out_rmse"), ("leave-one-out RMSE", "held-out RMSE (test runs)")):
        for design, rows in frame.groupby("design", sort=False):
            ax.plot(rows["runs"], rows[col], "s--" if design == "lhs" else "o-",
                    label="Latin hypercubes" if design == "lhs" else design)
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("runs")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel(f"RMSE of {target}")
    axes[0].legend()
    fig.tight_layout()
    return fig


if __name__ == "__main__":
    main()
