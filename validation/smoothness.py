"""Smooth across inputs (docs/quasi_static.md, "Smooth across inputs"): the validation report's
section on how smoothly the insertion's outputs follow its inputs.

Two checks, each reading sweeps made with the project's own tools, each judged against the larger
of a share of the output's spread and a multiple of the runs' own scatter (the standard deviation
over replicate runs that differ by a 7 % finer wall mesh, ``benchmarks/sweeps/gp_replicates.toml``
against the first ten runs of ``gp_train.toml``; reported per output):

- **against scope diameter**: RSJ D36 mu 0 at scope diameters 9.0 to 13.5 mm in 0.5 mm steps
  (``benchmarks/sweeps/smoothness.toml``); each output's departure from the least-squares cubic
  in the diameter, largest over the runs, as a share of the output's range. Pass under
  max(2 % of the range, 2 x the scatter). The
  largest deformation is also judged against the larger of the cubics of A and C, which it is
  the larger of (:func:`larger_of_cubics`): a crease where one overtakes the other is a regime
  change no single cubic follows, shown, not smoothed.
- **a surrogate's held-out error**: the project's GP surrogate fitted on a 20-run Latin hypercube
  of RSJ (scope 9-13.5 mm, D 20-40 mm, mu 0-0.1; ``gp_train.toml``) predicts 30 independent runs
  in the same ranges (``gp_test.toml``); its RMSE as a share of the held-out output's standard
  deviation. Pass under max(5 % of that deviation, 1.25 x the scatter).
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from colonsim.files import save_figure
from colonsim.insertion.study.claims import NO_DEFORMATION_CM
from colonsim.insertion.anatomy.scopes import colonoscope

CUBIC_TOLERANCE = 0.02  # of the output's range ...
CUBIC_SCATTER_FACTOR = 2.0  # ... or this many times the runs' own scatter, whichever is larger
SURROGATE_TOLERANCE = 0.05  # of the held-out output's spread ...
SURROGATE_SCATTER_FACTOR = 1.25  # ... or this many times the runs' own scatter, whichever is larger
# a replicate pairs with the run of the same inputs (rounded to this many decimals)
REPLICATE_INPUTS = ("scope_diameter_mm", "diameter_mm", "friction")
CUBIC_OUTPUTS = (("final_deformation_cm", "final [cm]"), ("max_deformation_cm", "max [cm]"),
                 ("point_C_cm", "C [cm]"), ("point_A_cm", "A [cm]"))
SURROGATE_OUTPUTS = ("final_deformation_cm", "max_deformation_cm", "point_A_cm", "point_C_cm", "peak_contact_force_N",
                     "peak_push_force_N")


def _ok(table):
    return table[table["status"] == "ok"] if "status" in table else table


def section(smooth, train, test, figure_path, figure_link, replicates=None):
    """The report's smoothness section: the departures from a cubic of the ``smooth`` sweep (figure
    written to ``figure_path``, cited as ``figure_link``) and the surrogate fitted on ``train``
    predicting ``test``, each judged against the larger of its share and of a multiple of the runs'
    own scatter (:func:`replicate_scatter` of ``replicates`` against ``train``)."""
    scatter = replicate_scatter(train, replicates)
    return {"cubic": cubic_departures(smooth, figure_path, scatter), "figure": figure_link,
            "surrogate": surrogate_holdout(train, test, scatter), "scatter": scatter}


def replicate_scatter(train, replicates) -> dict:
    """The runs' own scatter of each output (docs/quasi_static.md, "Smooth across inputs"): its
    standard deviation over pairs of runs that differ only by a negligible perturbation (a
    ``replicates`` run and the ``train`` run of the same inputs, :data:`REPLICATE_INPUTS`),
    sqrt(mean(difference^2) / 2), cm or N, with the number of pairs; {} without replicates."""
    if replicates is None or not (replicates.ran and train.ran):
        return {}
    a, b = _ok(train.table).copy(), _ok(replicates.table).copy()
    on = [f"_{c}" for c in REPLICATE_INPUTS]
    for t in (a, b):
        for c in REPLICATE_INPUTS:
            t[f"_{c}"] = t[c].astype(float).round(3)
    pairs = a.merge(b, on=on, suffixes=("", "_replicate"))
    out = {}
    for column in {*SURROGATE_OUTPUTS, *(c for c, _ in CUBIC_OUTPUTS)}:
        d = (pairs[column].astype(float) - pairs[f"{column}_replicate"].astype(float)).to_numpy()
        d = d[np.isfinite(d)]
        out[column] = {"scatter": float(np.sqrt(np.mean(d**2) / 2)) if d.size else math.nan, "pairs": int(d.size)}
    return out


def _scatter(scatter, column):
    return (scatter.get(column) or {}).get("scatter", math.nan)


def cubic_departures(sweep, figure_path, scatter=None):
    """Each output's largest departure from its cubic fit in the scope diameter, over its range."""
    if not sweep.ran:
        return {"ran": False}
    runs = _ok(sweep.table)
    d = np.array([colonoscope(s).diameter * 1e3 for s in runs["scope"]])
    order = np.argsort(d)
    d = d[order]
    rows, curves = [], []
    for column, label in CUBIC_OUTPUTS:
        y = runs[column].to_numpy(dtype=float)[order]
        keep = np.isfinite(y)
        if keep.sum() < 5:
            rows.append(_too_few_row(label, column, keep))
            continue
        coef, residual = cubic_fit(d[keep], y[keep])
        rows.append(_departure_row(label, column, d[keep], y[keep], residual, scatter))
        curves.append((label, d[keep], y[keep], coef))
    rows.append(_crease_row(runs, order, d, scatter))
    _cubic_figure(curves, figure_path)
    return {"ran": True, "rows": rows, "tolerance": CUBIC_TOLERANCE, "scatter_factor": CUBIC_SCATTER_FACTOR,
            "scatter_alone": scatter_alone_band(d)}


CREASE_LABEL = "max [cm], against the larger of the cubics of A and C"


def larger_of_cubics(d, a, c):
    """The larger of the least-squares cubics in ``d`` of ``a`` and ``c`` (each over its finite
    values), at ``d``: the smooth fit of an output that is the larger of the two."""
    fits = []
    for y in (a, c):
        keep = np.isfinite(y)
        fits.append(np.polyval(cubic_fit(d[keep], y[keep])[0], d) if keep.sum() >= 5 else np.full(d.shape, -np.inf))
    return np.maximum(*fits)


def _crease_row(runs, order, d, scatter=None):
    """The largest deformation's departure from :func:`larger_of_cubics` of A and C, as a row of
    :func:`cubic_departures`."""
    a, c, y = (runs[k].to_numpy(dtype=float)[order] for k in ("point_A_cm", "point_C_cm", "max_deformation_cm"))
    fit = larger_of_cubics(d, a, c)
    keep = np.isfinite(y) & np.isfinite(fit)
    if keep.sum() < 5:
        return _too_few_row(CREASE_LABEL, "max_deformation_cm", keep)
    return _departure_row(CREASE_LABEL, "max_deformation_cm", d[keep], y[keep], y[keep] - fit[keep], scatter)


def _too_few_row(label, column, keep):
    """A row of :func:`cubic_departures` for an output with under 5 finite values (``keep``): no verdict."""
    return {"output": label, "column": column, "runs": int(keep.sum()), "departure": math.nan, "passed": None}


def _departure_row(label, column, d, y, residual, scatter=None):
    """A row of :func:`cubic_departures`: the largest departure ``residual`` of the output ``y``
    (finite values, at scope diameters ``d``, mm) from its smooth fit, over ``y``'s range, and the
    verdict against the larger of :data:`CUBIC_TOLERANCE` of the range and
    :data:`CUBIC_SCATTER_FACTOR` times the runs' own scatter (where measured)."""
    spread = float(np.ptp(y))
    # an output that stays below 0.1 cm everywhere has no range to judge against (nothing
    # measurable, as in the claims: insertion/study/claims.py NO_DEFORMATION_CM)
    judged = float(np.abs(y).max()) >= NO_DEFORMATION_CM and spread > 0
    departure_cm = float(np.max(np.abs(residual)))
    departure = departure_cm / spread if judged else math.nan
    noise = _scatter(scatter or {}, column)
    bound = max(CUBIC_TOLERANCE * spread, CUBIC_SCATTER_FACTOR * noise if np.isfinite(noise) else 0.0)
    return {"output": label, "column": column, "runs": int(y.size), "range": spread,
            "departure": departure, "departure_cm": departure_cm if judged else math.nan,
            "at_scope_mm": float(d[np.argmax(np.abs(residual))]) if judged else None,
            "replicate_scatter": noise, "scatter_share": noise / spread if judged else math.nan,
            "bound": bound if judged else math.nan,
            "passed": bool(departure_cm < bound) if judged else None}


def cubic_fit(d, y):
    """The least-squares cubic in ``d`` through ``y``: its coefficients and the residuals."""
    coef = np.polyfit(d, y, 3)
    return coef, y - np.polyval(coef, d)


def scatter_alone_band(d, draws=5000, seed=0):
    """What scatter alone gives: the largest departure from the least-squares cubic of outputs
    that are independent standard normal at the diameters ``d`` (a trend plus scatter of sd 1),
    as the 5 %, 50 % and 95 % points over ``draws`` Monte Carlo samples: a departure in units of
    the runs' scatter inside that band is what rerunning the same cases would show."""
    rng = np.random.default_rng(seed)
    largest = [float(np.max(np.abs(cubic_fit(d, y)[1]))) for y in rng.standard_normal((draws, len(d)))]
    return dict(zip(("p05", "p50", "p95"), np.percentile(largest, [5, 50, 95]).tolist()))


def _cubic_figure(curves, path):
    fig = Figure(figsize=(4.0 * max(len(curves), 1), 3.4))
    axes = np.atleast_1d(fig.subplots(1, max(len(curves), 1)))
    for ax, (label, d, y, coef) in zip(axes, curves):
        fine = np.linspace(d.min(), d.max(), 200)
        ax.plot(d, y, "o", label="runs")
        ax.plot(fine, np.polyval(coef, fine), "-", lw=1, label="cubic fit")
        ax.set_xlabel("scope diameter [mm]")
        ax.set_ylabel(label)
    axes[0].legend(fontsize=8)
    fig.suptitle("RSJ D36, mu 0: outputs against scope diameter", fontsize=10)
    fig.tight_layout()
    save_figure(fig, path)


def scatter_of(gp):
    """The noise sd a GP estimates; of an output modelled as the larger of two others
    (colonsim.surrogate.larger), the larger of its parts' (the larger of two values, each with
    that scatter or less, scatters no more)."""
    parts = getattr(gp, "parts", None)
    return max(p.noise_std for p in parts) if parts else gp.noise_std


def surrogate_holdout(train, test, replicates=None):
    """The project's surrogate fitted on ``train`` predicting ``test``: RMSE over the held-out
    spread, and the calibration of its 95 % intervals, per output.

    Beside it, what limits that error: a surrogate fitted on both sweeps together (50 runs) gives
    its leave-one-out RMSE and the noise sd it estimates, the runs' own scatter about a smooth
    trend. Held-out runs carry that scatter, so no number of training runs brings the RMSE below
    it: where scatter / spread is above the tolerance, the check fails for the simulation's
    scatter, not for the surrogate's sparsity."""
    if not (train.ran and test.ran):
        return {"ran": False}
    import pandas as pd

    from colonsim.surrogate.model import SweepSurrogate

    train_runs, test_runs = _ok(train.table), _ok(test.table)
    targets = [t for t in SURROGATE_OUTPUTS if t in train_runs and train_runs[t].notna().sum() >= 4]
    model = SweepSurrogate(targets=targets).fit(train_runs)
    pooled_runs = pd.concat([train_runs, test_runs], ignore_index=True)
    pooled = SweepSurrogate(targets=targets).fit(pooled_runs)
    rows = []
    for target in targets:
        truth = test_runs[target].to_numpy(dtype=float)
        frame = model.predict_frame(test_runs, targets=[target], segment="rsj")
        mean, sd = frame[target].to_numpy(dtype=float), frame[f"{target}_std"].to_numpy(dtype=float)
        keep = np.isfinite(truth) & np.isfinite(mean)
        err = mean[keep] - truth[keep]
        rmse = float(np.sqrt(np.mean(err**2)))
        spread = float(np.std(truth[keep]))
        share = rmse / spread if spread > 0 else math.nan
        # no interval where the model cannot vouch for its error (predict_frame leaves the sd NaN)
        covered = (float(np.mean(np.abs(err) <= 1.96 * sd[keep])) if keep.any() and np.isfinite(sd[keep]).all()
                   else math.nan)
        pooled_spread = float(np.nanstd(pooled_runs[target].to_numpy(dtype=float)))
        scatter = float(scatter_of(pooled.models_["rsj"][target]))
        rows.append({"output": target, "train_runs": int(train_runs[target].notna().sum()), "test_runs": int(keep.sum()),
                     "rmse": rmse, "spread": spread, "share": share, "coverage95": covered,
                     **_surrogate_verdict(rmse, spread, _scatter(replicates or {}, target)),
                     "pooled_runs": int(pooled_runs[target].notna().sum()),
                     "pooled_loo_share": pooled.cv_["rsj"][target]["rmse"] / pooled_spread if pooled_spread > 0 else math.nan,
                     "scatter": scatter, "scatter_share": scatter / pooled_spread if pooled_spread > 0 else math.nan})
    return {"ran": True, "rows": rows, "tolerance": SURROGATE_TOLERANCE, "scatter_factor": SURROGATE_SCATTER_FACTOR}


def _surrogate_verdict(rmse, spread, noise) -> dict:
    """The held-out RMSE judged against the larger of :data:`SURROGATE_TOLERANCE` of the held-out
    spread and :data:`SURROGATE_SCATTER_FACTOR` times the runs' own scatter (where measured)."""
    bound = max(SURROGATE_TOLERANCE * spread, SURROGATE_SCATTER_FACTOR * noise if np.isfinite(noise) else 0.0)
    return {"replicate_scatter": noise, "replicate_scatter_share": noise / spread if spread > 0 else math.nan,
            "bound": bound, "passed": bool(rmse < bound) if spread > 0 and np.isfinite(rmse) else None}
