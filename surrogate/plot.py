"""Figure: a predicted output against one input, with its 95 % band, one curve per scope."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from colonsim.errors import ColonsimError
from colonsim.surrogate.recommend import default_scopes
from colonsim.surrogate.tissue import tissue_inputs
from colonsim.surrogate.table import INPUT_LABELS, PAIN_PROXY, TARGET_LABELS, scope_diameter_mm
from colonsim.surrogate.validation import Z95


def prediction_figure(model, segment, vs, inputs: dict, target=PAIN_PROXY, scopes=None, points=120,
                      strict=False) -> Figure:
    """Predicted ``target`` of ``segment`` against the input ``vs`` over its training range.

    The other inputs come from ``inputs``; ``scopes`` (default: the sweep's named scopes) give one
    curve each unless ``vs`` is the scope diameter; tissue inputs not given are set to the tissue
    distribution's mean (the title shows them). The band is the 95 % interval of a new
    simulation result. Training runs that share the other inputs are drawn as dots. Other inputs
    outside the training domain: a warning, or an error with ``strict``."""
    domain, gp = model.model_for(segment, target)
    if vs not in domain.inputs:
        raise ColonsimError(f"{domain.segment} does not depend on {vs} in this surrogate; plot against one of "
                            f"{', '.join(domain.inputs)}")
    missing = [c for c in tissue_inputs(domain) if c != vs and inputs.get(c) is None]
    if missing:  # a curve is for one tissue: the tissue distribution's mean unless given
        if model.tissue_ is None:
            raise ColonsimError(f"give {', '.join(missing)}: the surrogate holds no tissue distribution")
        draws = model.tissue_.draws()
        inputs = {**inputs, **{c: float(np.mean(draws[c])) for c in missing}}
    j = domain.inputs.index(vs)
    grid = np.linspace(domain.low[j], domain.high[j], points)
    fig = Figure(figsize=(6.4, 4.4))
    ax = fig.subplots()
    curves = [None]
    if vs != "scope_diameter_mm" and "scope_diameter_mm" in domain.inputs:
        curves = [str(s).lower() for s in (scopes or default_scopes(domain))]
    X_runs, y_runs = gp.training_runs()
    for scope in curves:
        query = dict(inputs)
        if scope is not None:
            query["scope_diameter_mm"] = scope_diameter_mm(scope, domain.scopes)
        query[vs] = grid
        X, _, _ = domain.check(query, n=points, strict=strict)
        mean, std = gp.predict(X, return_std=True)
        label = "prediction" if scope is None else f"{scope.upper()} ({query['scope_diameter_mm']:g} mm)"
        line, = ax.plot(grid, mean, label=label)
        ax.fill_between(grid, mean - Z95 * std, mean + Z95 * std, color=line.get_color(), alpha=0.2, lw=0)
        same = np.ones(len(X_runs), dtype=bool)
        for k in range(len(domain.inputs)):
            if k != j:
                same &= np.isclose(X_runs[:, k], X[0, k], rtol=1e-6, atol=1e-9)
        if same.any():
            ax.plot(X_runs[same, j], y_runs[same], "o", color=line.get_color(), ms=4)
    fixed = ", ".join(f"{k} {float(np.asarray(v)):g}" for k, v in inputs.items()
                      if k in domain.inputs and k != vs and np.ndim(v) == 0)
    ax.set_title(f"{domain.segment.upper()}: {fixed}" if fixed else domain.segment.upper(), fontsize=9)
    ax.set_xlabel(INPUT_LABELS.get(vs, vs))
    ax.set_ylabel(TARGET_LABELS.get(target, target))
    ax.legend(fontsize=8, title="line: mean; band: 95 % of a new run; dots: runs", title_fontsize=7)
    return fig
