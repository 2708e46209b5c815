"""Command line of the surrogate: ``colonsim surrogate fit|plot|info|validate``, ``colonsim predict``,
``colonsim recommend`` (docs/surrogate.md).

Patient presets (--sex, --age, --region) and raw parameters (--angle, --friction, --diameter, ...)
can be mixed; a raw parameter wins over the preset that would set the same input.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from colonsim import catalog, options
from colonsim.cli_queries import (format_predictions, load_model, patient_query, presets_of, query_frame, records,
                                  segment_of as _segment)
from colonsim.errors import ColonsimError
from colonsim.options import bounded_int, finite_float, output_file, seed, worker_count

VS_NAMES = {"scope": "scope_diameter_mm", "scope-diameter": "scope_diameter_mm", "diameter": "diameter_mm",
            "angle": "angle_deg", "friction": "friction", "wall-thickness": "wall_thickness_mm",
            "wall-mu0": catalog.WALL_MU0, "wall-c11": catalog.WALL_C11, "distal-resistance": "distal_resistance_N",
            "stiffness": catalog.TISSUE_STIFFNESS}
MATERIAL_HELP = ("calibration file of the tissue distribution predictions average over: a material.json (its "
                 "posterior; a model over the tissue stiffness maps it to the stiffness factor) or a population.json "
                 "(its specimens); default: the one the sweep sampled, the reference wall for the shipped predictor")
MODEL_HELP = ("MODEL.json written by 'colonsim surrogate fit' (default: the predictor shipped with colonsim, which "
              "refuses a query outside its training domain unless --extrapolate)")


def _cv(text):
    if text.lower() == "loo":
        return "loo"
    try:
        k = int(text)
        if k < 2:
            raise ValueError
    except ValueError:
        raise argparse.ArgumentTypeError(f"--cv takes 'loo' or a number of folds >= 2, got {text!r}")
    return k


def _patient_options(p, scope_diameter=True):
    g = p.add_argument_group("patient: presets (docs/surrogate.md) and raw parameters (raw ones win)")
    g.add_argument("--segment", help=options.segment_help())
    g.add_argument("--scope", nargs="+", help=f"{options.scope_help()} (default: the scopes of the sweep)")
    g.add_argument("--sex", help="male (0 deg), intermediate (30 deg), female (45 deg): alpha in RSF, beta in THF")
    g.add_argument("--age", help="young (mu 0), middle (0.05), older (0.1, diverticular disease)")
    g.add_argument("--region", help="european (23 mm), african (36 mm): colon diameter in RSJ")
    g.add_argument("--presets", type=Path, help="JSON file overriding the preset tables")
    if scope_diameter:
        g.add_argument("--scope-diameter", type=finite_float, help="scope outer diameter, mm (instead of --scope)")
    g.add_argument("--diameter", type=finite_float, help="colon inner diameter, mm")
    g.add_argument("--angle", type=finite_float, help=f"degrees: {options.angle_help()}")
    g.add_argument("--friction", type=finite_float, help="Coulomb friction scope/wall")
    g.add_argument("--wall-thickness", type=finite_float, help="colon wall thickness, mm")
    g.add_argument("--distal-resistance", type=finite_float,
                   help="force the colon beyond the model opposes to the tip, N (docs/model.md, \"Loading\")")
    g.add_argument("--wall-mu0", type=finite_float, help="a known wall's small-strain shear modulus, kPa (with --wall-c11)")
    g.add_argument("--wall-c11", type=finite_float, help="a known wall's C11, kPa (without both: averaged over the tissue)")
    g.add_argument("--stiffness", type=finite_float,
                   help="the wall as a factor on the reference wall law (1: the reference), for a model fitted "
                        "over it, such as the shipped predictor")
    g.add_argument("--material", type=Path, help=MATERIAL_HELP)
    g.add_argument("--strict", action="store_true", help="a query outside the training domain is an error, not a warning")
    g.add_argument("--extrapolate", action="store_true",
                   help="answer outside the training domain too, every such number marked (the shipped predictor "
                        "refuses without it)")


def add_parsers(sub):
    """Add ``surrogate``, ``predict`` and ``recommend`` to the ``colonsim`` subcommands."""
    s = sub.add_parser("surrogate", help="fit, inspect and plot a GP surrogate of a sweep",
                       description="Gaussian-process surrogate of a sweep's results table (docs/surrogate.md).")
    ssub = s.add_subparsers(dest="surrogate_command", required=True)
    fit = ssub.add_parser("fit", help="fit a surrogate on a results table",
                          description="Fit one GP per segment and output on the successful runs of RESULTS, "
                                      "cross-validate it, and write MODEL.json + MODEL.npz.")
    fit.add_argument("results", type=Path, help="results.parquet (or .csv) of a sweep")
    fit.add_argument("-o", "--out", type=_model_path, required=True, help="model path: writes MODEL.json and MODEL.npz")
    fit.add_argument("--targets", nargs="+", help="output columns to model (default: deformations, A, C, forces, stretch)")
    fit.add_argument("--segments", nargs="+", help="segments to fit (default: all in the table)")
    fit.add_argument("--cv", type=_cv, default="loo", help="'loo' (closed-form leave-one-out, default) or k folds")
    fit.add_argument("--restarts", type=bounded_int(0, 50),
                     help="extra optimizer starts per GP, 0-50 (default 32 up to 100 runs, 2 above)")
    fit.add_argument("--hyperparameter-draws", type=bounded_int(0, 256),
                     help="draws of each GP's hyperparameters its predictions average over, 0-256 (0: the "
                          "likelihood's maximum alone; default 16 up to 100 runs, 0 above)")
    fit.add_argument("--min-runs", type=bounded_int(2, 20_000), default=4, help="fewest runs a model is fitted on (default 4)")
    fit.add_argument("--seed", type=seed, default=0, help="seed of the restarts and folds (default 0)")
    fit.add_argument("--material", type=Path, help=MATERIAL_HELP.replace("predictions average", "stored with the "
                                                                          "model, that predictions average"))
    fit.add_argument("--replicates", type=Path,
                     help="results table of training cases run again at another wall mesh: their scatter is each "
                          "output's noise floor (docs/surrogate.md, 'Noise floor'; another push speed hardly "
                          "moves a settled output, 'Limits')")
    fit.add_argument("--threads", type=worker_count, default=1,
                     help="BLAS threads (default 1; more only pays on an idle machine with thousands of runs)")
    fit.set_defaults(func=cmd_fit)

    info = ssub.add_parser("info", help="training domain, hyperparameters and cross-validated accuracy of a model")
    info.add_argument("model", type=Path, nargs="?", help=MODEL_HELP.split(", which")[0] + ")")
    info.add_argument("--json", action="store_true", help="print the model's JSON document")
    info.set_defaults(func=cmd_info)

    val = ssub.add_parser("validate", help="score a model on runs it was not fitted on",
                          description="RMSE, Q2, coverage of the 50/90/95 %% intervals, mean and sd of the "
                                      "standardized error, and how often predicted orders of run pairs hold against "
                                      "the probability stated, on a held-out results table (docs/surrogate.md).")
    val.add_argument("model", type=Path, help="MODEL.json written by 'colonsim surrogate fit'")
    val.add_argument("table", type=Path, help="results.parquet (or .csv) of runs the model was not fitted on")
    val.add_argument("--target", nargs="+", help="outputs to score (default: those the model has and the table holds)")
    val.add_argument("--segment", help="segment to score (default: the model's only one)")
    val.add_argument("--plot", type=output_file(".png", ".pdf", ".svg"), help="reliability plot: nominal against "
                                                                                  "observed coverage")
    val.add_argument("--json", action="store_true", help="JSON output")
    val.add_argument("-o", "--out", type=output_file(".json"), help="write the scores to this JSON file")
    val.set_defaults(func=cmd_validate)

    plot = ssub.add_parser("plot", help="predicted output against one input, with its 95 %% band",
                           description="One curve per scope over the input's training range; the other inputs "
                                       "from the patient options.")
    plot.add_argument("model", type=Path, nargs="?", help=MODEL_HELP)
    plot.add_argument("--vs", required=True, help="scope, diameter, angle, friction or wall-thickness")
    plot.add_argument("--target", default=catalog.PAIN_PROXY, help=f"output column (default {catalog.PAIN_PROXY}, the pain proxy)")
    _patient_options(plot)
    plot.add_argument("-o", "--out", type=output_file(".png", ".pdf", ".svg"), required=True,
                      help="figure file (.png, .pdf, .svg)")
    plot.set_defaults(func=cmd_plot)

    pr = sub.add_parser("predict", help="predict deformation, forces and stretch from a surrogate",
                        description="Mean, standard deviation and 95 % interval of each output for the query, "
                                    "or for every row of --csv.")
    pr.add_argument("model", type=Path, nargs="?", help=MODEL_HELP)
    _patient_options(pr)
    pr.add_argument("--target", nargs="+", help="outputs to predict (default: all the model has)")
    pr.add_argument("--csv", type=Path, help="batch queries: one per row, columns segment, scope or "
                                             "scope_diameter_mm, diameter_mm, angle_deg, friction, "
                                             "wall_thickness_mm, and/or sex, age, region; options fill missing columns")
    pr.add_argument("--json", action="store_true", help="JSON output (records) instead of text")
    pr.add_argument("-o", "--out", type=output_file(".csv", ".json"), help="write the predictions to this file (.csv or .json)")
    pr.set_defaults(func=cmd_predict)

    rec = sub.add_parser("recommend", help="rank the scopes for a patient by predicted deformation",
                         description="Ranks scopes by predicted deformation and states the probability of the "
                                     "ranking from the joint GP posterior (docs/surrogate.md).")
    rec.add_argument("model", type=Path, nargs="?", help=MODEL_HELP)
    _patient_options(rec, scope_diameter=False)
    rec.add_argument("--target", default=catalog.PAIN_PROXY, help=f"output to rank by (default {catalog.PAIN_PROXY}, the largest "
                     "deformation over the run: docs/surrogate.md, 'The pain proxy'; final_deformation_cm is the end value)")
    rec.add_argument("--reference", help="scope the others are compared with (default sdc)")
    rec.add_argument("--json", action="store_true", help="JSON output")
    rec.add_argument("-o", "--out", type=output_file(".json"), help="write the JSON recommendation to this file")
    rec.set_defaults(func=cmd_recommend)


def _model_path(text):
    """A model path whose .json and .npz files can both be written."""
    from colonsim.surrogate.store import model_paths

    file_type = output_file()
    for path in model_paths(text):
        file_type(str(path))
    return Path(text)


def _tissue(args):
    """The tissue distribution of --material, or None."""
    from colonsim.surrogate.tissue import TissueDistribution

    return None if args.material is None else TissueDistribution.from_file(args.material)


def cmd_fit(args):
    from colonsim.surrogate.model import SweepSurrogate
    from colonsim.surrogate.store import save_surrogate
    from colonsim.surrogate.table import TARGETS, read_results

    if (args.restarts is not None and args.restarts < 0) or args.min_runs < 2 or args.threads < 1:
        raise ColonsimError("--restarts must be >= 0, --min-runs >= 2 and --threads >= 1")
    tissue = _tissue(args)
    table = read_results(args.results)
    replicates = None if args.replicates is None else read_results(args.replicates)
    model = SweepSurrogate(targets=tuple(args.targets or TARGETS), segments=args.segments, cv=args.cv,
                           n_restarts=args.restarts, min_runs=args.min_runs, random_state=args.seed,
                           threads=args.threads, tissue=tissue, replicates=replicates,
                           hyperparameter_draws=args.hyperparameter_draws).fit(table)
    json_path, npz_path = save_surrogate(model, args.out, source=args.results)
    print(model.report())
    print(f"model: {json_path} + {npz_path.name}")


def cmd_info(args):
    from colonsim.surrogate.predictor import load_shipped, shipped_path
    from colonsim.surrogate.store import load_surrogate, model_paths

    model = load_shipped() if args.model is None else load_surrogate(args.model)
    if args.json:
        print(model_paths(shipped_path() if args.model is None else args.model)[0].read_text(encoding="utf-8"), end="")
        return
    about = getattr(model, "about_", None)
    if about:
        print(f"{about['what']}; fitted on {', '.join(about['sweeps'])} (held out: "
              f"{', '.join(about['held_out_sweeps']) or 'none'}) by the engine of "
              f"{', '.join(c[:10] for c in about['engine_commits']) or 'unknown commits'}")
    print(model.report())


def cmd_validate(args):
    from colonsim.files import save_figure, write_json
    from colonsim.surrogate.holdout import format_score, reliability_figure, score
    from colonsim.surrogate.store import load_surrogate
    from colonsim.surrogate.table import read_results, target_unit

    model = load_surrogate(args.model)
    table = read_results(args.table)
    segment = _segment(args, model)
    fitted = list(model.models_.get(segment, {}))
    targets = args.target or [t for t in fitted if t in table.columns]
    if not targets:
        raise ColonsimError(f"{args.table} holds none of the outputs the model has ({', '.join(fitted) or 'none'})")
    scores = [score(model, table, t, segment, name=str(args.table)) for t in targets]
    if args.out:
        write_json(args.out, {"model": str(args.model), "table": str(args.table), "scores": scores})
    if args.plot:
        save_figure(reliability_figure(scores), args.plot)
    if args.json:
        print(json.dumps({"scores": scores}, indent=2, allow_nan=False))
    else:
        print("\n".join(format_score(s, target_unit(s["target"])) for s in scores))
        for path in (p for p in (args.out, args.plot) if p):
            print(f"written: {path}")


def _check_material(model, segments, strict) -> dict:
    """Segment -> why the material is outside its domain ("" inside); refused with ``strict``."""
    from colonsim.surrogate.predictor import check_material

    return {segment: check_material(model, segment, strict=strict) for segment in dict.fromkeys(segments)}


def cmd_predict(args):
    from colonsim.files import write_csv, write_json
    from colonsim.surrogate.model import SUFFIXES
    from colonsim.surrogate.predictor import joined_notes, mark_extrapolated

    model, strict, note = load_model(args)
    frame, defaults = query_frame(args, model)
    note = joined_notes(note, defaults)
    outside = _check_material(model, frame["segment"], strict)
    targets = list(args.target or model.targets)
    unknown = sorted(set(targets) - set(model.targets))
    if unknown:
        raise ColonsimError(f"the surrogate has no target {', '.join(unknown)}; it models {', '.join(model.targets)}")
    out = model.predict_frame(frame, targets=targets, strict=strict)
    for segment, why in outside.items():
        mark_extrapolated(out, why, segment)
    if note:
        out["tissue_note"] = out["tissue_note"] + "; " + note
    out = out.drop(columns=[t + suffix for t in targets if out[t].isna().all() for suffix in SUFFIXES])
    shown = [t for t in targets if t in out]
    if not shown:
        why = "; ".join(f"{seg} {t}: {model.skipped_.get(seg, {}).get(t, 'not fitted')}"
                        for seg in dict.fromkeys(out["segment"]) for t in targets)
        raise ColonsimError(f"no model for this query ({why})")
    if args.out:
        if args.out.suffix.lower() == ".json":
            write_json(args.out, {"predictions": records(out)})
        else:
            write_csv(args.out, out)
    if args.json:
        print(json.dumps({"predictions": records(out)}, indent=2, allow_nan=False, default=str))
    else:
        print(format_predictions(out, shown))
        if args.out:
            print(f"predictions: {args.out}")


def cmd_recommend(args):
    from colonsim.files import write_json
    from colonsim.surrogate.patients import describe_patient
    from colonsim.surrogate.predictor import joined_notes, mark_extrapolated
    from colonsim.surrogate.recommend import format_recommendation, recommend

    model, strict, note = load_model(args)
    segment = _segment(args, model)
    outside = _check_material(model, [segment], strict)[segment]
    query, defaults = patient_query(model, segment, args, presets_of(args))
    note = joined_notes(note, defaults)
    rec = mark_extrapolated(recommend(model, segment, query, scopes=args.scope, target=args.target,
                                      reference=args.reference, strict=strict), outside)
    if note:
        rec["tissue"]["note"] += "; " + note
    patient = describe_patient(segment, args.sex, args.age, args.region, presets_of(args))
    rec["patient"] = patient
    if args.out:
        write_json(args.out, rec)
    if args.json:
        print(json.dumps(rec, indent=2, allow_nan=False))
    else:
        if patient:
            print(f"patient: {patient}")
        print(format_recommendation(rec))


def cmd_plot(args):
    from colonsim.files import save_figure
    from colonsim.surrogate.plot import prediction_figure

    model, strict, _ = load_model(args)
    segment = _segment(args, model)
    vs = VS_NAMES.get(args.vs.lower(), args.vs)
    query, _ = patient_query(model, segment, args, presets_of(args))
    fig = prediction_figure(model, segment, vs, query, target=args.target, scopes=args.scope, strict=strict)
    save_figure(fig, args.out)
    print(f"figure: {args.out}")
