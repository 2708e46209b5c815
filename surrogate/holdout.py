"""Score a fitted surrogate on runs it was not fitted on (``colonsim surrogate validate``).

For each held-out run of a segment the model predicts a new simulation result (mean and sd, the
quantity a run is). From the errors ``e = y - mean`` and the standardized errors ``z = e / sd``:

- ``rmse`` and ``q2 = 1 - SSE / SS`` (SS about the held-out mean: 1 = perfect, 0 = no better than
  the held-out average);
- the observed coverage of the central 50 / 90 / 95 % intervals (``|e| <= z_p sd``), and over a
  grid of nominal levels for the reliability plot (a calibrated model lies on the diagonal);
- the mean and spread (sd) of ``z``: about 0 and 1 for a calibrated model; a spread above 1 =
  intervals too narrow (overconfident), below 1 = too wide;
- predicted orders: for every pair of held-out runs with different scope diameters, the model's
  probability that the first deforms less than the second (joint Gaussian of the two new results:
  the trend's covariance plus each run's scatter), the order it states (the likelier one) and
  whether the runs bear it out. With no overconfidence the share of orders that hold is at least
  the mean stated probability.

Held-out runs that set an input the model keeps fixed to another value cannot be scored (the model
knows nothing of that value) and are counted as left out; runs slightly outside the box of the
training runs are scored and counted (``outside_box``). Each run counts once: a key on several rows
is scored on its first (``duplicates`` counts the others). A run at the inputs of a training run
(the same case, to :data:`SAME_CASE` relative) is not held out: it is left out and counted
(``training_cases``), and a table whose runs are all training cases (the training table itself)
is refused.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
from scipy.special import ndtr, ndtri

from colonsim.errors import ColonsimError
from colonsim.surrogate.domain import OutOfDomainWarning
from colonsim.surrogate.table import numeric_column, successful_runs

NOMINAL = (0.5, 0.9, 0.95)
SAME_CASE = 1e-6  # relative difference of every input below which two runs are one case
RELIABILITY_LEVELS = tuple(np.round(np.arange(0.05, 1.0, 0.05), 2))


def interval_z(level):
    """Half-width of the central ``level`` interval of a standard normal (1.96 for 0.95)."""
    return float(ndtri(0.5 + 0.5 * level))


def heldout_runs(model, table: pd.DataFrame, segment, target, name="held-out table"):
    """The held-out runs of ``segment`` with a value of ``target``, checked against the model.

    Returns (X, y, scope diameters, left out, outside the box, training cases, duplicates): the
    model's input matrix and outputs of the runs it can score, and the counts of runs left out (a
    fixed input set to another value), scored outside the box, left out as training cases, and rows
    of a key already counted."""
    domain, _ = model.model_for(segment, target)
    missing = [c for c in domain.inputs if c not in table.columns]
    if missing:
        raise ColonsimError(f"{name} lacks the input column(s) {', '.join(missing)} the {domain.segment} {target} model "
                            f"was fitted on; score it on runs of a sweep over the same inputs")
    if target not in table.columns:
        raise ColonsimError(f"{name} has no column {target}; score a target the table holds")
    runs = successful_runs(table, domain.segment)
    duplicates = 0
    if "key" in runs.columns:  # each run once
        twice = runs["key"].duplicated()
        duplicates = int(twice.sum())
        runs = runs[~twice].reset_index(drop=True)
    if runs.empty:
        raise ColonsimError(f"{name} has no successful {domain.segment} run; the model was fitted on "
                            f"{', '.join(model.domains_)}")
    y = numeric_column(runs, target).to_numpy(dtype=float)
    runs, y = runs[np.isfinite(y)], y[np.isfinite(y)]
    query = {c: runs[c].to_numpy() for c in (*domain.inputs, *domain.fixed) if c in runs.columns}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", OutOfDomainWarning)
        X, _, reasons = domain.check(query, n=len(runs))
    fixed_off = np.array(["every" in r for r in reasons], dtype=bool)  # a fixed input set to another value
    outside = np.array([bool(r) for r in reasons]) & ~fixed_off
    keep = ~fixed_off
    same = keep & training_cases(X, model.model_for(segment, target)[1])
    if same.any() and same.sum() == keep.sum():
        raise ColonsimError(f"{name}: every one of its {int(keep.sum())} {domain.segment} runs is a case the model was "
                            "fitted on (the same inputs as a training run), so none is held out; score the model on "
                            "runs of another sweep")
    keep &= ~same
    if keep.sum() < 2:
        raise ColonsimError(f"{name}: {int(keep.sum())} {domain.segment} run(s) with a value of {target} inside the "
                            f"model's fixed inputs ({domain.describe()}); score on at least 2")
    scope = (X[:, domain.inputs.index("scope_diameter_mm")] if "scope_diameter_mm" in domain.inputs
             else np.full(len(X), domain.fixed.get("scope_diameter_mm", np.nan)))
    return X[keep], y[keep], scope[keep], int(fixed_off.sum()), int(outside[keep].sum()), int(same.sum()), duplicates


def training_cases(X, gp) -> np.ndarray:
    """Which rows of ``X`` are at the inputs of one of ``gp``'s training runs (:data:`SAME_CASE`)."""
    X_train = gp.training_runs()[0]
    scale = np.maximum(np.abs(X_train).max(axis=0), 1e-300) if len(X_train) else 1.0
    same = np.zeros(len(X), dtype=bool)
    for start in range(0, len(X), 256):  # 256 x training runs x inputs at a time
        part = X[start:start + 256]
        same[start:start + 256] = (np.abs(part[:, None, :] - X_train[None, :, :]) <= SAME_CASE * scale).all(axis=2).any(axis=1)
    return same


def coverage(err, sd, level):
    """Share of errors inside the central ``level`` interval mean +- z sd."""
    return float(np.mean(np.abs(err) <= interval_z(level) * sd))


def pair_orders(mean, cov, scope):
    """Stated probability and outcome of each pair of runs with different scope diameters.

    Returns (p, first_less): for pairs (i, j), i < j, P(the order the model states holds) and a
    function of the outcomes ``y`` telling whether it held."""
    i, j = np.triu_indices(len(mean), k=1)
    keep = scope[i] != scope[j]
    i, j = i[keep], j[keep]
    sd = np.sqrt(np.maximum(cov[i, i] + cov[j, j] - 2.0 * cov[i, j], 1e-300))
    p_i_less = ndtr((mean[j] - mean[i]) / sd)
    states_i_less = p_i_less >= 0.5
    stated = np.where(states_i_less, p_i_less, 1.0 - p_i_less)

    def held(y):
        return np.where(states_i_less, y[i] < y[j], y[j] < y[i])

    return stated, held


def score(model, table: pd.DataFrame, target, segment=None, name="held-out table") -> dict:
    """Accuracy and calibration of ``model``'s ``target`` on the held-out runs of ``table``."""
    if segment is None:
        if len(model.domains_) != 1:
            raise ColonsimError(f"give --segment ({', '.join(model.domains_)})")
        segment = next(iter(model.domains_))
    domain, gp = model.model_for(segment, target)
    X, y, scope, left_out, outside, same, duplicates = heldout_runs(model, table, segment, target, name)
    _, trend_cov = gp.predict(X, return_cov=True)
    mean, sd = gp.predict(X, return_std=True)  # new simulation results: trend + scatter
    cov = trend_cov.copy()  # the trends' covariance between runs, each run's own sd on the diagonal
    cov[np.diag_indices_from(cov)] = sd**2
    err = y - mean
    z = err / sd
    ss = float(np.sum((y - y.mean()) ** 2))
    stated, held = pair_orders(mean, cov, scope)
    holds = held(y)
    return {"segment": domain.segment, "target": target, "n": int(len(y)), "left_out": left_out,
            "training_cases": same, "duplicates": duplicates, "outside_box": outside, "n_train": gp.n_train, "error_unknown": model.error_unknown(domain.segment, target),
            "rmse": float(np.sqrt(np.mean(err**2))), "q2": float(1.0 - np.sum(err**2) / ss) if ss > 0 else None,
            "coverage": {f"{round(100 * p)}": coverage(err, sd, p) for p in NOMINAL},
            "z_mean": float(z.mean()), "z_sd": float(z.std(ddof=1)),
            "reliability": {"nominal": list(RELIABILITY_LEVELS),
                            "observed": [coverage(err, sd, p) for p in RELIABILITY_LEVELS]},
            "orders": {"pairs": int(len(stated)), "mean_stated": float(stated.mean()) if len(stated) else None,
                       "held": float(holds.mean()) if len(stated) else None}}


def format_score(s, unit="") -> str:
    """The score as a few lines of text."""
    cov = s["coverage"]
    lines = [f"{s['segment']} {s['target']}: model fitted on {s['n_train']} runs, scored on {s['n']} held-out runs"
             + (f" ({s['left_out']} left out: a fixed input set to another value)" if s["left_out"] else "")
             + (f"; {s['outside_box']} slightly outside the training box" if s["outside_box"] else "")
             + (f"; {s['training_cases']} left out as cases the model was fitted on" if s.get("training_cases") else "")
             + (f"; {s['duplicates']} row(s) of a run already counted left out" if s.get("duplicates") else ""),
             f"  RMSE {s['rmse']:.3g} {unit}  Q2 {'-' if s['q2'] is None else format(s['q2'], '.3f')}".rstrip(),
             f"  coverage of the 50 / 90 / 95 % intervals: {100 * cov['50']:.0f} / {100 * cov['90']:.0f} / "
             f"{100 * cov['95']:.0f} %",
             f"  standardized error: mean {s['z_mean']:+.2f}, sd {s['z_sd']:.2f} (calibrated: about 0 and 1)"]
    if s.get("error_unknown"):
        lines.append(f"  the model itself prints no interval ({s['error_unknown']}): these are the intervals it "
                     "would state")
    o = s["orders"]
    if o["pairs"]:
        lines.append(f"  predicted orders of {o['pairs']} run pairs with different scopes: hold {100 * o['held']:.0f} %, "
                     f"stated probability {100 * o['mean_stated']:.0f} % on average"
                     + ("  OVERCONFIDENT" if o["held"] < o["mean_stated"] - 0.05 else ""))
    return "\n".join(lines)


def reliability_figure(scores, title="held-out runs"):
    """Nominal against observed coverage of the central intervals, one line per score (a model
    and output; its optional "label" and "style", keywords of the line); the diagonal is a
    calibrated model, below it the intervals are too narrow."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(4.8, 4.6))
    ax = fig.subplots()
    ax.plot([0, 1], [0, 1], color="0.6", lw=1, ls="--", label="calibrated")
    for s in scores:
        r = s["reliability"]
        ax.plot(r["nominal"], r["observed"], **{"marker": "o", "ms": 3, "ls": "-", **s.get("style", {})},
                label=s.get("label") or f"{s['segment']} {s['target']} ({s['n_train']} runs)")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    ax.set_xlabel("nominal coverage of the central interval")
    ax.set_ylabel(f"observed share of {title} inside it")
    ax.legend(fontsize=7)
    return fig
