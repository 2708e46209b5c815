"""Log marginal likelihood of the GP and its gradient in the log hyperparameters.

Model (standardized target, inputs in [0, 1]): ``y ~ N(0, c M + s I)`` with ``M`` the Matern 5/2
correlation of per-input length scales ``l``, ``c`` the signal variance and ``s`` the white-noise
variance. Parameters ``theta = log([c, l_1, ..., l_d, s])`` - the order and parametrisation of
scikit-learn's ``ConstantKernel * Matern + WhiteKernel``, so the two can be compared directly.

Written out because scikit-learn's gradient contracts an (n, n, p) tensor with ``einsum`` and
takes about 0.5 s per evaluation for 500 runs and 5 inputs; the traces below are elementwise
products of (n, n) matrices and take about 20 ms.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import cho_solve, cholesky

from surrogate.kernel import SQRT5

JITTER = 1e-10  # added to the diagonal, as scikit-learn's GaussianProcessRegressor(alpha=1e-10)


def squared_differences(X):
    """Per-input squared differences between all pairs of rows of ``X`` (n, d): (d, n, n)."""
    X = np.asarray(X, dtype=float)
    return np.stack([(X[:, k, None] - X[None, :, k]) ** 2 for k in range(X.shape[1])])


def log_marginal_likelihood(theta, sq_diff, y, eval_gradient=True):
    """Log marginal likelihood of standardized targets ``y`` for ``theta = log([c, l..., s])``.

    ``sq_diff`` comes from :func:`squared_differences` of the training inputs. Returns the value,
    or ``(value, gradient)``; ``(-inf, 0)`` if the covariance is not positive definite.
    """
    c, length_scale, s = np.exp(theta[0]), np.exp(theta[1:-1]), np.exp(theta[-1])
    n = len(y)
    D = sq_diff / (length_scale**2)[:, None, None]  # (d, n, n) scaled squared differences
    r = np.sqrt(D.sum(axis=0))
    e = np.exp(-SQRT5 * r)
    M = (1.0 + SQRT5 * r + 5.0 / 3.0 * r * r) * e
    K = c * M
    K[np.diag_indices(n)] += s + JITTER
    try:
        L = cholesky(K, lower=True, check_finite=False)
    except np.linalg.LinAlgError:
        return (-np.inf, np.zeros_like(theta)) if eval_gradient else -np.inf
    alpha = cho_solve((L, True), y, check_finite=False)
    value = -0.5 * y @ alpha - np.log(np.diag(L)).sum() - 0.5 * n * np.log(2.0 * np.pi)
    if not eval_gradient:
        return value
    # dLML/dtheta = 1/2 tr((alpha alpha^T - K^-1) dK/dtheta); both factors are symmetric
    W = np.outer(alpha, alpha) - cho_solve((L, True), np.eye(n), check_finite=False)
    grad = np.empty_like(theta)
    grad[0] = 0.5 * np.sum(W * K) - 0.5 * (s + JITTER) * np.trace(W)  # d(cM)/dlog c = cM
    # d M / d log l_k = 5/3 (1 + sqrt5 r) exp(-sqrt5 r) D_k
    G = c * 5.0 / 3.0 * (1.0 + SQRT5 * r) * e * W
    grad[1:-1] = 0.5 * np.einsum("kij,ij->k", D, G)
    grad[-1] = 0.5 * s * np.trace(W)
    return value, grad
