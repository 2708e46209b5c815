"""Rank scopes for one patient by predicted colon deformation, and say how sure the ranking is.

The scopes differ only in diameter, so their predictions are strongly correlated: the GP is
uncertain about the overall level for this patient far more than about the difference between
two scope diameters. Treating the predictions as independent would understate the confidence.
The probabilities below therefore use the joint posterior of the GP's smooth trend at the scopes'
query points (mean and full covariance). The run-to-run scatter (white-noise term) is left out:
the question is which scope deforms this colon less on average, not which of two single runs does.

- ``p_less_than_reference``: P(deformation of this scope < deformation of the reference scope,
  SDC by default) = Phi((mu_ref - mu) / sqrt(var + var_ref - 2 cov)), exact for the Gaussian.
- ``p_best``: P(this scope deforms least), and ``p_ranking``: P(the whole stated order holds),
  both from draws of the joint Gaussian.
- a model with tissue inputs and a patient without them: the patient's tissue is unknown, so the
  joint law is the mixture of these Gaussians over the tissue draws (:mod:`colonsim.surrogate.tissue`);
  each scope's sd splits into a tissue part (the spread of the means over the draws) and a
  surrogate part (the mean GP variance), and the probabilities are those of the mixture (the
  tissue moves all scopes together, so it widens each level far more than the differences).

Each scope's sd and 95 % interval, by contrast, are those of a *new simulation result* at the
patient's inputs (trend and scatter, the same numbers ``predict`` prints): that is what the
held-out check (``surrogate validate``) scores, so the interval printed beside a scope is the one
whose coverage has been measured. ``std_trend`` keeps the trend's own sd.

Where the patient coincides with simulated cases, the posterior of the trend is nearly exact and
the probabilities above approach 0 or 1: they then restate the simulations, not the surrogate's
accuracy. The ``..._with_cv_error`` variants add to every scope an independent error with the
output's leave-one-out RMSE (measured at fit time). Independent errors are a pessimistic reading
(errors at one patient are correlated across scopes), so the two numbers bracket the confidence.
"""

from __future__ import annotations

import numpy as np
from scipy.special import ndtr

from colonsim.errors import ColonsimError
from colonsim.surrogate.domain import EXTRAPOLATED
from colonsim.surrogate.tissue import plan, split_predict, trend_components
from colonsim.surrogate.table import NAMED_SCOPES_MM, PAIN_PROXY, STANDARD_SCOPE, scope_diameter_mm, target_unit
from colonsim.surrogate.validation import Z95


# more scope diameters than this in a sweep: a design over diameters (a hypercube), not scopes to rank
GRID_SCOPES = 5


def default_scopes(domain):
    """The named scopes the sweep ran (UTC, PDC, SDC or its own diameters, up to :data:`GRID_SCOPES`
    of them), else the three of docs/model.md."""
    named = {k: v for k, v in domain.scopes.items() if k in NAMED_SCOPES_MM}
    own = domain.scopes if len(domain.scopes) <= GRID_SCOPES else {}
    table = named or own or NAMED_SCOPES_MM
    return sorted(table, key=lambda name: table[name])  # thinnest first


def recommend(model, segment, inputs: dict, scopes=None, target=PAIN_PROXY, reference=None,
              strict=False, n_draws=20000, seed=0) -> dict:
    """Scopes for a patient (``inputs`` without the scope) ranked by predicted ``target``.

    Returns a JSON-ready dict: per scope the mean, std and 95 % interval of a new simulation result
    (and the trend's sd, ``std_trend``), the rank,
    ``p_best`` and ``p_less_than_reference``; overall ``p_ranking``; the domain check."""
    domain, gp = model.model_for(segment, target)
    if "scope_diameter_mm" not in domain.inputs:
        raise ColonsimError(f"segment {domain.segment} was trained on one scope diameter only "
                            f"({domain.fixed.get('scope_diameter_mm', '?')} mm); fit on a sweep over scopes to rank them")
    scopes = [str(s).strip().lower() for s in (scopes or default_scopes(domain))]
    if len(set(scopes)) < 2:
        raise ColonsimError("give at least two different scopes to rank")
    diameters = np.array([scope_diameter_mm(s, domain.scopes) for s in scopes])
    if reference is None:
        reference = STANDARD_SCOPE if STANDARD_SCOPE in scopes else scopes[int(np.argmax(diameters))]
    reference = str(reference).lower()
    if reference not in scopes:
        raise ColonsimError(f"reference scope {reference} is not among the scopes ranked ({', '.join(scopes)})")
    query = {k: v for k, v in inputs.items() if k not in ("scope", "scope_diameter_mm")}
    query["scope_diameter_mm"] = diameters
    patient = {k: float(np.asarray(v)) for k, v in query.items() if k != "scope_diameter_mm"}
    query, tissue = plan(domain, query, len(scopes), getattr(model, "tissue_", None), strict)
    X, inside, notes = domain.check(query, n=len(scopes), strict=strict)
    # one Gaussian of the trend per tissue draw (one in all without averaging): a mixture over the tissue
    means, covs = trend_components(gp, domain, X, tissue)
    mean, surrogate_cov = means.mean(axis=0), covs.mean(axis=0)
    tissue_cov = (means - mean).T @ (means - mean) / len(means)
    cov = surrogate_cov + tissue_cov
    var = np.maximum(np.diag(cov), 0.0)
    r = scopes.index(reference)
    component_var = np.maximum(np.diagonal(covs, axis1=1, axis2=2), 0.0)
    diff_sd = np.sqrt(np.maximum(component_var + component_var[:, [r]] - 2.0 * covs[:, :, r], 1e-300))
    p_less = ndtr((means[:, [r]] - means) / diff_sd).mean(axis=0)
    order = np.argsort(mean, kind="stable")
    draws = _mixture_draws(means, covs, n_draws, seed)
    p_best = np.bincount(np.argmin(draws, axis=1), minlength=len(scopes)) / n_draws
    p_ranking = float(np.mean(np.all(np.diff(draws[:, order], axis=1) > 0, axis=1)))
    cv_rmse = float(model.cv_[domain.segment][target]["rmse"])
    noisy = draws + np.random.default_rng(seed + 1).normal(0.0, cv_rmse, size=draws.shape)
    p_ranking_cv = float(np.mean(np.all(np.diff(noisy[:, order], axis=1) > 0, axis=1)))
    p_less_cv = np.mean(noisy < noisy[:, [r]], axis=0)
    # a new run's spread at each scope (trend + scatter, split into tissue and surrogate parts), as predict gives it
    _, std, std_tissue, std_surrogate = split_predict(gp, domain, X, tissue)
    std_trend = np.sqrt(var)
    rows = [{"scope": scopes[i], "diameter_mm": float(diameters[i]), "rank": int(np.flatnonzero(order == i)[0]) + 1,
             "mean": float(mean[i]), "std": float(std[i]), "std_trend": float(std_trend[i]),
             "std_tissue": None if np.isnan(std_tissue[i]) else float(std_tissue[i]),
             "std_surrogate": float(std_surrogate[i]), "low95": float(mean[i] - Z95 * std[i]),
             "high95": float(mean[i] + Z95 * std[i]), "p_best": float(p_best[i]),
             "p_less_than_reference": None if i == r else float(p_less[i]),
             "p_less_than_reference_with_cv_error": None if i == r else float(p_less_cv[i]),
             "in_domain": bool(inside[i]), "domain_note": notes[i]} for i in order]
    unknown = model.error_unknown(domain.segment, target)
    if unknown:  # the order stands by the means; no spread or probability the model cannot vouch for
        for row in rows:
            row.update({k: None for k in ("std", "std_trend", "std_tissue", "std_surrogate", "low95", "high95", "p_best",
                                          "p_less_than_reference", "p_less_than_reference_with_cv_error")})
        p_ranking = p_ranking_cv = None
    return {"segment": domain.segment, "target": target, "inputs": patient, "error_unknown": unknown,
            "n_runs": int(model.cv_[domain.segment][target]["n"]),
            "reference": reference, "ranking": [scopes[i] for i in order], "p_ranking": p_ranking,
            "cv_rmse": cv_rmse, "p_ranking_with_cv_error": p_ranking_cv, "scopes": rows,
            "uncertainty": "intervals: a new simulation result at these inputs (trend + run-to-run scatter, as predict); "
                           "probabilities: joint GP posterior of the smooth trend at the scopes (covariance included), "
                           "scatter excluded", "in_domain": bool(inside.all()), "tissue": tissue.to_dict()}


def _mixture_draws(means, covs, n_draws, seed):
    """``n_draws`` draws of the equally weighted mixture of Gaussians (means[k], covs[k])."""
    rng = np.random.default_rng(seed)
    if len(means) == 1:
        return rng.multivariate_normal(means[0], covs[0], size=n_draws, method="eigh")
    counts = np.bincount(np.arange(n_draws) % len(means), minlength=len(means))
    return np.concatenate([rng.multivariate_normal(m, c, size=k, method="eigh")
                           for m, c, k in zip(means, covs, counts) if k])


def format_recommendation(rec) -> str:
    """The recommendation as a few lines of text."""
    unit = target_unit(rec["target"])
    mark = "" if rec["in_domain"] else f"{EXTRAPOLATED} "
    if rec.get("error_unknown"):
        lines = [f"{mark}{rec['segment'].upper()}, {rec['target']}: " + " < ".join(s.upper() for s in rec["ranking"])
                 + f" by the predicted means; no probability or interval: the model rests on {rec['n_runs']} runs, "
                 f"{rec['error_unknown']}"]
        lines += [f"  {s['rank']}. {s['scope'].upper():>5} ({s['diameter_mm']:g} mm): {s['mean']:.3g} {unit}"
                  + ("" if s["in_domain"] else f"  {EXTRAPOLATED} OUTSIDE the training domain: {s['domain_note']}") for s in rec["scopes"]]
        return "\n".join(lines)
    lines = [f"{mark}{rec['segment'].upper()}, {rec['target']}: " + " < ".join(s.upper() for s in rec["ranking"])
             + f"  (probability this order holds: {100 * rec['p_ranking']:.0f} %; "
             f"{100 * rec['p_ranking_with_cv_error']:.0f} % allowing the surrogate's cross-validated error of "
             f"{rec['cv_rmse']:.2g} {unit} per scope)"]
    for s in rec["scopes"]:
        vs = ("" if s["p_less_than_reference"] is None
              else f"  P(less than {rec['reference'].upper()}) {100 * s['p_less_than_reference']:.0f} % "
                   f"({100 * s['p_less_than_reference_with_cv_error']:.0f} % with CV error)")
        lines.append(f"  {s['rank']}. {s['scope'].upper():>5} ({s['diameter_mm']:g} mm): {s['mean']:.3g} {unit} "
                     f"[95 % {s['low95']:.3g}, {s['high95']:.3g}]  P(least) {100 * s['p_best']:.0f} %{vs}"
                     + ("" if s["in_domain"] else f"  {EXTRAPOLATED} OUTSIDE the training domain: {s['domain_note']}"))
    tissue = rec["tissue"]
    if not tissue["modelled"]:
        lines.append(f"  uncertainty: surrogate only; {tissue['note']}")
    else:
        split = ", ".join(f"{s['scope'].upper()} tissue {s['std_tissue']:.2g}, surrogate {s['std_surrogate']:.2g}"
                          for s in rec["scopes"])
        lines.append(f"  {mark}uncertainty split (sd, {unit}): {split}; {tissue['note']}")
    lines.append(f"  ({rec['uncertainty']}; the model rests on {rec['n_runs']} runs)")
    return "\n".join(lines)
