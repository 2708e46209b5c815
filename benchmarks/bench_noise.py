"""How the surrogate's noise is chosen: four treatments compared on the training runs, then on held-out runs.

Treatments of the white-noise variance of each GP (the run-to-run scatter), per training size:

- ``ml``: maximum marginal likelihood, bounded below by 1e-6 of the output's variance (no replicates);
- ``ml+floor`` (the surrogate's, ``fit --replicates``): the same, bounded below by the scatter that
  replicate runs measure (:mod:`colonsim.surrogate.replicates`);
- ``joint``: no floor; the replicate pairs enter the likelihood as evidence about the noise (each
  pair's difference, its mean offset removed, is Gaussian with twice the noise variance), so runs
  scattered across inputs can raise it above the replicates' estimate, or lower it;
- ``loo-noise``: the noise variance chosen on a grid from the floor to half the output's variance
  by the closed-form leave-one-out predictive density, the other hyperparameters by maximum
  likelihood at each grid value (a noise chosen by cross-validation).

The choice is made on the TRAINING runs only: leave-one-out with refitting (each run predicted by
the treatment fitted on the others, hyperparameters included), mean log predictive density per
run (higher is better), with the coverage of the 50 / 95 % intervals and the sd of the
standardized errors. The held-out scores on the independent sweep are printed beside it, but they
are the check, not the criterion.

Run: ``NUMBA_NUM_THREADS=1 python benchmarks/bench_noise.py --heldout TRAIN [TRAIN ...] --test TEST
--replicates REPLICATES [--train-sizes 12 20 40] [--target max_deformation_cm] [--restarts]``;
``--restarts`` adds how often the likelihood's best optimum is missed with 0, 2, 8, 32 and 64
restarts over the leave-one-out refits (the surrogate's default is 32 up to 100 runs,
:func:`colonsim.surrogate.gp.restarts_for`)
(docs/surrogate.md, "How the noise is chosen").
"""

import argparse
import warnings

import numpy as np
import pandas as pd
from scipy.stats import norm
from threadpoolctl import threadpool_limits

from colonsim.surrogate.gp import GaussianProcess
from colonsim.surrogate.holdout import score
from colonsim.surrogate.likelihood import log_marginal_likelihood
from colonsim.surrogate.model import SweepSurrogate
from colonsim.surrogate.validation import loo_predictions
from bench_heldout import heldout_arguments, replicate_pool, table_of, training_set

LOO_GRID = 12  # noise values tried by loo-noise
PROFILE_SD = (0.003, 0.0055, 0.0075, 0.01, 0.0125, 0.015, 0.02)  # noise sd at which the likelihood is profiled


class JointReplicateGP(GaussianProcess):
    """GP whose likelihood also holds the replicate pairs: ``pairs`` = (sum of squared deviations
    of the pair differences from their mean, number of pairs), target units."""

    pairs = (0.0, 0)

    def _optimize(self, Xs, ys):
        ss, m = self.pairs
        ss = ss / self.y_scale_**2

        def extra(theta):  # sum over pairs of log N(d - mean; 0, 2 s), m - 1 degrees of freedom
            s = np.exp(theta[-1])
            grad = np.zeros_like(theta)
            grad[-1] = 0.5 * ss / (2.0 * s) - 0.5 * (m - 1)
            return -0.25 * ss / s - 0.5 * (m - 1) * np.log(2.0 * np.pi * 2.0 * s), grad

        return self._best(Xs, ys, extra)

    def _best(self, Xs, ys, extra, fixed_noise=None, starts=None):
        """Maximize the likelihood (+ ``extra``) from ``starts`` (default: the GP's start and
        restarts); with ``fixed_noise`` (log variance) over the other hyperparameters only."""
        bounds = self._bounds(Xs.shape[1])
        starts = self._starts(Xs.shape[1], len(ys)) if starts is None else starts
        free = slice(None) if fixed_noise is None else slice(0, -1)

        def value_and_gradient(t):
            theta = t if fixed_noise is None else np.append(t, fixed_noise)
            value, grad = log_marginal_likelihood(theta, Xs, ys)
            if extra is not None:
                v, g = extra(theta)
                value, grad = value + v, grad + g
            return value, grad[free]

        best = self._maximize(value_and_gradient, bounds[free], [s[free] for s in starts])
        return best if fixed_noise is None else np.append(best, fixed_noise)


class LooNoiseGP(JointReplicateGP):
    """GP whose noise is chosen by the closed-form leave-one-out predictive density; at each noise
    value the other hyperparameters start from the maximum-likelihood fit and the default start."""

    def _optimize(self, Xs, ys):
        low = self._bounds(Xs.shape[1])[-1, 0]
        starts = [GaussianProcess._optimize(self, Xs, ys), self._starts(Xs.shape[1], 0)[0]]
        best = None
        for noise in np.linspace(low, max(low, np.log(0.5)), LOO_GRID):
            theta = self._best(Xs, ys, None, fixed_noise=noise, starts=starts)
            self._condition(Xs, ys, theta)
            mean, sd = loo_predictions(self)
            lpd = float(np.sum(norm.logpdf(self.y_mean_ + self.y_scale_ * ys, mean, sd)))
            if best is None or lpd > best[0]:
                best = (lpd, theta, self.log_marginal_likelihood_)
        self.log_marginal_likelihood_ = best[2]
        return best[1]


def make(treatment, floor_sd, pairs):
    """A GP factory (input range -> unfitted GP) of ``treatment``."""
    cls = {"ml": GaussianProcess, "ml+floor": GaussianProcess, "joint": JointReplicateGP, "loo-noise": LooNoiseGP}[treatment]
    floor = floor_sd if treatment in ("ml+floor", "loo-noise") else 0.0

    def factory(low, high):
        # the noise treatments as measured (docs/surrogate.md "How the noise is chosen"): each with
        # the likelihood's maximum alone, before the surrogate integrated its hyperparameters out
        gp = cls(input_range=(low, high), noise_floor_sd=floor, hyperparameter_draws=0)
        gp.pairs = pairs
        return gp

    return factory


class Surrogate(SweepSurrogate):
    """The surrogate with another noise treatment (``factory``), for :func:`score`."""

    factory = None

    def _make_gp(self, domain, noise_floor_sd=0.0):
        return lambda: self.factory(domain.low, domain.high)


def refit_loo(factory, runs, inputs, target):
    """Each run predicted by the treatment fitted on the others: mean log density, coverage, z."""
    X, y = runs[inputs].to_numpy(dtype=float), runs[target].to_numpy(dtype=float)
    low, high = X.min(axis=0), X.max(axis=0)
    z, lpd = np.empty(len(y)), np.empty(len(y))
    for i in range(len(y)):
        others = np.arange(len(y)) != i
        mean, sd = factory(low, high).fit(X[others], y[others]).predict(X[i:i + 1], return_std=True)
        z[i], lpd[i] = (y[i] - mean[0]) / sd[0], norm.logpdf(y[i], mean[0], sd[0])
    return {"lpd": float(lpd.mean()), "c50": float(np.mean(np.abs(z) <= 0.6745)),
            "c95": float(np.mean(np.abs(z) <= 1.96)), "z_sd": float(z.std(ddof=1))}


def profile(runs, inputs, target, sds=PROFILE_SD):
    """Largest log marginal likelihood of ``runs`` at each noise sd (target units), the other
    hyperparameters maximized: how strongly the runs themselves point at a noise level."""
    X, y = runs[inputs].to_numpy(dtype=float), runs[target].to_numpy(dtype=float)
    gp = JointReplicateGP(noise_bounds=(1e-9, 10.0))
    gp.fit(X, y)  # scales the inputs and the output
    values = []
    for sd in sds:
        gp._best(gp.X_train_, gp.y_train_, None, fixed_noise=np.log((sd / gp.y_scale_) ** 2))
        values.append(gp.log_marginal_likelihood_)
    return values


def restart_check(runs, inputs, target, floor_sd, counts=(0, 2, 8, 32, 64)):
    """Leave-one-out refits of ``runs`` (the many small likelihoods a fit of few runs meets): per
    number of restarts, the folds whose optimum falls more than 0.1 log units short of the best any
    count reached, and by how much at most."""
    X, y = runs[inputs].to_numpy(dtype=float), runs[target].to_numpy(dtype=float)
    low, high = X.min(axis=0), X.max(axis=0)
    lml = np.array([[GaussianProcess(input_range=(low, high), n_restarts=r, noise_floor_sd=floor_sd)
                     .fit(X[np.arange(len(y)) != i], y[np.arange(len(y)) != i]).log_marginal_likelihood_
                     for i in range(len(y))] for r in counts])
    short = lml.max(axis=0) - lml
    return ", ".join(f"{r}: {int(np.sum(g > 0.1))} short (by up to {g.max():.1f})" for r, g in zip(counts, short))


def compare(train_folders, test_folder, replicates_folder, sizes, target, treatments, restarts=False):
    folders = [table_of(f) for f in train_folders]
    test = table_of(test_folder)
    replicates = replicate_pool(pd.concat(folders, ignore_index=True), table_of(replicates_folder))
    print(f"noise treatments, {target}: training runs from {', '.join(map(str, train_folders))}, held out "
          f"{test_folder} ({len(test)}), replicates {replicates_folder}\n"
          "  'LOO' = leave-one-out with refitting on the training runs (the criterion: mean log density per run); "
          "'held out' = the check")
    for size in sizes:
        runs = training_set(folders, size)
        if runs is None:
            continue
        plain = SweepSurrogate(targets=(target,), n_restarts=0, replicates=replicates).fit(runs)
        inputs = plain.domains_["rsj"].inputs
        scatter = plain.scatter_["rsj"][target]
        pairs = (2.0 * scatter["sd"] ** 2 * (scatter["pairs"] - 1), scatter["pairs"])
        rows = []
        for treatment in treatments:
            factory = make(treatment, scatter["sd"], pairs)
            model = Surrogate(targets=(target,), replicates=replicates)
            model.factory = factory
            model.fit(runs)
            loo, s = refit_loo(factory, runs, inputs, target), score(model, test, target, "rsj")
            rows.append((treatment, model.models_["rsj"][target].noise_std, loo, s))
        top = max(r[2]["lpd"] for r in rows)
        chosen = " = ".join(r[0] for r in rows if r[2]["lpd"] >= top - 5e-4)
        lml = profile(runs, inputs, target)
        print(f"  {size} runs (replicate scatter {scatter['sd']:.3g} from {scatter['pairs']} pairs); the criterion "
              f"chooses {chosen}\n    log likelihood of the runs at noise sd (cm) "
              + ", ".join(f"{sd:g}: {v:.1f}" for sd, v in zip(PROFILE_SD, lml)))
        if restarts:
            print(f"    restarts (ml+floor), {len(runs)} leave-one-out refits: "
                  + restart_check(runs, inputs, target, scatter["sd"]))
        for treatment, noise, loo, s in rows:
            c = s["coverage"]
            print(f"    {treatment:10s} noise sd {noise:.4f} | LOO log density {loo['lpd']:+.3f}  cover 50/95 "
                  f"{100 * loo['c50']:3.0f}/{100 * loo['c95']:3.0f} %  z sd {loo['z_sd']:.2f} | held out RMSE "
                  f"{s['rmse']:.4f}  cover 50/90/95 {100 * c['50']:3.0f}/{100 * c['90']:3.0f}/{100 * c['95']:3.0f} %  "
                  f"z {s['z_mean']:+.2f} sd {s['z_sd']:.2f}", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    heldout_arguments(parser)
    parser.add_argument("--target", default="max_deformation_cm")
    parser.add_argument("--treatments", nargs="+", default=["ml", "ml+floor", "joint", "loo-noise"])
    parser.add_argument("--restarts", action="store_true", help="also: the optimum reached with 0-64 restarts")
    args = parser.parse_args()
    warnings.simplefilter("ignore")  # an optimum at a bound is normal (a length scale of 100 = input ignored)
    with threadpool_limits(limits=1, user_api="blas"):
        compare(args.heldout, args.test, args.replicates, args.train_sizes, args.target, args.treatments, args.restarts)


if __name__ == "__main__":
    main()
