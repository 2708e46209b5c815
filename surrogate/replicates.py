"""The simulation's own scatter, measured by replicate runs: the surrogate's noise floor.

A replicate is a training run's case (the same inputs) run again at another solver setting that
should not matter, such as a slightly different wall mesh or push speed
(``benchmarks/sweeps/gp_replicates.toml``: ten RSJ cases on a 2.8 mm instead of 3 mm mesh). The
two results of a pair differ by the simulation's scatter (contact on a discrete mesh, dynamic
effects) plus an offset the setting causes in every run alike. With ``d`` the differences of the
pairs, the offset is ``mean(d)`` and the scatter of one run has standard deviation
``sd(d) / sqrt(2)`` (offset removed, ``pairs - 1`` degrees of freedom).

Without a floor, maximizing the GP's marginal likelihood on a few dozen runs may explain the
scatter by short length scales and put the noise at the bottom of its range: intervals 100x too
narrow (docs/surrogate.md, "Noise floor"). The floor keeps the white-noise variance at least at the
measured scatter.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from colonsim.errors import ColonsimError
from colonsim.surrogate.table import numeric_column, successful_runs

MIN_PAIRS = 3  # fewer pairs say nothing about a standard deviation
DECIMALS = 6  # inputs equal to this many decimals are the same case


def _keys(runs: pd.DataFrame, inputs) -> list:
    return [tuple(np.round(row, DECIMALS)) for row in runs[list(inputs)].to_numpy(dtype=float)]


def replicate_scatter(runs: pd.DataFrame, replicates: pd.DataFrame, segment, inputs, target) -> dict | None:
    """Scatter of ``target`` from the replicate runs of ``segment`` paired with the training ``runs``
    by their ``inputs`` (the model's varying and fixed inputs); None if the segment has none.

    Returns {"sd", "pairs", "offset", "unpaired"} in the target's unit; an error for fewer than
    :data:`MIN_PAIRS` pairs (too few to measure a standard deviation)."""
    reps = successful_runs(replicates, segment)
    if reps.empty:
        return None
    missing = [c for c in inputs if c not in reps.columns]
    if missing:
        raise ColonsimError(f"the replicate table lacks the input column(s) {', '.join(missing)} of the {segment} runs; "
                            "give the results table of the same cases run again")
    y_train = dict(zip(_keys(runs, inputs), numeric_column(runs, target).to_numpy(dtype=float)))
    y_rep = numeric_column(reps, target).to_numpy(dtype=float)
    d = np.array([y - y_train[k] for k, y in zip(_keys(reps, inputs), y_rep) if k in y_train])
    d = d[np.isfinite(d)]
    if len(d) < MIN_PAIRS:
        raise ColonsimError(f"{segment} {target}: {len(d)} replicate run(s) pair with a training run (same inputs), "
                            f"at least {MIN_PAIRS} are needed to measure the scatter; run training cases again at "
                            "another mesh or push speed")
    return {"sd": float(np.std(d, ddof=1) / np.sqrt(2.0)), "pairs": int(len(d)), "offset": float(np.mean(d)),
            "unpaired": int(len(reps) - len(d))}
