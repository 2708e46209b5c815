"""Parameter uncertainty and correlation of a least-squares fit, from the Jacobian.

With residuals r(theta) = F_exp - F_sim(theta) at n points and p parameters, the linearised
covariance at the optimum is

    Sigma = s^2 (J^T J)^-1,  J = dF_sim / dtheta,  s^2 = |r|^2 / (n - p),

which also absorbs systematic misfit into s^2. docs/model.md warns that uniaxial data pin
C10 + C01 and C11 but barely the C10/C01 split: this shows as a correlation near -1 and a
large condition number of J^T J, and is reported rather than hidden.

Where the data do not fix a combination of the parameters at all (two Ogden terms with the same
exponent, a parameter the curve does not reach), J^T J is singular and its inverse does not
exist; a pseudo-inverse would quietly give that combination zero variance, and a parameter in it
an sd of nearly nothing. Here the inverse is taken on the scaled Jacobian's singular directions
(each parameter in units of its bound width): a direction is **unidentified** when its singular
value is below :data:`SINGULAR_RCOND` of the largest (singular to the Jacobian's accuracy) or
when its sd exceeds the whole width of the bounds (:data:`UNBOUNDED_SD`). Such directions are
listed, and every parameter and every combination with a share in one has an infinite sd
(``null`` in JSON), never a small one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats


SINGULAR_RCOND = 1e-6  # a scaled singular value below this share of the largest: singular to the Jacobian's accuracy
UNBOUNDED_SD = 1.0  # a direction whose sd exceeds this many bound widths is not identified within the bounds
SHARE = 1e-6  # a parameter (or a combination) with a larger share in an unidentified direction has an infinite sd


def sd_for_json(sd):
    """A standard deviation as JSON holds it: a number, or null for an infinite one (not identified)."""
    return float(sd) if np.isfinite(sd) else None


@dataclass
class FitUncertainty:
    """Linearised uncertainty of fitted parameters (all in Pa).

    ``covariance`` is that of the identified directions; ``unidentified`` (k, p) holds the unit
    directions, in parameter units scaled by ``scales``, along which the data fix nothing."""

    names: tuple
    estimate: np.ndarray
    covariance: np.ndarray
    dof: int
    residual_sd: float
    condition_number: float
    unidentified: np.ndarray | None = None
    scales: np.ndarray | None = None

    def _unbounded(self, weights) -> bool:
        """Does the combination ``weights . theta`` have a share in an unidentified direction?"""
        if self.unidentified is None or not len(self.unidentified):
            return False
        w = np.asarray(weights, dtype=float) * self.scales  # the combination in scaled parameters
        norm = np.linalg.norm(w)
        return bool(norm > 0.0 and np.any(np.abs(self.unidentified @ w) > SHARE * norm))

    @property
    def std(self):
        sd = np.sqrt(np.clip(np.diag(self.covariance), 0.0, None))
        return np.where([self._unbounded(e) for e in np.eye(len(sd))], np.inf, sd)

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

    def unidentified_words(self) -> str | None:
        """One line naming the combinations the data do not fix (None when every one is fixed)."""
        if self.unidentified is None or not len(self.unidentified):
            return None
        combos = ["(" + " ".join(f"{c:+.2f} {n}" for c, n in zip(v, self.names) if abs(c) > 1e-3) + ")"
                  for v in self.unidentified]
        return (f"not identified by the data: {', '.join(combos)} (in bound widths); every parameter in "
                "them has an infinite sd: fix one of them, or fit data that load them differently")

    def linear_combination_std(self, weights):
        w = np.asarray(weights, dtype=float)
        if self._unbounded(w):
            return float("inf")
        return float(np.sqrt(max(w @ self.covariance @ w, 0.0)))

    def to_dict(self, level=0.95) -> dict:
        ci = self.interval(level)
        sd = self.std
        directions = [] if self.unidentified is None else self.unidentified
        return {
            "method": "linearised least squares: s^2 (J^T J)^-1 at the optimum, J by central differences, inverted "
                      "on the identified singular directions of the Jacobian scaled by the bound widths",
            "std": {n: sd_for_json(sd[i]) for i, n in enumerate(self.names)},
            f"ci{int(level * 100)}": {n: (ci[i].tolist() if np.isfinite(sd[i]) else None)
                                       for i, n in enumerate(self.names)},
            "unidentified": [{"direction_in_bound_widths": dict(zip(self.names, np.round(v, 6).tolist())),
                              "meaning": "the data do not fix this combination of the parameters: its sd, and "
                                         "that of every parameter with a share in it, is infinite (null)"}
                             for v in directions],
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
    Js = J * scales
    _, sv, vt = np.linalg.svd(Js, full_matrices=False)
    cond = float((sv[0] / sv[-1]) ** 2) if sv[-1] > 0 else float("inf")
    with np.errstate(divide="ignore"):
        sd_along = np.where(sv > 0.0, np.sqrt(s2) / sv, np.inf)  # sd along each singular direction, bound widths
    known = (sv > SINGULAR_RCOND * sv[0]) & (sd_along <= UNBOUNDED_SD)
    v = vt[known]
    cov_scaled = (v.T / sv[known] ** 2) @ v * s2
    cov = cov_scaled * np.outer(scales, scales)
    return FitUncertainty(tuple(names), theta, cov, dof, float(np.sqrt(s2)), cond, unidentified=vt[~known],
                          scales=scales)
