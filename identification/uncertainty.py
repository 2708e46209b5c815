"""Parameter uncertainty and correlation of a least-squares fit, from the Jacobian.

With residuals r(theta) = F_exp - F_sim(theta) at n points and p parameters, the linearised
covariance at the optimum is

    Sigma = s^2 (J^T J)^-1,  J = dF_sim / dtheta,  s^2 = |r|^2 / (n - p),

which also absorbs systematic misfit into s^2. docs/model.md warns that uniaxial data pin
C10 + C01 and C11 but barely the C10/C01 split: this shows as a correlation near -1 and a
large condition number of J^T J, and is reported rather than hidden.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats


@dataclass
class FitUncertainty:
    """Linearised uncertainty of fitted parameters (all in Pa)."""

    names: tuple
    estimate: np.ndarray
    covariance: np.ndarray
    dof: int
    residual_sd: float
    condition_number: float

    @property
    def std(self):
        return np.sqrt(np.clip(np.diag(self.covariance), 0.0, None))

    @property
    def correlation(self):
        sd = self.std
        with np.errstate(invalid="ignore", divide="ignore"):
            c = self.covariance / np.outer(sd, sd)
        return np.where(np.isfinite(c), c, 0.0)

    def interval(self, level=0.95):
        """Per-parameter confidence intervals (Student t), shape (p, 2)."""
        half = stats.t.ppf(0.5 + level / 2, self.dof) * self.std
        return np.stack([self.estimate - half, self.estimate + half], axis=1)

    def mahalanobis2(self, theta):
        d = np.asarray(theta, dtype=float) - self.estimate
        return float(d @ np.linalg.pinv(self.covariance) @ d)

    def region_threshold(self, level=0.95):
        """Squared Mahalanobis radius of the joint confidence region p F(p, n-p; level)."""
        p = len(self.names)
        return float(p * stats.f.ppf(level, p, self.dof))

    def contains(self, theta, level=0.95) -> bool:
        """Whether ``theta`` lies inside the joint confidence ellipsoid at ``level``."""
        return self.mahalanobis2(theta) <= self.region_threshold(level)

    def linear_combination_std(self, weights):
        w = np.asarray(weights, dtype=float)
        return float(np.sqrt(max(w @ self.covariance @ w, 0.0)))

    def to_dict(self, level=0.95) -> dict:
        ci = self.interval(level)
        return {
            "method": "linearised least squares: s^2 (J^T J)^-1 at the optimum, J by central differences",
            "std": dict(zip(self.names, self.std.tolist())),
            f"ci{int(level * 100)}": {n: ci[i].tolist() for i, n in enumerate(self.names)},
            "correlation": self.correlation.tolist(),
            "covariance": self.covariance.tolist(),
            "dof": self.dof,
            "residual_sd_N": self.residual_sd,
            "condition_number_JTJ_scaled": self.condition_number if np.isfinite(self.condition_number) else None,
            "joint_region": f"(theta - est)^T Sigma^-1 (theta - est) <= {self.region_threshold(level):.3f} ({level:.0%})",
        }


def jacobian(simulate, theta, steps):
    """Central-difference Jacobian of ``simulate(theta)`` (n,) with per-parameter ``steps``."""
    theta = np.asarray(theta, dtype=float)
    cols = []
    for i, h in enumerate(steps):
        e = np.zeros_like(theta)
        e[i] = h
        cols.append((simulate(theta + e) - simulate(theta - e)) / (2 * h))
    return np.stack(cols, axis=1)


def fit_uncertainty(simulate, force_exp, theta, names, scales):
    """Uncertainty of the fit ``theta`` of ``simulate`` to ``force_exp``.

    ``scales`` (the parameter bound widths) set the difference steps (1e-3 of each) and the
    scaling under which the condition number is reported.
    """
    theta = np.asarray(theta, dtype=float)
    scales = np.asarray(scales, dtype=float)
    r = np.asarray(force_exp) - simulate(theta)
    n, p = r.size, theta.size
    J = jacobian(simulate, theta, 1e-3 * scales)
    dof = max(n - p, 1)
    s2 = float(r @ r) / dof
    JTJ = J.T @ J
    cov = s2 * np.linalg.pinv(JTJ)
    Js = J * scales
    sv = np.linalg.svd(Js, compute_uv=False)
    cond = float((sv[0] / sv[-1]) ** 2) if sv[-1] > 0 else float("inf")
    return FitUncertainty(tuple(names), theta, cov, dof, float(np.sqrt(s2)), cond)
