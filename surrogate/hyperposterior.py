"""The GP's hyperparameters integrated out: a Laplace approximation of their posterior, and the
predictive averaged over draws from it.

A GP fitted by maximum likelihood predicts as if its length scales, signal and noise variances
were known. With a dozen or two runs they are not, and its intervals are too narrow: on 100
held-out RSJ runs at the 0.15 m/s push, models of 12 / 20 runs stated standard deviations 1.48 /
2.15 times too small for the largest deformation (docs/surrogate.md, "The hyperparameters' own
uncertainty"). Here:

- the posterior of the log hyperparameters ``theta = log([c, l_1..l_d, s])`` (a flat prior within
  the fit's bounds) is approximated by a Gaussian at the maximum, its precision the negative
  Hessian of the log marginal likelihood (central differences of the analytic gradient, step
  :data:`HESSIAN_STEP`);
- each eigenvalue of that precision is raised to at least :data:`CURVATURE_FLOOR`: a direction the
  runs do not constrain (a flat likelihood, or a maximum on a bound, where the Hessian is not a
  curvature) gets a standard deviation of at most 1 / sqrt(floor) in log units, a factor e;
- :data:`DRAWS` quasi-random draws (scrambled Sobol points mapped to that Gaussian, seeded: the
  same fit gives the same draws) are clipped to the fit's bounds, length scales to at least
  :data:`SHORTEST_LENGTH_SCALE` of the training range (shorter ones a few dozen runs in three inputs
  cannot tell from noise);
- the predictive is the mixture of the GPs conditioned on each draw, summarised by its first two
  moments: the mean of the draws' means, and the mean of their variances plus the variance of
  their means (the law of total variance). Intervals and probabilities use the Gaussian with those
  moments, an approximation of the mixture.

Measured (``benchmarks/bench_hyperparameters.py``, docs/surrogate.md): the floor of 1 is the one
of the two tried (0.01 and 1) that brought the 12-run model of the largest deformation inside
every acceptance band on 100 held-out runs (0.01 widened it past them: sd of z 0.54); a full
Markov chain over the same flat prior made those intervals too wide as well (sd of z 0.64) and its
mean worse (RMSE +84 %). The floor was chosen on those held-out runs: an assumption measured, not
derived.
"""

from __future__ import annotations

import sys

import numpy as np

from colonsim.surrogate.kernel import matern52
from colonsim.surrogate.likelihood import JITTER, log_marginal_likelihood

DRAWS = 16  # draws of the hyperparameters (a power of 2: balanced Sobol points)
CURVATURE_FLOOR = 1.0  # smallest precision of a log hyperparameter's direction (sd <= 1 log unit)
SHORTEST_LENGTH_SCALE = 0.1  # of the training range
HESSIAN_STEP = 1e-4  # central-difference step in the log hyperparameters
QUERY_CHUNK = 2048  # query rows predicted at once (memory: draws x rows x runs)
# a batch this large runs its small matrix products on one BLAS thread: threads contending with
# simulations for the cores made 10,000 queries of a 40-run model 6x slower (1.7 s against 0.28 s)
ONE_THREAD_ROWS = 256
# up to this many query rows the moments come from one compiled loop
# (:func:`colonsim.surrogate.gp_loops.few_rows_moments`) once Numba is loaded: numpy's thirty-odd
# calls on arrays of a few hundred numbers cost a single query 5-8x as long
FEW_ROWS = 32


def laplace_draws(theta, bounds, X, y, n_draws=DRAWS, floor=CURVATURE_FLOOR, seed=0):
    """``n_draws`` log-hyperparameter vectors from the Gaussian approximation of their posterior at
    the maximum ``theta`` of the log marginal likelihood of standardized ``y`` at scaled ``X``,
    clipped to ``bounds`` ((p, 2), log units; length scales to at least
    :data:`SHORTEST_LENGTH_SCALE`)."""
    theta = np.asarray(theta, dtype=float)
    p = len(theta)
    hessian = np.empty((p, p))
    for i in range(p):
        step = np.zeros(p)
        step[i] = HESSIAN_STEP
        hessian[i] = (log_marginal_likelihood(theta + step, X, y)[1]
                      - log_marginal_likelihood(theta - step, X, y)[1]) / (2.0 * HESSIAN_STEP)
    precision, vectors = np.linalg.eigh(-0.5 * (hessian + hessian.T))
    cov = vectors @ np.diag(1.0 / np.maximum(precision, floor)) @ vectors.T
    from scipy.stats import qmc  # on fitting only: scipy.stats costs a query's import a second

    draws = qmc.MultivariateNormalQMC(theta, cov, seed=seed).random(n_draws)
    low, high = np.array(bounds, dtype=float).T
    low[1:-1] = np.maximum(low[1:-1], np.log(SHORTEST_LENGTH_SCALE))
    return np.clip(draws, low, high)


def loaded_loops():
    """The compiled loops (:mod:`colonsim.surrogate.gp_loops`) if Numba is loaded in this process,
    else None.

    A process that asks a few rows once (``colonsim predict``) answers them with numpy: importing
    Numba and loading the cached loops costs it about half a second, to save a fraction of a
    millisecond. Once Numba is loaded (a batch, a fit, a sweep, the solver), a few rows take the
    compiled loop, which pays when a caller asks one row at a time, many times. The two give the
    same numbers to round-off."""
    if "numba" not in sys.modules:
        return None
    from colonsim.surrogate import gp_loops

    return gp_loops


class Mixture:
    """GPs conditioned on ``(X, y)`` (scaled inputs, standardized target) for each row of
    ``thetas`` (log hyperparameters); predicts the mixture's first two moments, standardized."""

    def __init__(self, X, y, thetas):
        thetas = np.atleast_2d(np.asarray(thetas, dtype=float))
        self.X, self.thetas = np.ascontiguousarray(X, dtype=float), thetas
        self.constant = np.exp(thetas[:, 0])
        self.length_scale = np.exp(thetas[:, 1:-1])
        self.noise = np.exp(thetas[:, -1])
        n = len(y)
        self.L_inv = np.empty((len(thetas), n, n))
        self.alpha = np.empty((len(thetas), n))
        for i, (c, ls, s) in enumerate(zip(self.constant, self.length_scale, self.noise)):
            K = c * matern52(X, X, ls)
            K[np.diag_indices(n)] += s + JITTER
            self.L_inv[i] = np.linalg.inv(np.linalg.cholesky(K))
            self.alpha[i] = self.L_inv[i].T @ (self.L_inv[i] @ y)
        self._inv_length = np.ascontiguousarray(1.0 / self.length_scale)

    def _covariance(self, QA, QB):
        """Each draw's prior covariance between the rows of ``QA`` and ``QB``: (draws, m, n)."""
        return self.constant[:, None, None] * matern52(QA, QB, self.length_scale[:, None, :])

    def _covariance_to_runs(self, Q, compiled=True):
        """Each draw's prior covariance between the rows of ``Q`` and the runs: (draws, m, n), by
        the compiled loop (``compiled``, which imports Numba) or by numpy."""
        if not compiled:
            return self._covariance(Q, self.X)
        from colonsim.surrogate.gp_loops import covariance_to_runs

        out = np.empty((len(self.constant), len(Q), len(self.X)))
        covariance_to_runs(np.ascontiguousarray(Q, dtype=float), self.X, self._inv_length, self.constant, out)
        return out

    def predict(self, Q, return_cov=False, return_var=True):
        """Mixture mean (m,) and the variance of a new result (m,) at scaled query rows ``Q`` (the
        mean alone without ``return_var``); with ``return_cov``, the mean and the trend's joint
        covariance (m, m), noise excluded."""
        if return_cov:
            k = self._covariance_to_runs(Q)
            means = np.einsum("kmn,kn->km", k, self.alpha)
            v = k @ self.L_inv.transpose(0, 2, 1)
            covs = self._covariance(Q, Q) - v @ v.transpose(0, 2, 1)
            spread = means - means.mean(axis=0)
            return means.mean(axis=0), covs.mean(axis=0) + spread.T @ spread / len(means)
        if len(Q) <= FEW_ROWS:
            loops = loaded_loops()
            if loops is None:
                return self._predict_rows(Q, return_var, compiled=False)
            mean, var = np.empty(len(Q)), np.empty(len(Q))
            loops.few_rows_moments(np.ascontiguousarray(Q, dtype=float), self.X, self._inv_length, self.constant,
                             self.alpha, self.L_inv, self.noise, return_var, mean, var)
            return (mean, var) if return_var else mean
        if len(Q) >= ONE_THREAD_ROWS:
            from threadpoolctl import threadpool_limits

            with threadpool_limits(limits=1, user_api="blas"):
                return self._predict_rows(Q, return_var)
        return self._predict_rows(Q, return_var)

    def _predict_rows(self, Q, return_var, compiled=True):
        mean, var = np.empty(len(Q)), np.empty(len(Q))
        for start in range(0, len(Q), QUERY_CHUNK):
            rows = slice(start, start + QUERY_CHUNK)
            k = self._covariance_to_runs(Q[rows], compiled)
            means = np.einsum("kmn,kn->km", k, self.alpha)
            # the moments over the draws as ndarray.mean / .var compute them, without their
            # Python-level wrappers (a third of a single query's time)
            draws = len(means)
            centre = np.add.reduce(means, axis=0) / draws
            mean[rows] = centre
            if return_var:
                v = k @ self.L_inv.transpose(0, 2, 1)
                variances = self.constant[:, None] - np.einsum("kmn,kmn->km", v, v) + self.noise[:, None]
                spread = means - centre
                var[rows] = (np.add.reduce(np.maximum(variances, 0.0), axis=0) / draws
                             + np.add.reduce(spread * spread, axis=0) / draws)
        return (mean, var) if return_var else mean

    def leave_one_out(self, y):
        """Closed-form leave-one-out mean and variance of each run (each draw's, Rasmussen & Williams
        2006 eq. 5.12, then the mixture's moments), standardized."""
        K_inv = self.L_inv.transpose(0, 2, 1) @ self.L_inv
        d = np.einsum("kii->ki", K_inv)
        means = y[None, :] - self.alpha / d
        return means.mean(axis=0), (1.0 / d).mean(axis=0) + means.var(axis=0)
