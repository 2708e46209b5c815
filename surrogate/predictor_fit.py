"""Fit the shipped pain predictor on the patient-space sweeps and store it as package data.

The predictor is a :class:`SweepSurrogate` of the patient models (RSJ, RSF, THF) fitted on the
training sweeps' results (presets ``patient_space_rsj``, ``_rsf``, ``_thf``), with their tip-folded
runs left out and counted, the noise floor of each output from the replicate sweeps
(``_replicates``), and the reference wall (tissue stiffness 1) as the tissue of a query that names
none. Its JSON says what it is (``about``): the sweeps it was fitted on and those held
out, the engine commits of the runs, the training domain of each model, the runs left out.
"""

from __future__ import annotations

import datetime

import numpy as np
import pandas as pd

from colonsim.catalog import TISSUE_STIFFNESS
from colonsim.surrogate.model import TIP_FOLDED, SweepSurrogate
from colonsim.surrogate.predictor import SHIPPED
from colonsim.surrogate.store import save_surrogate
from colonsim.surrogate.table import TARGETS, check_results
from colonsim.surrogate.tissue import TissueDistribution

PATIENT_MODELS = ("rsj", "rsf", "thf")
# a query that names no tissue is about the reference wall, the material of every insertion by default
REFERENCE_TISSUE = TissueDistribution("empirical", "reference", "the reference wall (tissue stiffness 1; give "
                                                                "--stiffness or --material for a patient's tissue)",
                                      points={TISSUE_STIFFNESS: np.array([1.0])})


def fit_predictor(tables: dict, held_out=(), replicates=None, targets=TARGETS, **fit_options) -> SweepSurrogate:
    """The predictor fitted on ``tables`` (sweep name -> results DataFrame), with ``about_`` set.

    ``held_out``: the names of the sweeps kept for its check (recorded, never read here);
    ``replicates``: sweep name -> results of cases run at two wall meshes (each output's noise
    floor, :mod:`colonsim.surrogate.replicates`), or None; ``targets`` and ``fit_options``:
    :class:`SweepSurrogate` settings (restarts, draws)."""
    table = pd.concat([check_results(t, f"sweep {name}") for name, t in tables.items()], ignore_index=True)
    pairs = (None if not replicates else
             pd.concat([check_results(t, f"sweep {name}") for name, t in replicates.items()], ignore_index=True))
    model = SweepSurrogate(targets=targets, segments=[s for s in PATIENT_MODELS if (table["segment"] == s).any()],
                           tissue=REFERENCE_TISSUE, replicates=pairs, **fit_options).fit(table)
    model.about_ = {
        "what": "the pain predictor shipped with colonsim: a surrogate over the patient space of each patient model",
        "sweeps": sorted(tables), "held_out_sweeps": sorted(held_out), "replicate_sweeps": sorted(replicates or {}),
        "engine_commits": model.training_["git_commits"],
        "domain": {seg: domain.describe() for seg, domain in model.domains_.items()},
        f"{TIP_FOLDED}_left_out": model.training_["tip_folded"],
        "fitted": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
    }
    return model


def save_predictor(model: SweepSurrogate, path=SHIPPED):
    """Write ``model`` (from :func:`fit_predictor`) where :func:`load_shipped` reads it."""
    return save_surrogate(model, path, source=", ".join(model.about_["sweeps"]), about=model.about_)
