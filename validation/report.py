"""Validation report: solver verification, calibration recovery, and the colon models against the
source (docs/model.md, "Reference results") on a main sweep and a validation sweep, as Markdown
with figures and a JSON of the same numbers.

Run (from the repository root, one Numba thread is enough)::

    python -m validation.report --sweep colonsim_results/sweep_thesis \\
        --validation-sweep colonsim_results/sweep_validation --size full

The main sweep is the ``thesis`` preset (the source's insertions with its meshed scope diameters),
the validation sweep the ``validation`` preset (mesh pair, half-speed rate check, flexure turns of
135 and 180 deg). Writes ``OUT/report.md``, ``OUT/report.json`` and ``OUT/figures/*.png``
(``--out``, default ``docs/validation``). ``--size reduced`` runs the verification problems at the
sizes of the CI tests and the calibration with the pipeline's quick budget; ``--size full`` at
the full sizes of the tests and the default budget. The sweeps are only read: runs missing from a
table are reported as missing, the claims that need them as NOT EVALUATED, and the sections of a
validation sweep that has not run as NOT RUN. ``--markdown-only`` writes ``OUT/report.md`` again
from ``OUT/report.json`` (after a change of the page's layout), reading no sweep.

The page names no commit and no folder outside the repository (``report.json`` keeps both; a test
scans the site's pages for them).
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import shlex
import sys
import time
from pathlib import Path

import numpy as np


from colonsim.errors import ColonsimError
from colonsim.files import write_json
from colonsim.provenance import code_version
from colonsim.insertion.case.insertion_case import InsertionCase
from colonsim.insertion.study.sweep_presets import HALF_SPEED
from colonsim.insertion.case.ringing import RINGING_LIMIT
from colonsim.insertion.study.claims import evaluate_claims

from . import carry
from . import changes
from . import checks
from . import figures
from . import sections
from . import resistance
from . import smoothness
from .markdown import write_markdown
from .readings import add_readings
from .sweeps import paired, read_sweep

SYMBOL = {"rsf": "alpha", "thf": "beta"}


def header(args, argv, started, sweeps):
    """The report's provenance: the page shows it without commits or machine paths
    (validation/markdown.py), report.json keeps it whole."""
    # taken when the script started (code_version caches it), before it rewrote its own outputs
    recorded = code_version()["git_commit"] or "unknown (not a git checkout)"
    commit, dirty = recorded.removesuffix("+modified"), recorded.endswith("+modified")
    threads = os.environ.get("NUMBA_NUM_THREADS")
    command = ("NUMBA_NUM_THREADS=" + threads + " " if threads else "") + " ".join(
        ["python -m validation.report", *(shlex.quote(a) for a in argv)])
    return {"date": started.isoformat(timespec="seconds"), "commit": commit,
            "commit_note": "uncommitted changes in tracked files" if dirty else "clean tree",
            "machine": f"{platform.system()} {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
            "command": command, "size": args.size,
            "sweeps": {label: sweep.describe() for label, sweep in sweeps.items()}}


def shape_figure(entries, path, title, out):
    """Final shapes of ``entries`` [(case, sweep)], one panel per (model, angle, flexure); None if
    no run finished."""
    panels = {}
    for case, sweep in entries:
        row, status = sweep.run(case)
        if row is not None:
            key = (case.segment, case.angle_deg, case.flexure_angle_deg)
            panels.setdefault(key, []).append((case, sweep.run_folder(row)))
    if not panels:
        return None
    ordered = [(f"{seg.upper()} {SYMBOL.get(seg, 'angle')} = {a:g} deg, flexure {f:g} deg", runs)
               for (seg, a, f), runs in sorted(panels.items())]
    drawn, missing = figures.final_shapes(ordered, out / path, title)
    return {"file": path, "title": title, "runs": drawn, "without_final_shape": missing}


def flexure_models(main, out):
    rows = sections.flexure_model_runs(main)
    figs = []
    for segment in ("rsf", "thf"):
        entries = [(r["_case"], main) for r in rows if r["segment"] == segment]
        fig = shape_figure(entries, f"figures/{segment}_shapes.png",
                           f"{segment.upper()}, main sweep: final shapes per angle", out)
        figs += [fig] if fig else []
    case = InsertionCase()
    return {"rows": sections.public(rows), "figures": figs, "relax_s": case.relax_s, "relax_max_s": case.relax_max_s}


def resistance_section(sweep, half, out):
    """The distal resistance section, with the final shapes at one level per RSF/THF angle; ``half``:
    its runs above the ringing limit at half the push speed (the proposed bound)."""
    section = resistance.resistance_section(sweep, half)
    if section["ran"]:
        speed = InsertionCase().push_speed
        for segment in ("rsf", "thf"):
            level = resistance.SHAPES_LEVEL_N
            entries = [(c, sweep) for c in sweep.cases if c.segment == segment and c.distal_resistance_N == level
                       and math.isclose(c.push_speed, speed)]
            fig = shape_figure(entries, f"figures/{segment}_shapes_{level:g}N.png",
                               f"{segment.upper()}, {level:g} N distal resistance: final shapes per angle", out)
            section["figures"] += [fig] if fig else []
    return section


NOT_RUN_HOW = {"validation": ("--validation-sweep", "colonsim sweep --preset validation"),
               "rate_angles": ("--rate-angles-sweep", "colonsim sweep benchmarks/sweeps/rate_angles.toml")}


def not_run_note(sweep):
    option, command = NOT_RUN_HOW[sweep.label]
    if sweep.folder is None:
        return f"no {option} given; run `{command} --out DIR` and pass {option} DIR."
    return f"no results table in `{sweep.folder}`; run `{command} --out {sweep.folder}`."


def pair_section(validation, main, check):
    if not validation.ran:
        return {"ran": False, "note": not_run_note(validation), "rows": [], "summary": ""}
    rows = sections.pair_rows(validation, main, check)
    judged = [r["passed"] for r in rows if r["passed"] is not None]
    summary = (f"{sum(judged)} of {len(rows)} pairs pass, {len(judged) - sum(judged)} fail, "
               f"{len(rows) - len(judged)} not judged (a run missing, or nothing measurable).")
    return {"ran": True, "rows": rows, "summary": summary}


def rate_section(validation, main, angles=None):
    """The rate check's section: its pairs (:func:`pair_section`), the two push speeds and the held
    push's share and lead; with ``angles`` (a sweep of further half-speed runs), their pairs too."""
    section = {**pair_section(validation, main, "rate"), "speeds": (InsertionCase().push_speed, HALF_SPEED),
               "held_share": InsertionCase().held_push_share, "held_lead_mm": InsertionCase().held_push_lead_mm}
    if angles is not None:
        section["angles"] = pair_section(angles, main, "rate")
    return section


def flexure_section(validation, main, out):
    angles = sorted({v.angle_deg for kind, _, v, _ in paired(validation, main) if kind == "flexure"})
    if not validation.ran:
        return {"ran": False, "note": not_run_note(validation), "angles_deg": angles, "rows": [], "figures": []}
    entries, seen = [], set()
    for kind, _, variant, base in paired(validation, main):
        if kind != "flexure":
            continue
        for case, sweep in ((variant, validation), (base, main)):
            if case is not None and case.key() not in seen:
                seen.add(case.key())
                entries.append((case, sweep))
    figs = []
    for segment in ("rsf", "thf"):
        fig = shape_figure([e for e in entries if e[0].segment == segment], f"figures/{segment}_flexure_shapes.png",
                           f"{segment.upper()}: final shapes at flexure turns of 90 / 135 / 180 deg", out)
        figs += [fig] if fig else []
    return {"ran": True, "angles_deg": angles, "rows": sections.flexure_sensitivity(validation, main), "figures": figs}


def read_previous(path):
    """The previous report's document, for the section on what moved."""
    try:
        return json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise ColonsimError(f"--previous {path}: cannot read it as a report.json ({type(exc).__name__}); copy the "
                            "landed one aside first: git show HEAD:docs/validation/report.json > previous.json") from None


def _clean(value):
    """NaN/inf -> None so the JSON is strict."""
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if isinstance(value, (np.floating, float)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, np.generic):
        return value.item()
    return value


def rewrite_markdown(out) -> int:
    """Write ``out/report.md`` again from ``out/report.json``; 2 when there is no report there."""
    source = Path(out) / "report.json"
    if not source.is_file():
        print(f"error: no report.json in {out}; give the folder of a report with --out (default docs/validation)",
              file=sys.stderr)
        return 2
    write_markdown(json.loads(source.read_text(encoding="utf-8")), Path(out) / "report.md")
    print(f"wrote {Path(out) / 'report.md'} from {source}")
    return 0


def main(argv=None):
    code_version()  # the commit and whether the tree is clean, before anything is written
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sweep", type=Path, default=Path("colonsim_results/sweep_thesis"),
                        help="main sweep folder (the thesis preset) with results.parquet and runs/<key>/ "
                             "(default colonsim_results/sweep_thesis)")
    parser.add_argument("--validation-sweep", type=Path, default=None,
                        help="validation sweep folder (the validation preset); its sections say NOT RUN without it")
    for name, what in (("smoothness", "the smoothness sweep (benchmarks/sweeps/smoothness.toml)"),
                       ("gp-train", "the surrogate's training sweep (benchmarks/sweeps/gp_train.toml)"),
                       ("gp-test", "the surrogate's held-out sweep (benchmarks/sweeps/gp_test.toml)"),
                       ("rate-angles", "the rate check at the other angles (benchmarks/sweeps/rate_angles.toml)"),
                       ("replicates", "the replicates that measure the runs' own scatter "
                                      "(benchmarks/sweeps/gp_replicates.toml)"),
                       ("resistance", "the distal resistance sweep (colonsim sweep --preset resistance)"),
                       ("ringing-half", "the resistance runs above the ringing limit at half the push speed "
                                        "(benchmarks/sweeps/ringing_half_speed.toml)")):
        parser.add_argument(f"--{name}-sweep", type=Path, default=None,
                            help=f"folder of {what}; its section says NOT RUN without it")
    parser.add_argument("--previous", type=Path, default=None,
                        help="the previous report's report.json (a copy: the new report replaces it); adds the "
                             "section on what moved since, which says NOT RUN without it")
    parser.add_argument("--carry", action="store_true",
                        help="take every section whose sweep is not given from --previous, marked with the report "
                             "and code it comes from, instead of saying NOT RUN (validation/carry.py)")
    parser.add_argument("--out", type=Path, default=Path("docs/validation"), help="output folder (default docs/validation)")
    parser.add_argument("--size", choices=("reduced", "full"), default="reduced",
                        help="verification at the CI test sizes and quick calibration budget, or at full size")
    parser.add_argument("--markdown-only", action="store_true",
                        help="rewrite OUT/report.md from OUT/report.json after a change of the page's layout: no "
                             "sweep is read and nothing is recomputed")
    args = parser.parse_args(argv)
    if args.markdown_only:
        return rewrite_markdown(args.out)
    started = datetime.datetime.now(datetime.timezone.utc)
    t0 = time.perf_counter()
    try:
        if args.carry and args.previous is None:
            raise ColonsimError("--carry takes the sections of the sweeps not given from the previous report: "
                                "give it with --previous OLD/report.json")
        main_sweep = read_sweep("main", args.sweep)
        validation = read_sweep("validation", args.validation_sweep, preset="validation")
        smooth, gp_train, gp_test, resisted, angles, ringing_half, replicates = (
            read_sweep(label, folder, optional=True) for label, folder in (
                ("smoothness", args.smoothness_sweep), ("gp_train", args.gp_train_sweep),
                ("gp_test", args.gp_test_sweep), ("resistance", args.resistance_sweep),
                ("rate_angles", args.rate_angles_sweep), ("ringing_half", args.ringing_half_sweep),
                ("replicates", args.replicates_sweep)))
        previous = None if args.previous is None else read_previous(args.previous)
    except ColonsimError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    out = args.out
    (out / "figures").mkdir(parents=True, exist_ok=True)
    full = args.size == "full"
    figs = {}

    print("verification ...", flush=True)
    t = time.perf_counter()
    verification = checks.verify(full, figs, out)
    t_verification = time.perf_counter() - t
    print(f"  {sum(r['passed'] for r in verification)}/{len(verification)} pass, {t_verification:.0f} s", flush=True)
    print("calibration recovery ...", flush=True)
    t = time.perf_counter()
    calibration = checks.calibration_recovery(full, out)
    t_calibration = time.perf_counter() - t
    print(f"  {t_calibration:.0f} s", flush=True)

    print("sweeps ...", flush=True)
    rsj_rows, curves = sections.rsj_comparison(main_sweep)
    figures.rsj_deformation(curves, out / "figures" / "rsj_deformation.png")
    figs["rsj_deformation"] = {"file": "figures/rsj_deformation.png"}
    sensitivity = flexure_section(validation, main_sweep, out)
    described = {"main": main_sweep, "validation": validation, "smoothness": smooth, "gp_train": gp_train,
                 "gp_test": gp_test, "resistance": resisted, "rate_angles": angles, "ringing_half": ringing_half,
                 "replicates": replicates}
    flexure_source = "section 10"
    if args.carry and args.validation_sweep is None:  # the claims' readings cite the flexure turns (section 10)
        carried = carry.carried_section(previous, "validation", ("flexure_sensitivity",))
        if carried is not None:
            sensitivity = carried
            flexure_source = f"section 10, carried from the report of {carried['carried_from']['date']}"
    claims = add_readings([c.to_dict() for c in evaluate_claims(main_sweep.table)], main_sweep, sensitivity["rows"],
                          flexure_source)
    times = sections.run_times(main_sweep)
    doc = {"header": header(args, sys.argv[1:] if argv is None else argv, started, described), "verification": verification,
           "calibration": calibration, "rsj": {"rows": rsj_rows, "checks": sections.rsj_checks(rsj_rows)},
           "claims": claims, "flexure_models": flexure_models(main_sweep, out),
           "ringing": {"limit": RINGING_LIMIT, "sweeps": {"main": sections.ringing_rows(main_sweep),
                                                          "validation": sections.ringing_rows(validation)}},
           "mesh_pair": pair_section(validation, main_sweep, "mesh"),
           "rate_check": rate_section(validation, main_sweep, angles),
           "smoothness": smoothness.section(smooth, gp_train, gp_test, out / "figures" / "smoothness.png",
                                            "figures/smoothness.png", replicates),
           "flexure_sensitivity": sensitivity,
           "resistance": resistance_section(resisted, ringing_half, out),
           "node_counts": sections.node_counts(),
           "run_ends": {"main": sections.run_ends(main_sweep), "validation": sections.run_ends(validation)},
           "run_times": {"rows": times, "summary": sections.run_time_summary(times)}, "figures": figs}
    doc["timings"] = {"verification_s": t_verification, "calibration_s": t_calibration,
                      "total_s": time.perf_counter() - t0}
    doc = _clean(doc)
    if args.carry:
        doc["header"]["carried"] = carry.carry(
            doc, previous, {label: sweep.folder is not None for label, sweep in described.items()})
    doc["changes"] = changes.changes(previous, doc)  # both documents as JSON holds them (NaN -> null)
    write_json(out / "report.json", doc)
    write_markdown(doc, out / "report.md")
    for cl in claims:
        print(f"{cl['verdict']:>15}  {cl['name']}")
    for name, ends in doc["run_ends"].items():
        print(f"{name} sweep: {ends['counts']} (jams: {ends['jams']})")
    print(f"wrote {out / 'report.md'} ({doc['timings']['total_s']:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
