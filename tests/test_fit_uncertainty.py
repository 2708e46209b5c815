"""The linearised fit uncertainty (identification/uncertainty.py) on models with known answers:
a combination the data do not fix gets an infinite sd, never a small one."""

import json

import numpy as np
import pytest

from colonsim.identification.diagnostics import identification_words
from colonsim.identification.uncertainty import fit_uncertainty

X = np.linspace(0.1, 1.0, 40)
NOISE = np.random.default_rng(3).normal(0.0, 0.01, X.size)


def fit(simulate, theta, scales=(10.0, 10.0)):
    target = simulate(np.asarray(theta, dtype=float)) + NOISE
    return fit_uncertainty(simulate, target, theta, ("a", "b"), scales)


def test_a_well_posed_fit_has_the_textbook_standard_errors():
    """F = a x + b x^2: the covariance is s^2 (J^T J)^-1 and nothing is unidentified."""
    unc = fit(lambda t: t[0] * X + t[1] * X**2, [2.0, 1.0])
    J = np.column_stack([X, X**2])
    expected = unc.residual_sd**2 * np.linalg.inv(J.T @ J)
    assert np.allclose(unc.covariance, expected, rtol=1e-6)
    assert len(unc.unidentified) == 0 and np.all(np.isfinite(unc.std)) and unc.unidentified_words() is None


def test_a_combination_the_data_do_not_fix_has_an_infinite_sd():
    """F = (a + b) x: the data fix a + b (sd of the slope) and nothing of a - b, so a and b each
    have an infinite sd, a + b the slope's, and the JSON says so with nulls (strict JSON)."""
    unc = fit(lambda t: (t[0] + t[1]) * X, [2.0, 1.0])
    assert len(unc.unidentified) == 1
    assert np.allclose(np.abs(unc.unidentified[0]), [2**-0.5, 2**-0.5], atol=1e-6)
    assert np.all(np.isinf(unc.std))
    slope_sd = unc.residual_sd / np.sqrt(X @ X)
    assert unc.linear_combination_std([1.0, 1.0]) == pytest.approx(slope_sd, rel=1e-6)
    assert np.isinf(unc.linear_combination_std([1.0, 0.0]))
    d = unc.to_dict()
    assert d["std"] == {"a": None, "b": None} and d["ci95"] == {"a": None, "b": None}
    json.dumps(d, allow_nan=False)
    assert identification_words(3.0, np.inf, True).startswith("not identified")
    assert "+0.71 a -0.71 b" in unc.unidentified_words() or "-0.71 a +0.71 b" in unc.unidentified_words()


def test_a_direction_looser_than_the_bounds_is_not_identified():
    """F = a x + b (x + 1e-4 x^2): a - b is fixed only to far more than the bound width of 10:
    unidentified within the bounds, where the pseudo-inverse of before gave it a finite sd."""
    unc = fit(lambda t: t[0] * X + t[1] * (X + 1e-4 * X**2), [2.0, 1.0])
    assert len(unc.unidentified) == 1 and np.all(np.isinf(unc.std))
    wide = fit(lambda t: t[0] * X + t[1] * (X + 1e-4 * X**2), [2.0, 1.0], scales=(1e6, 1e6))
    assert len(wide.unidentified) == 0 and np.all(np.isfinite(wide.std))  # bounds wide enough to hold it
