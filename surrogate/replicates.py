"""The simulation's own scatter, measured by replicate runs: the surrogate's noise floor.

A replicate is a training run's case (the same inputs) run again at another solver setting that
should not matter, such as a slightly different wall mesh (another push speed hardly moves a
settled output such as the final deformation: docs/surrogate.md, "Limits")
(``benchmarks/sweeps/gp_replicates.toml``: ten RSJ cases on a 2.8 mm instead of 3 mm mesh). The
two results of a pair differ by the simulation's scatter (contact on a discrete mesh, dynamic
effects) plus an offset the setting causes in every run alike. With ``d`` the differences of the
pairs, the offset is ``mean(d)`` and the scatter of one run has standard deviation
``sd(d) / sqrt(2)`` (offset removed, ``pairs - 1`` degrees of freedom).

Without a floor, maximizing the GP's marginal likelihood on a few dozen runs may explain the
scatter by short length scales and put the noise at the bottom of its range: intervals 100x too
narrow (docs/surrogate.md, "Noise floor"). The floor keeps the white-noise variance at least at the
measured scatter. It is a lower bound: a mesh change moves only part of the scatter a GP meets
across the inputs (0.5-0.75 of it in RSJ runs), so a fit whose noise sits at the floor has not
estimated it (:func:`colonsim.surrogate.validation.error_unknown`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from colonsim.errors import ColonsimError
from colonsim.surrogate.table import NOT_SETTINGS, numeric_column, successful_runs

MIN_PAIRS = 3  # fewer pairs say nothing about a standard deviation
DECIMALS = 6  # inputs equal to this many decimals are the same case


def _keys(runs: pd.DataFrame, inputs) -> list:
    return [tuple(np.round(row, DECIMALS)) for row in runs[list(inputs)].to_numpy(dtype=float)]


def replicate_scatter(runs: pd.DataFrame, replicates: pd.DataFrame, segment, inputs, target) -> dict | None:
    """Scatter of ``target`` from the pairs of ``segment`` runs with the same ``inputs`` (the model's
    varying and fixed inputs) at two solver settings; None if the replicate table has no run of it.

    A pair is two runs of one case among the replicate table and the training ``runs`` together
    (a run in both, by its ``key``, counts once): a replicate with its training run, or both runs
    of a case in the replicate table (so a model fitted on a subset of the training sweep still
    finds the pairs). Within a pair the runs are ordered by their solver settings, so ``offset`` is
    the mean change from one setting to the other. Returns {"sd", "pairs", "offset", "unpaired"} in
    the target's unit; an error for fewer than :data:`MIN_PAIRS` pairs."""
    reps = successful_runs(replicates, segment)
    if reps.empty:
        return None
    missing = [c for c in inputs if c not in reps.columns]
    if missing:
        raise ColonsimError(f"the replicate table lacks the input column(s) {', '.join(missing)} of the {segment} runs; "
                            "give the results table of the same cases run again")
    pool = pd.concat([reps, runs], ignore_index=True)
    if "key" in pool.columns:
        pool = pool.drop_duplicates(subset="key")
    y = numeric_column(pool, target).to_numpy(dtype=float)
    settings = [c for c in pool.columns if c not in NOT_SETTINGS and c not in inputs]
    # map(str), not astype(str): pandas 3 keeps a missing value missing through astype(str), and a
    # setting one table lacks is missing in the pool
    signature = (pool[settings].apply(lambda column: column.map(str)).agg("|".join, axis=1).to_numpy()
                 if settings else np.full(len(pool), ""))
    groups = {}
    for i, key in enumerate(_keys(pool, inputs)):
        if np.isfinite(y[i]):
            groups.setdefault(key, []).append(i)
    d, paired = [], set()
    for key, members in groups.items():
        members = sorted(members, key=lambda i: signature[i])
        if len(members) >= 2 and signature[members[0]] != signature[members[-1]]:
            d.append(y[members[-1]] - y[members[0]])
            paired.add(key)
    if len(d) < MIN_PAIRS:
        raise ColonsimError(f"{segment} {target}: {len(d)} pair(s) of runs of one case at two solver settings, at least "
                            f"{MIN_PAIRS} are needed to measure the scatter; run training cases again at another mesh "
                            "or push speed")
    d = np.asarray(d)
    return {"sd": float(np.std(d, ddof=1) / np.sqrt(2.0)), "pairs": int(len(d)), "offset": float(np.mean(d)),
            "unpaired": int(sum(key not in paired for key in _keys(reps, inputs)))}


def unmatched_replicates(replicates: pd.DataFrame, scatter: dict):
    """Refuse a replicate table that gave no noise floor at all (``scatter``: segment -> target ->
    the result of :func:`replicate_scatter`): its runs are of no segment the model fits (another
    segment's table, another study), so the floor the user asked for would silently be missing."""
    if any(s is not None for by_target in scatter.values() for s in by_target.values()):
        return
    segments = sorted({str(s) for s in replicates.loc[replicates["status"] == "ok", "segment"]})
    raise ColonsimError(f"the replicate table matches no run of the model: its successful runs are of "
                        f"{', '.join(segments) or 'no segment'}, the model fits {', '.join(scatter) or 'no segment'}; "
                        "give the results table of the training cases run again (or leave out --replicates)")
