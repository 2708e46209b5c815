"""A sweep that chooses its next runs: fit the surrogate, run where it is least certain, refit.

Round 0 is the spec's own Latin hypercube (``[lhs] samples`` points per ``[[grid]]`` case). After
each round the surrogate (:class:`colonsim.surrogate.model.SweepSurrogate`, one GP per segment)
is fitted on the sweep's successful runs, and the next batch is the candidates of greatest
posterior variance, or of greatest expected squared prediction error
(:func:`colonsim.surrogate.acquisition.greedy_batch`), among a fresh, seeded hypercube of the same
ranges (:class:`colonsim.insertion.study.adaptive_design.AdaptiveDesign`).
A segment whose leave-one-out RMSE has reached the target gets no more runs. The sweep stops when
every segment has reached it, or at the budget (total runs, failed ones included).

Runs go through :func:`colonsim.insertion.study.sweep.run_sweep` (local processes or Dask), into
one sweep folder. Besides its ``results.parquet``, ``runs/`` and ``sweep.json`` (which lists every
run chosen so far), the folder holds

    adaptive_rounds.json   every round: the runs chosen, why (the predicted sd at selection),
                           the cross-validation metrics after the round, the runs so far
    adaptive_rmse.png      leave-one-out RMSE of the target against runs, per segment

A rerun into the same folder continues from the recorded rounds: no run is repeated, and the
choices are the same for the same sweep (the fit reads the runs in key order, the candidates are
seeded by the sweep's seed and the round).
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from colonsim.catalog import PAIN_PROXY
from colonsim.errors import ColonsimError
from colonsim.files import check_output_folder, save_figure, write_json
from colonsim.insertion.case.run_budget import DEFAULT_MAX_STEPS
from colonsim.insertion.case.scenario import InsertionCase
from colonsim.insertion.study.adaptive_design import AdaptiveDesign, input_matrix
from colonsim.insertion.study.sweep import run_sweep
from colonsim.insertion.study.sweep_outcomes import LocalPool
from colonsim.insertion.study.sweep_worker import utc_now
from colonsim.surrogate.acquisition import CRITERIA, greedy_batch
from colonsim.surrogate.table import TARGET_LABELS, model_segment

ROUNDS = "adaptive_rounds.json"
FIGURE = "adaptive_rmse.png"
WHY = {"variance": "greatest posterior variance of the trend (greedy, the GP conditioned on each pick)",
       "error": "greatest expected squared prediction error: the nearest run's squared leave-one-out error plus "
                "the trend's posterior variance (greedy, the GP conditioned on each pick)"}
METRICS = ("n", "rmse", "max_abs_error", "coverage_95", "mean_std", "q2")


@dataclass
class AdaptiveSettings:
    """When an adaptive sweep stops and how it chooses.

    Parameters
    ----------
    budget : int
        Most runs in total (the first round included, failed runs included).
    target_rmse : float or None
        Stop when the leave-one-out RMSE of ``target`` is at most this in every segment (the
        target's unit: cm for deformations); None runs to the budget.
    batch : int
        Runs chosen per round (run in parallel).
    target : str
        The output column the surrogate is judged and the runs chosen by.
    criterion : "variance" or "error"
        How a round chooses (:func:`colonsim.surrogate.acquisition.greedy_batch`).
    """

    budget: int
    target_rmse: float | None = None
    batch: int = 4
    target: str = PAIN_PROXY
    criterion: str = "variance"

    def check(self, first_round: int):
        if self.target not in TARGET_LABELS:
            raise ColonsimError(f"--target {self.target!r} is not an output the surrogate models; use one of "
                                f"{', '.join(TARGET_LABELS)}")
        if self.target_rmse is not None and not self.target_rmse > 0:
            raise ColonsimError(f"--target-rmse {self.target_rmse:g} must be positive (the leave-one-out RMSE to reach, "
                                "in the target's unit, e.g. 0.1 cm)")
        if self.criterion not in CRITERIA:
            raise ColonsimError(f"--criterion {self.criterion!r} is unknown; use one of {', '.join(CRITERIA)}")
        if self.batch < 1:
            raise ColonsimError(f"--batch {self.batch}; choose at least 1 run per round")
        if self.budget < first_round:
            raise ColonsimError(f"--budget {self.budget} is smaller than the first round ({first_round} runs: the [lhs] "
                                "samples times the grid cases); raise the budget or lower [lhs] samples")


@dataclass
class AdaptiveReport:
    """What :func:`run_adaptive_sweep` did: the rounds (as recorded), why it stopped, the table."""

    folder: Path
    rounds: list
    stopped: str
    runs: int
    ran: int
    table: pd.DataFrame = field(repr=False)

    @property
    def reached(self) -> bool:
        return self.stopped == "target reached"


@dataclass
class _Document:
    """What ``sweep.json`` says of an adaptive folder: the spec's TOML, every run chosen so far."""

    spec: object
    cases: list
    settings: AdaptiveSettings

    @property
    def source(self):  # the folder's identity: the same TOML accepts a growing set of runs
        return self.spec.source

    def document(self):
        return {**dataclasses.replace(self.spec, cases=self.cases).document(),
                "adaptive": {"rounds": ROUNDS, "target": self.settings.target, "budget": self.settings.budget}}


def read_rounds(folder, spec, settings) -> dict:
    """The round log of ``folder`` (a new one if there is none); refuses a log of another sweep or target."""
    path = Path(folder) / ROUNDS
    if not path.is_file():
        return {"sweep": spec.name, "seed": spec.seed, "toml": spec.source, "target": settings.target, "rounds": []}
    try:
        log = json.loads(path.read_text(encoding="utf-8"))
        rounds, toml, target = log["rounds"], log["toml"], log["target"]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise ColonsimError(f"cannot read {path} ({type(exc).__name__}); it records an adaptive sweep's rounds: move "
                            "it away only together with the folder, or use another --out") from None
    if toml != spec.source:
        raise ColonsimError(f"{folder} holds the adaptive rounds of another sweep TOML ({log.get('sweep')!r}); resume "
                            "it with its own file, or give this sweep another --out")
    if target != settings.target:
        raise ColonsimError(f"{folder} chose its runs by {target}; resume with --target {target}, or give "
                            "another --out")
    return log


def _pick_record(design, case, pick=None) -> dict:
    record = {"key": case.key(), "segment": case.segment, "inputs": design.inputs(case)}
    if pick is not None:
        record.update(predicted_sd=pick.sd, predicted_sd_with_scatter=pick.sd_with_scatter)
        if pick.bias:
            record["nearest_loo_error"] = pick.bias
    record["case"] = case.to_dict()
    return record


def _case(record) -> InsertionCase:
    case = InsertionCase(**record["case"])
    if case.key() != record["key"]:
        raise ColonsimError(f"run {record['key']} of {ROUNDS} has key {case.key()} with this code; its inputs changed "
                            "meaning, so the sweep cannot be continued: start it in another --out")
    return case


def fit_round(table, target, seed, n_restarts=None):
    """The surrogate of the sweep's successful runs (read in key order) and, per segment, the
    leave-one-out metrics of ``target`` (or why there is no model). ``n_restarts``: the GP
    optimizer's restarts (None: :func:`colonsim.surrogate.gp.restarts_for` the number of runs)."""
    from colonsim.surrogate.model import SweepSurrogate

    table = table.sort_values("key").reset_index(drop=True)
    model = SweepSurrogate(targets=[target], cv="loo", random_state=seed, n_restarts=n_restarts).fit(table)
    cv = {}
    for segment in model.domains_:
        metrics = model.cv_[segment].get(target)
        cv[segment] = ({k: metrics[k] for k in METRICS} if metrics is not None else
                       {"no_model": model.skipped_[segment].get(target, "no model")})
    return model, cv


def _open_segments(cv, target_rmse) -> list:
    """Segments still above the target (all with a model when there is no target)."""
    return [s for s, m in cv.items() if "rmse" in m and (target_rmse is None or m["rmse"] > target_rmse)]


def choose_batch(design, model, target, segments, round_index, exclude, batch, criterion="variance"):
    """The next ``batch`` cases among the round's candidates of ``segments``, with their picks."""
    by_segment = {}
    for case in design.candidates(round_index, exclude):
        segment = model_segment(case.segment, case.centerline)  # a patient's file is a segment of its own
        if segment in segments:
            by_segment.setdefault(segment, []).append(case)
    groups, cases = [], []
    for segment, found in by_segment.items():
        domain, gp = model.model_for(segment, target)
        groups.append((gp, input_matrix(found, domain.inputs)))
        cases.append(found)
    picks = greedy_batch(groups, batch, criterion) if groups else []
    return [(cases[p.group][p.index], p) for p in picks]


def run_adaptive_sweep(spec, out, settings: AdaptiveSettings, workers=2, scheduler=None, runner=None,
                       retry_failed=False, progress=True, log=print, max_steps=DEFAULT_MAX_STEPS) -> AdaptiveReport:
    """Run an adaptive sweep of ``spec`` into ``out`` (resuming the rounds recorded there).

    ``workers``, ``scheduler``, ``runner``, ``retry_failed``, ``max_steps``: as for
    :func:`colonsim.insertion.study.sweep.run_sweep`. ``log`` gets one line per round.
    """
    design = AdaptiveDesign(spec)
    settings.check(len(design.first_round))
    out = check_output_folder(out)
    record = read_rounds(out, spec, settings)
    rounds = record["rounds"]
    if not rounds:
        rounds.append({"round": 0, "why": f"the sweep's Latin hypercube ([lhs] samples, seed {spec.seed}) crossed "
                                          "with its grid", "chosen": [_pick_record(design, c) for c in design.first_round]})
    cases = {r["key"]: _case(r) for rnd in rounds for r in rnd["chosen"]}
    ran, stopped = 0, ""
    # local workers kept across the rounds: spawned, and their kernels loaded, once
    with LocalPool(workers, warm_up=runner is None) if scheduler is None else contextlib.nullcontext() as pool:
        while True:
            sweep = run_sweep(list(cases.values()), out, workers=workers, scheduler=scheduler, runner=runner,
                              retry_failed=retry_failed, spec=_Document(spec, list(cases.values()), settings),
                              progress=progress, log=log, max_steps=max_steps, pool=pool)
            ran += sweep.ran
            retry_failed = False  # retried once, in the first call
            current = rounds[-1]
            try:
                model, cv = fit_round(sweep.table, settings.target, spec.seed)
            except ColonsimError as exc:
                raise ColonsimError(f"adaptive sweep, round {current['round']}: {exc}") from None
            current.update(cv=cv, runs=len(cases), ok=int((sweep.table["status"] == "ok").sum()),
                           finished_at=utc_now())
            save_figure(rounds_figure(record, settings.target_rmse), out / FIGURE, dpi=120)
            open_segments = _open_segments(cv, settings.target_rmse)
            log(f"round {current['round']}: {len(current['chosen'])} run(s), {len(cases)} in all; LOO RMSE "
                + ", ".join(f"{s} {m['rmse']:.3g}" if "rmse" in m else f"{s} no model" for s, m in cv.items()))
            if settings.target_rmse is not None and not open_segments and all("rmse" in m for m in cv.values()):
                stopped = "target reached"
            elif len(cases) >= settings.budget:
                stopped = "budget reached"
            if not stopped:
                picks = choose_batch(design, model, settings.target, open_segments, current["round"] + 1, cases,
                                     min(settings.batch, settings.budget - len(cases)), settings.criterion)
                if not picks:
                    stopped = "no candidate left (every segment without a model, or the candidates all run)"
            if stopped:
                record["stopped"] = {"reason": stopped, "runs": len(cases), "at": utc_now(),
                                     "target_rmse": settings.target_rmse, "budget": settings.budget}
                write_json(out / ROUNDS, record)
                break
            rounds.append({"round": current["round"] + 1, "why": WHY[settings.criterion],
                           "criterion": settings.criterion, "batch": settings.batch, "target_rmse": settings.target_rmse,
                           "chosen": [_pick_record(design, case, pick) for case, pick in picks]})
            record.pop("stopped", None)
            write_json(out / ROUNDS, record)  # the choice first: a sweep killed during the batch reruns the same batch
            cases.update((case.key(), case) for case, _ in picks)
    return AdaptiveReport(out, rounds, stopped, len(cases), ran, sweep.table)


def rounds_table(record) -> pd.DataFrame:
    """One row per round and segment: runs so far and the cross-validation metrics after the round."""
    rows = [{"round": rnd["round"], "runs": rnd.get("runs"), "segment": segment, **metrics}
            for rnd in record["rounds"] for segment, metrics in (rnd.get("cv") or {}).items()]
    return pd.DataFrame(rows)


def rounds_figure(record, target_rmse=None):
    """Leave-one-out RMSE of the target against runs, one line per segment, the target dashed."""
    from matplotlib.figure import Figure

    table = rounds_table(record)
    fig = Figure(figsize=(6.0, 4.0))
    ax = fig.subplots()
    for segment, rows in table.groupby("segment", sort=False):
        if "rmse" in rows:
            rows = rows.dropna(subset=["rmse"])
            ax.plot(rows["runs"], rows["rmse"], "o-", label=segment)
    if target_rmse is not None:
        ax.axhline(target_rmse, color="k", ls="--", lw=1, label=f"target {target_rmse:g}")
    ax.set_xlabel("runs")
    ax.set_ylabel(f"leave-one-out RMSE, {TARGET_LABELS.get(record['target'], record['target'])}")
    criteria = sorted({r["criterion"] for r in record["rounds"] if "criterion" in r})
    ax.set_title(f"adaptive sweep {record['sweep']} (criterion: {', '.join(criteria) or 'none yet'})", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    return fig


__all__ = ["AdaptiveReport", "AdaptiveSettings", "FIGURE", "ROUNDS", "choose_batch", "fit_round", "read_rounds",
           "rounds_figure", "rounds_table", "run_adaptive_sweep"]
