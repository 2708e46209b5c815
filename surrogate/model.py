"""The surrogate of a sweep: one GP per colon segment and output, fitted on the results table.

``SweepSurrogate(...).fit(table)`` returns the fitted estimator; ``predict(query, segment, target,
return_std=True)`` answers in microseconds. Learned state lives in attributes ending with ``_``:
``domains_`` (segment -> :class:`SegmentDomain`), ``models_`` (segment -> target ->
:class:`GaussianProcess`, or :class:`LargerOf` for an output that is the larger of two fitted
ones, :mod:`colonsim.surrogate.larger`), ``cv_`` (segment -> target -> cross-validation
metrics), ``skipped_`` (segment -> target -> why no model), ``scatter_`` (segment -> target -> the scatter measured by
replicate runs, or None), ``notes_`` (things about the table a user should know).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from colonsim.errors import ColonsimError
from colonsim.surrogate.domain import SegmentDomain
from colonsim.surrogate.replicates import replicate_scatter, unmatched_replicates
from colonsim.surrogate.gp import GaussianProcess
from colonsim.surrogate.larger import LargerOf, cross_validate_larger, identity_holds
from colonsim.surrogate.table import (INPUT_OPTIONS, INPUTS, PAIN_PROXY, TARGETS, check_results, numeric_column,
                                      scope_diameter_mm, scope_diameters, solver_settings, split_inputs,
                                      successful_runs)
from colonsim.surrogate.tissue import (TISSUE_INPUTS, TissueDistribution, plan, split_predict, tissue_inputs,
                                       tissue_representation)
from colonsim.surrogate.validation import Z95, cross_validate, error_unknown
from colonsim.insertion.study.material_samples import MATERIAL_PARAMETERS
from colonsim.catalog import LARGER_OF, TIP_FOLDED
# columns of each target in predict_frame (the 95 % interval is mean +- 1.96 total sd)
SUFFIXES = ("", "_std", "_low95", "_high95", "_std_tissue", "_std_surrogate")


class SweepSurrogate:
    """Gaussian-process surrogate of a sweep, per segment and per output.

    Parameters
    ----------
    targets : sequence of str
        Output columns to model (default :data:`colonsim.surrogate.table.TARGETS`); a segment whose runs
        leave a target undefined (NaN, e.g. points A and C outside RSJ) gets no model for it.
    inputs : sequence of str
        Candidate input columns; those constant over a segment's runs are recorded as fixed.
    segments : sequence of str or None
        Segments to fit (default: all in the table).
    cv : "loo" or int
        Cross-validation scheme run at fit time (see :mod:`colonsim.surrogate.validation`).
    n_restarts : int or None
        Extra optimizer starts of each GP's hyperparameters; None: as many as the runs call for
        (:func:`colonsim.surrogate.gp.restarts_for`).
    min_runs : int
        Fewer successful runs with a value than this: no model for that segment and target.
    random_state : int
    threads : int or None
        BLAS threads during the fit (default 1). The matrices are small (runs x runs): on a machine
        shared with simulations, more BLAS threads contend for the cores and made a 500-run fit
        four times slower in the benchmark. None leaves the BLAS default.
    tissue : TissueDistribution or None
        The wall-material distribution predictions average over (:mod:`colonsim.surrogate.tissue`);
        default: the one the sweep sampled, read from the runs (``tissue_``).
    replicates : DataFrame or None
        Results table of training cases run again at another wall mesh: per output, the
        scatter of the pairs is the noise floor of its GP (:mod:`colonsim.surrogate.replicates`,
        ``scatter_``). None: no floor.
    hyperparameter_draws : int or None
        Draws of each GP's hyperparameters its predictions average over (0: the likelihood's
        maximum alone, a plug-in); None: as many as the runs call for
        (:func:`colonsim.surrogate.gp.draws_for`, :mod:`colonsim.surrogate.hyperposterior`).
    tip_folded : bool
        Train on runs that ended with a folded tip too (``ended_by`` :data:`TIP_FOLDED`). Default
        False: a folded tip is outside the model; such runs are left out and counted (``training_``).
    """

    def __init__(self, targets=TARGETS, inputs=INPUTS, segments=None, cv="loo", n_restarts=None, min_runs=4,
                 random_state=0, threads=1, tissue=None, replicates=None, hyperparameter_draws=None,
                 tip_folded=False):
        self.targets = targets
        self.inputs = inputs
        self.segments = segments
        self.cv = cv
        self.n_restarts = n_restarts
        self.min_runs = min_runs
        self.random_state = random_state
        self.threads = threads
        self.tissue = tissue
        self.replicates = replicates
        self.hyperparameter_draws = hyperparameter_draws
        self.tip_folded = tip_folded

    def _make_gp(self, domain, noise_floor_sd=0.0):
        return lambda: GaussianProcess(input_range=(domain.low, domain.high), n_restarts=self.n_restarts,
                                       random_state=self.random_state, noise_floor_sd=noise_floor_sd,
                                       hyperparameter_draws=self.hyperparameter_draws)

    def fit(self, table: pd.DataFrame):
        """Fit every (segment, target) model on the runs with status "ok"; returns self."""
        from threadpoolctl import threadpool_limits

        with threadpool_limits(limits=self.threads, user_api="blas"):
            return self._fit(check_results(table))

    def _fit(self, table):
        if self.cv != "loo" and not (isinstance(self.cv, (int, np.integer)) and self.cv >= 2):
            raise ColonsimError(f"cv must be 'loo' or a number of folds >= 2, got {self.cv!r}")
        replicates = None if self.replicates is None else check_results(self.replicates, "replicate table")
        unknown = sorted(set(self.targets) - set(table.columns))
        if unknown:
            raise ColonsimError(f"the results table has no column {', '.join(unknown)}; choose targets among its outputs")
        segments = self.segments or [s for s in dict.fromkeys(table["segment"]) if (table["segment"] == s).any()]
        self.domains_, self.models_, self.cv_, self.skipped_, self.notes_, self.scatter_ = {}, {}, {}, {}, [], {}
        self.about_ = None  # what a shipped predictor says of itself (colonsim.surrogate.predictor_fit)
        self.held_out_ = {}  # segment -> output -> coverage on held-out runs (colonsim.surrogate.predictor_fit)
        folded = ((table["status"] == "ok") & (table["ended_by"] == TIP_FOLDED) if "ended_by" in table.columns
                  else pd.Series(False, index=table.index))
        if folded.any() and not self.tip_folded:  # counted in training_, said by report()
            table = table[~folded].reset_index(drop=True)
        ok = table["status"] == "ok"
        commits = sorted(set(table.loc[ok, "git_commit"].dropna().astype(str)) - {""}) if "git_commit" in table else []
        self.training_ = {"runs": int(len(table)), "ok": int(ok.sum()), "failed": int((~ok).sum()),
                          "tip_folded": int(folded.sum()), "tip_folded_trained": bool(self.tip_folded),
                          "git_commits": commits}
        absent = [name for name in self.inputs if name not in table.columns]
        if absent:
            self.notes_.append(f"the table has no column {', '.join(absent)}: the model cannot take "
                               f"{'it' if len(absent) == 1 else 'them'} into account, and a query that sets "
                               f"{', '.join(INPUT_OPTIONS.get(a, a) for a in absent)} is refused")
        for segment in segments:
            runs = successful_runs(table, segment)
            if runs.empty:
                self.notes_.append(f"{segment}: no successful run, no model")
                continue
            varying, fixed = split_inputs(runs, self.inputs)
            varying, note = tissue_representation(runs, varying)
            if note:
                self.notes_.append(f"{segment}: {note}")
            undefined = [n for n in self.inputs if n in runs.columns and runs[n].isna().all()]
            if undefined:
                self.notes_.append(f"{segment}: {', '.join(undefined)} undefined (NaN) in every run, not an input")
            settings, varying_settings = solver_settings(runs)
            low = runs[varying].min().to_numpy(dtype=float) if varying else np.zeros(0)
            high = runs[varying].max().to_numpy(dtype=float) if varying else np.zeros(0)
            domain = SegmentDomain(segment, varying, low, high, fixed, len(runs), scope_diameters(runs), settings)
            self.domains_[segment] = domain
            if set(varying) & set(TISSUE_INPUTS):  # the material's effect goes through mu0 and C11
                varying_settings = [v for v in varying_settings if v not in ("material", MATERIAL_PARAMETERS)]
            if varying_settings:
                self.notes_.append(f"{segment}: solver setting(s) {', '.join(varying_settings)} vary between runs; "
                                   "they are not inputs, so their effect shows up as scatter")
            # today's "quasi_static" is the ringing criterion; tables of older code hold their check in
            # a column of its own
            check = next((c for c in ("quasi_static_without_imposed_sliding", "quasi_static") if c in runs.columns), None)
            if check is not None and (runs[check] == False).any():  # noqa: E712 (NaN-safe)
                self.notes_.append(f"{segment}: {int((runs[check] == False).sum())} of {len(runs)} runs "  # noqa: E712
                                   "were not quasi-static (their push force rang: docs/quasi_static.md); "
                                   "they train like the others")
            self.models_[segment], self.cv_[segment], self.skipped_[segment] = {}, {}, {}
            self.scatter_[segment] = {}
            fitted = {}  # target -> (rows used, their values, GP factory): what a larger-of model needs
            # an output that may be the larger of two others comes after them (its parts fitted first)
            for target in sorted(self.targets, key=lambda t: t in LARGER_OF):
                y = numeric_column(runs, target).to_numpy()
                keep = np.isfinite(y)
                if not varying:
                    self.skipped_[segment][target] = "no input varies over the runs"
                elif keep.sum() < self.min_runs:
                    self.skipped_[segment][target] = f"{int(keep.sum())} runs with a value (< {self.min_runs})"
                if target in self.skipped_[segment]:
                    continue
                why = [f"{int(n)} {what}" for n, what in ((np.isinf(y).sum(), "with an infinite value"),
                                                          (np.isnan(y).sum(), "without a value (NaN)")) if n]
                if why:
                    self.notes_.append(f"{segment} {target}: {int((~keep).sum())} of {len(y)} successful runs left "
                                       f"out ({' and '.join(why)}), {int(keep.sum())} used")
                X = runs.loc[keep, varying].to_numpy(dtype=float)
                scatter = None if replicates is None else replicate_scatter(runs, replicates, segment,
                                                                            [*varying, *fixed], target)
                self.scatter_[segment][target] = scatter
                if self._larger_of(segment, runs, varying, fitted, target, keep, y[keep]):
                    continue
                make_gp = self._make_gp(domain, 0.0 if scatter is None else scatter["sd"])
                with np.errstate(over="ignore", invalid="ignore"):  # an overflow shows in the check below
                    gp = make_gp().fit(X, y[keep])
                if not all(np.isfinite(v).all() for v in (gp.y_scale_, gp.alpha_, gp.L_, gp.length_scale_)):
                    raise ColonsimError(f"{segment} {target}: the fit is not finite (values from {y[keep].min():.3g} "
                                        f"to {y[keep].max():.3g}); check that column's values and unit")
                self.models_[segment][target] = gp
                self.cv_[segment][target] = cross_validate(gp, X, y[keep], self.cv, make_gp, self.random_state)
                fitted[target] = (keep, y[keep], make_gp)
            for store in (self.models_, self.cv_, self.skipped_, self.scatter_):  # in the order of the targets
                store[segment] = {t: store[segment][t] for t in self.targets if t in store[segment]}
        if replicates is not None:
            unmatched_replicates(replicates, self.scatter_)
        self.tissue_, note = ((self.tissue, None) if self.tissue is not None
                              else TissueDistribution.from_runs(table[table["status"] == "ok"]))
        if note and any(tissue_inputs(d) for d in self.domains_.values()):
            self.notes_.append(note)
        if not any(self.models_.values()):
            reasons = "; ".join(f"{s} {t}: {why}" for s, d in self.skipped_.items() for t, why in d.items())
            raise ColonsimError(f"no model could be fitted ({reasons or 'no successful run in the segments asked for'})")
        return self

    def _larger_of(self, segment, runs, varying, fitted, target, keep, y) -> bool:
        """Model ``target`` (its values ``y`` on the rows ``keep`` of ``runs``) through its parts if it
        is the larger of two fitted outputs (:data:`LARGER_OF`) and the identity holds on every run
        (:mod:`colonsim.surrogate.larger`); False when it is to be fitted as one output."""
        parts = LARGER_OF.get(target)
        if parts is None or not all(p in fitted for p in parts):
            return False
        why = identity_holds(runs, target)
        if why is None and not all((fitted[p][0] == keep).all() for p in parts):
            why = "its parts have values on other runs than it"
        if why is not None:
            self.notes_.append(f"{segment} {target}: fitted as one output, not as the larger of "
                               f"{' and '.join(parts)} ({why})")
            return False
        model = LargerOf(parts, *(self.models_[segment][p] for p in parts))
        self.models_[segment][target] = model
        self.cv_[segment][target] = cross_validate_larger(
            model, runs.loc[keep, varying].to_numpy(dtype=float), [fitted[p][1] for p in parts], y, self.cv,
            [fitted[p][2] for p in parts], self.random_state)
        return True

    # -- queries -------------------------------------------------------------------------------------
    def model_for(self, segment, target):
        """The training domain and GP of ``segment`` and ``target``; a one-line error if there is none."""
        segment = str(segment).lower()
        if segment not in self.domains_:
            raise self.no_model_of(segment)
        model = self.models_[segment].get(target)
        if model is None:
            why = self.skipped_[segment].get(target, "not among the fitted targets")
            raise ColonsimError(f"no {target} model for {segment} ({why}); choose --target among "
                                f"{', '.join(self.models_[segment]) or 'none'}")
        return self.domains_[segment], model

    def no_model_of(self, segment) -> ColonsimError:
        """The error for a query of a segment the model has no domain of: which it covers, and for
        the shipped predictor (an ``about_``) which sweeps it was fitted on."""
        covered = ", ".join(self.domains_)
        if getattr(self, "about_", None):
            return ColonsimError(f"the predictor has no model of segment {segment!r}: it covers {covered}, fitted on "
                                 f"the sweeps {', '.join(self.about_.get('sweeps', []))}; ask one of those, or fit a "
                                 "surrogate on a sweep of your own ('colonsim surrogate fit RESULTS -o MODEL')")
        return ColonsimError(f"the surrogate has no model of segment {segment!r}; it was fitted on {covered}")

    def error_unknown(self, segment, target) -> str | None:
        """Why the model of ``segment`` and ``target`` cannot state its error (too few runs to check
        it), or None when its sd, intervals and probabilities are vouched for: by its held-out runs
        where it carries their coverage (``held_out_``, the shipped predictor), else by its
        cross-validation (:func:`colonsim.surrogate.validation.error_unknown`)."""
        domain, gp = self.model_for(segment, target)
        return error_unknown(self.cv_[domain.segment][target], gp, self.held_out_.get(domain.segment, {}).get(target))

    def query(self, segment, values: dict) -> dict:
        """``values`` with scope names (key ``scope``) turned into ``scope_diameter_mm``; a diameter
        given as well wins, names fill the rows where it is missing (NaN)."""
        values = dict(values)
        scope = values.pop("scope", None)
        if scope is None:
            return values
        known = self.domains_[segment].scopes if segment in self.domains_ else {}
        given = values.get("scope_diameter_mm")
        if given is None and np.ndim(scope) == 0:  # the common single query
            values["scope_diameter_mm"] = scope_diameter_mm(scope, known)
            return values
        names = np.atleast_1d(np.asarray(scope, dtype=object))
        from_names = np.array([np.nan if s is None or (isinstance(s, float) and np.isnan(s))
                               else scope_diameter_mm(s, known) for s in names])
        values["scope_diameter_mm"] = (from_names if given is None else
                                       np.where(np.isnan(np.asarray(given, dtype=float)), from_names, given))
        return values

    def predict(self, X, segment, target=PAIN_PROXY, return_std=False, strict=False, return_split=False):
        """Predicted ``target`` for ``segment`` at the query ``X``.

        ``X``: a mapping input name -> scalar or array (``scope`` may name a scope), a DataFrame
        with those columns, or an (n, d) array in the order of ``domains_[segment].inputs``.
        Outside the training domain: :class:`OutOfDomainWarning`, or an error with ``strict``.
        Returns the mean (n,), and with ``return_std`` the standard deviation of a new simulation
        result (trend + run-to-run scatter). A query without the tissue inputs of a model that has
        them is averaged over the tissue distribution (:mod:`colonsim.surrogate.tissue`);
        ``return_split`` returns (mean, total sd, tissue sd, surrogate sd).
        """
        domain, gp = self.model_for(segment, target)
        if isinstance(X, np.ndarray):
            X = dict(zip(domain.inputs, np.atleast_2d(X).T))
        elif isinstance(X, pd.DataFrame):
            X = {c: X[c].to_numpy() for c in X.columns}
        query = self.query(domain.segment, X)
        n = max([np.size(query[c]) for c in domain.inputs if query.get(c) is not None], default=1)
        query, tissue = plan(domain, query, n, getattr(self, "tissue_", None), strict)
        Xm, _, _ = domain.check(query, strict=strict)
        if not return_split and (not tissue.modelled or tissue.given.all()):
            return gp.predict(Xm, return_std=return_std)
        mean, sd, sd_tissue, sd_surrogate = split_predict(gp, domain, Xm, tissue)
        if return_split:
            return mean, sd, sd_tissue, sd_surrogate
        return (mean, sd) if return_std else mean

    def predict_frame(self, frame: pd.DataFrame, targets=None, segment=None, strict=False) -> pd.DataFrame:
        """Batch prediction: one row per query row, per target its mean, std, 95 % interval and the
        std's tissue and surrogate parts (tissue NaN where not modelled; ``tissue_note`` says how;
        all NaN where the model has too few runs to know its error, and ``error_note`` says so).

        ``frame`` holds input columns (and ``segment`` unless given). Targets a segment has no model
        of are NaN. Columns ``in_domain`` and ``domain_note`` say which rows extrapolate."""
        frame = frame.reset_index(drop=True)
        if segment is not None:
            frame = frame.assign(segment=segment)
        if "segment" not in frame.columns:
            raise ColonsimError("the queries lack a segment column; add one or pass --segment")
        frame = frame.assign(segment=frame["segment"].astype(str).str.strip().str.lower())
        targets = list(targets or self.targets)
        out = frame.copy()
        out["in_domain"], out["domain_note"], out["tissue_note"], out["error_note"] = True, "", "", ""
        for t in targets:
            for suffix in SUFFIXES:
                out[t + suffix] = np.nan
        for seg, rows in frame.groupby("segment", sort=False):
            if seg not in self.domains_:
                raise self.no_model_of(seg)
            domain = self.domains_[seg]
            values = self.query(seg, {c: rows[c].to_numpy() for c in rows.columns if c != "segment"})
            values, tissue = plan(domain, values, len(rows), getattr(self, "tissue_", None), strict)
            Xm, inside, note = domain.check(values, n=len(rows), strict=strict)
            out.loc[rows.index, "tissue_note"] = tissue.note
            out.loc[rows.index, "in_domain"] = inside
            out.loc[rows.index, "domain_note"] = note
            if values.get("scope_diameter_mm") is not None:
                out.loc[rows.index, "scope_diameter_mm"] = values["scope_diameter_mm"]
            for t in targets:
                gp = self.models_[seg].get(t)
                if gp is None:
                    continue
                mean, std, std_tissue, std_surrogate = split_predict(gp, domain, Xm, tissue)
                unknown = self.error_unknown(seg, t)
                if unknown:  # no number where the model cannot vouch for it
                    std = std_tissue = std_surrogate = np.full(len(mean), np.nan)
                    out.loc[rows.index, "error_note"] += f"{t}: {unknown}. "
                out.loc[rows.index, t] = mean
                out.loc[rows.index, t + "_std"] = std
                out.loc[rows.index, t + "_std_tissue"] = std_tissue
                out.loc[rows.index, t + "_std_surrogate"] = std_surrogate
                out.loc[rows.index, t + "_low95"] = mean - Z95 * std
                out.loc[rows.index, t + "_high95"] = mean + Z95 * std
        return out

    # -- description ---------------------------------------------------------------------------------
    def report(self) -> str:
        """Training domain, hyperparameters and cross-validated accuracy, as text."""
        folded = self.training_.get("tip_folded", 0)  # absent in models of before
        lines = [f"trained on {self.training_['ok']} successful runs ({self.training_['failed']} failed runs ignored"
                 + (f"; {folded} tip-folded runs {'trained on' if self.training_.get('tip_folded_trained') else 'left out'}"
                    if folded else "") + ")"]
        for seg, domain in self.domains_.items():
            lines.append(domain.describe())
            for target, gp in self.models_[seg].items():
                cv = self.cv_[seg][target]
                if isinstance(gp, LargerOf):
                    about = gp.description
                else:
                    scales = ", ".join(f"{n} {v:.2g}" for n, v in zip(domain.inputs, gp.length_scale_))
                    about = f"scatter sd {gp.noise_std:.2g}  length scales ({scales})"
                    if len(gp.draws_):
                        about += f"  averaged over {len(gp.draws_)} hyperparameter draws"
                lines.append(f"  {target:<22} n {cv['n']:>3}  CV RMSE {cv['rmse']:.3g}  max {cv['max_abs_error']:.3g}  "
                             f"95% coverage {100 * cv['coverage_95']:.0f} %  Q2 {cv['q2'] if cv['q2'] is None else round(cv['q2'], 3)}  "
                             f"{about}")
                scatter = self.scatter_.get(seg, {}).get(target)
                if scatter and not isinstance(gp, LargerOf):  # a larger-of model's parts have their own floors
                    lines.append(f"  {'':<22} noise floor {scatter['sd']:.2g} (scatter of {scatter['pairs']} replicate "
                                 f"pairs; their offset {scatter['offset']:+.2g})")
                unknown, held = self.error_unknown(seg, target), self.held_out_.get(seg, {}).get(target)
                if held:
                    lines.append(f"  {'':<22} held out: {held['runs']} runs, 95 % intervals covered "
                                 f"{100 * held['coverage_95']:.0f} %, 50 % intervals {100 * held['coverage_50']:.0f} %")
                if unknown:
                    lines.append(f"  {'':<22} {unknown}: its sd, intervals and probabilities are not printed")
            for target, why in self.skipped_[seg].items():
                lines.append(f"  {target:<22} no model: {why}")
        if getattr(self, "tissue_", None) is not None and any(tissue_inputs(d) for d in self.domains_.values()):
            given = sorted({c for d in self.domains_.values() for c in tissue_inputs(d)}, key=TISSUE_INPUTS.index)
            lines.append(f"tissue: predictions without {' / '.join(given)} average over {self.tissue_.description}")
        lines.extend(f"note: {n}" for n in self.notes_)
        if self.domains_:
            scheme = next((self.cv_[s][t].get("scheme") for s in self.models_ for t, gp in self.models_[s].items()
                           if isinstance(gp, GaussianProcess)), None)  # a larger-of model's: its parts'
            if scheme:
                lines.append(f"cross-validation: {scheme}; length scales are in units of the training range "
                             "(>> 1: the output barely depends on that input)")
        return "\n".join(lines)

