"""The compiled loops of a GP mixture's prediction (:class:`colonsim.surrogate.hyperposterior.Mixture`):
the Matern 5/2 covariances of query rows to the runs for every hyperparameter draw, and the
mixture's moments at a few rows in one pass.

A module of its own so that Numba is imported only where these loops run
(:func:`colonsim.surrogate.hyperposterior.loaded_loops`), not by every query.
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True)
def covariance_to_runs(Q, X, inv_length, constant, out):
    """Each draw's Matern 5/2 covariance between the rows of ``Q`` (m, d) and the runs ``X`` (n, d)
    into ``out`` (draws, m, n): inverse length scales ``inv_length[k]``, signal variance
    ``constant[k]``, the formulas of :func:`few_rows_moments`. One pass over the output: numpy's
    distance and correlation took ten temporaries of its size and three quarters of a batch's time
    (2026-11-29, 10,000 queries of a 40-run model)."""
    for k in range(out.shape[0]):
        for i in range(Q.shape[0]):
            for j in range(X.shape[0]):
                out[k, i, j] = _covariance_of_rows(Q, i, X, j, inv_length, constant, k)


@numba.njit(cache=True, inline="always")
def _covariance_of_rows(Q, i, X, j, inv_length, constant, k):
    """Draw ``k``'s Matern 5/2 covariance between row ``i`` of ``Q`` and run ``j`` of ``X`` (the
    distance from the difference of the rows)."""
    r2 = 0.0
    for a in range(X.shape[1]):
        z = (Q[i, a] - X[j, a]) * inv_length[k, a]
        r2 += z * z
    s = math.sqrt(5.0 * r2)
    return constant[k] * (1.0 + s + s * s / 3.0) * math.exp(-s)


@numba.njit(cache=True)
def few_rows_moments(Q, X, inv_length, constant, alpha, L_inv, noise, with_var, mean, var):
    """The mixture's mean and the variance of a new result (standardized) at the rows of ``Q``
    (m, d), into ``mean`` and ``var`` (m,): per draw k the Matern 5/2 covariance to the runs ``X``
    (n, d) with inverse length scales ``inv_length[k]`` and signal variance ``constant[k]``, its
    mean ``k . alpha[k]`` and variance ``constant[k] - |L_inv[k] k|^2 + noise[k]``; then the law
    of total variance over the draws, as :meth:`colonsim.surrogate.hyperposterior.Mixture._predict_rows` (the same numbers to
    round-off: sums in another order, the distance from the difference of the rows)."""
    draws, n = alpha.shape
    cov = np.empty(n)
    means = np.empty(draws)
    variances = np.empty(draws)
    for m in range(Q.shape[0]):
        for k in range(draws):
            mu = 0.0
            for j in range(n):
                cov[j] = _covariance_of_rows(Q, m, X, j, inv_length, constant, k)
                mu += cov[j] * alpha[k, j]
            means[k] = mu
            if with_var:
                explained = 0.0
                for i in range(n):
                    v = 0.0
                    for j in range(n):
                        v += L_inv[k, i, j] * cov[j]
                    explained += v * v
                variances[k] = max(constant[k] - explained + noise[k], 0.0)
        centre = means.sum() / draws
        mean[m] = centre
        if with_var:
            spread = 0.0
            for k in range(draws):
                spread += (means[k] - centre) ** 2
            var[m] = variances.sum() / draws + spread / draws
