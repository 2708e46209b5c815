"""Fit the shipped pain predictor on the patient-space sweeps and store it as package data.

The predictor is a :class:`SweepSurrogate` of the patient models (RSJ, RSF, THF) whose training
sweeps it is given (presets ``patient_space_rsj``, ``_rsf``, ``_thf``), fitted on their results,
with their tip-folded runs left out and counted, the noise floor of each output from the replicate
sweeps (``_replicates``), and the reference wall (tissue stiffness 1) as the tissue of a query that
names none. Its domain is each sweep's design range (:func:`design_domains`), where the runs reach
it. Its JSON says what it is (``about``): the sweeps it was fitted on and those held out, the engine
commits of the runs, the training domain of each model, the runs left out.
"""

from __future__ import annotations

import datetime

import numpy as np
import pandas as pd

from colonsim.catalog import TISSUE_STIFFNESS
from colonsim.insertion.study.sweep_presets import PATIENT_MODELS as DESIGNS, PATIENT_RANGES
from colonsim.insertion.study.sweep_spec import LHS_DECIMALS
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
    design_domains(model)
    model.about_ = {
        "what": "the pain predictor shipped with colonsim: a surrogate over the patient space of "
                + ", ".join(seg.upper() for seg in model.domains_),
        "sweeps": sorted(tables), "held_out_sweeps": sorted(held_out), "replicate_sweeps": sorted(replicates or {}),
        "engine_commits": model.training_["git_commits"],
        "domain": {seg: domain.describe() for seg, domain in model.domains_.items()},
        f"{TIP_FOLDED}_left_out": model.training_["tip_folded"],
        "fitted": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
    }
    return model


def vouch(model: SweepSurrogate, rows, sweeps):
    """Store in ``model`` (in place) the coverage of its intervals on held-out runs: ``rows`` of the
    held-out table (``benchmarks/bench_predictor.py``: model, output, runs, coverage_95,
    coverage_50), scored on ``sweeps`` (name -> results table; each row names the sweeps that hold
    runs of its model). Where they are stored they decide whether the
    model prints that output's intervals (:func:`colonsim.surrogate.validation.error_unknown`); the
    runs themselves are never fitted on."""
    model.held_out_ = {}
    for row in rows:
        names = sorted(name for name, table in sweeps.items() if (table["segment"] == row["model"]).any())
        model.held_out_.setdefault(row["model"], {})[row["output"]] = {
            "runs": int(row["runs"]), "coverage_95": float(row["coverage_95"]),
            "coverage_50": float(row["coverage_50"]), "sweeps": names}
    return model


def design_range(segment, name):
    """The range the patient-space sweep of ``segment`` draws input ``name`` from (a results
    column), and its training runs; None for an input it does not vary."""
    inputs, own, runs, _ = DESIGNS[segment]
    design = "stiffness_factor" if name == TISSUE_STIFFNESS else name
    return (*own.get(design, PATIENT_RANGES[design]), runs) if design in inputs else None


def design_domains(model):
    """Widen each segment's domain (in place) from the runs' box to the sweep's design ranges.

    A Latin hypercube of n runs puts one run in each of the n strata of every range, so the runs'
    box falls short of the design range by less than one stratum (range / n) at either end, plus
    the rounding of its values to :data:`LHS_DECIMALS`: a query at the edge of the design
    (friction 0, the default of an insertion) is then at most that far from a run, where the GP
    interpolates as it does between runs. Where the runs fall short of an end by more (a sweep not
    of this design, or its end run lost: failed or tip-folded), the domain keeps the runs' bound.
    The GP's input scaling is its own and is not changed."""
    for segment, domain in model.domains_.items():
        low, high = domain.low.copy(), domain.high.copy()
        for j, name in enumerate(domain.inputs):
            design = design_range(segment, name) if segment in DESIGNS else None
            if design is None:
                continue
            lo, hi, runs = design
            stratum = (hi - lo) / runs + 0.5 * 10.0 ** -LHS_DECIMALS
            if lo <= low[j] <= lo + stratum:
                low[j] = lo
            if hi - stratum <= high[j] <= hi:
                high[j] = hi
        domain.low, domain.high = low, high  # new arrays: the GPs keep the runs' box as their scaling
    return model


def save_predictor(model: SweepSurrogate, path=SHIPPED):
    """Write ``model`` (from :func:`fit_predictor`) where :func:`load_shipped` reads it."""
    return save_surrogate(model, path, source=", ".join(model.about_["sweeps"]), about=model.about_)
