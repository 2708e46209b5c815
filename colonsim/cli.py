"""The ``colonsim`` command line: thin wrappers that read options, run a workflow, print a report.

Every error a user can cause is a :class:`colonsim.errors.ColonsimError`: printed as one line,
exit code 2, no traceback.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

from colonsim import cli_surrogate, cli_sweep
from colonsim.data import BUNDLED_MANIFEST
from colonsim.errors import ColonsimError, ColonsimWarning
from colonsim.options import finite_float, output_folder, positive_int
from colonsim.insertion.case.run_budget import DEFAULT_MAX_STEPS



def _mesh(text):
    try:
        nl, nw = (int(v) for v in text.lower().split("x"))
        if nl < 1 or nw < 1:
            raise ValueError
    except ValueError:
        raise argparse.ArgumentTypeError(f"mesh must look like 8x3 (divisions along the length x half-width), got {text!r}")
    return nl, nw


def _add_calibrate(sub):
    p = sub.add_parser("calibrate", help="identify hyperelastic parameters from tensile test curves",
                       description="Fit a hyperelastic law to strip tensile curves (docs/model.md): Latin-hypercube "
                                   "sensitivity study -> CMA-ES -> Nelder-Mead on a scikit-fem model of the "
                                   "clamped specimen. Writes material.json (read by the insertion solver), "
                                   "CSV tables and figures.")
    src = p.add_argument_group("test data (default: the bundled synthetic data set)")
    src.add_argument("--manifest", type=Path,
                     help="CSV listing specimens: specimen,file,length_mm,width_mm,thickness_mm")
    src.add_argument("--curve", type=Path,
                     help="one force-displacement CSV or testing-machine export (geometry from --length, --width, "
                          "--thickness or the file's preamble)")
    src.add_argument("--length", type=float, help="free length between the grips, mm (wins over the file's preamble)")
    src.add_argument("--width", type=float, help="specimen width, mm (wins over the file's preamble)")
    src.add_argument("--thickness", type=float, help="wall thickness, mm (wins over the file's preamble)")
    src.add_argument("--displacement-unit", help="unit of the displacement column if the header does not say (mm, m, cm, um, in)")
    src.add_argument("--force-unit", help="unit of the force column if the header does not say (N, mN, kN, gf, kgf, lbf)")
    fit = p.add_argument_group("fit")
    fit.add_argument("--per-specimen", action="store_true",
                     help="fit every specimen separately and report the population mean and spread "
                          "(default: fit the mean curve of all specimens, the source's way)")
    fit.add_argument("--law", help="mooney_rivlin_3 (default), mooney_rivlin_2, neo_hookean, yeoh")
    fit.add_argument("--compare-laws", action="store_true",
                     help="fit every law the insertion solver runs, write laws.csv and laws.png, and material.json "
                          "for the law BIC chooses")
    fit.add_argument("--analytic", action="store_true",
                     help="fit the closed-form homogeneous uniaxial model instead of the clamped FE strip")
    fit.add_argument("--mesh", type=_mesh, default=(8, 3), help="FE divisions of the quarter strip, default 8x3")
    fit.add_argument("--points", type=int, default=20, help="simulation displacement points (default 20)")
    fit.add_argument("--quick", action="store_true",
                     help="reduced budget (40 designs, 100 CMA-ES, 160 Nelder-Mead evaluations) instead of 100/300/300")
    fit.add_argument("--seed", type=int, default=1, help="seed of the Latin hypercube and CMA-ES (default 1)")
    fit.add_argument("--workers", type=int, default=2, help="processes for --per-specimen (default 2)")
    p.add_argument("--out", type=output_folder, default="colonsim_results/calibration",
                   help="output folder (default colonsim_results/calibration)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_calibrate)


def _load_curves(args):
    """The curves named by ``args``; what the reader noticed is printed as ``colonsim: warning:``
    lines, and geometry taken from a file's preamble is said."""
    import warnings

    from colonsim.identification.testdata import CurveWarning, read_curve, read_manifest

    units = {"displacement_unit": args.displacement_unit, "force_unit": args.force_unit}
    if args.curve and args.manifest:
        raise ColonsimError("give either --curve or --manifest, not both")
    if not args.curve and any(v is not None for v in (args.length, args.width, args.thickness)):
        raise ColonsimError("--length/--width/--thickness go with --curve; a manifest has its own geometry columns")
    manifest = args.manifest or BUNDLED_MANIFEST
    if not args.curve and args.manifest is None and not manifest.is_file():
        raise ColonsimError(f"the bundled data set {manifest} is missing (install from a clone of the repository) "
                            "or pass --manifest/--curve")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", CurveWarning)
        if args.curve:
            curves = [read_curve(args.curve, *(None if v is None else v * 1e-3 for v in (args.length, args.width, args.thickness)),
                                 given_as="--{}", **units)]
        else:
            curves = read_manifest(manifest, **units)
    for w in caught:
        print(f"colonsim: warning: {w.message}", file=sys.stderr)
    for c in curves:
        notes = [f"{q} from the {src}" for q, src in c.meta.get("geometry_from", {}).items() if src.startswith("preamble")]
        ignored = c.meta.get("layout", {}).get("rows_after_data_ignored")
        if ignored:
            notes.append(f"{ignored} rows after the data ignored (from line {c.meta['layout']['first_ignored_line']})")
        if notes:
            print(f"{c.name}: {'; '.join(notes)}", flush=True)
    return curves


class _Progress:
    """A tqdm bar over objective evaluations (or specimens), showing stage and best e1."""

    def __init__(self, total, unit, enabled):
        from tqdm import tqdm

        self.bar = tqdm(total=total, unit=unit, disable=None if enabled else True, dynamic_ncols=True, leave=False, mininterval=0.5)
        self.best = {}

    def evaluation(self, name, stage, n, e1):
        if stage is None:  # a whole specimen finished (process pool)
            self.bar.set_postfix_str(f"{name} done")
            self.bar.update(1)
            return
        self.best[name] = min(self.best.get(name, float("inf")), e1)
        self.bar.set_postfix_str(f"{name} {stage} best e1 {self.best[name]:.4g} N^2")
        self.bar.update(1)

    def close(self):
        self.bar.close()


def _format_result(r) -> str:
    from colonsim.identification.diagnostics import split_unidentified
    from colonsim.identification.report import small_strain

    unc, ci = r.uncertainty, r.uncertainty.interval()
    lines = [f"{r.curve.name}: {r.model['model']}, law {r.model['law']}"]
    for i, n in enumerate(r.names):
        lines.append(f"  {n:>4} = {r.parameters[i]:12.1f} Pa   sd {unc.std[i]:10.1f}   95% [{ci[i, 0]:.1f}, {ci[i, 1]:.1f}]")
    corr = unc.correlation
    pairs = ", ".join(f"{r.names[i]}/{r.names[j]} {corr[i, j]:+.3f}" for i in range(len(r.names)) for j in range(i + 1, len(r.names)))
    if pairs:
        lines.append(f"  correlation: {pairs}")
    split = split_unidentified(r)
    if split is not None:
        lines.append(f"  the C10/C01 split is not identified by uniaxial data (correlation {split:+.3f}); mu0 carries their sum")
    ss = small_strain(r)
    lines.append(f"  mu0 = {ss['mu0_Pa']:.1f} Pa, sd {ss['mu0_sd_Pa']:.1f} from the noise: {ss['identification']}")
    mf = ss["model_form"]
    if mf is not None:
        share = f" = {abs(mf['difference_in_noise_sd']):.1f} noise sd" if mf["difference_in_noise_sd"] is not None else ""
        lines.append(f"  model form: mu0 {mf['mu0_clamped_fe_Pa']:.1f} Pa (clamped FE) vs {mf['mu0_closed_form_Pa']:.1f} Pa "
                     f"(closed form), the clamp shifts mu0 by {mf['difference_Pa']:+.1f} Pa{share}")
    st = r.stages
    lines.append(f"  objective e1: initial {st['initial']['e1']:.4g} -> sensitivity {st['sensitivity']['e1']:.4g} -> "
                 f"CMA-ES {st['cma-es']['e1']:.4g} -> Nelder-Mead {st['nelder-mead']['e1']:.4g} N^2")
    r2 = f", R^2 {r.fit['r2']:.6f}" if r.fit["r2"] is not None else ""
    lines.append(f"  fit: RMS {r.fit['rms_N']:.4f} N = {r.fit['rms_over_noise']:.2f} x the curve's noise "
                 f"({r.fit['noise_sd_N']:.4f} N per sample), max {r.fit['max_abs_N']:.4f} N{r2} "
                 f"({r.fit['evaluations']} evaluations, {r.fit['wall_time_s']:.1f} s)")
    mc = r.model_comparison
    if "unavailable" in mc:
        lines.append(f"  clamped FE vs closed form: {mc['unavailable']}")
    else:
        lines.append(f"  clamped FE vs closed form at these parameters: {100 * mc['fe_over_closed_form_minus_1_min']:+.2f} % "
                     f"to {100 * mc['fe_over_closed_form_minus_1_max']:+.2f} % in force (end: {mc['force_end_fe_N']:.3f} vs "
                     f"{mc['force_end_closed_form_N']:.3f} N)")
    return "\n".join(lines)


def _print_warnings(results):
    from colonsim.identification.diagnostics import misfit_warning

    for r in results:
        warning = misfit_warning(r)
        if warning:
            print(f"colonsim: warning: {warning}", file=sys.stderr, flush=True)


def run_calibration(args, out: Path) -> list:
    """Load the curves named by ``args``, calibrate, write results into ``out``; return the results."""
    from colonsim.files import check_output_folder
    from colonsim.laws import get_law
    from colonsim.identification.pipeline import Budget
    from colonsim.identification.population import calibrate_curve, calibrate_specimens, population_summary, population_table, write_population
    from colonsim.identification.report import write_calibration
    from colonsim.identification.testdata import mean_curve

    check_output_folder(out)
    if args.compare_laws and args.law is not None:
        raise ColonsimError(f"--compare-laws fits every law the insertion solver runs; drop --law {args.law}")
    if args.compare_laws and args.per_specimen:
        raise ColonsimError("--compare-laws fits one curve (or the mean curve); drop --per-specimen")
    law = args.law or "mooney_rivlin_3"
    get_law(law)
    if args.points < 5:
        raise ColonsimError(f"--points {args.points} is too few to fit 3 parameters; use at least 5 (default 20)")
    if args.workers < 1:
        raise ColonsimError(f"--workers {args.workers}; give at least 1")
    curves = _load_curves(args)
    budget = Budget.quick() if args.quick else Budget()
    options = dict(law=law, analytic=args.analytic, budget=budget, seed=args.seed, n_points=args.points)
    if not args.analytic:
        options.update(n_length=args.mesh[0], n_width=args.mesh[1])
    per_eval = 1 + budget.designs + budget.cma_max_evaluations + budget.cma_popsize + budget.nm_max_evaluations
    show = not args.no_progress
    if args.per_specimen:
        workers = max(1, min(args.workers, len(curves)))
        print(f"fitting {len(curves)} specimens separately ({workers} process{'es' if workers > 1 else ''}, "
              f"{'quick' if args.quick else 'full'} budget) ...", flush=True)
        bar = _Progress(len(curves) if workers > 1 else per_eval * len(curves),
                        "specimen" if workers > 1 else "eval", show)
        try:
            results = calibrate_specimens(curves, workers=workers, progress=bar.evaluation, **options)
        finally:
            bar.close()
        paths = write_population(results, out)
        for r in results:
            print(_format_result(r))
        _print_warnings(results)
        summary = population_summary(population_table(results), results[0].names)
        print("population (between-specimen mean +- sd):")
        for n, s in summary.items():
            print(f"  {n:>4} = {s['mean_Pa']:12.1f} +- {s['sd_Pa']:.1f} Pa")
        print(f"results: {out}/ (population.json, population.csv, population.png, one folder per specimen)")
        return results
    curve = curves[0] if len(curves) == 1 else mean_curve(curves)
    if len(curves) > 1:
        print(f"fitting the mean curve of {len(curves)} specimens (mean thickness {curve.thickness * 1e3:.3f} mm; "
              "--per-specimen fits each one)", flush=True)
    if args.compare_laws:
        return _compare_laws(curve, options, per_eval, show, out)
    bar = _Progress(per_eval, "eval", show)
    try:
        result = calibrate_curve(curve, progress=lambda stage, n, e1: bar.evaluation(curve.name, stage, n, e1), **options)
    finally:
        bar.close()
    paths = write_calibration(result, out)
    print(_format_result(result))
    _print_warnings([result])
    print(f"results: {paths['material']} (+ history.csv, sensitivity.csv, top10_designs.csv, fit.csv, *.png in {out}/)")
    return [result]


def _compare_laws(curve, options, per_eval, show, out: Path) -> list:
    """``calibrate --compare-laws``: every law the solver runs on ``curve``, BIC chooses."""
    import pandas as pd

    from colonsim.identification.law_comparison import compare_laws, write_law_comparison
    from colonsim.identification.population import calibrate_curve
    from colonsim.laws import LAWS

    bar = _Progress(per_eval * len(LAWS), "eval", show)

    def fit(law):
        return calibrate_curve(curve, progress=lambda stage, n, e1: bar.evaluation(f"{curve.name} {law}", stage, n, e1),
                               **{**options, "law": law})

    try:
        comparison = compare_laws(fit)
    finally:
        bar.close()
    paths = write_law_comparison(comparison, out)
    shown = comparison.table.drop(columns=["note"]).set_index("law")
    with pd.option_context("display.width", 200, "display.max_columns", 30):
        print(shown.to_string(float_format=lambda v: f"{v:.4g}", na_rep="-"))
    print(f"chosen: {comparison.chosen}, {comparison.reason}")
    print(_format_result(comparison.chosen_result))
    _print_warnings([comparison.chosen_result])
    print(f"results: {paths['material']} ({comparison.chosen}), {paths['laws_table']}, {paths['laws_plot']}; "
          f"every law's calibration files in {out}/laws/")
    return [comparison.chosen_result]


def cmd_calibrate(args):
    run_calibration(args, args.out)


def cmd_demo(args):
    from colonsim.demo import run_demo

    run_demo(args)


def _add_insert(sub):
    p = sub.add_parser("insert", help="simulate a colonoscope insertion (explicit dynamics)",
                       description="Push a colonoscope through a colon model (docs/model.md) and record the colon "
                                   "deformation, contact and push forces, tip motion and energies. Writes "
                                   "timeseries.csv, summary.json and insertion.png per scope, a comparison table "
                                   "and figure, and optional VTU files for ParaView.")
    p.add_argument("--segment", default="rsj", help="rsj (default), rsf, thf, thf-fixed, or straight (sanity case)")
    p.add_argument("--scope", nargs="+", default=["sdc"], help="utc, pdc, sdc or an outer diameter in mm; several allowed")
    p.add_argument("--diameter", type=finite_float, default=36.0, help="colon inner diameter, mm (default 36)")
    p.add_argument("--angle", type=finite_float, default=0.0, help="alpha (RSF) or beta (THF), degrees (default 0)")
    p.add_argument("--friction", type=finite_float, default=0.0, help="Coulomb friction scope/wall (default 0)")
    p.add_argument("--wall-thickness", type=finite_float, default=2.0, help="colon wall thickness, mm (default 2, an assumption)")
    p.add_argument("--element-size", type=finite_float, default=3.0, help="wall triangle size, mm (default 3)")
    p.add_argument("--material", help="material JSON from colonsim calibrate (default: the source's parameters)")
    p.add_argument("--flexure-angle", type=finite_float, default=90.0,
                   help="turn of the splenic (RSF) or hepatic (THF) flexure, degrees (default 90, an assumption)")
    p.add_argument("--exit-length", type=finite_float, default=100.0,
                   help="mm of fixed colon after the last mobile piece (default 100, an assumption)")
    p.add_argument("--vtu", action="store_true", help="write deformed meshes for ParaView (needs meshio)")
    p.add_argument("--snapshot-every", type=finite_float, default=0.02, help="simulated seconds between VTU snapshots")
    p.add_argument("--threads", type=int, default=None,
                   help="Numba threads (default: all cores). Use 1 when running several insertions side by side: "
                        "oversubscribed threads slow the kernels down by an order of magnitude")
    p.add_argument("--max-steps", type=positive_int, default=DEFAULT_MAX_STEPS,
                   help=f"refuse a run estimated to need more time steps (default {DEFAULT_MAX_STEPS:,}; "
                        "a stiff wall or a fine mesh needs many)")
    p.add_argument("--out", type=output_folder, default="colonsim_results/insertion", help="output folder")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_insert)


def run_insertions(cases, out: Path, vtu=False, snapshot_every=0.02, show=True, max_steps=DEFAULT_MAX_STEPS):
    """Run each case, write its folder under ``out`` and a comparison; return the results.

    Every case is checked first, its run time estimated included (:mod:`colonsim.insertion.case.run_budget`):
    a case needing more than ``max_steps`` time steps is refused before any run starts."""
    from tqdm import tqdm

    from colonsim.files import save_figure, write_csv
    from colonsim.insertion.case.results import comparison_table, insertion_figure, write_insertion
    from colonsim.insertion.case.run_budget import check_run_budget
    from colonsim.insertion.case.scenario import run_insertion

    budgets = [check_run_budget(case, max_steps) for case in cases]
    results = []
    for case, budget in zip(cases, budgets):
        print(f"{case.segment.upper()} {case.scope.upper()}: {budget.describe()}", flush=True)
        # the bar follows simulated time, which costs wall time evenly (depth does not: the
        # push ramps up and RSF/THF pause), so its time left is meaningful
        chunk_s = 0.01
        bar = tqdm(total=round(budget.simulated_s * 1e3), unit="ms", disable=None if show else True,
                   dynamic_ncols=True, leave=False, mininterval=0.5, desc=f"{case.segment} {case.scope} (simulated ms)")

        def progress(tip_arc, tip_end, bar=bar):
            bar.update(min(round(chunk_s * 1e3), bar.total - bar.n))
            bar.set_postfix_str(f"tip {100 * tip_arc:.1f}/{100 * tip_end:.1f} cm", refresh=False)

        try:
            r = run_insertion(case, progress=progress, snapshot_interval=snapshot_every if vtu else None,
                              chunk_s=chunk_s)
        finally:
            bar.close()
        folder = out / f"{case.segment}_{r.summary['scope']['name'].replace(' ', '')}"
        write_insertion(r, folder, vtu=vtu)
        results.append(r)
        s = r.summary
        pts = ", ".join(f"{k} {v['deformation_cm']:.2f} cm" for k, v in s["points_cm"].items() if v is not None)
        print(f"{case.segment.upper()} {s['scope']['name']:>8}: final deformation {s['final_deformation_cm']:.2f} cm, "
              f"max {s['max_deformation_cm']:.2f} cm ({pts}); peak contact {s['peak_contact_force_N']:.2f} N, "
              f"peak push {s['peak_push_force_N']:.2f} N; quasi-static {'holds' if s['quasi_static']['holds'] else 'does NOT hold'} "
              f"(KE/IE < 10 %: colon {100 * s['quasi_static']['fraction_below_10pct']['colon']:.0f} %, "
              f"scope {100 * s['quasi_static']['fraction_below_10pct']['scope']:.0f} % of samples without its imposed "
              f"sliding); ended: {s['end']['reason']} at {s['end']['depth_cm']:.1f} cm; "
              f"{s['steps']} steps in {s['wall_time_s']:.1f} s -> {folder}/")
    table, figure = comparison_table(results), insertion_figure(results)  # both made before either file is replaced
    write_csv(out / "comparison.csv", table)
    save_figure(figure, out / "comparison.png")
    print(f"comparison: {out}/comparison.csv, {out}/comparison.png")
    return results


def cmd_insert(args):
    import numba

    from colonsim.insertion.case.scenario import InsertionCase

    if args.threads is not None:
        if not 1 <= args.threads <= numba.config.NUMBA_NUM_THREADS:
            raise ColonsimError(f"--threads {args.threads} must lie in 1-{numba.config.NUMBA_NUM_THREADS} (the cores Numba sees)")
        numba.set_num_threads(args.threads)

    cases = [InsertionCase(segment=args.segment, scope=scope, diameter_mm=args.diameter, angle_deg=args.angle,
                           flexure_angle_deg=args.flexure_angle, friction=args.friction,
                           wall_thickness_mm=args.wall_thickness,
                           element_size_mm=args.element_size, material=args.material,
                           exit_length_mm=args.exit_length) for scope in args.scope]
    if args.material is not None:
        from colonsim.insertion.engine.material import load_material

        load_material(args.material)
    run_insertions(cases, args.out, vtu=args.vtu, snapshot_every=args.snapshot_every, show=not args.no_progress,
                   max_steps=args.max_steps)


class OneLineParser(argparse.ArgumentParser):
    """Option errors as one line, like every other error (exit code 2), instead of the usage text."""

    def error(self, message):
        raise ColonsimError(f"{message} (see '{self.prog} --help')")


def build_parser():
    from colonsim import __version__

    parser = OneLineParser(prog="colonsim", description="Colonoscope-colon interaction toolkit.")
    parser.add_argument("--version", action="version", version=f"colonsim {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    _add_calibrate(sub)
    _add_insert(sub)
    cli_sweep.add_parser(sub)
    cli_surrogate.add_parsers(sub)
    demo = sub.add_parser("demo", help="run the workflows on the bundled data (a few minutes on 2 cores)")
    demo.add_argument("--out", type=output_folder, default="colonsim_demo", help="output folder (default colonsim_demo)")
    demo.add_argument("--element-size", type=finite_float, default=3.0,
                      help="wall mesh of the insertions and the sweep, mm (default 3; coarser is faster, not validated)")
    demo.add_argument("--workers", type=positive_int, default=None,
                      help="processes for the demo's sweep (default: up to 2 cores)")
    demo.add_argument("--no-progress", action="store_true", help="no progress bar")
    demo.set_defaults(func=cmd_demo)
    return parser


def _one_line(text) -> str:
    return " ".join(str(text).split())


def main(argv=None):
    show, shown = warnings.showwarning, set()

    def show_warning(message, category, filename, lineno, file=None, line=None):
        if not issubclass(category, ColonsimWarning):
            show(message, category, filename, lineno, file, line)
        elif _one_line(message) not in shown:  # each distinct warning once (a material is read per run)
            shown.add(_one_line(message))
            print(f"colonsim: warning: {_one_line(message)}", file=sys.stderr)

    with warnings.catch_warnings():  # restores the filters and the display on return
        warnings.simplefilter("always", ColonsimWarning)
        warnings.showwarning = show_warning
        try:
            args = build_parser().parse_args(argv)
            args.func(args)
        except ColonsimError as exc:
            print(f"colonsim: error: {_one_line(exc)}", file=sys.stderr)
            return 2
        except KeyboardInterrupt:
            print("colonsim: interrupted; files written so far are complete", file=sys.stderr)
            return 130
    return 0


if __name__ == "__main__":
    sys.exit(main())
