"""The tissue's share of a prediction's spread: the law of total variance over the wall material.

A surrogate fitted on a sweep whose wall material varied has the tissue among its inputs
(:data:`TISSUE_INPUTS`): as the tissue stiffness factor when every run's wall is one law scaled
(:mod:`colonsim.insertion.study.tissue_stiffness`; the patient-space sweep), else as the material's
small-strain shear modulus and C11 (:func:`tissue_representation`). A patient's tissue is not known: it is a
draw ``t`` from a tissue distribution (by default the one the sweep sampled, stored with the
surrogate; or a user's own calibration). For a query ``x`` the prediction averages over it::

    mean  = E_t[m(x, t)]
    var   = Var_t[m(x, t)]  +  E_t[s^2(x, t)]
            tissue part        surrogate part

``m`` and ``s^2`` are the GP's mean and variance (of a new simulation result in ``predict``, of
the smooth trend in ``recommend``). The expectations run over :data:`DRAWS` draws of a posterior
(seed :data:`SEED`, so answers repeat) or exactly over the equally weighted points of an empirical
distribution (a population's specimens, or the distinct materials of the runs). A query that sets
every tissue input is conditional on that tissue: its tissue part is 0. A model whose runs all used
one material has no tissue input: its tissue part is *not modelled*, and is reported as such.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import pandas as pd

from colonsim.catalog import TISSUE_STIFFNESS, WALL_C11, WALL_MU0
from colonsim.errors import ColonsimError
from colonsim.inputs import check_input
from colonsim.surrogate.domain import OutOfDomainWarning
from colonsim.insertion.case.case_material import case_material
from colonsim.insertion.engine.material import read_material_document
from colonsim.insertion.study.material_samples import (MATERIAL_PARAMETERS, Posterior, read_population,
                                                       read_posterior, tissue_columns)

TISSUE_INPUTS = (WALL_MU0, WALL_C11, TISSUE_STIFFNESS)
SCALED = 1e-6  # relative spread of mu0 / stiffness (and C11 / stiffness) below which the walls are one law scaled
DRAWS, SEED = 1000, 0
# More than this share of the draws outside the runs' tissue range: a warning. With N materials
# drawn in the sweep and two tissue inputs, about 1 - (1 - 2 / (N + 1))^2 of new draws fall outside
# the box of the N (75 % for N = 3, 18 % for N = 20).
OUTSIDE_WARNING = 0.5
CHUNK = 200_000  # query rows x draws per GP call (memory: that many rows of kernel values)


@dataclass
class TissueDistribution:
    """A distribution of the tissue inputs: a calibration's posterior, or equally weighted points.

    ``posterior``: a :class:`Posterior` (Pa); ``points``: input name -> values in kPa (NaN: the law
    has no such term)."""

    kind: str  # "posterior" or "empirical"
    source: str
    description: str
    posterior: Posterior | None = None
    points: dict | None = None

    @classmethod
    def from_file(cls, path):
        """A calibration's ``material.json`` (its posterior), a ``population.json`` (its specimens),
        or a material that states no uncertainty (its parameters alone: no tissue part)."""
        path = check_input(path, "material file")
        doc = read_material_document(path)
        if "specimens" in doc:
            pop = read_population(path)
            return cls("empirical", str(path), f"the {len(pop.values)} specimens of {path.name} ({pop.law})",
                       points=tissue_columns(pop.law, pop.values))
        if doc.get("covariance_Pa2") is None:
            material = case_material(str(path))
            return cls("empirical", str(path), f"the material of {path.name} ({material.law}; the file states no "
                                               "parameter uncertainty, so no tissue part)",
                       points=tissue_columns(material.law, [material.parameters]))
        post = read_posterior(path)
        return cls("posterior", str(path), f"the posterior of {path.name} ({post.law}, normal truncated to "
                                           "non-negative parameters)", posterior=post)

    @classmethod
    def from_runs(cls, runs: pd.DataFrame):
        """The distribution a sweep sampled, from its successful runs: the calibration file their drawn
        materials came from if it can still be read, else the distinct materials of the runs.
        Returns (distribution or None, note or None)."""
        note = None
        if MATERIAL_PARAMETERS in runs.columns and "material" in runs.columns:
            drawn = runs[runs[MATERIAL_PARAMETERS].fillna("").astype(str).str.strip() != ""]
            files = sorted(set(drawn["material"].dropna().astype(str)))
            if len(files) == 1:
                try:
                    return cls.from_file(files[0]), None
                except ColonsimError as exc:
                    note = f"the runs' tissue distribution is their distinct materials ({exc})"
            elif len(files) > 1:
                note = "the runs drew materials from several files; their tissue distribution is their distinct materials"
        present = [c for c in TISSUE_INPUTS if c in runs.columns]
        if not present:
            return None, note
        values = runs[present].astype(float).drop_duplicates()
        if len(values) < 2:
            return None, note
        points = {c: values[c].to_numpy() for c in present}
        return cls("empirical", "runs", f"the {len(values)} distinct wall materials of the runs", points=points), note

    def draws(self, n=DRAWS, seed=SEED) -> dict:
        """Tissue inputs (kPa) of ``n`` posterior draws, or every point of an empirical distribution."""
        if self.kind == "posterior":
            return tissue_columns(self.posterior.law, self.posterior.draw(n, seed))
        return {k: np.asarray(v, dtype=float) for k, v in self.points.items()}

    def to_dict(self) -> dict:
        doc = {"kind": self.kind, "source": self.source, "description": self.description}
        if self.kind == "posterior":
            p = self.posterior
            return {**doc, "law": p.law, "names": list(p.names), "mean_Pa": p.mean.tolist(),
                    "covariance_Pa2": p.covariance.tolist(), "draws": DRAWS, "seed": SEED,
                    "truncation": "draws with a negative parameter rejected"}
        # strict JSON: an undefined value (a law without C11) is null
        return {**doc, "points_kPa": {k: [None if np.isnan(v) else float(v) for v in vals]
                                      for k, vals in self.points.items()}}

    @classmethod
    def from_dict(cls, doc):
        if doc is None:
            return None
        if doc["kind"] == "posterior":
            post = Posterior(doc["law"], tuple(doc["names"]), np.asarray(doc["mean_Pa"], dtype=float),
                             np.asarray(doc["covariance_Pa2"], dtype=float), doc["source"])
            return cls("posterior", doc["source"], doc["description"], posterior=post)
        points = {k: np.array([np.nan if v is None else v for v in vals], dtype=float)
                  for k, vals in doc["points_kPa"].items()}
        return cls("empirical", doc["source"], doc["description"], points=points)


def tissue_representation(runs: pd.DataFrame, varying: list):
    """The model's inputs ``varying`` with one representation of the tissue, and a note (or None).

    When every run's wall is one law scaled (mu0 and C11 in a fixed ratio to the stiffness factor),
    the stiffness factor stands for the three; otherwise mu0 and C11 do, and the stiffness factor,
    which follows from them, is left out."""
    if TISSUE_STIFFNESS not in varying:
        return varying, None
    moduli = [c for c in (WALL_MU0, WALL_C11) if c in varying]
    stiffness = runs[TISSUE_STIFFNESS].to_numpy(dtype=float)
    ratios = [runs[c].to_numpy(dtype=float) / stiffness for c in moduli]
    if all(np.ptp(r) <= SCALED * np.max(np.abs(r)) for r in ratios):
        note = (f"{', '.join(moduli)} follow {TISSUE_STIFFNESS} in every run (the walls are one law scaled): the "
                "stiffness factor stands for them" if moduli else None)
        return [c for c in varying if c not in moduli], note
    return [c for c in varying if c != TISSUE_STIFFNESS], None


def tissue_inputs(domain) -> list:
    """The tissue inputs a segment's model depends on (those that varied over its runs)."""
    return [name for name in domain.inputs if name in TISSUE_INPUTS]


@dataclass
class TissuePlan:
    """How a batch of queries treats the tissue: averaged over draws, given by the query, or not modelled."""

    columns: list  # the model's tissue inputs (empty: not modelled)
    given: np.ndarray  # per query row: the query sets the tissue
    draws: np.ndarray | None  # (K, len(columns)) for the averaged rows
    note: str
    outside: float = 0.0  # share of the draws outside the runs' tissue range

    @property
    def modelled(self) -> bool:
        return bool(self.columns)

    def to_dict(self) -> dict:
        averaged = self.modelled and not self.given.all()
        return {"modelled": self.modelled, "averaged": bool(averaged), "note": self.note,
                "draws": None if not averaged else int(len(self.draws)),
                "draws_outside_training_range": float(self.outside) if averaged else None}


def plan(domain, query: dict, n: int, distribution: TissueDistribution | None, strict=False):
    """The query with the tissue inputs filled for the domain check, and its :class:`TissuePlan`.

    Warns (:class:`OutOfDomainWarning`; an error with ``strict``) when more than
    :data:`OUTSIDE_WARNING` of the tissue draws lie outside the runs' tissue range."""
    columns = tissue_inputs(domain)
    if not columns:
        value = domain.fixed.get(WALL_MU0)
        why = (f"every {domain.segment} run used one wall material (mu0 {value:.4g} kPa)" if value is not None
               else "the runs' table has no wall material columns")
        return query, TissuePlan([], np.zeros(n, bool), None, f"tissue part not modelled: {why}")
    given = np.column_stack([np.broadcast_to(domain.numbers(query[c], c) if query.get(c) is not None
                                             else np.nan, (n,)) for c in columns])
    full, none = ~np.isnan(given).any(axis=1), np.isnan(given).all(axis=1)
    if not (full | none).all():
        raise ColonsimError(f"segment {domain.segment}: give all of {', '.join(columns)} (a known tissue) or none "
                            "(the prediction then averages over the tissue distribution)")
    if full.all():
        return query, TissuePlan(columns, full, None, "tissue given by the query: no tissue part")
    if distribution is None:
        raise ColonsimError(f"segment {domain.segment} depends on {', '.join(columns)} but the surrogate holds no tissue "
                            "distribution; give --material FILE (a calibration's material.json or population.json)")
    values = distribution.draws()
    missing = [c for c in columns if c not in values or np.isnan(values[c]).any()]
    if missing:
        raise ColonsimError(f"the tissue distribution ({distribution.description}) has no {', '.join(missing)}; give a "
                            "calibration of the law the sweep ran")
    draws = np.column_stack([values[c] for c in columns])
    j = [domain.inputs.index(c) for c in columns]
    span = np.maximum(domain.high[j] - domain.low[j], 0.0)
    outside = float(np.mean(((draws < domain.low[j] - 1e-6 * span) | (draws > domain.high[j] + 1e-6 * span)).any(axis=1)))
    if outside > OUTSIDE_WARNING:
        message = (f"{domain.segment}: {100 * outside:.0f} % of the tissue draws lie outside the runs' tissue range, "
                   "where the GP returns to its mean: the tissue part is extrapolated and likely understated")
        if strict:
            raise ColonsimError(message + "; sweep more materials, or drop --strict to extrapolate anyway")
        warnings.warn(message + "; sweep more materials of this distribution", OutOfDomainWarning, stacklevel=3)
    filled = dict(query)
    for c, k in zip(columns, j):  # the domain check of the other inputs sees a tissue inside the range
        filled[c] = np.where(full, given[:, columns.index(c)], 0.5 * (domain.low[k] + domain.high[k]))
    what = (f"tissue: {distribution.description}" if len(draws) == 1 else
            f"averaged over {len(draws)} {'draws' if distribution.kind == 'posterior' else 'materials'} of "
            f"{distribution.description}")
    note = (what + (f"; {100 * outside:.0f} % of them outside the runs' tissue range "
                                               "(extrapolated)" if outside > 0 else ""))
    return filled, TissuePlan(columns, full, draws, note, outside)


def _with_tissue(domain, X, plan_, rows, draws):
    """(len(draws) * len(rows), d) inputs: the query rows ``rows`` with each draw's tissue."""
    j = [domain.inputs.index(c) for c in plan_.columns]
    XX = np.repeat(X[rows][None], len(draws), axis=0)
    XX[:, :, j] = draws[:, None, :]
    return XX.reshape(-1, X.shape[1])


def split_predict(gp, domain, X, plan_):
    """Mean, total sd, tissue sd and surrogate sd of a new simulation result at the rows of ``X``.

    Tissue sd is NaN when the tissue is not modelled, 0 where the query gives it."""
    mean, sd = gp.predict(X, return_std=True)
    tissue = np.full(len(X), np.nan if not plan_.modelled else 0.0)
    surrogate = sd.copy()
    rows = np.flatnonzero(~plan_.given) if plan_.modelled else np.zeros(0, int)
    if rows.size:
        K, n = len(plan_.draws), rows.size
        step = max(1, CHUNK // n)
        shift = s1 = s2 = sv = 0.0
        for start in range(0, K, step):
            d = plan_.draws[start:start + step]
            m, s = gp.predict(_with_tissue(domain, X, plan_, rows, d), return_std=True)
            m, v = m.reshape(len(d), n), (s**2).reshape(len(d), n)
            if start == 0:
                shift = m[0].copy()  # sums about a shift keep the variance free of cancellation
            s1, s2, sv = s1 + (m - shift).sum(0), s2 + ((m - shift) ** 2).sum(0), sv + v.sum(0)
        centre = s1 / K
        mean[rows] = shift + centre
        tissue[rows] = np.sqrt(np.maximum(s2 / K - centre**2, 0.0))
        surrogate[rows] = np.sqrt(sv / K)
    total = np.sqrt(np.where(np.isnan(tissue), 0.0, tissue) ** 2 + surrogate**2)
    return mean, total, tissue, surrogate


def trend_components(gp, domain, X, plan_):
    """Per tissue draw, the GP's trend mean (K, n) and joint covariance (K, n, n) at the rows of
    ``X`` (one component when the tissue is not averaged): the mixture ``recommend`` ranks with."""
    if not plan_.modelled or plan_.given.all():
        mean, cov = gp.predict(X, return_cov=True)
        return mean[None], cov[None]
    if plan_.given.any():
        raise ColonsimError("a recommendation gives the tissue for every scope or for none")
    rows = np.arange(len(X))
    means, covs = [], []
    for d in plan_.draws:
        m, c = gp.predict(_with_tissue(domain, X, plan_, rows, d[None]), return_cov=True)
        means.append(m)
        covs.append(c)
    return np.array(means), np.array(covs)
