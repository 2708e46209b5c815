"""The shipped predictor on its held-out runs: per patient model, the table the predictor is judged by.

For the largest and the final deformation of each patient model (RSJ, RSF, THF): the held-out
runs scored, the coverage of the nominal 95 % and 50 % intervals against their bands (88-99 %,
38-62 %), and the RMSE beside the output's spread (sd of the held-out values) and the runs' own
scatter (from the replicate runs, ``--replicates``: cases run at two wall meshes; else the noise
floor the model was fitted with; else not measured). Tip-folded and failed held-out runs are left out and counted.

    python benchmarks/bench_predictor.py                       # the shipped model, the committed records
    python benchmarks/bench_predictor.py --json benchmarks/records/predictor_heldout.json   # the committed table
    python benchmarks/bench_predictor.py --model MODEL.json --heldout /work/runs/patient_space_rsj_heldout ...

Default tables: the committed records ``benchmarks/records/patient_space_{rsj,rsf,thf}_heldout``, ``..._heldout2``
(two independent held-out hypercubes, 30 and 70 runs) and ``..._replicates`` (``results.parquet``).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import binom, binomtest

from colonsim.errors import ColonsimError
from colonsim.surrogate.domain import OutOfDomainWarning
from colonsim.surrogate.holdout import score
from colonsim.surrogate.model import TIP_FOLDED
from colonsim.surrogate.predictor import load_shipped
from colonsim.surrogate.replicates import replicate_scatter
from colonsim.surrogate.store import load_surrogate
from colonsim.surrogate.table import numeric_column, read_results, successful_runs

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_heldout import BANDS, TARGETS  # noqa: E402  (the acceptance bands and the outputs judged)

RECORDS = Path(__file__).resolve().parent / "records"
MODELS = ("rsj", "rsf", "thf")
# the committed table of the shipped predictor on its held-out runs (written with --json; its test
# checks that the shipped model reproduces it)
RECORD = RECORDS / "predictor_heldout.json"


def records_of(part) -> list:
    """The committed records of the patient-space sweeps' ``part`` that exist: "heldout" (each
    model's held-out hypercubes, ``_heldout`` and ``_heldout2``) or "replicates"."""
    return [p for m in MODELS for p in sorted(RECORDS.glob(f"patient_space_{m}_{part}*/results.parquet"))]


def table_of(paths, what) -> pd.DataFrame:
    """The runs of ``paths`` (results tables or sweep folders) in one table."""
    tables = [read_results(Path(p) / "results.parquet" if Path(p).is_dir() else p) for p in paths]
    if not tables:
        raise ColonsimError(f"no {what} table: give --{what}, or commit the patient_space_*_{what} records")
    return pd.concat(tables, ignore_index=True)


def _scatter(model, runs, replicates, segment, target):
    """The runs' own scatter sd of ``target``, and where it comes from."""
    domain = model.domains_[segment]
    if replicates is not None:
        found = replicate_scatter(runs, replicates, segment, [*domain.inputs, *domain.fixed], target)
        if found:
            return found["sd"], f"{found['pairs']} replicate pairs"
    fitted = model.scatter_.get(segment, {}).get(target)
    if fitted:
        return fitted["sd"], f"the model's floor ({fitted['pairs']} pairs)"
    return math.nan, "not measured"


def _within(value, band) -> bool:
    return band[0] <= value <= band[1]


def pass_chance(n, nominal, band) -> float:
    """The probability that exact ``nominal`` intervals cover a share of ``n`` independent held-out
    runs inside ``band``: what the band asks of a perfect predictor (30 runs: 0.72 for 95 % within
    88-99 %, 0.80 for 50 % within 38-62 %)."""
    return float(sum(binom.pmf(k, n, nominal) for k in range(n + 1) if band[0] <= k / n <= band[1]))


def chance(coverage, n, nominal) -> float:
    """Two-sided binomial probability of a coverage at least as far from ``nominal`` as ``coverage``
    of ``n`` runs, were the intervals exact and the runs independent: with 30 held-out runs a
    calibrated 95 % interval covers all 30 one time in five (0.95^30), which the band 88-99 %
    counts as failing."""
    return float(binomtest(int(round(coverage * n)), n, nominal).pvalue) if n else math.nan


def predictor_table(model, table: pd.DataFrame, replicates=None, targets=TARGETS) -> list:
    """One row per patient model and output: coverage, verdicts, RMSE, spread and scatter."""
    ended = table["ended_by"].astype(str) if "ended_by" in table else pd.Series("", index=table.index)
    folded = (table["status"] == "ok") & (ended == TIP_FOLDED)
    kept = table[~folded].reset_index(drop=True)
    rows = []
    for segment in model.domains_:
        runs = successful_runs(kept, segment)
        if runs.empty:
            continue
        failed = int(((table["segment"] == segment) & (table["status"] != "ok")).sum())
        for target in targets:
            if target not in model.models_[segment] or target not in runs:
                continue
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", OutOfDomainWarning)
                s = score(model, kept, target, segment, name="held-out runs")
            y = numeric_column(runs, target).to_numpy(dtype=float)
            scatter, source = _scatter(model, runs, replicates, segment, target)
            c95, c50 = s["coverage"]["95"], s["coverage"]["50"]
            rows.append({"model": segment, "output": target, "runs": s["n"], "n_train": s["n_train"],
                         "tip_folded_left_out": int(((table["segment"] == segment) & folded).sum()),
                         "failed_left_out": failed, "outside_box": s["outside_box"],
                         "coverage_95": c95, "coverage_95_ok": _within(c95, BANDS["c95"]),
                         "coverage_95_chance": chance(c95, s["n"], 0.95),
                         "coverage_50": c50, "coverage_50_ok": _within(c50, BANDS["c50"]),
                         "coverage_50_chance": chance(c50, s["n"], 0.50),
                         "rmse": s["rmse"], "spread_sd": float(np.std(y[np.isfinite(y)])),
                         "scatter_sd": scatter, "scatter_from": source})
    if not rows:
        raise ColonsimError(f"the held-out runs hold no successful run of the model's segments ({', '.join(model.domains_)})")
    return rows


def format_table(rows) -> str:
    """The rows as a Markdown table, with the bands in its header."""
    (lo95, hi95), (lo50, hi50) = BANDS["c95"], BANDS["c50"]
    lines = [f"| model | output | held-out runs | 95 % covered ({100 * lo95:.0f}-{100 * hi95:.0f}) | "
             f"50 % covered ({100 * lo50:.0f}-{100 * hi50:.0f}) | RMSE (cm) | spread sd (cm) | scatter sd (cm) |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        def verdict(ok):
            return "" if ok else " FAILS"
        scatter = "-" if math.isnan(r["scatter_sd"]) else f"{r['scatter_sd']:.3g}"
        left = [f"{r[k]} {what}" for k, what in (("tip_folded_left_out", "tip-folded"), ("failed_left_out", "failed"))
                if r[k]]
        runs = f"{r['runs']}" + (f" ({', '.join(left)} left out)" if left else "")
        lines.append(f"| {r['model'].upper()} | {r['output']} | {runs} | "
                     f"{100 * r['coverage_95']:.0f} %{verdict(r['coverage_95_ok'])} (p {r['coverage_95_chance']:.2g}) | "
                     f"{100 * r['coverage_50']:.0f} %{verdict(r['coverage_50_ok'])} (p {r['coverage_50_chance']:.2g}) | "
                     f"{r['rmse']:.3g} | {r['spread_sd']:.3g} | {scatter} ({r['scatter_from']}) |")
    lines.append("\np: the chance of a coverage at least this far from the nominal one were the intervals exact "
                 "(two-sided binomial, runs independent); a verdict with p above 0.05 may be chance.")
    for n in sorted({r["runs"] for r in rows}):
        both = pass_chance(n, 0.95, BANDS["c95"]) * pass_chance(n, 0.50, BANDS["c50"])
        lines.append(f"With {n} held-out runs exact intervals pass both bands with probability {both:.2f}; "
                     f"all {len(rows)} rows with {both ** len(rows):.2f}.")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", type=Path, help="MODEL.json (default: the predictor shipped with colonsim)")
    parser.add_argument("--heldout", type=Path, nargs="+", help="held-out results tables or sweep folders")
    parser.add_argument("--replicates", type=Path, nargs="+",
                        help="replicate runs (cases at two wall meshes; default: the committed patient_space_*_replicates)")
    parser.add_argument("--json", type=Path, help="write the rows to this JSON file")
    args = parser.parse_args(argv)
    try:
        model = load_shipped() if args.model is None else load_surrogate(args.model)
        table = table_of(args.heldout or records_of("heldout"), "heldout")
        paths = args.replicates or records_of("replicates")
        replicates = table_of(paths, "replicates") if paths else None
        rows = predictor_table(model, table, replicates)
    except ColonsimError as exc:
        print(f"bench_predictor: {exc}", file=sys.stderr)
        return 2
    print(format_table(rows))
    if args.json:
        args.json.write_text(json.dumps({"rows": rows}, indent=2), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
