"""Does the hyperparameters' own uncertainty explain the surrogate's overconfidence? Measured.

The surrogate predicts with the hyperparameters that maximize the likelihood (a plug-in): the
length scales, signal and noise variances are taken as known. With 12-20 training runs they are
not, and the held-out runs show intervals too narrow by 1.5-2.3x at the 0.15 m/s push
(docs/surrogate.md, "At the 0.15 m/s push"). This benchmark predicts the same held-out runs with
the hyperparameters integrated out, the predictive a mixture over draws of them (its mean and
variance: the draws' average mean, and their average variance plus the variance of their means;
intervals from the Gaussian with those moments, as the surrogate does for the larger of A and C):

- ``plug-in``: the surrogate's GP before 2026-11-27 (maximum likelihood, noise floored at the
  replicate scatter, ``hyperparameter_draws=0``);
- ``laplace F``: (the surrogate's today with F = 1 and 16 draws,
  :func:`colonsim.surrogate.hyperposterior.laplace_draws`) draws from the Gaussian approximation of
  the posterior at the maximum, its precision the negative Hessian of the log likelihood in the log hyperparameters (central
  differences of the analytic gradient), each eigenvalue raised to at least F (a direction the
  runs do not constrain gets at most a standard deviation of 1 / sqrt(F) in log units), the draws
  clipped to the fit's bounds;
- ``mcmc``: an adaptive random-walk Metropolis chain on the log likelihood, a flat prior in the log
  hyperparameters within the fit's bounds, thinned to the same number of draws.

Length scales below :data:`~colonsim.surrogate.hyperposterior.SHORTEST_LENGTH_SCALE` (0.1 of the
training range) are outside both posteriors: shorter than the spacing of a few dozen runs in three
inputs, the runs cannot tell them from noise. Every mixture is the surrogate's own
(``GaussianProcess.set_draws``); only the draws differ.

Per training size and output (point A, point C, final deformation, and the largest deformation as
the larger of A and C): RMSE, coverage of the 50 / 90 / 95 % intervals and the mean and sd of the
standardized errors on the held-out runs, '!' outside the acceptance band of
``bench_heldout.py``; and the time of one query of a mixture of that many draws. The treatments
are compared on held-out runs: an exploration, not a choice made on training data.

Run: ``NUMBA_NUM_THREADS=1 python benchmarks/bench_hyperparameters.py --heldout TRAIN [TRAIN ...]
--test TEST --replicates REPLICATES [--train-sizes 12 20 40] [--draws 64] [--floors 0.01 1]``
"""

import argparse
import copy
import time
import warnings

import numpy as np
import pandas as pd
from threadpoolctl import threadpool_limits

from colonsim.surrogate.gp import GaussianProcess
from colonsim.surrogate.hyperposterior import SHORTEST_LENGTH_SCALE, laplace_draws
from colonsim.surrogate.larger import larger_moments
from colonsim.surrogate.likelihood import log_marginal_likelihood
from colonsim.surrogate.replicates import replicate_scatter
from bench_heldout import heldout_arguments, BANDS, replicate_pool, table_of, training_set

INPUTS = ["scope_diameter_mm", "diameter_mm", "friction"]
PARTS = ("point_A_cm", "point_C_cm")
TARGETS = (*PARTS, "final_deformation_cm")


def map_theta(gp):
    return np.log(np.r_[gp.constant_, gp.length_scale_, gp.noise_level_])


def bounds_of(gp):
    """The fit's bounds of the log hyperparameters, length scales from the surrogate's shortest."""
    b = gp._bounds(gp.X_train_.shape[1])
    b[1:-1, 0] = np.maximum(b[1:-1, 0], np.log(SHORTEST_LENGTH_SCALE))
    return b


def mcmc_draws(gp, n_draws, seed, steps=6000, burn=2000):
    """Draws of the log hyperparameters from an adaptive Metropolis chain (flat prior in the bounds)."""
    rng, b = np.random.default_rng(seed), bounds_of(gp)

    def log_post(t):
        inside = np.all(t >= b[:, 0]) and np.all(t <= b[:, 1])
        return log_marginal_likelihood(t, gp.X_train_, gp.y_train_, eval_gradient=False) if inside else -np.inf

    current = np.clip(map_theta(gp), b[:, 0], b[:, 1])
    value, cov, chain = log_post(current), 0.1 * np.eye(len(current)), []
    for i in range(steps):
        if i > 200 and i % 200 == 0:  # adapt the proposal to the chain so far (Haario et al. 2001)
            cov = (np.cov(np.array(chain[-1000:]).T) + 1e-6 * np.eye(len(current))) * 2.38**2 / len(current)
        proposal = rng.multivariate_normal(current, cov)
        candidate = log_post(proposal)
        if np.log(rng.random()) < candidate - value:
            current, value = proposal, candidate
        chain.append(current)
    chain = np.array(chain[burn:])
    return chain[np.linspace(0, len(chain) - 1, n_draws).astype(int)]


def averaged(gp, draws):
    """The fitted plug-in ``gp`` predicting as the mixture over ``draws`` (the surrogate's own code)."""
    mixture = copy.copy(gp)
    mixture.set_draws(draws)
    return mixture


def scored(y, mean, sd):
    z = (y - mean) / sd
    cover = {k: np.mean(np.abs(z) <= q) for k, q in (("50", 0.6745), ("90", 1.6449), ("95", 1.96))}
    flag = lambda key, v: "" if BANDS[key][0] <= v <= BANDS[key][1] else "!"  # noqa: E731
    ok = all(BANDS[k][0] <= v <= BANDS[k][1] for k, v in (("c50", cover["50"]), ("c95", cover["95"]),
                                                          ("z_mean", z.mean()), ("z_sd", z.std(ddof=1))))
    return (f"RMSE {np.sqrt(np.mean((y - mean) ** 2)):.4f}  cover 50/90/95 {100 * cover['50']:3.0f}"
            f"{flag('c50', cover['50'])}/{100 * cover['90']:3.0f}/{100 * cover['95']:3.0f}{flag('c95', cover['95'])} %  "
            f"z {z.mean():+.2f}{flag('z_mean', z.mean())} sd {z.std(ddof=1):.2f}{flag('z_sd', z.std(ddof=1))}  "
            f"{'PASS' if ok else 'MISS'}")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    heldout_arguments(p)
    p.add_argument("--draws", type=int, default=64, help="draws of the hyperparameters per mixture")
    p.add_argument("--floors", type=float, nargs="+", default=[0.01, 1.0], help="Laplace precision floors")
    p.add_argument("--seed", type=int, default=0)
    args = p.parse_args()
    folders = [table_of(f) for f in args.heldout]
    test = table_of(args.test)
    # the replicates with every training run they repeat, as bench_heldout pairs them
    pool = replicate_pool(pd.concat(folders, ignore_index=True), table_of(args.replicates))
    Q = test[INPUTS].to_numpy(float)
    print(f"held out: {args.test} ({len(test)} runs); draws {args.draws}, length scales >= {SHORTEST_LENGTH_SCALE}")
    with threadpool_limits(limits=1, user_api="blas"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for size in args.train_sizes:
            runs = training_set(folders, size)
            if runs is None:
                print(f"{size} runs: not enough training runs, skipped")
                continue
            X = runs[INPUTS].to_numpy(float)
            treatments = ["plug-in", *(f"laplace {f:g}" for f in args.floors), "mcmc"]
            predictions = {}
            for target in TARGETS:
                y = runs[target].to_numpy(float)
                scatter = replicate_scatter(runs, pool, "rsj", INPUTS, target)
                gp = GaussianProcess(input_range=(X.min(0), X.max(0)), noise_floor_sd=scatter["sd"] if scatter else 0.0,
                                     hyperparameter_draws=0).fit(X, y)
                models = {"plug-in": gp}
                for f in args.floors:
                    models[f"laplace {f:g}"] = averaged(gp, laplace_draws(map_theta(gp), gp._bounds(X.shape[1]), gp.X_train_,
                                                                          gp.y_train_, args.draws, f, args.seed))
                models["mcmc"] = averaged(gp, mcmc_draws(gp, args.draws, args.seed))
                predictions[target] = {name: m.predict(Q, return_std=True) for name, m in models.items()}
                if target == TARGETS[0]:
                    start = time.perf_counter()
                    for _ in range(200):
                        models["mcmc"].predict(Q[:1], return_std=True)
                    query_ms = (time.perf_counter() - start) / 200 * 1e3
            print(f"\n{size} training runs (one query of a {args.draws}-draw mixture: {query_ms:.2f} ms per GP)")
            for name in treatments:
                a, c = predictions[PARTS[0]][name], predictions[PARTS[1]][name]
                mean, sd, _ = larger_moments(a[0], a[1], c[0], c[1])
                print(f"  {'max (larger of A, C)':<22} {name:<12} {scored(test['max_deformation_cm'].to_numpy(float), mean, sd)}")
            for target in TARGETS:
                for name in treatments:
                    mean, sd = predictions[target][name]
                    print(f"  {target:<22} {name:<12} {scored(test[target].to_numpy(float), mean, sd)}")


if __name__ == "__main__":
    main()
