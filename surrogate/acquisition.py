"""Where to run next: a batch of points at which the surrogate is least certain.

Greedy maximum posterior variance, batch by conditioning: pick the candidate with the largest
variance of the smooth trend, condition the GP on a (noisy) run there, pick again. A GP's
posterior variance does not depend on the values observed, only on where they were observed, so
the conditioning needs no result of the picked runs: the batch is exactly what a one-at-a-time
design would have chosen, and its points spread out instead of crowding around one uncertain
spot (Rasmussen & Williams 2006, sec. 2.2: the posterior covariance; each pick is a rank-one
update of it). Candidates of several models (one GP per colon segment) compete on one scale, the
target's unit: the batch goes to the segment whose trend is least known.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import solve_triangular

from colonsim.errors import ColonsimError
from colonsim.surrogate.gp import GaussianProcess
from colonsim.surrogate.kernel import matern52


@dataclass
class Pick:
    """One chosen candidate: which group (model) and row, and why (the trend's sd when chosen)."""

    group: int
    index: int
    sd: float  # posterior sd of the smooth trend at the pick, given the runs and the earlier picks (target units)
    sd_with_scatter: float  # the same plus the run-to-run scatter: the sd of a new run's result


class _Posterior:
    """The posterior covariance of one GP's trend over its candidates, updated pick by pick."""

    def __init__(self, gp: GaussianProcess, X):
        self.gp = gp
        self.C = gp.scale(np.atleast_2d(np.asarray(X, dtype=float)))
        # prior-minus-data part: V = L^-1 k(train, C), cov = c k(C, C) - V^T V (standardized units)
        self.V = solve_triangular(gp.L_, gp.constant_ * matern52(gp.X_train_, self.C, gp.length_scale_),
                                  lower=True, check_finite=False)
        self.var = np.maximum(gp.constant_ - np.einsum("ij,ij->j", self.V, self.V), 0.0)
        self.updates = []  # one vector per pick: cov(C, pick) / sqrt(var(pick) + noise)
        self.taken = np.zeros(len(self.C), dtype=bool)

    def covariance_column(self, j):
        """Current posterior covariance between every candidate and candidate ``j``."""
        gp = self.gp
        col = gp.constant_ * matern52(self.C, self.C[j:j + 1], gp.length_scale_)[:, 0] - self.V.T @ self.V[:, j]
        for u in self.updates:
            col -= u * u[j]
        return col

    def condition_on(self, j):
        """Add a run at candidate ``j`` (with the GP's scatter) to what the posterior knows."""
        u = self.covariance_column(j) / np.sqrt(self.var[j] + self.gp.noise_level_)
        self.updates.append(u)
        self.var = np.maximum(self.var - u * u, 0.0)
        self.taken[j] = True


def trend_sd(gp: GaussianProcess, X) -> np.ndarray:
    """Posterior sd of the smooth trend (no run-to-run scatter) at the rows of ``X``, target units."""
    return gp.y_scale_ * np.sqrt(_Posterior(gp, X).var)


def greedy_max_variance(groups, batch: int) -> list:
    """Choose ``batch`` candidates, each where the trend's posterior variance is largest given the
    runs and the candidates chosen before it.

    Parameters
    ----------
    groups : sequence of (GaussianProcess, ndarray (m, d))
        Per model, the fitted GP and its candidate inputs (physical units, the GP's input order).
    batch : int
        Number of picks (fewer if the candidates run out).

    Returns
    -------
    list of Pick, in the order chosen.
    """
    if batch < 1:
        raise ColonsimError(f"batch = {batch}; choose at least 1 run per round")
    posteriors = [_Posterior(gp, X) for gp, X in groups]
    picks = []
    for _ in range(batch):
        best = None
        for g, post in enumerate(posteriors):
            var = np.where(post.taken, -np.inf, post.var * post.gp.y_scale_**2)  # target units: groups compare
            if var.size and (best is None or var.max() > best[2]):
                best = (g, int(np.argmax(var)), float(var.max()))
        if best is None or not np.isfinite(best[2]):
            break
        g, j, var = best
        noise = posteriors[g].gp.noise_std**2
        picks.append(Pick(g, j, float(np.sqrt(var)), float(np.sqrt(var + noise))))
        posteriors[g].condition_on(j)
    return picks


__all__ = ["Pick", "greedy_max_variance", "trend_sd"]
