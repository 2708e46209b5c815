"""The console workflows the command line and the demo share: calibrate from test files, run
insertions. They take dataclasses (:class:`CalibrationRequest`, a list of
:class:`colonsim.insertion.case.scenario.InsertionCase`), print progress bars and summaries,
and write their files; the command line only turns options into these dataclasses.
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass
from pathlib import Path

from colonsim.data import BUNDLED_MANIFEST
from colonsim.errors import ColonsimError
from colonsim.insertion.case.run_budget import DEFAULT_MAX_STEPS


def available_cores() -> int:
    """CPU cores this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


@dataclass(frozen=True)
class CalibrationRequest:
    """What to calibrate and how (user units: mm; the command line's ``calibrate`` options).

    ``curve`` (one file, geometry from ``length_mm``/``width_mm``/``thickness_mm`` or its
    preamble) or ``manifest`` (default: the bundled synthetic set); ``law`` None means
    mooney_rivlin_3; ``mesh`` = FE divisions (along the length, across the half-width).
    """

    manifest: Path | None = None
    curve: Path | None = None
    length_mm: float | None = None
    width_mm: float | None = None
    thickness_mm: float | None = None
    displacement_unit: str | None = None
    force_unit: str | None = None
    per_specimen: bool = False
    law: str | None = None
    compare_laws: bool = False
    analytic: bool = False
    mesh: tuple = (8, 3)
    points: int = 20
    quick: bool = False
    budget: object = None  # an identification Budget; None: the full one, or quick's
    seed: int = 1
    workers: int = 2
    show_progress: bool = True
    # cleaning (colonsim.identification.cleanup): None, "detect", "off" or the load start in mm; points
    load_start: object = None
    decimate: int | None = None
    # how errors name the geometry options ("--{}": the command line's --length ...)
    given_as: str = "{}_mm"


def _load_curves(request):
    """The curves named by ``request``; what the reader noticed is printed as ``colonsim: warning:``
    lines, and geometry taken from a file's preamble is said."""
    import warnings

    from colonsim.identification.testdata import CurveWarning, read_curve, read_manifest

    units = {"displacement_unit": request.displacement_unit, "force_unit": request.force_unit}
    if request.curve and request.manifest:
        raise ColonsimError("give either --curve or --manifest, not both")
    if not request.curve and any(v is not None for v in (request.length_mm, request.width_mm, request.thickness_mm)):
        raise ColonsimError("--length/--width/--thickness go with --curve; a manifest has its own geometry columns")
    manifest = request.manifest or BUNDLED_MANIFEST
    if not request.curve and request.manifest is None and not manifest.is_file():
        raise ColonsimError(f"the bundled data set {manifest} is missing (install from a clone of the repository) "
                            "or pass --manifest/--curve")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", CurveWarning)
        if request.curve:
            curves = [read_curve(request.curve, *(None if v is None else v * 1e-3 for v in (request.length_mm, request.width_mm, request.thickness_mm)),
                                 given_as=request.given_as, **units)]
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


def _clean(curves, request, out):
    """The curves cleaned as asked (slack found is always corrected); notes printed, figure written."""
    from colonsim.files import save_figure
    from colonsim.identification.cleanup import clean_curves, figure

    load_start = request.load_start * 1e-3 if isinstance(request.load_start, (int, float)) else request.load_start
    cleaned, notes, changed = clean_curves(curves, load_start, request.decimate)
    for note in notes:
        print(note, flush=True)
    if changed:
        save_figure(figure(changed), Path(out) / "cleaning.png")
    return cleaned


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
    if unc.unidentified_words():
        lines.append(f"  {unc.unidentified_words()}")
    corr = unc.correlation
    pairs = ", ".join(f"{r.names[i]}/{r.names[j]} {corr[i, j]:+.3f}" for i in range(len(r.names)) for j in range(i + 1, len(r.names)))
    if pairs:
        lines.append(f"  correlation: {pairs}")
    split = split_unidentified(r)
    if split is not None:
        lines.append(f"  the C10/C01 split is not identified by uniaxial data (correlation {split:+.3f}); mu0 carries their sum")
    ss = small_strain(r)
    sd = "inf" if ss["mu0_sd_Pa"] is None else f"{ss['mu0_sd_Pa']:.1f}"  # null in material.json: not identified
    lines.append(f"  mu0 = {ss['mu0_Pa']:.1f} Pa, sd {sd} from the noise: {ss['identification']}")
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

    from colonsim.identification.report import strip_stability

    for r in results:
        unstable = strip_stability(r).warning()
        for warning in (misfit_warning(r), unstable and f"{r.curve.name}: {unstable}"):
            if warning:
                print(f"colonsim: warning: {warning}", file=sys.stderr, flush=True)


def calibrate(request: CalibrationRequest, out: Path) -> list:
    """Load the curves ``request`` names, calibrate, write results into ``out``; return the results."""
    from colonsim.files import check_output_folder, output_set
    from colonsim.laws import DEFAULT_LAW, get_law
    from colonsim.limits import (POINTS_RANGE, check_count, check_geometry_mm, check_mesh, check_seed,
                                 check_workers)
    from colonsim.identification.pipeline import Budget
    from colonsim.identification.population import calibrate_curve, calibrate_specimens, population_summary, population_table, write_population
    from colonsim.identification.report import write_calibration
    from colonsim.identification.testdata import mean_curve

    check_output_folder(out)
    if request.compare_laws and request.law is not None:
        raise ColonsimError(f"--compare-laws fits every law; drop --law {request.law}")
    if request.compare_laws and request.per_specimen:
        raise ColonsimError("--compare-laws fits one curve (or the mean curve); drop --per-specimen")
    law = request.law or DEFAULT_LAW
    get_law(law)
    if isinstance(request.points, int) and request.points < POINTS_RANGE[0]:
        raise ColonsimError(f"--points {request.points} is too few to fit 3 parameters; use at least 5 (default 20)")
    check_count("--points", request.points, *POINTS_RANGE)
    check_workers("--workers", request.workers)
    check_seed("--seed", request.seed)
    check_mesh("--mesh", request.mesh)
    for quantity in ("length", "width", "thickness"):
        value = getattr(request, f"{quantity}_mm")
        if value is not None:
            check_geometry_mm(quantity, value, request.given_as)
    curves = _clean(_load_curves(request), request, out)
    budget = request.budget or (Budget.quick() if request.quick else Budget())
    options = dict(law=law, analytic=request.analytic, budget=budget, seed=request.seed, n_points=request.points)
    if not request.analytic:
        options.update(n_length=request.mesh[0], n_width=request.mesh[1])
    per_eval = 1 + budget.designs + budget.cma_max_evaluations + budget.cma_popsize + budget.nm_max_evaluations
    show = request.show_progress
    if request.per_specimen:
        workers = max(1, min(request.workers, len(curves)))
        print(f"fitting {len(curves)} specimens separately ({workers} process{'es' if workers > 1 else ''}, "
              f"{'quick' if request.quick else 'full'} budget) ...", flush=True)
        bar = _Progress(len(curves) if workers > 1 else per_eval * len(curves),
                        "specimen" if workers > 1 else "eval", show)
        try:
            results = calibrate_specimens(curves, workers=workers, progress=bar.evaluation, **options)
        finally:
            bar.close()
        with output_set(out) as stage:  # replaced as a whole, after every file is written
            write_population(results, stage)
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
    if request.compare_laws:
        return _compare_laws(curve, options, per_eval, show, out)
    bar = _Progress(per_eval, "eval", show)
    try:
        result = calibrate_curve(curve, progress=lambda stage, n, e1: bar.evaluation(curve.name, stage, n, e1), **options)
    finally:
        bar.close()
    with output_set(out, files=("material.json",)) as stage:
        write_calibration(result, stage)
    print(_format_result(result))
    _print_warnings([result])
    print(f"results: {out / 'material.json'} (+ history.csv, sensitivity.csv, top10_designs.csv, fit.csv, *.png in {out}/)")
    return [result]


def _compare_laws(curve, options, per_eval, show, out: Path) -> list:
    """``calibrate --compare-laws``: every law of :data:`colonsim.laws.LAWS` on ``curve``, BIC chooses."""
    import pandas as pd

    from colonsim.files import output_set
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
    with output_set(out, files=("material.json", "laws.csv", "laws.png"), folders=("laws",)) as stage:
        write_law_comparison(comparison, stage)
    shown = comparison.table.drop(columns=["note"]).set_index("law")
    with pd.option_context("display.width", 200, "display.max_columns", 30):
        print(shown.to_string(float_format=lambda v: f"{v:.4g}", na_rep="-"))
    print(f"chosen: {comparison.chosen}, {comparison.reason}")
    print(_format_result(comparison.chosen_result))
    _print_warnings([comparison.chosen_result])
    print(f"results: {out / 'material.json'} ({comparison.chosen}), {out / 'laws.csv'}, {out / 'laws.png'}; "
          f"every law's calibration files in {out}/laws/")
    return [comparison.chosen_result]


def anatomy_inputs(segment, centerline, diameter_mm, smoothing_mm) -> dict:
    """The anatomy fields of an :class:`InsertionCase` from the insert options (None: not given).

    ``centerline`` implies segment ``patient``; its diameter is, unless given, the median of the
    file's ``diameter_mm`` column (the profile that runs), else 36 mm. The smoothing tolerance
    goes with a centerline only."""
    from colonsim.catalog import COLON_MODELS, colon_model
    from colonsim.insertion.case.scenario import InsertionCase

    default = InsertionCase()
    if centerline is None:
        if smoothing_mm is not None:
            raise ColonsimError("--centerline-smoothing goes with --centerline; drop it or give the centerline file")
        return {"segment": segment or default.segment,
                "diameter_mm": default.diameter_mm if diameter_mm is None else diameter_mm}
    if segment is not None and not colon_model(segment).reads_centerline:
        raise ColonsimError(f"--centerline is a patient's own colon; drop --segment {segment} (it has its own shape)")
    from colonsim.insertion.anatomy.patient_centerline import load_patient_centerline

    smoothing = default.centerline_smoothing_mm if smoothing_mm is None else smoothing_mm
    if diameter_mm is None:
        diameter_mm = load_patient_centerline(centerline, smoothing).median_diameter_mm or default.diameter_mm
    patient = segment or next(name for name, model in COLON_MODELS.items() if model.reads_centerline)
    return {"segment": patient, "centerline": str(Path(centerline).expanduser().resolve()),
            "centerline_smoothing_mm": smoothing, "diameter_mm": diameter_mm}


def insert(cases, out: Path, vtu=False, snapshot_every=0.02, show=True, max_steps=DEFAULT_MAX_STEPS, animate=False,
           stretch_threshold=None):
    """Run each case, write its folder under ``out`` and a comparison; return the results.

    Every case is checked first, its run time estimated included (:mod:`colonsim.insertion.case.run_budget`):
    a case needing more than ``max_steps`` time steps is refused before any run starts. ``animate``:
    write the movie of every run (True) or of the cases whose keys it holds; ``stretch_threshold``:
    the stretch above which the summaries count the wall as stretched (None: the catalog's)."""
    from colonsim.files import output_set
    from colonsim.insertion.case.run_budget import check_run_budget
    from colonsim.insertion.case.stretch_map import check_threshold

    if stretch_threshold is not None:
        check_threshold(stretch_threshold)
    budgets = [check_run_budget(case, max_steps) for case in cases]
    animated = {c.key() for c in cases} if animate is True else set(animate or ())
    with output_set(out, files=("comparison.csv", "comparison.png")) as stage:  # swapped in when all are written
        results = _run_cases(cases, budgets, out, stage, (vtu, snapshot_every, animated, stretch_threshold), show)
    print(f"comparison: {out}/comparison.csv, {out}/comparison.png")
    return results


def run_folder(result) -> str:
    """The name of a run's folder under ``insert``'s output folder: model and scope (``rsj_SDC``)."""
    return f"{result.case.segment}_{result.summary['scope']['name'].replace(' ', '')}"


def _run_cases(cases, budgets, out, stage, outputs, show):
    """Run ``cases`` and write their folders and the comparison into ``stage`` (what becomes
    ``out``); ``outputs``: VTU files, snapshot interval, keys of the cases animated, stretch threshold."""
    from tqdm import tqdm

    from colonsim.files import save_figure, write_csv
    from colonsim.insertion.case.results import (comparison_table, distal_words, insertion_figure, quasi_static_words,
                                              relax_words, rest_words, write_insertion)
    from colonsim.insertion.case.scenario import run_insertion
    from colonsim.insertion.case.stretch_map import restate_threshold

    vtu, snapshot_every, animated, stretch_threshold = outputs
    results = []
    for case, budget in zip(cases, budgets):
        print(f"{case.segment.upper()} {case.scope.upper()}: {budget.describe()}", flush=True)
        # the bar follows simulated time, which costs wall time evenly (depth does not: the
        # push ramps up and RSF/THF pause), so its time left is meaningful
        bar = tqdm(total=round(budget.simulated_s * 1e3), unit="ms", disable=None if show else True,
                   dynamic_ncols=True, leave=False, mininterval=0.5, desc=f"{case.segment} {case.scope} (simulated ms)")

        def progress(time_s, tip_arc, tip_end, bar=bar):
            bar.update(max(min(round(time_s * 1e3), bar.total) - bar.n, 0))
            bar.set_postfix_str(f"tip {100 * tip_arc:.1f}/{100 * tip_end:.1f} cm", refresh=False)

        try:
            animate = case.key() in animated
            r = run_insertion(case, progress=progress, snapshot_interval=snapshot_every if vtu or animate else None)
        finally:
            bar.close()
        if stretch_threshold is not None:
            restate_threshold(r.summary, r, stretch_threshold)
        name = run_folder(r)
        write_insertion(r, stage / name, vtu=vtu, animate=animate)
        folder = out / name
        results.append(r)
        s = r.summary
        pts = ", ".join(f"{k} {v['deformation_cm']:.2f} cm" for k, v in s["points_cm"].items() if v is not None)
        print(f"{case.segment.upper()} {s['scope']['name']:>8}: final deformation {s['final_deformation_cm']:.2f} cm, "
              f"max {s['max_deformation_cm']:.2f} cm ({pts}); peak contact {s['peak_contact_force_N']:.2f} N, "
              f"peak push {s['peak_push_force_N']:.2f} N; {distal_words(s)}; {quasi_static_words(s['quasi_static'])}; "
              f"{relax_words(s.get('relax'))}{rest_words(s['at_rest'])}; ended_by {s['ended_by']} ({s['end']['reason']}) at "
              f"{s['end']['depth_cm']:.1f} cm; "
              f"{s['steps']} steps in {s['wall_time_s']:.1f} s -> {folder}/")
    table, figure = comparison_table(results), insertion_figure(results)  # both made before either file is replaced
    write_csv(stage / "comparison.csv", table)
    save_figure(figure, stage / "comparison.png")
    return results
