"""Cross-validated accuracy of a fitted GP: RMSE, maximum error, coverage of the 95 % intervals.

Two schemes:

- ``"loo"`` (default): leave-one-out in closed form (Rasmussen & Williams 2006, eq. 5.12):
  ``mean_-i = y_i - [K^-1 y]_i / [K^-1]_ii``, ``var_-i = 1 / [K^-1]_ii``. Exact for the
  prediction without run i, but with the hyperparameters fitted on all runs, so slightly
  optimistic. Costs one matrix inverse: scikit-learn has no leave-one-out for its GP, and refitting
  it without each run (hyperparameters kept) gives the same numbers (to 1e-10) 400-3000x slower
  (500 runs: 0.02 s against 17 s). Measured by
  ``NUMBA_NUM_THREADS=1 python benchmarks/bench_surrogate.py``.
- ``k`` (an integer >= 2): k-fold, refitting the hyperparameters on each training part. Honest,
  k times the fit cost.

The interval is that of a new simulation result (trend + scatter), the quantity a held-out run is.
"""

from __future__ import annotations

import numpy as np
from scipy.special import bdtr, chdtri

from colonsim.errors import ColonsimError
from colonsim.surrogate.likelihood import inverse_from_cholesky

Z95 = 1.959963984540054
# a noise variance within 5 % (2.5 % in sd) of its lower bound sits at it: where the likelihood is
# flat the optimizer stops short of the bound (measured: 1.02 x the replicate floor, 16 RSJ runs)
NOISE_AT_BOUND = 1.05
MIN_CHECKED_RUNS = 10  # fewer: the model cannot vouch for its error (measured, docs/surrogate.md "Too few runs")
# fewer runs per input than a computer experiment's usual size, n = 10 d (Loeppky, Sacks & Welch
# 2009, Technometrics 51:366), cannot vouch for its error either, with replicate runs or without
# (measured: 12- and 20-run models of three inputs stated 95 % intervals that held 43 / 63 % of
# 100 held-out runs without replicates, 51 / 83 % with them; docs/surrogate.md "Without replicate
# runs", "Rerun on 2026-12-01")
MIN_RUNS_PER_INPUT = 10
# held-out runs vouch for a model's intervals in place of its cross-validation (held_out_unknown)
# from this many runs on: the number the shipped predictor is judged by per patient model
MIN_HELD_OUT_RUNS = 30
HELD_OUT_LEVELS = (("coverage_95", 0.95), ("coverage_50", 0.50))
HELD_OUT_SIGNIFICANCE = 0.05  # so few covered runs happen this rarely with exact intervals: too narrow


def metrics(y, mean, std):
    """RMSE, maximum absolute error, coverage of mean +- 1.96 std, Q^2 = 1 - SSE / SS, and the root
    mean square of the standardized errors ``(y - mean) / std`` (about 1 when the sd is right)."""
    err = np.asarray(mean) - np.asarray(y)
    ss = float(np.sum((y - np.mean(y)) ** 2))
    return {"n": int(len(y)), "rmse": float(np.sqrt(np.mean(err**2))), "max_abs_error": float(np.max(np.abs(err))),
            "coverage_95": float(np.mean(np.abs(err) <= Z95 * np.asarray(std))),
            "mean_std": float(np.mean(std)), "q2": float(1.0 - np.sum(err**2) / ss) if ss > 0 else None,
            "z_rms": float(np.sqrt(np.mean((err / np.asarray(std)) ** 2)))}


def held_out_unknown(held_out: dict) -> str | None:
    """Why the held-out runs ``held_out`` do not vouch for a model's intervals, or None when they do.

    ``held_out``: {"runs", "coverage_95", "coverage_50", "sweeps"}, the coverage of the model's
    nominal 95 % and 50 % intervals on runs never used in its fit. They do not vouch when the
    intervals are too narrow: at either level so few runs covered that exact intervals would cover
    that few or fewer with probability below :data:`HELD_OUT_SIGNIFICANCE` (one-sided binomial,
    runs independent). Intervals too wide are conservative and stay stated; the held-out table
    (``benchmarks/bench_predictor.py``) says so."""
    n = int(held_out["runs"])
    for key, nominal in HELD_OUT_LEVELS:
        covered = int(round(float(held_out[key]) * n))
        p = float(bdtr(covered, n, nominal))
        if p < HELD_OUT_SIGNIFICANCE:
            return (f"its {100 * nominal:.0f} % intervals covered {covered} of {n} held-out runs "
                    f"({', '.join(held_out.get('sweeps', [])) or 'held-out sweeps'}), too few for intervals of "
                    f"that level (p {p:.2g}); fit more runs")
    return None


def error_unknown(cv: dict, gp, held_out: dict | None = None) -> str | None:
    """Why the model cannot state its error, or None when it can (docs/surrogate.md, "Too few runs").

    ``cv``: its cross-validation metrics; ``gp``: the fitted :class:`GaussianProcess` (or
    :class:`colonsim.surrogate.larger.LargerOf`, whose parts are checked); ``held_out``: the
    coverage of its intervals on at least :data:`MIN_HELD_OUT_RUNS` held-out runs, or None. Where
    held-out runs measured it, they decide (:func:`held_out_unknown`): a direct measure of the
    intervals, where the rules below are signs that cross-validation cannot be trusted to. Else
    the error is unknown when

    - fewer than :data:`MIN_CHECKED_RUNS` runs were predicted without themselves;
    - the noise sits at the bottom of its range: the fit explained the runs' scatter by short
      length scales instead of estimating it, and its intervals are then too narrow, which
      leave-one-out with those hyperparameters does not reveal. Without replicate runs the bottom is
      a nominal 1e-6 of the variance (intervals 100x too narrow, docs/surrogate.md, "Noise floor");
      with them it is their scatter, which is one source of the run-to-run scatter only (a mesh
      change), 0.5-0.75 of what a fit on 170 RSJ runs estimates (docs/surrogate.md, "Too few runs");
    - the model rests on fewer than :data:`MIN_RUNS_PER_INPUT` runs per input, whether or not
      replicate runs measured the scatter: between a collapsed noise and an estimated one lies a
      fit that put part of the scatter (or, for the largest deformation fitted as one output, the
      crease where C overtakes A) into short length scales or a noise just above the floor, which
      the checks above and leave-one-out with those hyperparameters do not reveal;
    - the standardized cross-validated errors are larger than the stated sd allows: the sum of
      their squares above the 95th percentile of a chi-square with as many degrees of freedom (a
      model whose sd is right exceeds it one time in twenty).
    """
    if held_out is not None and int(held_out["runs"]) >= MIN_HELD_OUT_RUNS:
        return held_out_unknown(held_out)
    n, z_rms = int(cv["n"]), cv.get("z_rms")
    if z_rms is None:
        return "its error was not cross-checked (a model of an older colonsim); refit it"
    if n < MIN_CHECKED_RUNS:
        return f"too few runs to know its error ({n} < {MIN_CHECKED_RUNS})"
    parts = getattr(gp, "parts", (gp,))  # a LargerOf: either part
    inputs = int(parts[0].X_train_.shape[1])
    needed = MIN_RUNS_PER_INPUT * inputs
    collapsed = [p for p in parts if noise_at_bottom(p)]
    if any(not replicate_floored(p) for p in collapsed):  # at the nominal bound, not a floor
        more = f" and fit at least {needed} runs" if n < needed else ""
        return ("too few runs to know its error: the fit put the run-to-run scatter at the bottom of its range instead "
                f"of estimating it; measure it with replicate runs (fit --replicates){more}")
    if collapsed:
        return ("too few runs to know its error: the fit put the run-to-run scatter at the floor the replicate runs "
                "measured instead of estimating it, and that floor is only part of the scatter; fit more runs")
    if n < needed:
        return (f"too few runs to know its error ({n} < {MIN_RUNS_PER_INPUT} per input, "
                f"{needed} for its {inputs}); fit more runs")
    limit = float(np.sqrt(chdtri(n, 0.05) / n))  # the chi-square's 95th percentile
    if z_rms > limit:
        return (f"too few runs to know its error: its cross-validated errors are {z_rms:.1f} times the sd it states "
                f"(at most {limit:.2f} with {n} runs)")
    return None


def replicate_floored(gp) -> bool:
    """Whether replicate runs floor the noise of ``gp`` above its nominal lower bound."""
    return gp.noise_bottom() > gp.noise_bounds[0]


def noise_at_bottom(gp) -> bool:
    """Whether the fitted noise variance of ``gp`` sits at its lower bound: the nominal one, or the
    replicate runs' scatter where that is higher."""
    return gp.noise_level_ <= NOISE_AT_BOUND * gp.noise_bottom()


def loo_predictions(gp):
    """Closed-form leave-one-out mean and std (target units) of a fitted :class:`GaussianProcess`
    (of the mixture over its hyperparameter draws where it has them)."""
    if gp.mixture_ is not None:
        mean, var = gp.mixture_.leave_one_out(gp.y_train_)
        return gp.y_mean_ + gp.y_scale_ * mean, gp.y_scale_ * np.sqrt(var)
    d = np.diag(inverse_from_cholesky(gp.L_))
    mean = gp.y_mean_ + gp.y_scale_ * (gp.y_train_ - gp.alpha_ / d)
    return mean, gp.y_scale_ / np.sqrt(d)


def kfold_predictions(make_gp, X, y, k, seed=0):
    """Held-out mean and std of each run from ``k`` folds, a new GP (``make_gp()``) fitted per fold."""
    n = len(y)
    if not 2 <= k <= n:
        raise ColonsimError(f"k-fold cross-validation needs 2 <= k <= {n} runs, got k = {k}; use --cv loo")
    folds = np.array_split(np.random.default_rng(seed).permutation(n), k)
    mean, std = np.empty(n), np.empty(n)
    for test in folds:
        train = np.setdiff1d(np.arange(n), test)
        gp = make_gp().fit(X[train], y[train])
        mean[test], std[test] = gp.predict(X[test], return_std=True)
    return mean, std


def cross_validate(gp, X, y, cv="loo", make_gp=None, seed=0):
    """Metrics of ``gp`` (fitted on ``X, y``) under ``cv`` ("loo" or an integer k)."""
    if cv == "loo":
        mean, std = loo_predictions(gp)
        scheme = "leave-one-out (closed form, hyperparameters from all runs)"
    else:
        mean, std = kfold_predictions(make_gp, X, y, int(cv), seed)
        scheme = f"{int(cv)}-fold (hyperparameters refitted per fold)"
    return {"scheme": scheme, **metrics(y, mean, std)}
