"""Where to run next: a batch of points at which the surrogate is least certain.

Greedy maximum posterior variance, batch by conditioning: pick the candidate with the largest
variance of the smooth trend, condition the GP on a (noisy) run there, pick again. A GP's
posterior variance does not depend on the values observed, only on where they were observed, so
the conditioning needs no result of the picked runs: the batch is exactly what a one-at-a-time
design would have chosen, and its points spread out instead of crowding around one uncertain
spot (Rasmussen & Williams 2006, sec. 2.2: the posterior covariance; each pick is a rank-one
update of it). Candidates of several models (one GP per colon segment) compete on one scale, the
target's unit: the batch goes to the segment whose trend is least known.

The variance of a stationary GP depends on the outputs only through its hyperparameters: that
criterion spreads runs where the model knows least, never towards a feature the runs have hinted
at. The second criterion, ``"error"``, adds that: the expected squared prediction error of Liu,
Cai & Ong (2017, Computers & Chemical Engineering 106, 171-182), the squared leave-one-out error
of the nearest run (in the kernel's metric: a bias estimate, large near a feature the model
misses) plus the posterior variance, with their balance fixed at one half. A pick's own
leave-one-out error is unknown until it has run, so it counts as zero for the candidates nearest
to it within the batch.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import solve_triangular

from colonsim.errors import ColonsimError
from colonsim.surrogate.gp import GaussianProcess
from colonsim.surrogate.kernel import matern52
from colonsim.surrogate.validation import loo_predictions

CRITERIA = ("variance", "error")


@dataclass
class Pick:
    """One chosen candidate: which group (model) and row, and why (the trend's sd when chosen)."""

    group: int
    index: int
    sd: float  # posterior sd of the smooth trend at the pick, given the runs and the earlier picks (target units)
    sd_with_scatter: float  # the same plus the run-to-run scatter: the sd of a new run's result
    bias: float = 0.0  # criterion "error": the leave-one-out error of the nearest run (target units)


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
        self.bias = None  # criterion "error": squared LOO error of each candidate's nearest run (standardized)

    def track_bias(self):
        """Start tracking the squared leave-one-out error of each candidate's nearest run."""
        gp = self.gp
        loo_mean, _ = loo_predictions(gp)
        y = gp.y_mean_ + gp.y_scale_ * gp.y_train_
        error2 = ((loo_mean - y) / gp.y_scale_) ** 2
        self.metric = self.C / gp.length_scale_  # the kernel's distance
        runs = gp.X_train_ / gp.length_scale_
        d2 = (np.einsum("ij,ij->i", self.metric, self.metric)[:, None] + np.einsum("ij,ij->i", runs, runs)[None]
              - 2.0 * self.metric @ runs.T)
        nearest = np.argmin(d2, axis=1)
        self.bias, self.nearest_d2 = error2[nearest], d2[np.arange(len(d2)), nearest]

    def score(self):
        """The criterion at every candidate, target units squared (taken ones -inf)."""
        value = self.var if self.bias is None else 0.5 * (self.bias + self.var)
        return np.where(self.taken, -np.inf, value * self.gp.y_scale_**2)

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
        if self.bias is not None:  # the pick is now the nearest run of the candidates closest to it
            d2 = ((self.metric - self.metric[j]) ** 2).sum(axis=1)
            closer = d2 < self.nearest_d2
            self.bias[closer], self.nearest_d2[closer] = 0.0, d2[closer]


def trend_sd(gp: GaussianProcess, X) -> np.ndarray:
    """Posterior sd of the smooth trend (no run-to-run scatter) at the rows of ``X``, target units."""
    return gp.y_scale_ * np.sqrt(_Posterior(gp, X).var)


def greedy_batch(groups, batch: int, criterion: str = "variance") -> list:
    """Choose ``batch`` candidates one after the other, each where ``criterion`` is largest given
    the runs and the candidates chosen before it.

    Parameters
    ----------
    groups : sequence of (GaussianProcess, ndarray (m, d))
        Per model, the fitted GP and its candidate inputs (physical units, the GP's input order).
    batch : int
        Number of picks (fewer if the candidates run out).
    criterion : "variance" or "error"
        The trend's posterior variance, or the expected squared prediction error (module docstring).

    Returns
    -------
    list of Pick, in the order chosen.
    """
    if batch < 1:
        raise ColonsimError(f"batch = {batch}; choose at least 1 run per round")
    if criterion not in CRITERIA:
        raise ColonsimError(f"criterion {criterion!r} is unknown; use one of {', '.join(CRITERIA)}")
    posteriors = [_Posterior(gp, X) for gp, X in groups]
    if criterion == "error":
        for post in posteriors:
            post.track_bias()
    picks = []
    for _ in range(batch):
        best = None
        for g, post in enumerate(posteriors):
            score = post.score()
            if score.size and (best is None or score.max() > best[2]):
                best = (g, int(np.argmax(score)), float(score.max()))
        if best is None or not np.isfinite(best[2]):
            break
        g, j, _ = best
        post = posteriors[g]
        scale = post.gp.y_scale_
        var = post.var[j] * scale**2
        bias = 0.0 if post.bias is None else float(np.sqrt(post.bias[j]) * scale)
        picks.append(Pick(g, j, float(np.sqrt(var)), float(np.sqrt(var + post.gp.noise_std**2)), bias))
        post.condition_on(j)
    return picks


__all__ = ["CRITERIA", "Pick", "greedy_batch", "trend_sd"]
