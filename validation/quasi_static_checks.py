"""The quasi-static checks (docs/quasi_static.md) on sweeps: one line per criterion with its verdict
and the numbers behind it, then the report's tables of the mesh pair, the rate check and the
smoothness checks.

On the committed sweep records (unpacked into a temporary folder, read only)::

    python -m validation.quasi_static_checks --records                 # the report's sweeps
    python -m validation.quasi_static_checks --records --set global    # the same cases before the estimate's contact floor

On sweep folders of your own, for a setting the records do not hold::

    export NUMBA_NUM_THREADS=1
    colonsim sweep benchmarks/sweeps/checks_global_base.toml --out BASE
    colonsim sweep benchmarks/sweeps/checks_global_variants.toml --out VARIANTS
    python -m validation.quasi_static_checks --base BASE --variants VARIANTS [--smoothness S] \\
        [--gp-train T --gp-test H [--replicates R]] [--ringing SWEEP ...]

A variant pairs with the base run it differs from in its push speed or wall mesh alone. Rows of
sweeps made before today's rules are read with them applied where their time series allow
(column ``rules``). Exit 0 whatever the verdicts (they are printed); 2 when a folder is missing.
"""

import argparse
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

from . import smoothness
from .sweep_records import RECORDS, unpack
from .markdown_checks import mesh_pair, rate_check
from .markdown_checks import smoothness as smoothness_section
from .report import pair_section, rate_section
from .sections import ringing_rows
from .sweeps import TABLE, read_sweep

from colonsim.catalog import TIP_FOLDED
from colonsim.insertion.case.insertion_case import InsertionCase

# the records each set reads, by role: the report's sweeps, and the same cases at the global estimate
# before its contact floor (the replicates, the runs' own scatter, are the report's in both)
SETS = {"report": {"base": "thesis", "variants": "validation", "smoothness": "smoothness", "gp_train": "gp_train",
                   "gp_test": "gp_test", "replicates": "gp_replicates", "ringing": ("thesis", "validation", "resistance")},
        "global": {"base": "checks_global_base", "variants": "checks_global_variants",
                   "smoothness": "smoothness_global", "gp_train": "gp_train_global", "gp_test": "gp_test_global",
                   "replicates": "gp_replicates", "ringing": ("checks_global_base", "checks_global_variants")}}
FOLDERS = ("base", "variants", "smoothness", "gp_train", "gp_test", "replicates")


def _missing(args):
    """The first given folder without a results table, or why the folders given do not make a check."""
    for name in FOLDERS:
        folder = getattr(args, name)
        if folder is not None and not (Path(folder) / TABLE).is_file():
            return (f"no {TABLE} in {folder}; run `colonsim sweep SWEEP.toml --out {folder}` first "
                    "(python -m validation.quasi_static_checks --help)")
    pairs = (args.base, args.variants), (args.gp_train, args.gp_test)
    if any((a is None) != (b is None) for a, b in pairs):
        return "give --base with --variants and --gp-train with --gp-test"
    if all(getattr(args, name) is None for name in FOLDERS) and not args.ringing:
        return "give --records, or the sweeps to check: --base and --variants, --smoothness, --gp-train and --gp-test"
    return None


def _verdict(ok):
    return "PASS" if ok else "FAIL"


def ringing_line(label, sweep) -> list:
    """The ringing criterion on one sweep: its verdict line and one line per failing run with its cause."""
    rows = ringing_rows(sweep)
    if not rows["ran"]:
        return [f"ringing ({label}): not run"]
    failing = [r for r in rows["rows"] if not r["quasi_static"]]
    snapped = [r for r in rows["rows"] if (r["snap_throughs"] or 0) > 0]
    folded = int((sweep.table.get("ended_by") == TIP_FOLDED).sum())
    lines = [f"ringing ({label}): {_verdict(not failing)}: {rows['passed']} of {rows['runs']} runs quasi-static "
             f"(largest ratio {rows['largest']:.3f}, median {rows['median']:.3f}); {len(snapped)} with snap-throughs "
             f"(left out {max((r['left_out_share'] or 0 for r in snapped), default=0):.0%} at most); "
             f"{folded} ended {TIP_FOLDED}; rules {sweep.describe()['rules']}"]
    lines += [f"    fails: {r['segment'].upper()} {r['scope']} {r['inputs']}: {r['cause']}" for r in failing]
    return lines


def pair_line(name, section) -> str:
    rows = section["rows"]
    judged = [r for r in rows if r["passed"] is not None]
    unjudged = sorted({q["quantity"] for r in rows for q in r["quantities"] if q.get("why")})
    fails = [f"{r['segment'].upper()} {r['scope']} {r['inputs']}: "
             + ", ".join(f"{q['quantity']} {q['base']} / {q['variant']}" if q["quantity"] == "snap-throughs" else
                         f"{q['quantity']} {q['change']:+.1%}" for q in r["quantities"] if q["passed"] is False)
             for r in judged if not r["passed"]]
    return (f"{name}: {_verdict(all(r['passed'] for r in judged) and judged)}: {sum(r['passed'] for r in judged)} of "
            f"{len(rows)} pairs pass, {len(rows) - len(judged)} not judged; left unjudged by rule: "
            f"{', '.join(unjudged) or 'nothing'}" + "".join(f"\n    fails: {f}" for f in fails))


def smoothness_lines(section) -> list:
    lines = []
    for key, name in (("cubic", "smooth against scope diameter"), ("surrogate", "surrogate held-out error")):
        part = section[key]
        if not part["ran"]:
            lines.append(f"{name}: not run")
            continue
        judged = [r for r in part["rows"] if r["passed"] is not None]
        cells = []
        for r in part["rows"]:
            value = r["departure_cm"] if key == "cubic" else r["rmse"]
            cells.append(f"{r['output']} {value:.3g} vs bound {r.get('bound', np.nan):.3g} "
                         f"({'pass' if r['passed'] else 'FAIL' if r['passed'] is False else '-'})")
        lines.append(f"{name}: {_verdict(all(r['passed'] for r in judged) and judged)}: "
                     f"{sum(r['passed'] for r in judged)} of {len(judged)}: " + "; ".join(cells))
    scatter = section.get("scatter") or {}
    lines.append("runs' own scatter (replicates): " + ("; ".join(
        f"{k} {v['scatter']:.3g} ({v['pairs']} pairs)" for k, v in sorted(scatter.items())) or "not measured"))
    return lines


def time_step_line(sweeps) -> str:
    counts = {}
    for sweep in sweeps:
        for estimate, n in sweep.describe()["time_step_estimate"].items():
            counts[estimate] = counts.get(estimate, 0) + n
    return (f"time step: the default estimate is {InsertionCase().time_step_estimate!r}; the runs read here were made "
            f"with {', '.join(f'{k} ({v})' for k, v in sorted(counts.items())) or 'none'}")


def check(folders, ringing=(), figures=None) -> list:
    """Every criterion on the sweeps in ``folders`` (role -> folder or None) and ``ringing``
    [(label, folder)]: the summary lines, then the report's tables."""
    lines, tables, read = [], [], []
    for label, folder in ringing:
        sweep = read_sweep(label, folder)
        read.append(sweep)
        lines += ringing_line(label, sweep)
    if folders.get("base"):
        base, variants = read_sweep("main", folders["base"]), read_sweep("validation", folders["variants"])
        read += [base, variants]
        mesh, rate = pair_section(variants, base, "mesh"), rate_section(variants, base)
        lines += [pair_line("mesh (3 vs 2 mm)", mesh), pair_line("rate (half the push speed)", rate)]
        tables += mesh_pair(mesh) + rate_check(rate)
    if folders.get("smoothness") or folders.get("gp_train"):
        smooth, train, test, replicates = (read_sweep(label, folders.get(label), optional=True)
                                           for label in ("smoothness", "gp_train", "gp_test", "replicates"))
        figure = Path(figures or folders.get("smoothness") or ".") / "smoothness.png"
        figure.parent.mkdir(parents=True, exist_ok=True)
        section = smoothness.section(smooth, train, test, figure, str(figure), replicates)
        lines += smoothness_lines(section)
        tables += smoothness_section(section)
    lines.append(time_step_line(read))
    return lines + [""] + tables


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--records", nargs="?", const=str(RECORDS), default=None,
                        help=f"check the committed sweep records (default folder {RECORDS.relative_to(Path.cwd()) if RECORDS.is_relative_to(Path.cwd()) else RECORDS})")
    parser.add_argument("--set", choices=tuple(SETS), default="report",
                        help="with --records: the report's sweeps, or the same cases at the global estimate before its contact floor")
    parser.add_argument("--base", help="sweep of base runs (default settings otherwise)")
    parser.add_argument("--variants", help="sweep of their variants: half the push speed, 2 mm wall triangles")
    parser.add_argument("--smoothness", help="sweep of RSJ D36 mu 0 over scope diameters")
    parser.add_argument("--gp-train", help="sweep the surrogate is fitted on")
    parser.add_argument("--gp-test", help="held-out sweep it predicts")
    parser.add_argument("--replicates", help="replicates of --gp-train runs on a 7 %% finer wall mesh (the scatter)")
    parser.add_argument("--ringing", nargs="*", default=[], help="further sweeps whose runs' ringing is judged")
    parser.add_argument("--figures", help="folder for the smoothness figure (default: the smoothness folder)")
    args = parser.parse_args(argv)
    # the held-out runs reach a little beyond the training runs' hull: the surrogate says so per query
    warnings.filterwarnings("ignore", message=".*outside the training domain.*")
    if args.records is None:
        why = _missing(args)
        if why:
            print(f"error: {why}", file=sys.stderr)
            return 2
        folders = {name: getattr(args, name) for name in FOLDERS}
        ringing = [(Path(f).name, f) for f in args.ringing]
        print("\n".join(check(folders, ringing, args.figures)))
        return 0
    chosen = SETS[args.set]
    names = {*(v for k, v in chosen.items() if k != "ringing"), *chosen["ringing"]}
    absent = sorted(n for n in names if not (Path(args.records) / n / TABLE).is_file())
    if absent:
        print(f"error: no record {', '.join(absent)} in {args.records}; give the records folder "
              "(benchmarks/records)", file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory(prefix="colonsim-records-") as tmp:
        for name in sorted(names):
            unpack(Path(args.records) / name, Path(tmp) / name)
        folders = {k: Path(tmp) / v for k, v in chosen.items() if k != "ringing"}
        ringing = [(n, Path(tmp) / n) for n in chosen["ringing"]]
        print(f"records: {args.records} (set {args.set})\n")
        print("\n".join(check(folders, ringing, args.figures or tmp)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
