"""An output that is the larger of two others, modelled as such: the RSJ's largest deformation.

In the RSJ the largest deformation over a run is the larger of point A (the first maximum) and
point C (the largest value after the minimum B): ``max_deformation_cm = max(point_A_cm,
point_C_cm)`` run by run (:data:`colonsim.catalog.LARGER_OF`). Each point is a smooth function of
the inputs, but their maximum has a crease where C overtakes A (thin scopes in wide colons),
which one stationary GP of a few dozen runs smooths over with a large noise and still misses
(docs/surrogate.md, "The largest deformation: the larger of two smooth outputs"). Here a new
result is ``Y = max(Y_A, Y_C)`` with ``Y_A`` and ``Y_C`` the two fitted GPs' predictive
Gaussians, taken as independent, and its mean, sd and the joint covariance of its trend are
Clark's (1961) moments of the maximum of two Gaussians:

    a = sqrt(s_A^2 + s_C^2), alpha = (m_A - m_C) / a
    E[Y]   = m_A Phi(alpha) + m_C Phi(-alpha) + a phi(alpha)
    E[Y^2] = (m_A^2 + s_A^2) Phi(alpha) + (m_C^2 + s_C^2) Phi(-alpha) + (m_A + m_C) a phi(alpha)

and, between two query points, the covariance of the linearisation
``Y_i ~ Phi(alpha_i) Y_A,i + Phi(-alpha_i) Y_C,i`` (exact far from the crease, where one point
dominates). The intervals printed are mean +- z sd of this moment-matched Gaussian; how well they
cover is measured on held-out runs, not assumed.
"""

from __future__ import annotations

import numpy as np
from scipy.special import ndtr

from colonsim.catalog import LARGER_OF
from colonsim.surrogate.table import numeric_column
from colonsim.surrogate.validation import kfold_predictions, loo_predictions, metrics

# the identity max = max(A, C) must hold to this share of the output's range on every training
# run (the table's values are rounded to about ten digits)
IDENTITY_TOLERANCE = 1e-6

SQRT_2PI = np.sqrt(2.0 * np.pi)


def larger_moments(m_a, s_a, m_c, s_c):
    """Mean, sd and the weight Phi(alpha) of part A of max(Y_A, Y_C), independent Gaussians."""
    a = np.sqrt(np.maximum(s_a**2 + s_c**2, 1e-300))
    alpha = (m_a - m_c) / a
    # the standard normal density written out (scipy.stats' formula; its distribution object
    # cost a tenth of a query)
    w, pdf = ndtr(alpha), np.exp(-alpha**2 / 2.0) / SQRT_2PI
    mean = m_a * w + m_c * (1.0 - w) + a * pdf
    second = (m_a**2 + s_a**2) * w + (m_c**2 + s_c**2) * (1.0 - w) + (m_a + m_c) * a * pdf
    return mean, np.sqrt(np.maximum(second - mean**2, 0.0)), w


def identity_holds(runs, target) -> str | None:
    """None when ``target`` equals the larger of its parts (:data:`LARGER_OF`) on every run of
    ``runs`` that has a value of it, else why not (a part missing or the identity broken)."""
    parts = LARGER_OF[target]
    y = numeric_column(runs, target).to_numpy(dtype=float)
    a, c = (numeric_column(runs, p).to_numpy(dtype=float) for p in parts)
    has = np.isfinite(y)
    if not (np.isfinite(a[has]).all() and np.isfinite(c[has]).all()):
        return f"{int((has & ~(np.isfinite(a) & np.isfinite(c))).sum())} runs lack {' or '.join(parts)}"
    scale = max(float(np.ptp(y[has])) if has.any() else 0.0, 1e-12)
    off = np.abs(y[has] - np.maximum(a[has], c[has])) > IDENTITY_TOLERANCE * scale
    if off.any():
        return f"{int(off.sum())} runs where it is not the larger of {' and '.join(parts)}"
    return None


class LargerOf:
    """Predictions of an output that is the larger of two fitted outputs (GaussianProcess each),
    with the interface of :class:`colonsim.surrogate.gp.GaussianProcess` that queries use."""

    def __init__(self, names, gp_a, gp_c):
        self.names = tuple(names)
        self.parts = (gp_a, gp_c)

    @property
    def n_train(self) -> int:
        return self.parts[0].n_train

    def training_runs(self):
        """The training runs' inputs and the larger of their two parts (the output, by the identity)."""
        (X, y_a), (_, y_c) = (gp.training_runs() for gp in self.parts)
        return X, np.maximum(y_a, y_c)

    @property
    def description(self) -> str:
        return f"the larger of the {self.names[0]} and {self.names[1]} models (Clark's moments)"

    def predict(self, X, return_std=False, return_cov=False):
        """Mean of a new result at the rows of ``X``; with ``return_std`` its sd (both parts' trend
        and scatter inside the maximum); with ``return_cov`` the mean and joint covariance of the
        maximum of the two trends (scatter left out, as :meth:`GaussianProcess.predict`)."""
        gp_a, gp_c = self.parts
        if return_cov:
            m_a, k_a = gp_a.predict(X, return_cov=True)
            m_c, k_c = gp_c.predict(X, return_cov=True)
            s_a, s_c = (np.sqrt(np.maximum(np.diag(k), 0.0)) for k in (k_a, k_c))
            mean, sd, w = larger_moments(m_a, s_a, m_c, s_c)
            cov = np.outer(w, w) * k_a + np.outer(1.0 - w, 1.0 - w) * k_c
            # Clark's variance on the diagonal where it exceeds the linearisation's (keeps it PSD)
            cov[np.diag_indices_from(cov)] += np.maximum(sd**2 - np.diag(cov), 0.0)
            return mean, cov
        (m_a, s_a), (m_c, s_c) = gp_a.predict(X, return_std=True), gp_c.predict(X, return_std=True)
        mean, sd, _ = larger_moments(m_a, s_a, m_c, s_c)
        return (mean, sd) if return_std else mean


def cross_validate_larger(model: LargerOf, X, parts_y, y, cv="loo", make_gps=None, seed=0):
    """Cross-validation metrics of ``model`` against the output ``y``: each run predicted from its
    parts' leave-one-out (or k-fold, the same folds for both parts) predictions, combined as above.

    ``parts_y``: the two parts' values at the rows of ``X``; ``make_gps``: a GP factory per part
    (k-fold only)."""
    if cv == "loo":
        (m_a, s_a), (m_c, s_c) = (loo_predictions(gp) for gp in model.parts)
        scheme = "leave-one-out of both parts (closed form, hyperparameters from all runs), larger of the two"
    else:
        (m_a, s_a), (m_c, s_c) = (kfold_predictions(make, X, yp, int(cv), seed) for make, yp in zip(make_gps, parts_y))
        scheme = f"{int(cv)}-fold of both parts (hyperparameters refitted per fold), larger of the two"
    mean, sd, _ = larger_moments(m_a, s_a, m_c, s_c)
    return {"scheme": scheme, **metrics(y, mean, sd)}
