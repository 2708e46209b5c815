"""Gaussian-process regression of one scalar output, scikit-learn estimator style.

Kernel ``ConstantKernel * Matern(nu=2.5, length_scale=[one per input]) + WhiteKernel``: a smooth
trend whose per-input length scales say how strongly each input matters (a length scale far above
1 = the output barely depends on that input), plus white noise for the run-to-run scatter of the
simulations. Inputs are scaled to [0, 1] over ``input_range`` (default: the training data), the
target is standardized. Hyperparameters maximize the log marginal likelihood (L-BFGS-B from a
default start and quasi-random restarts, :func:`restarts_for`). Up to :data:`SMALL_FIT_RUNS` runs
the prediction then integrates them out: it averages the GPs of :data:`hyperposterior.DRAWS
<colonsim.surrogate.hyperposterior.DRAWS>` draws from the Laplace approximation of their posterior
(:mod:`colonsim.surrogate.hyperposterior`), so its sd includes what a few runs leave unknown
about the length scales and the noise; above, the maximum's hyperparameters alone (a plug-in, as
many runs pin them down). Prediction is numpy from stored factors.

Hand-written rather than scikit-learn's ``GaussianProcessRegressor`` configured as the same model,
because it is faster at the same likelihood: the fit with hyperparameter optimisation 1.7-4x
(500 runs, 5 inputs: 3.0 s against 12.2 s), one query 2.4-9x (500 runs: 0.19 ms against
0.45 ms; 40 runs: 0.06 ms against 0.49 ms), and a saved model needs neither the library nor
pickle. Measured by ``NUMBA_NUM_THREADS=1 python benchmarks/bench_surrogate.py`` (docs/surrogate.md).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import cho_solve, cholesky, solve_triangular

from colonsim.errors import ColonsimError
from colonsim.surrogate.hyperposterior import DRAWS, Mixture, laplace_draws
from colonsim.surrogate.kernel import matern52
from colonsim.surrogate.likelihood import JITTER, log_marginal_likelihood

# Restarts when none are asked for: a likelihood of a dozen runs has several optima of nearly the
# same height, and a few starts may stop on a lower one (measured on the 12 leave-one-out refits,
# 11 runs each, of a 12-run RSJ sweep: 0 / 2 / 8 restarts fell short of the best optimum in 6 / 6
# / 4 of them, by up to 2.4 log units; 32 and 64 in none; docs/surrogate.md "The model"). Up to
# SMALL_FIT_RUNS runs a start costs milliseconds (100 runs: 13 ms); above, up to a second (500
# runs), and the likelihood of that many runs is better determined.
SMALL_FIT_RUNS = 100
SMALL_FIT_RESTARTS = 32
LARGE_FIT_RESTARTS = 2


def restarts_for(n_runs, n_restarts=None) -> int:
    """Optimizer restarts of a fit on ``n_runs`` runs: ``n_restarts`` if given, else
    :data:`SMALL_FIT_RESTARTS` up to :data:`SMALL_FIT_RUNS` runs and :data:`LARGE_FIT_RESTARTS` above."""
    if n_restarts is not None:
        return int(n_restarts)
    return SMALL_FIT_RESTARTS if n_runs <= SMALL_FIT_RUNS else LARGE_FIT_RESTARTS


def draws_for(n_runs, hyperparameter_draws=None) -> int:
    """Draws of the hyperparameters a fit on ``n_runs`` runs predicts with: ``hyperparameter_draws``
    if given, else :data:`~colonsim.surrogate.hyperposterior.DRAWS` up to :data:`SMALL_FIT_RUNS`
    runs and 0 (the maximum's hyperparameters alone) above."""
    if hyperparameter_draws is not None:
        return int(hyperparameter_draws)
    return DRAWS if n_runs <= SMALL_FIT_RUNS else 0


class GaussianProcess:
    """GP regression of one output on a few continuous inputs.

    Parameters
    ----------
    input_range : (low, high) arrays or None
        Interval of each input mapped onto [0, 1]; default the training data's min and max.
    constant_bounds, length_scale_bounds, noise_bounds : (float, float)
        Bounds of the signal variance, of the length scales (in scaled inputs, so 1 = the
        training range) and of the noise variance (both variances in units of the target's variance).
    n_restarts : int or None
        Optimizer runs from quasi-random (scrambled Sobol) log-uniform starting points, besides the
        default start; None: :func:`restarts_for` the number of runs.
    random_state : int
        Seed of the scrambling of the restarts.
    noise_floor_sd : float
        Smallest standard deviation of the run-to-run scatter, target units (0: none). The
        lower bound of the noise variance becomes at least its square (the scatter measured by
        replicate runs, :mod:`colonsim.surrogate.replicates`).
    hyperparameter_draws : int or None
        Draws of the hyperparameters the prediction averages over (0: the maximum's alone); None:
        :func:`draws_for` the number of runs. The attributes ``constant_``, ``length_scale_``,
        ``noise_level_``, ``L_`` and ``alpha_`` are the maximum's either way.
    """

    def __init__(self, input_range=None, constant_bounds=(1e-2, 1e2), length_scale_bounds=(1e-2, 1e2),
                 noise_bounds=(1e-6, 1.0), n_restarts=None, random_state=0, noise_floor_sd=0.0,
                 hyperparameter_draws=None):
        self.input_range = input_range
        self.hyperparameter_draws = hyperparameter_draws
        self.noise_floor_sd = noise_floor_sd
        self.constant_bounds = constant_bounds
        self.length_scale_bounds = length_scale_bounds
        self.noise_bounds = noise_bounds
        self.n_restarts = n_restarts
        self.random_state = random_state

    # -- fitting -----------------------------------------------------------------------------------
    def fit(self, X, y):
        """Fit hyperparameters and condition on ``(X, y)``; returns self."""
        X, y = np.atleast_2d(np.asarray(X, dtype=float)), np.asarray(y, dtype=float).ravel()
        if len(X) != len(y) or len(y) < 2:
            raise ColonsimError(f"a GP needs at least 2 runs with matching inputs and outputs, got {len(X)} and {len(y)}")
        low, high = (X.min(axis=0), X.max(axis=0)) if self.input_range is None else map(np.asarray, self.input_range)
        self.x_low_ = np.asarray(low, dtype=float)
        self.x_span_ = np.where(np.asarray(high) > low, np.asarray(high) - low, 1.0)
        self.y_mean_ = float(y.mean())
        self.y_scale_ = float(y.std()) or 1.0
        Xs = self.scale(X)
        ys = (y - self.y_mean_) / self.y_scale_
        theta = self._optimize(Xs, ys)
        self._condition(Xs, ys, theta)
        n_draws = draws_for(len(ys), self.hyperparameter_draws)
        self.set_draws(laplace_draws(theta, self._bounds(Xs.shape[1]), Xs, ys, n_draws, seed=self.random_state)
                       if n_draws else np.zeros((0, len(theta))))
        return self

    def set_draws(self, draws):
        """Predict with the mixture over ``draws`` (log hyperparameters, one per row) of the GP
        conditioned on the training runs; an empty array: the maximum's hyperparameters alone."""
        self.draws_ = np.asarray(draws, dtype=float).reshape(-1, self.X_train_.shape[1] + 2)
        self.mixture_ = Mixture(self.X_train_, self.y_train_, self.draws_) if len(self.draws_) else None

    def noise_bottom(self) -> float:
        """Lower bound of the noise variance (standardized units): the nominal bound, or the square
        of the replicate floor ``noise_floor_sd`` where that is higher."""
        return max(self.noise_bounds[0], (self.noise_floor_sd / self.y_scale_) ** 2)

    def _bounds(self, d):
        bottom = self.noise_bottom()
        noise = (bottom, max(self.noise_bounds[1], bottom))
        return np.log([self.constant_bounds] + [self.length_scale_bounds] * d + [noise])

    def _starts(self, d, n_runs):
        """Starting points (log hyperparameters) of the optimizer: the default and the restarts."""
        starts = [np.log([1.0] + [0.5] * d + [1e-2])]
        # restarts log-uniform over plausible values, not the whole box: a start with length
        # scales of 0.01 (white noise) costs many iterations and never wins. Sobol points fill
        # that box evenly, where random ones leave gaps and clumps
        n_restarts = restarts_for(n_runs, self.n_restarts)
        if n_restarts:
            low, high = np.log([0.1] + [0.1] * d + [1e-4]), np.log([10.0] + [10.0] * d + [0.1])
            from scipy.stats import qmc  # on fitting only: scipy.stats costs a query's import a second

            sobol = qmc.Sobol(d + 2, seed=self.random_state).random_base2(int(np.ceil(np.log2(n_restarts))))
            starts += list(low + (high - low) * sobol[:n_restarts])
        return starts

    def _optimize(self, Xs, ys):
        return self._maximize(lambda theta: log_marginal_likelihood(theta, Xs, ys), self._bounds(Xs.shape[1]),
                              self._starts(Xs.shape[1], len(ys)))

    def _maximize(self, value_and_gradient, bounds, starts):
        """The best of L-BFGS-B runs from each start within ``bounds`` of ``value_and_gradient(theta)
        -> (value, gradient)``; sets ``log_marginal_likelihood_`` to that value, returns its theta."""
        from scipy.optimize import minimize  # on fitting only: a query does not pay its import

        def objective(theta):
            value, grad = value_and_gradient(theta)
            return (1e25, np.zeros_like(theta)) if not np.isfinite(value) else (-value, -grad)

        best = None
        for start in starts:
            res = minimize(objective, np.clip(start, bounds[:, 0], bounds[:, 1]), jac=True, method="L-BFGS-B",
                           bounds=bounds)
            if best is None or res.fun < best.fun:
                best = res
        self.log_marginal_likelihood_ = float(-best.fun)
        return best.x

    def _condition(self, Xs, ys, theta):
        """Store what prediction needs: training inputs, hyperparameters, Cholesky factor, alpha (the
        plug-in at ``theta``; :meth:`set_draws` adds a mixture)."""
        self.X_train_ = Xs
        self.y_train_ = ys
        self.constant_ = float(np.exp(theta[0]))
        self.length_scale_ = np.exp(theta[1:-1])
        self.noise_level_ = float(np.exp(theta[-1]))
        K = self.constant_ * matern52(Xs, Xs, self.length_scale_)
        K[np.diag_indices_from(K)] += self.noise_level_ + JITTER
        self.L_ = cholesky(K, lower=True, check_finite=False)
        self.alpha_ = cho_solve((self.L_, True), ys, check_finite=False)
        self.set_draws(np.zeros((0, len(theta))))  # conditioned anew: the plug-in until draws are set

    # -- prediction --------------------------------------------------------------------------------
    def scale(self, X):
        """Inputs in physical units -> [0, 1] over the input range."""
        return (np.asarray(X, dtype=float) - self.x_low_) / self.x_span_

    def predict(self, X, return_std=False, return_cov=False):
        """Posterior mean at the rows of ``X`` (physical units), in target units.

        ``return_std``: also the standard deviation of a new simulation result (trend + run-to-run
        scatter, what the cross-validation checks). ``return_cov``: the joint covariance of the
        smooth trend at the rows (used to compare scopes for one patient); noise is never in it.
        """
        Xs = self.scale(np.atleast_2d(X))
        if self.mixture_ is not None:
            if return_cov:
                mean, cov = self.mixture_.predict(Xs, return_cov=True)
                return self.y_mean_ + self.y_scale_ * mean, cov * self.y_scale_**2
            if not return_std:
                return self.y_mean_ + self.y_scale_ * self.mixture_.predict(Xs, return_var=False)
            mean, var = self.mixture_.predict(Xs)
            return self.y_mean_ + self.y_scale_ * mean, self.y_scale_ * np.sqrt(var)
        k = self.constant_ * matern52(Xs, self.X_train_, self.length_scale_)
        mean = self.y_mean_ + self.y_scale_ * (k @ self.alpha_)
        if not (return_std or return_cov):
            return mean
        v = solve_triangular(self.L_, k.T, lower=True, check_finite=False)
        if return_cov:
            cov = self.constant_ * matern52(Xs, Xs, self.length_scale_) - v.T @ v
            return mean, cov * self.y_scale_**2
        var = self.constant_ - np.einsum("ij,ij->j", v, v) + self.noise_level_
        return mean, self.y_scale_ * np.sqrt(np.maximum(var, 0.0))

    def training_runs(self):
        """The training runs' inputs (physical units) and outputs (target units)."""
        return self.x_low_ + self.x_span_ * self.X_train_, self.y_mean_ + self.y_scale_ * self.y_train_

    @property
    def n_train(self) -> int:
        """Number of training runs."""
        return int(len(self.alpha_))

    @property
    def noise_std(self):
        """Standard deviation of the run-to-run scatter, target units."""
        return self.y_scale_ * np.sqrt(self.noise_level_)

    @property
    def kernel_description(self):
        ls = ", ".join(f"{v:.3g}" for v in self.length_scale_)
        mixture = f", averaged over {len(self.draws_)} draws of the hyperparameters (Laplace)" if len(self.draws_) else ""
        return f"{self.constant_:.3g} * Matern(length_scale=[{ls}], nu=2.5) + WhiteKernel({self.noise_level_:.3g}){mixture}"
