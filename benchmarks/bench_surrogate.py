"""The surrogate's Gaussian process, hand-written against scikit-learn's, and the surrogate's speed.

Part 1 (the dependency decision, docs/surrogate.md "Why the GP is hand-written"): in one process,
the same model fitted two ways - colonsim.surrogate.gp.GaussianProcess and scikit-learn's
``GaussianProcessRegressor`` with ``ConstantKernel * Matern(nu=2.5, ARD) + WhiteKernel``, the same
bounds and start, ``alpha`` = the same jitter, ``n_restarts_optimizer`` = the same number of
restarts, on the same scaled inputs and standardized output. Per table it measures

- fit with hyperparameter optimisation (seconds, log marginal likelihood reached), and one
  evaluation of the likelihood and its gradient (what the optimizer repeats, milliseconds);
- leave-one-out CV: time and error (RMSE, Q^2, coverage of the 95 % interval). The library has no
  leave-one-out: it refits the GP without each run (hyperparameters kept, ``optimizer=None``),
  which is the quantity the closed form computes (the largest difference is printed);
- one query (mean + std): median and 95th percentile latency;
- 10,000 queries in one call (best of 3).

Tables: SYNTHETIC sweeps (colonsim.surrogate.synthetic) of one segment with five varying inputs at
``--sizes`` runs, and with ``--results PATH`` a real results table (every segment; skipped with a
note if the path does not exist).

Part 2 (the issue's targets for the whole surrogate, ``--model-runs`` runs): the fit of every
default output with LOO CV (target < 30 s), save and load, one query with the domain check
(target < 1 ms), 10,000 queries (target < 1 s).

Part 3 (with ``--heldout``, :mod:`bench_heldout`): the surrogate fitted on training sweeps of
``--train-sizes`` runs, without and with the noise floor of ``--replicates``, scored on the
independent sweep ``--test``: interval coverage, standardized error and predicted orders against
the acceptance bands, a reliability plot (``--figure``), and the query speed of the largest model
(targets < 0.5 ms for one query, < 0.5 s for 10,000). ``--hyperparameter-draws 0`` scores the
models that predict with the likelihood's maximum alone (the plug-in before 2026-11-27).

Run: ``NUMBA_NUM_THREADS=1 python benchmarks/bench_surrogate.py [--sizes 40 150 500]
[--results /work/sweeps/thesis2] [--restarts 2] [--target final_deformation_cm] [--model-runs 500]
[--heldout TRAIN [TRAIN ...] --test TEST --replicates REPLICATES --train-sizes 12 20 40 --figure F.png
[--hyperparameter-draws N]]``
(docs/surrogate.md, "Noise floor", gives the sweeps and the command).
BLAS runs on one thread for both fits (as the surrogate's own fit). Needs scikit-learn, which is
in the test extra (``pip install "colonsim[test]"``). On a shared machine timings vary by +-20 %.
"""

import argparse
import copy
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

from colonsim.errors import ColonsimError
from colonsim.surrogate.gp import GaussianProcess
from colonsim.surrogate.likelihood import JITTER, log_marginal_likelihood
from colonsim.surrogate.model import SweepSurrogate
from colonsim.surrogate.store import load_surrogate, save_surrogate
from colonsim.surrogate.synthetic import synthetic_outputs, synthetic_sweep
from colonsim.surrogate.table import numeric_column, read_results, split_inputs, successful_runs
from colonsim.surrogate.validation import loo_predictions, metrics
from bench_heldout import heldout, query_speed

try:
    from sklearn.gaussian_process import GaussianProcessRegressor
    from sklearn.exceptions import ConvergenceWarning
    from sklearn.gaussian_process.kernels import ConstantKernel, Matern, WhiteKernel
except ImportError:  # pragma: no cover - the benchmark's only extra dependency
    raise SystemExit('bench_surrogate.py compares against scikit-learn: pip install "colonsim[test]"') from None


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


def training_sets(table, target):
    """(segment, X, y) of every segment of ``table`` with varying inputs and >= 4 values of ``target``,
    selected as :class:`SweepSurrogate` selects them."""
    for segment in dict.fromkeys(table["segment"]):
        runs = successful_runs(table, segment)
        varying, _ = split_inputs(runs)
        if runs.empty or not varying or target not in runs.columns:
            continue
        y = numeric_column(runs, target).to_numpy()
        keep = np.isfinite(y)
        if keep.sum() >= 4:
            yield segment, runs.loc[keep, varying].to_numpy(dtype=float), y[keep]


def library_twin(gp, n_inputs, restarts, seed):
    """scikit-learn's regressor configured as ``gp``: kernel, bounds, default start, jitter, restarts.

    Inputs and output are scaled outside (as ``gp`` scales them), so ``normalize_y`` stays off."""
    kernel = (ConstantKernel(1.0, gp.constant_bounds)
              * Matern(length_scale=[0.5] * n_inputs, length_scale_bounds=gp.length_scale_bounds, nu=2.5)
              + WhiteKernel(1e-2, gp.noise_bounds))
    return GaussianProcessRegressor(kernel, alpha=JITTER, n_restarts_optimizer=restarts, random_state=seed)


def timed(fn, *args, **kwargs):
    t0 = time.perf_counter()
    out = fn(*args, **kwargs)
    return out, time.perf_counter() - t0


def latency(predict, x, repeats=2000):
    """Median and 95th percentile (seconds) of ``predict(x)``, after a warm-up."""
    for _ in range(50):
        predict(x)
    times = np.empty(repeats)
    for i in range(repeats):
        t0 = time.perf_counter()
        predict(x)
        times[i] = time.perf_counter() - t0
    return float(np.median(times)), float(np.percentile(times, 95))


def best_of(fn, *args, repeats=3):
    """Shortest of ``repeats`` timings (seconds) of ``fn(*args)``."""
    return min(timed(fn, *args)[1] for _ in range(repeats))


def library_loo(sk, Xs, ys):
    """Leave-one-out by refitting scikit-learn's GP without each run, hyperparameters kept."""
    n = len(ys)
    mean, std = np.empty(n), np.empty(n)
    for i in range(n):
        keep = np.arange(n) != i
        fold = GaussianProcessRegressor(sk.kernel_, alpha=JITTER, optimizer=None).fit(Xs[keep], ys[keep])
        m, s = fold.predict(Xs[i:i + 1], return_std=True)
        mean[i], std[i] = m[0], s[0]
    return mean, std


def compare(label, X, y, restarts, n_queries, seed=0):
    """Fit, LOO CV and query both GPs on ``(X, y)``; one dict of figures per implementation."""
    # the same model as the library's: the likelihood's maximum alone, no hyperparameter draws
    gp = GaussianProcess(n_restarts=restarts, random_state=seed, hyperparameter_draws=0)
    _, fit_hand = timed(gp.fit, X, y)
    Xs, ys = gp.scale(X), (y - gp.y_mean_) / gp.y_scale_  # the scaling both fits see
    sk = library_twin(gp, X.shape[1], restarts, seed)
    _, fit_lib = timed(sk.fit, Xs, ys)

    # one evaluation of the likelihood and its gradient, what the optimizer repeats
    theta = np.log([gp.constant_, *gp.length_scale_, gp.noise_level_])
    grad_hand = best_of(log_marginal_likelihood, theta, Xs, ys, repeats=5)
    probe = copy.deepcopy(sk)  # evaluated as its optimizer does (kernel not cloned), which sets the kernel's theta
    grad_lib = best_of(lambda t: probe.log_marginal_likelihood(t, eval_gradient=True, clone_kernel=False), theta,
                       repeats=5)
    (loo_mean, loo_std), loo_hand = timed(loo_predictions, gp)
    (lib_mean, lib_std), loo_lib = timed(library_loo, sk, Xs, ys)
    hand_cv = metrics(y, loo_mean, loo_std)
    lib_cv = metrics(y, gp.y_mean_ + gp.y_scale_ * lib_mean, gp.y_scale_ * lib_std)
    # the closed form is exact: refitting the library with the hand-written hyperparameters agrees
    same_theta = GaussianProcessRegressor(sk.kernel_.clone_with_theta(theta), alpha=JITTER, optimizer=None)
    check_mean, _ = library_loo(same_theta.fit(Xs, ys), Xs, ys)
    loo_gap = float(np.max(np.abs(gp.y_scale_ * check_mean + gp.y_mean_ - loo_mean)))

    def lib_predict(Q):
        m, s = sk.predict(gp.scale(Q), return_std=True)
        return gp.y_mean_ + gp.y_scale_ * m, gp.y_scale_ * s

    def hand_predict(Q):
        return gp.predict(Q, return_std=True)

    query = X[len(X) // 2:len(X) // 2 + 1] * 1.001
    batch = np.random.default_rng(1).uniform(X.min(axis=0), X.max(axis=0), (n_queries, X.shape[1]))
    agree = float(np.max(np.abs(lib_predict(batch[:200])[0] - hand_predict(batch[:200])[0])))
    rows = {}
    for name, predict, fit_s, grad_s, lml, loo_s, cv in (
            ("hand-written", hand_predict, fit_hand, grad_hand, gp.log_marginal_likelihood_, loo_hand, hand_cv),
            ("scikit-learn", lib_predict, fit_lib, grad_lib, sk.log_marginal_likelihood_value_, loo_lib, lib_cv)):
        med, p95 = latency(predict, query)
        rows[name] = {"fit_s": fit_s, "grad_ms": 1e3 * grad_s, "lml": lml, "loo_s": loo_s,
                      **{k: cv[k] for k in ("rmse", "q2", "coverage_95")},
                      "query_ms": 1e3 * med, "query_p95_ms": 1e3 * p95, "batch_s": best_of(predict, batch)}
    print(f"\n{label}: {len(y)} runs, {X.shape[1]} inputs, {restarts} restarts; largest difference of the two "
          f"fitted means at 200 queries {agree:.2g}, of closed-form and refitted LOO means {loo_gap:.2g}")
    print_rows(rows, n_queries)
    return rows


def print_rows(rows, n_queries):
    """The two implementations' figures as a table, and the library's time over the hand-written's."""
    print(f"  {'':13}{'fit s':>8}{'grad ms':>9}{'LML':>9}{'LOO s':>9}{'LOO RMSE':>10}{'Q2':>8}{'cover95':>8}"
          f"{'query ms':>10}{'p95 ms':>8}{f'{n_queries} q s':>10}")
    for name, r in rows.items():
        print(f"  {name:13}{r['fit_s']:8.2f}{r['grad_ms']:9.2f}{r['lml']:9.1f}{r['loo_s']:9.4f}{r['rmse']:10.4g}"
              f"{r['q2'] if r['q2'] is None else round(r['q2'], 4):>8}{r['coverage_95']:8.3f}"
              f"{r['query_ms']:10.3f}{r['query_p95_ms']:8.3f}{r['batch_s']:10.3f}")
    hand, lib = rows["hand-written"], rows["scikit-learn"]
    print(f"  library / hand-written: fit {lib['fit_s'] / hand['fit_s']:.1f}x, "
          f"likelihood + gradient {lib['grad_ms'] / hand['grad_ms']:.1f}x, LOO {lib['loo_s'] / hand['loo_s']:.0f}x, "
          f"query {lib['query_ms'] / hand['query_ms']:.1f}x, {n_queries} queries {lib['batch_s'] / hand['batch_s']:.1f}x")


def surrogate_targets(n_runs, restarts, n_queries):
    """Part 2: the whole surrogate (7 outputs, domain check, files) against the issue's targets."""
    table = five_input_table(n_runs)
    model, fit_s = timed(SweepSurrogate(n_restarts=restarts).fit, table)
    n_models = len(model.models_["rsf"])
    print(f"\nsurrogate fit: {n_runs} runs, 5 inputs, {n_models} outputs, LOO CV: {fit_s:.2f} s "
          f"({fit_s / n_models:.2f} s per output)   target < 30 s  {'OK' if fit_s < 30 else 'MISSED'}")
    with tempfile.TemporaryDirectory() as folder:
        _, save_s = timed(save_surrogate, model, Path(folder) / "model")
        model, load_s = timed(load_surrogate, Path(folder) / "model.json")
    print(f"save {1e3 * save_s:.0f} ms, load {1e3 * load_s:.0f} ms (JSON + NPZ, no pickle)")
    query = {"scope": "pdc", "diameter_mm": 30.0, "angle_deg": 30.0, "friction": 0.05, "wall_thickness_mm": 2.0}
    one, p95 = latency(lambda q: model.predict(q, "rsf", return_std=True), query)
    print(f"one query (mean + std, domain check): median {1e3 * one:.3f} ms, 95th percentile {1e3 * p95:.3f} ms   "
          f"target < 1 ms  {'OK' if one < 1e-3 else 'MISSED'}")
    domain = model.domains_["rsf"]  # queries inside the training domain: no warning
    rng = np.random.default_rng(1)
    batch = dict(zip(domain.inputs, rng.uniform(domain.low, domain.high, (n_queries, len(domain.inputs))).T))
    many = best_of(lambda b: model.predict(b, "rsf", return_std=True), batch)
    print(f"{n_queries} queries in one call (mean + std of one output): {many:.3f} s (best of 3)   "
          f"target < 1 s  {'OK' if many < 1.0 else 'MISSED'}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="*", default=[40, 150, 500], help="runs of the synthetic tables")
    parser.add_argument("--results", type=Path, help="a sweep's results.parquet / .csv, or its folder")
    parser.add_argument("--target", default="final_deformation_cm", help="output compared (part 1)")
    parser.add_argument("--restarts", type=int, default=2, help="optimizer restarts per GP in parts 1 and 2")
    parser.add_argument("--queries", type=int, default=10_000)
    parser.add_argument("--model-runs", type=int, default=500, help="runs of part 2's table; 0 skips part 2")
    parser.add_argument("--heldout", type=Path, nargs="+", help="part 3: training sweep folders (RSJ, in order)")
    parser.add_argument("--test", type=Path, help="part 3: the held-out sweep folder")
    parser.add_argument("--replicates", type=Path, help="part 3: training cases run again (the noise floor)")
    parser.add_argument("--train-sizes", type=int, nargs="+", default=[12, 20, 40], help="part 3: training runs")
    parser.add_argument("--figure", type=Path, help="part 3: reliability plot of the model with the floor")
    parser.add_argument("--hyperparameter-draws", type=int, help="part 3: draws the predictions average over "
                        "(0: the likelihood's maximum alone; default: the surrogate's)")
    args = parser.parse_args()
    if args.heldout:
        if args.test is None:
            parser.error("--heldout needs --test")
        # part 3 fits as `colonsim surrogate fit` does, with the surrogate's own number of restarts
        models = heldout(args.heldout, args.test, args.replicates, args.train_sizes, None, args.figure,
                         draws=args.hyperparameter_draws)
        query_speed(models[max(models, key=lambda key: key[0])])

    # an optimum at a bound is normal here (a length scale of 100 = the output ignores that input)
    warnings.simplefilter("ignore", ConvergenceWarning)
    with threadpool_limits(limits=1, user_api="blas"):
        for n in args.sizes:
            table = five_input_table(n)
            for segment, X, y in training_sets(table, args.target):
                compare(f"SYNTHETIC {segment} {args.target}", X, y, args.restarts, args.queries)
        if args.results is not None:
            path = args.results / "results.parquet" if args.results.is_dir() else args.results
            try:
                table = read_results(path)
            except ColonsimError as exc:
                print(f"\n--results: {exc}; real table skipped")
            else:
                for segment, X, y in training_sets(table, args.target):
                    compare(f"{path} {segment} {args.target}", X, y, args.restarts, args.queries)
    if args.model_runs:
        surrogate_targets(args.model_runs, args.restarts, args.queries)


if __name__ == "__main__":
    main()
