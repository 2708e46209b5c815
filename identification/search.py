"""The search of docs/model.md, for any least-squares problem: Latin hypercube -> CMA-ES -> Nelder-Mead.

1. Sensitivity study: a Latin hypercube over the parameter bounds, every design evaluated and
   ranked by the objective e1 (the sum of squared residuals).
2. Global search: CMA-ES (package ``cma``) in bound-normalised coordinates whose first
   population holds the 10 best designs of step 1 (``inject(..., force=True)``), driven by
   ask/tell so evaluations could run anywhere.
3. Local search: Nelder-Mead (scipy) from the best global design, within the bounds.

Every evaluation is recorded (stage, parameters, e1, wall time, two probes of the prediction)
and the whole run is seeded. The problem is a prediction ``simulate(params)`` and the data
``target`` it should match: the force of one strip (:mod:`colonsim.identification.pipeline`) or
the weighted stresses of several test modes (:mod:`colonsim.identification.joint`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import cma
import numpy as np
import pandas as pd
from scipy import optimize, stats
from scipy.stats import qmc


@dataclass
class Budget:
    """Evaluation budget of each stage (defaults: the full pipeline).

    CMA-ES locates the basin; the Nelder-Mead polish does most of the last two decades of e1 and
    gets the larger share (measured on the bundled data: 150 simplex evaluations stopped short
    of convergence, 300 do not).
    """

    designs: int = 100
    cma_popsize: int = 10
    cma_max_evaluations: int = 300
    cma_sigma0: float = 0.15
    nm_max_evaluations: int = 300

    @classmethod
    def quick(cls):
        """A reduced budget for demos and tests (stated as such in results)."""
        return cls(designs=40, cma_popsize=10, cma_max_evaluations=100, nm_max_evaluations=160)

    @classmethod
    def closed_form(cls):
        """The budget of closed-form (stress-stretch) fits: an evaluation costs microseconds, and
        Ogden's six parameters need a longer CMA-ES run and simplex than three parameters do."""
        return cls(designs=200, cma_popsize=16, cma_max_evaluations=4000, nm_max_evaluations=3000)


@dataclass
class SearchProblem:
    """What the search minimises: ``|target - simulate(params)|^2``.

    ``failures`` are the exceptions of a model that cannot be solved for a parameter set (the
    evaluation is recorded as failed with ``failure_value``, never NaN); ``probes`` name the
    prediction at the middle and at the end of ``target``, recorded per evaluation for the
    sensitivity study.
    """

    simulate: object
    target: np.ndarray
    failure_value: float = 1e6
    failures: tuple = ()
    probes: tuple = ("F_mid", "F_end")


class Recorder:
    """Evaluates the problem in normalised coordinates and records every evaluation."""

    def __init__(self, problem: SearchProblem, lower, upper, names, progress=None):
        self.problem, self.lower, self.upper, self.names = problem, lower, upper, names
        self.rows = []
        self.progress = progress
        self.stage = ""

    def to_params(self, x):
        return self.lower + np.clip(np.asarray(x, dtype=float), 0.0, 1.0) * (self.upper - self.lower)

    def __call__(self, x):
        params = self.to_params(x)
        t0 = time.perf_counter()
        p = self.problem
        try:
            prediction = p.simulate(params)
            r = p.target - prediction
            value = float(r @ r)
            ok = np.isfinite(value)
        except p.failures:  # a failed model evaluation is recorded, never fatal
            prediction, value, ok = None, p.failure_value, False
        if not ok:
            value = p.failure_value
        row = {"evaluation": len(self.rows), "stage": self.stage, **dict(zip(self.names, params)),
               "e1": value, "ok": ok, "seconds": time.perf_counter() - t0}
        if prediction is not None:
            n = prediction.size
            row[p.probes[0]] = float(prediction[n // 2 - 1])
            row[p.probes[1]] = float(prediction[-1])
        self.rows.append(row)
        if self.progress is not None:
            self.progress(self.stage, len(self.rows), value)
        return value

    def best(self, stage=None):
        rows = [r for r in self.rows if stage is None or r["stage"] == stage]
        return min(rows, key=lambda r: r["e1"])


def sensitivity_measures(designs: pd.DataFrame, names, probes=("F_mid", "F_end")) -> pd.DataFrame:
    """Spearman rank correlation of each parameter with log(e1) and the two probes of the prediction."""
    ok = designs[designs["ok"]]
    out = {}
    for target, column in (("log_e1", np.log(ok["e1"].clip(lower=1e-300))), *((p, ok[p]) for p in probes)):
        out[f"spearman_{target}"] = [stats.spearmanr(ok[n], column).statistic for n in names]
    return pd.DataFrame(out, index=list(names))


@dataclass
class SearchOutcome:
    """The best parameters of :func:`search`, every evaluation, and what each stage reached."""

    theta: np.ndarray
    history: pd.DataFrame
    stages: dict
    sensitivity: pd.DataFrame
    wall_time_s: float
    evaluations: int


def search(problem: SearchProblem, names, bounds, initial, budget: Budget, seed=1, progress=None) -> SearchOutcome:
    """Minimise ``problem`` within ``bounds`` (``{name: (low, high)}``) from ``initial`` ({name: value})."""
    lower = np.array([bounds[n][0] for n in names], dtype=float)
    upper = np.array([bounds[n][1] for n in names], dtype=float)
    rec = Recorder(problem, lower, upper, names, progress)
    t_start = time.perf_counter()

    rec.stage = "initial"
    x_init = (np.array([initial[n] for n in names]) - lower) / (upper - lower)
    e_init = rec(x_init)

    # 1. Sensitivity study on a Latin hypercube.
    rec.stage = "sensitivity"
    lhs = qmc.LatinHypercube(d=len(names), seed=seed).random(budget.designs)
    e_lhs = np.array([rec(x) for x in lhs])
    designs = pd.DataFrame(rec.rows[1:])
    order = np.argsort(e_lhs)
    top = lhs[order[:10]]

    # 2. CMA-ES with the 10 best designs in its first population.
    rec.stage = "cma-es"
    es = cma.CMAEvolutionStrategy(top[0], budget.cma_sigma0, {
        # BoundPenalty keeps the injected designs exactly as they are (BoundTransform would
        # remap those within 5 % of a bound); evaluations clip to the box.
        "bounds": [0.0, 1.0], "BoundaryHandler": cma.BoundPenalty, "popsize": max(budget.cma_popsize, len(top)), "seed": seed,
        "maxfevals": budget.cma_max_evaluations, "verbose": -9, "tolfun": 1e-12, "tolx": 1e-6,
    })
    es.inject(list(top), force=True)
    while not es.stop():
        X = es.ask()
        es.tell(X, [rec(x) for x in X])
    best_global = rec.best()
    x_global = (np.array([best_global[n] for n in names]) - lower) / (upper - lower)

    # 3. Nelder-Mead polish from the best design so far.
    rec.stage = "nelder-mead"
    simplex = np.vstack([x_global] + [np.clip(x_global + 0.02 * e, 0.0, 1.0) if x_global @ e < 0.98
                                      else x_global - 0.02 * e for e in np.eye(len(names))])
    nm = optimize.minimize(rec, x_global, method="Nelder-Mead", bounds=[(0.0, 1.0)] * len(names), options={
        "maxfev": budget.nm_max_evaluations, "xatol": 1e-5, "fatol": 1e-9, "initial_simplex": simplex})
    best = rec.best()
    theta = np.array([best[n] for n in names])
    wall = time.perf_counter() - t_start

    history = pd.DataFrame(rec.rows)
    stages = {
        "initial": {"e1": e_init, "parameters": dict(zip(names, (lower + x_init * (upper - lower)).tolist()))},
        "sensitivity": {"e1": float(e_lhs.min()), "evaluations": int(budget.designs)},
        "cma-es": {"e1": float(best_global["e1"]), "evaluations": int((history["stage"] == "cma-es").sum()),
                   "iterations": int(es.countiter), "stop": {k: str(v) for k, v in es.stop().items()}},
        "nelder-mead": {"e1": float(best["e1"]), "evaluations": int((history["stage"] == "nelder-mead").sum()),
                        "iterations": int(nm.nit), "message": str(nm.message)},
    }
    return SearchOutcome(theta, history, stages, sensitivity_measures(designs, names, problem.probes), wall, len(rec.rows))
