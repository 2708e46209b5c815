"""The GP machinery of the surrogate, checked against scikit-learn and against a known function.

The data are SYNTHETIC (a smooth function plus Gaussian noise): these tests check the regression,
not physics.
"""

import numpy as np
import pytest
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import ConstantKernel, Matern, WhiteKernel

from colonsim.surrogate.gp import SMALL_FIT_RUNS, GaussianProcess, restarts_for
from colonsim.surrogate.likelihood import log_marginal_likelihood
from colonsim.surrogate.validation import Z95, cross_validate, loo_predictions


def smooth(X):
    return np.sin(3.0 * X[:, 0]) + X[:, 1] ** 2 + 0.5 * X[:, 0] * X[:, 2]


@pytest.fixture(scope="module")
def data():
    rng = np.random.default_rng(3)
    X = rng.random((60, 3))
    y = smooth(X) + rng.normal(0.0, 0.02, len(X))
    return X, y


@pytest.fixture(scope="module")
def fitted(data):
    """The surrogate's GP: 60 runs, so its predictions average over draws of the hyperparameters."""
    return GaussianProcess(input_range=(np.zeros(3), np.ones(3)), n_restarts=1).fit(*data)


@pytest.fixture(scope="module")
def plug_in(data):
    """The same fit predicting with the likelihood's maximum alone, the GP scikit-learn computes."""
    return GaussianProcess(input_range=(np.zeros(3), np.ones(3)), n_restarts=1, hyperparameter_draws=0).fit(*data)


def _sklearn_twin(gp):
    kernel = (ConstantKernel(gp.constant_) * Matern(length_scale=gp.length_scale_, nu=2.5)
              + WhiteKernel(gp.noise_level_))
    return GaussianProcessRegressor(kernel, optimizer=None, alpha=1e-10).fit(gp.X_train_, gp.y_train_)


def test_likelihood_and_gradient_match_sklearn(data):
    X, y = data
    ys = (y - y.mean()) / y.std()
    kernel = ConstantKernel(1.3) * Matern(length_scale=[0.4, 0.7, 2.0], nu=2.5) + WhiteKernel(0.03)
    sk = GaussianProcessRegressor(kernel, optimizer=None).fit(X, ys)
    value, grad = sk.log_marginal_likelihood(sk.kernel_.theta, eval_gradient=True)
    ours, our_grad = log_marginal_likelihood(sk.kernel_.theta, X, ys)
    assert ours == pytest.approx(value, rel=1e-10)
    np.testing.assert_allclose(our_grad, grad, rtol=1e-7, atol=1e-9)


def test_numpy_predictor_matches_sklearn_predict(plug_in):
    fitted = plug_in
    sk = _sklearn_twin(fitted)
    Q = np.random.default_rng(0).uniform(-0.2, 1.2, (50, 3))
    mean, std = fitted.predict(Q, return_std=True)
    sk_mean, sk_std = sk.predict(fitted.scale(Q), return_std=True)
    np.testing.assert_allclose(mean, fitted.y_mean_ + fitted.y_scale_ * sk_mean, rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(std, fitted.y_scale_ * sk_std, rtol=1e-8)  # sklearn's std includes the white noise
    _, cov = fitted.predict(Q[:5], return_cov=True)
    _, sk_cov = sk.predict(fitted.scale(Q[:5]), return_cov=True)
    # sklearn's covariance carries the white noise on its diagonal; ours is the trend's only
    np.testing.assert_allclose(cov + fitted.y_scale_**2 * fitted.noise_level_ * np.eye(5),
                               fitted.y_scale_**2 * sk_cov, rtol=1e-7, atol=1e-12)


def test_recovers_the_function_within_its_stated_accuracy(fitted):
    Q = np.random.default_rng(1).random((400, 3))
    mean, std = fitted.predict(Q, return_std=True)
    std = np.sqrt(np.maximum(std**2 - fitted.noise_std**2, 0.0))  # the trend's alone, without the run-to-run scatter
    err = mean - smooth(Q)
    assert np.sqrt(np.mean(err**2)) < 0.03  # noise sd 0.02, range of the function about 2.5
    assert np.mean(np.abs(err) <= Z95 * std) > 0.85  # the trend's interval covers the truth
    assert fitted.noise_std == pytest.approx(0.02, rel=0.5)


@pytest.mark.parametrize("which", ["fitted", "plug_in"])
def test_std_grows_away_from_the_data(which, request):
    fitted = request.getfixturevalue(which)
    centre = np.array([[0.5, 0.5, 0.5]])
    far = [fitted.predict(centre + [[d, 0.0, 0.0]], return_std=True)[1][0] for d in (0.0, 1.0, 3.0, 10.0)]
    assert np.all(np.diff(far) > 0)
    # far away the GP returns to its prior: mean of the data, sd of the data (the mixture: the
    # draws' prior variances averaged)
    mean, std = fitted.predict([[50.0, 50.0, 50.0]], return_std=True)
    assert mean[0] == pytest.approx(fitted.y_mean_, abs=1e-6)
    prior = (np.exp(fitted.draws_[:, 0]) + np.exp(fitted.draws_[:, -1])).mean() if len(fitted.draws_) else \
        fitted.constant_ + fitted.noise_level_
    assert std[0] == pytest.approx(fitted.y_scale_ * np.sqrt(prior), rel=1e-6)


def test_closed_form_loo_equals_refitting_without_each_run(plug_in, data):
    fitted = plug_in
    X, y = data
    mean, std = loo_predictions(fitted)
    for i in (0, 17, 59):
        keep = np.arange(len(y)) != i
        gp = GaussianProcess(input_range=(np.zeros(3), np.ones(3)))
        gp.x_low_, gp.x_span_, gp.y_mean_, gp.y_scale_ = fitted.x_low_, fitted.x_span_, fitted.y_mean_, fitted.y_scale_
        theta = np.log([fitted.constant_, *fitted.length_scale_, fitted.noise_level_])
        gp._condition(fitted.X_train_[keep], fitted.y_train_[keep], theta)
        m, s = gp.predict(X[i:i + 1], return_std=True)
        assert mean[i] == pytest.approx(m[0], rel=1e-8)
        assert std[i] == pytest.approx(s[0], rel=1e-6)


def test_cross_validation_is_sensible(fitted, data):
    X, y = data
    loo = cross_validate(fitted, X, y, "loo")
    assert loo["n"] == 60 and 0.85 <= loo["coverage_95"] <= 1.0
    assert loo["rmse"] < 0.05 and loo["max_abs_error"] < 0.15 and loo["q2"] > 0.99
    kfold = cross_validate(fitted, X, y, 5, make_gp=lambda: GaussianProcess(n_restarts=0))
    assert kfold["scheme"].startswith("5-fold") and kfold["rmse"] < 0.06 and kfold["coverage_95"] >= 0.8


@pytest.mark.parametrize("seed", [0, 13])
def test_default_restarts_find_the_best_optimum_of_few_runs(seed):
    """Eleven noisy runs: a likelihood with several optima, where 2 restarts stop on a lower one and
    the default for small sweeps (32) reaches what 64 reach."""
    rng = np.random.default_rng(seed)
    X = rng.random((11, 3))
    y = smooth(X) + rng.normal(0.0, 0.05, len(X))

    def best(n_restarts):
        return GaussianProcess(input_range=(np.zeros(3), np.ones(3)), n_restarts=n_restarts).fit(X, y).log_marginal_likelihood_

    default = best(None)
    assert default >= best(64) - 1e-6
    assert best(2) < default - 0.5


def test_restarts_follow_the_size_of_the_sweep():
    assert restarts_for(SMALL_FIT_RUNS) == 32 and restarts_for(SMALL_FIT_RUNS + 1) == 2
    assert restarts_for(12, n_restarts=0) == 0 and restarts_for(500, n_restarts=7) == 7
