"""The GP's hyperparameters integrated out (colonsim.surrogate.hyperposterior): the mixture's
arithmetic against GPs conditioned one by one, the Laplace draws against an independent Hessian,
the curvature floor, and a saved model without draws.

The data are SYNTHETIC (a smooth function plus Gaussian noise): these tests check the regression,
not physics.
"""

import numpy as np
import pytest

from colonsim.surrogate.gp import GaussianProcess, draws_for, SMALL_FIT_RUNS
from colonsim.surrogate.hyperposterior import CURVATURE_FLOOR, DRAWS, FEW_ROWS, Mixture, laplace_draws, loaded_loops
from colonsim.surrogate.likelihood import log_marginal_likelihood
from colonsim.surrogate.validation import loo_predictions


def smooth(X):
    return np.sin(3.0 * X[:, 0]) + X[:, 1] ** 2


def runs(n, seed=3, noise=0.05):
    rng = np.random.default_rng(seed)
    X = rng.random((n, 3))  # the third input does not matter
    return X, smooth(X) + rng.normal(0.0, noise, n)


def fit(n, draws=None, seed=3):
    return GaussianProcess(input_range=(np.zeros(3), np.ones(3)), n_restarts=4, hyperparameter_draws=draws).fit(*runs(n, seed))


def map_theta(gp):
    return np.log([gp.constant_, *gp.length_scale_, gp.noise_level_])


def conditioned(gp, theta):
    """A plug-in GP on the same runs with the hyperparameters ``theta``."""
    one = GaussianProcess(input_range=(np.zeros(3), np.ones(3)))
    one.x_low_, one.x_span_, one.y_mean_, one.y_scale_ = gp.x_low_, gp.x_span_, gp.y_mean_, gp.y_scale_
    one._condition(gp.X_train_, gp.y_train_, theta)
    return one


def test_a_mixture_of_the_maximum_alone_is_the_plug_in():
    gp = fit(20, draws=0)
    Q = np.random.default_rng(0).random((30, 3))
    mean, std = gp.predict(Q, return_std=True)
    _, cov = gp.predict(Q[:6], return_cov=True)
    loo = loo_predictions(gp)
    gp.set_draws(map_theta(gp)[None])
    m, s = gp.predict(Q, return_std=True)
    _, c = gp.predict(Q[:6], return_cov=True)
    np.testing.assert_allclose(m, mean, rtol=1e-10)
    np.testing.assert_allclose(s, std, rtol=1e-8)
    np.testing.assert_allclose(c, cov, rtol=1e-7, atol=1e-14)
    np.testing.assert_allclose(loo_predictions(gp)[0], loo[0], rtol=1e-10)
    np.testing.assert_allclose(loo_predictions(gp)[1], loo[1], rtol=1e-8)


def test_the_mixture_follows_the_law_of_total_variance():
    gp = fit(20, draws=0)
    thetas = map_theta(gp) + np.array([[0.3, -0.2, 0.4, 0.0, 0.5], [-0.4, 0.3, -0.3, 0.2, -0.6]])
    parts = [conditioned(gp, t) for t in thetas]
    Q = np.random.default_rng(1).random((8, 3))
    means, sds = zip(*(p.predict(Q, return_std=True) for p in parts))
    covs = [p.predict(Q, return_cov=True)[1] for p in parts]
    gp.set_draws(thetas)
    mean, std = gp.predict(Q, return_std=True)
    _, cov = gp.predict(Q, return_cov=True)
    np.testing.assert_allclose(mean, np.mean(means, axis=0), rtol=1e-10)
    np.testing.assert_allclose(std**2, np.mean(np.square(sds), axis=0) + np.var(means, axis=0), rtol=1e-8)
    spread = np.array(means) - np.mean(means, axis=0)
    np.testing.assert_allclose(cov, np.mean(covs, axis=0) + spread.T @ spread / 2, rtol=1e-7, atol=1e-14)


def test_laplace_draws_spread_as_the_curvature_of_the_likelihood():
    """Many draws with no floor: their covariance is the inverse of the negative Hessian, here from
    second differences of the likelihood's value (the draws use its analytic gradient)."""
    gp = fit(60, draws=0)
    theta = map_theta(gp)[:3]  # the signal variance and the two length scales that matter
    full = map_theta(gp)

    def value(t3):
        return log_marginal_likelihood(np.r_[t3, full[3:]], gp.X_train_, gp.y_train_, eval_gradient=False)

    h, H = 1e-3, np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            ei, ej = np.eye(3)[i] * h, np.eye(3)[j] * h
            H[i, j] = (value(theta + ei + ej) - value(theta + ei - ej) - value(theta - ei + ej) + value(theta - ei - ej)) / (4 * h * h)
    draws = laplace_draws(full, np.log([[1e-3, 1e3]] * 5), gp.X_train_, gp.y_train_, n_draws=4096, floor=1e-9)
    # the marginal covariance of the first three of the full Gaussian is not the inverse of their
    # conditional Hessian; compare the conditional one: draws' precision block against -H
    precision = np.linalg.inv(np.cov(draws.T))[:3, :3]
    scale = np.sqrt(np.outer(np.diag(-H), np.diag(-H)))  # each entry against its diagonal's geometric mean
    assert np.abs((precision + H) / scale).max() < 0.06


def test_the_floor_bounds_a_direction_the_runs_leave_open():
    """The third input does not matter: its length scale is unconstrained by the runs, and its draws
    spread by at most 1 / sqrt(floor) in log units, not over the whole bound."""
    gp = fit(20)
    spread = np.std(gp.draws_, axis=0)
    assert len(gp.draws_) == DRAWS
    assert spread[3] <= 1.0 / np.sqrt(CURVATURE_FLOOR) * 1.3
    assert np.all(spread[:3] > 0)


def test_draws_widen_the_interval_more_with_fewer_runs():
    Q = np.random.default_rng(2).random((200, 3))

    def widening(n):
        integrated, plug = fit(n), fit(n, draws=0)
        return np.mean(integrated.predict(Q, return_std=True)[1] / plug.predict(Q, return_std=True)[1])

    few, many = widening(12), widening(80)
    assert few > 1.05 and few > many


def test_draws_are_reproducible_and_follow_the_size_of_the_sweep():
    np.testing.assert_array_equal(fit(15).draws_, fit(15).draws_)
    assert draws_for(SMALL_FIT_RUNS) == DRAWS and draws_for(SMALL_FIT_RUNS + 1) == 0 and draws_for(500, 4) == 4
    assert fit(15, draws=0).draws_.shape == (0, 5) and fit(15, draws=0).mixture_ is None


def test_a_saved_model_without_draws_predicts_with_the_maximum(tmp_path):
    """Files written before the draws (format 1.3) hold none: they load as the plug-in they were."""
    from colonsim.surrogate.model import SweepSurrogate
    from colonsim.surrogate.store import load_surrogate, save_surrogate
    from colonsim.surrogate.synthetic import synthetic_sweep

    table = synthetic_sweep(n_runs=16, segments=("rsj",), noise_cm=0.02, n_failed=0, seed=4)
    plug = SweepSurrogate(targets=("max_deformation_cm",), n_restarts=0, hyperparameter_draws=0).fit(table)
    json_path, _ = save_surrogate(plug, tmp_path / "old")
    loaded = load_surrogate(json_path)
    gp = loaded.models_["rsj"]["max_deformation_cm"]
    assert gp.mixture_ is None and loaded.hyperparameter_draws == 0
    q = {"scope_diameter_mm": 11.0, "diameter_mm": 30.0, "friction": 0.05}
    assert loaded.predict(q, "rsj", return_std=True)[1] == pytest.approx(plug.predict(q, "rsj", return_std=True)[1])


def test_mixture_batches_agree_with_single_queries():
    gp = fit(20)
    Q = np.random.default_rng(5).random((3000, 3))  # more than one chunk, on one BLAS thread
    mean, std = gp.predict(Q, return_std=True)
    for i in (0, 2047, 2048, 2999):
        m, s = gp.predict(Q[i:i + 1], return_std=True)
        assert m[0] == pytest.approx(mean[i], rel=1e-10) and s[0] == pytest.approx(std[i], rel=1e-8)
    assert isinstance(gp.mixture_, Mixture)


@pytest.mark.parametrize("with_var", [True, False])
def test_few_rows_take_the_compiled_loop_once_numba_is_loaded_and_give_the_numbers_of_the_batch(with_var):
    """A query of a few rows (FEW_ROWS) is answered by one compiled loop once Numba is loaded, by
    numpy before (a process that asks once), a batch by numpy around compiled covariances: the
    same mixture to round-off, at a training run (distance zero), near one and far away."""
    gp = fit(20)
    mix = gp.mixture_
    Q = np.vstack([gp.X_train_[3], gp.X_train_[5] + 1e-7, np.random.default_rng(1).random((FEW_ROWS - 3, 3)),
                   [3.0, -2.0, 0.5]])
    assert len(Q) == FEW_ROWS
    import colonsim.surrogate.gp_loops  # noqa: F401  (loads Numba: the compiled loop answers)

    assert loaded_loops() is not None
    compiled = mix.predict(Q, return_var=with_var)
    batch = mix._predict_rows(Q, with_var)
    light = mix._predict_rows(Q, with_var, compiled=False)  # what a process without Numba answers
    for got, want, plain in zip(*((r,) if not with_var else r for r in (compiled, batch, light))):
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(plain, want, rtol=1e-9, atol=1e-12)
    one = mix.predict(Q[:1], return_var=with_var)
    np.testing.assert_allclose(one[0] if with_var else one, (batch[0] if with_var else batch)[:1], rtol=1e-9)
