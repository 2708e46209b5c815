"""Held-out calibration of the surrogate (issue: "a surrogate that knows its own error").

Fits the surrogate on training sweeps of RSJ runs at several sizes and scores it with
:func:`colonsim.surrogate.holdout.score` on an independent held-out sweep, without and with the
noise floor measured by replicate runs. Prints, per output and training size, RMSE, Q2, the
coverage of the 50 / 90 / 95 % intervals, the mean and sd of the standardized error and the share
of held-out run pairs whose predicted order holds against the mean probability stated, each
against the acceptance band (95 %: 88-99 %, 50 %: 38-62 %, |mean z| <= 0.3, sd z 0.7-1.4, orders
hold >= stated - 5 points); and the query speed of the fitted model. The largest deformation is
scored as the surrogate models it (the larger of points A and C, :mod:`colonsim.surrogate.larger`)
and as one GP, the model before that.

Training sets: up to the runs of the first ``--heldout`` folder, that sweep or its maximin subset
(the most spread-out runs, chosen greedily from the centre); above, all the folders together or
their maximin subset. Used by ``benchmarks/bench_surrogate.py --heldout``.
"""

from __future__ import annotations

import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from colonsim.surrogate.holdout import reliability_figure, score
from colonsim.surrogate.larger import LargerOf
from colonsim.surrogate.model import SweepSurrogate
from colonsim.surrogate.table import read_results

TARGETS = ("max_deformation_cm", "final_deformation_cm")  # scored
# fitted besides: with points A and C the largest deformation is modelled as the larger of the two
# (colonsim.surrogate.larger); each size is also fitted without them, as one GP (the model before)
PARTS = ("point_A_cm", "point_C_cm")
BANDS = {"c95": (0.88, 0.99), "c50": (0.38, 0.62), "z_mean": (-0.3, 0.3), "z_sd": (0.7, 1.4)}


def heldout_arguments(parser):
    """The arguments of a held-out check: training sweeps, the held-out sweep, the replicates, sizes."""
    parser.add_argument("--heldout", type=Path, nargs="+", required=True, help="training sweep folders (RSJ, in order)")
    parser.add_argument("--test", type=Path, required=True, help="the held-out sweep folder")
    parser.add_argument("--replicates", type=Path, required=True,
                        help="training cases run again at another wall mesh (the noise floor)")
    parser.add_argument("--train-sizes", type=int, nargs="+", default=[12, 20, 40])


def table_of(folder) -> pd.DataFrame:
    path = Path(folder)
    table = read_results(path / "results.parquet" if path.is_dir() else path)
    return table[table["status"] == "ok"].reset_index(drop=True)


def maximin_subset(X, k):
    """Indices of ``k`` rows of ``X`` chosen greedily to be far apart (inputs scaled to [0, 1]),
    starting from the row nearest the centre; deterministic."""
    Xs = (X - X.min(axis=0)) / np.where(np.ptp(X, axis=0) > 0, np.ptp(X, axis=0), 1.0)
    chosen = [int(np.argmin(((Xs - 0.5) ** 2).sum(axis=1)))]
    while len(chosen) < k:
        nearest = np.min(((Xs[:, None, :] - Xs[chosen][None]) ** 2).sum(axis=-1), axis=1)
        nearest[chosen] = -1.0
        chosen.append(int(np.argmax(nearest)))
    return np.sort(chosen)


def training_set(folders, size, inputs=("scope_diameter_mm", "diameter_mm", "friction")):
    """The first training sweep (or its maximin subset) for sizes up to its runs, else all the
    sweeps together (or their maximin subset): 12 and 20 come from gp_train.toml, 40 is both."""
    first = folders[0]
    pool = first if size <= len(first) else pd.concat(folders, ignore_index=True)
    if size > len(pool):
        return None
    if size == len(pool):
        return pool
    return pool.iloc[maximin_subset(pool[list(inputs)].to_numpy(dtype=float), size)]


def verdicts(s) -> dict:
    values = {"c95": s["coverage"]["95"], "c50": s["coverage"]["50"], "z_mean": s["z_mean"], "z_sd": s["z_sd"]}
    out = {k: BANDS[k][0] <= v <= BANDS[k][1] for k, v in values.items()}
    o = s["orders"]
    out["orders"] = o["held"] >= o["mean_stated"] - 0.05
    return out


def print_score(label, s):
    ok = verdicts(s)
    flag = lambda key: "" if ok[key] else "!"  # noqa: E731
    o = s["orders"]
    print(f"    {label}RMSE {s['rmse']:.3g}  Q2 {s['q2']:.3f}  cover 50/90/95 {100 * s['coverage']['50']:3.0f}{flag('c50')}"
          f"/{100 * s['coverage']['90']:3.0f}/{100 * s['coverage']['95']:3.0f}{flag('c95')} %  "
          f"z {s['z_mean']:+.2f}{flag('z_mean')} sd {s['z_sd']:.2f}{flag('z_sd')}  "
          f"orders {100 * o['held']:.0f} % vs stated {100 * o['mean_stated']:.0f} %{flag('orders')}  "
          f"{'PASS' if all(ok.values()) else 'MISS'}")


def band_pass_share(n_runs, draws=100_000, seed=0) -> dict:
    """How often a perfectly calibrated model meets the bands on ``n_runs`` held-out runs with
    independent standard normal errors (Monte Carlo): per band and all four together. Errors that
    share the trend's error pass less often still."""
    z = np.random.default_rng(seed).standard_normal((draws, n_runs))
    values = {"c95": (np.abs(z) <= 1.959963984540054).mean(axis=1), "c50": (np.abs(z) <= 0.6744897501960817).mean(axis=1),
              "z_mean": z.mean(axis=1), "z_sd": z.std(axis=1, ddof=1)}
    inside = {k: (BANDS[k][0] <= v) & (v <= BANDS[k][1]) for k, v in values.items()}
    return {**{k: float(v.mean()) for k, v in inside.items()}, "all": float(np.logical_and.reduce(list(inside.values())).mean())}


def replicate_pool(train, replicates, inputs=("scope_diameter_mm", "diameter_mm", "friction")):
    """The replicate runs with the training runs they repeat: a training subset that lacks the
    originals still finds the pairs."""
    originals = train.merge(replicates[list(inputs)].drop_duplicates(), on=list(inputs))
    return pd.concat([replicates, originals], ignore_index=True)


def heldout(train_folders, test_folder, replicates_folder, sizes, restarts=None, figure=None, targets=TARGETS,
            draws=None):
    """Print the held-out scores; returns the fitted models by (size, label). ``draws``: the
    hyperparameter draws the predictions average over (None: the surrogate's default)."""
    folders = [table_of(f) for f in train_folders]
    train = pd.concat(folders, ignore_index=True)
    test = table_of(test_folder)
    replicates = None if replicates_folder is None else replicate_pool(train, table_of(replicates_folder))
    print(f"\nheld-out calibration: training runs from {', '.join(map(str, train_folders))} ({len(train)}), "
          f"held out {test_folder} ({len(test)}), replicates {replicates_folder} "
          f"({0 if replicates is None else len(replicates)} runs with the originals); '!' = outside the acceptance band")
    share = band_pass_share(len(test))
    print(f"  a calibrated model meets the bands on {len(test)} held-out runs in {100 * share['all']:.0f} % of samples "
          f"(95 %: {100 * share['c95']:.0f} %, 50 %: {100 * share['c50']:.0f} %, mean z: {100 * share['z_mean']:.0f} %, "
          f"sd z: {100 * share['z_sd']:.0f} %; independent errors)")
    kept, models = [], {}
    for size in sizes:
        runs = training_set(folders, size)
        if runs is None:
            print(f"  {size} runs: only {len(train)} training runs, skipped")
            continue
        for label, reps in (("no floor", None), ("replicate floor", replicates)):
            if label == "replicate floor" and reps is None:
                continue
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                model = SweepSurrogate(targets=(*targets, *PARTS), n_restarts=restarts, replicates=reps,
                                       hyperparameter_draws=draws).fit(runs)
                one_gp = SweepSurrogate(targets=targets, n_restarts=restarts, replicates=reps,
                                        hyperparameter_draws=draws).fit(runs)
            models[(size, label)] = model
            fits = [(target, target, model) for target in targets]
            fits += [(target, f"{target} as one GP", one_gp) for target in targets
                     if isinstance(model.models_["rsj"][target], LargerOf)]
            for target, name, fitted in fits:
                s = score(fitted, test, target, "rsj")
                scatter = fitted.scatter_["rsj"][target]
                floor = "" if scatter is None else f", floor {scatter['sd']:.3g} from {scatter['pairs']} pairs"
                print(f"  {name}, {size} runs, {label}{floor}: {noise_of(fitted.models_['rsj'][target])}; "
                      f"{s['error_unknown'] or 'error known'}")
                print_score("", s)
                if label == ("replicate floor" if replicates is not None else "no floor"):
                    style = {"color": f"C{sizes.index(size)}", "ls": "--" if fitted is one_gp else "-"}
                    kept.append({**s, "label": f"{name}, {size} runs", "style": style})
    if figure is not None and kept:
        from colonsim.files import save_figure

        save_figure(reliability_figure([s for s in kept if s["target"] == targets[0]]), figure)
        print(f"reliability plot: {figure}")
    return models


def noise_of(gp) -> str:
    """The fitted scatter sd of a model (of both parts of a larger-of model)."""
    if isinstance(gp, LargerOf):
        return "larger of " + " and ".join(f"{n} (noise sd {p.noise_std:.3g})" for n, p in zip(gp.names, gp.parts))
    return f"noise sd {gp.noise_std:.3g}"


def query_speed(model, segment="rsj", target="max_deformation_cm", n_queries=10_000):
    """Median time of one query (mean + sd, domain check included) and of 10,000 in one call."""
    domain = model.domains_[segment]
    centre = dict(zip(domain.inputs, 0.5 * (domain.low + domain.high)))
    for _ in range(50):
        model.predict(centre, segment, target, return_std=True)
    times = []
    for _ in range(2000):
        t0 = time.perf_counter()
        model.predict(centre, segment, target, return_std=True)
        times.append(time.perf_counter() - t0)
    batch = dict(zip(domain.inputs, np.random.default_rng(1).uniform(domain.low, domain.high,
                                                                       (n_queries, len(domain.inputs))).T))
    many = min(_timed(lambda: model.predict(batch, segment, target, return_std=True)) for _ in range(3))
    one = float(np.median(times))
    print(f"query speed ({model.models_[segment][target].n_train}-run model): one query {1e3 * one:.3f} ms "
          f"(target < 0.5 ms {'OK' if one < 5e-4 else 'MISSED'}), {n_queries} queries {many:.3f} s "
          f"(target < 0.5 s {'OK' if many < 0.5 else 'MISSED'})")


def _timed(fn):
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0
