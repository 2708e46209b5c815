"""``colonsim demo``: the three workflows end to end on the bundled data, in a few minutes on 2 cores.

1. calibrate Mooney-Rivlin parameters from the bundled SYNTHETIC tensile curves (reduced budget);
2. RSJ insertions of UTC, PDC and SDC (D = 36 mm, mu = 0) with the material just calibrated,
   each with its wall-stretch map, the SDC run also as a movie (``insertion.gif``);
3. a small sweep: RSJ x 3 scopes x D 23/36 mm x mu 0/0.1 (12 runs on local processes, three of
   which are step 2's runs, recorded rather than run again), and 4 of its cases again on a finer
   mesh (the simulation's scatter);
4. a surrogate fitted on that sweep, its noise floored at that scatter (leave-one-out
   cross-validation reported);
5. a scope recommendation for two contrasting patients, by the largest colon deformation over the
   run (the pain proxy, docs/surrogate.md; ``--target final_deformation_cm`` for the end value).

Everything goes to one folder (default ``colonsim_demo/``); ``report.md`` there lists what was
run and where each file is. Rerunning into the same folder skips the sweep runs already done.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

from colonsim.catalog import PAIN_PROXY
from colonsim.workflows import available_cores

DEMO_SWEEP = """
[sweep]
name = "demo"
description = "colonsim demo: RSJ x UTC/PDC/SDC x D 23/36 mm x mu 0/0.1 (12 runs)"

[fixed]
material = "{material}"
{size}

[[grid]]
segment = "rsj"
scope = ["utc", "pdc", "sdc"]
diameter_mm = [23, 36]
friction = [0, 0.1]
"""

# Four of its cases again on a 7 % finer wall mesh: the pairs measure the simulation's own
# scatter, the surrogate's noise floor (docs/surrogate.md, "Noise floor").
DEMO_REPLICATES = """
[sweep]
name = "demo_replicates"
description = "4 cases of the demo sweep on a 7 % finer wall mesh (the simulation's scatter)"

[fixed]
material = "{material}"
{size}
friction = 0.1

[[grid]]
segment = "rsj"
scope = ["utc", "sdc"]
diameter_mm = [23, 36]
"""
REPLICATE_MESH = 0.93  # the replicates' wall mesh over the sweep's

# Two patients at opposite corners of the sweep (presets of surrogate/patients.py).
PATIENTS = (
    {"label": "young African patient", "age": "young", "region": "african"},
    {"label": "older European patient (diverticular disease)", "age": "older", "region": "european"},
)
# points A and C: the largest deformation is modelled as the larger of the two (colonsim.surrogate.larger)
SURROGATE_TARGETS = ("max_deformation_cm", "final_deformation_cm", "point_A_cm", "point_C_cm", "peak_contact_force_N",
                     "max_wall_stretch")


def _section(text):
    print(f"\n== {text}", flush=True)


def calibrate_step(out: Path, show: bool):
    from colonsim.workflows import CalibrationRequest, calibrate

    _section("1/5 calibrate Mooney-Rivlin parameters from the bundled SYNTHETIC tensile data (data/README.md); "
             "reduced budget (--quick)")
    return calibrate(CalibrationRequest(law="mooney_rivlin_3", quick=True, workers=1, show_progress=show), out)[0]


def _toml(size: dict) -> str:
    """The run size (:func:`run_size`) as lines of a sweep's ``[fixed]`` table."""
    return "\n".join(f"{name} = {value!r}" for name, value in size.items())


def run_size(element_size: float, scope_spacing: float, push_speed: float | None) -> dict:
    """The inputs of every demo insertion that set its cost: wall mesh and scope node spacing (mm)
    and, when given, the push speed (m/s; absent: the model's default, and the case keys of
    earlier demos)."""
    size = {"element_size_mm": element_size, "scope_spacing_mm": scope_spacing}
    if push_speed is not None:
        size["push_speed"] = push_speed
    return size


def insertion_step(material: Path, size: dict, out: Path, show: bool):
    from colonsim.workflows import insert
    from colonsim.insertion.case.scenario import InsertionCase

    _section("2/5 RSJ insertions (D = 36 mm, mu = 0) of the three scopes with the calibrated material; "
             "docs/validation/report.md compares this model with the source")
    import numba

    # One thread: on a 2-core machine with anything else running, two Numba threads wait on each
    # other and a run takes up to 8x longer (measured: PDC 147 s instead of 17 s). `colonsim
    # insert --threads 2` is the faster choice on an idle machine.
    numba.set_num_threads(1)
    # the material named as the sweep names it, so that these three runs are cases of the sweep
    cases = [InsertionCase(segment="rsj", scope=s, diameter_mm=36.0, material=material.resolve().as_posix(), **size)
             for s in ("utc", "pdc", "sdc")]
    return insert(cases, out, show=show, animate={cases[-1].key()})  # the movie of the standard scope's run


def record_step_runs(spec, insertions, out: Path) -> int:
    """Record in the sweep folder ``out`` the runs of step 2 that are cases of the sweep (the same
    key: the same inputs, material and mesh), so that the sweep does not run them again; return
    how many were recorded."""
    from colonsim.insertion.study.sweep import SweepStore
    from colonsim.insertion.study.sweep_worker import ok_outcome, utc_now

    cases = {c.key(): c for c in spec.cases}
    with SweepStore(out) as store:
        store.check_same_sweep(cases, spec.source)
        done = store.finished()
        new = [r for r in insertions if r.case.key() in cases and r.case.key() not in done]
        for r in new:
            store.record(cases[r.case.key()], {**ok_outcome(r), "wall_time_s": r.summary["wall_time_s"],
                                               "finished_at": utc_now()})
    return len(new)


def sweep_step(material: Path, size: dict, out: Path, workers: int, show: bool, insertions=()):
    from colonsim.insertion.study.sweep import run_sweep
    from colonsim.insertion.study.sweep_spec import parse_sweep

    text = DEMO_SWEEP.format(material=material.resolve().as_posix(), size=_toml(size))
    spec = parse_sweep(text, origin="demo sweep")
    _section(f"3/5 sweep: {spec.description.split(': ', 1)[1]} on {workers} local process"
             f"{'es' if workers > 1 else ''}")
    reused = record_step_runs(spec, insertions, out)
    if reused:
        print(f"{reused} of its cases are the runs of step 2 (recorded, not run again)")
    report = run_sweep(spec.cases, out, workers=workers, spec=spec, progress=show)
    rate = f" ({report.runs_per_hour:.0f} runs/hour)" if report.ran else ""
    print(f"{report.skipped} already done, {report.ran} run in {report.wall_time_s:.0f} s{rate}: {report.ok} ok, "
          f"{report.failed} failed -> {out / 'results.parquet'}")
    cols = ["scope", "diameter_mm", "friction", "status", "point_A_cm", "point_C_cm", "max_deformation_cm",
            "final_deformation_cm", "peak_contact_force_N", "wall_time_s"]
    table = report.table.sort_values(["diameter_mm", "friction", "scope_diameter_mm"])[cols]
    print(table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    finer = {**size, "element_size_mm": round(REPLICATE_MESH * size["element_size_mm"], 3)}
    text = DEMO_REPLICATES.format(material=material.resolve().as_posix(), size=_toml(finer))
    spec = parse_sweep(text, origin="demo replicates")
    print(f"replicates: {spec.description}")
    again = run_sweep(spec.cases, out.with_name("replicates"), workers=workers, spec=spec, progress=show)
    print(f"{again.skipped} already done, {again.ran} run: {again.ok} ok, {again.failed} failed -> "
          f"{out.with_name('replicates') / 'results.parquet'}")
    return report


def surrogate_step(results: Path, replicates: Path, out: Path):
    from colonsim.files import save_figure
    from colonsim.surrogate.model import SweepSurrogate
    from colonsim.surrogate.plot import prediction_figure
    from colonsim.surrogate.store import save_surrogate
    from colonsim.surrogate.table import read_results

    _section("4/5 Gaussian-process surrogate of the sweep (leave-one-out cross-validation)")
    model = SweepSurrogate(targets=SURROGATE_TARGETS, random_state=0,
                           replicates=read_results(replicates)).fit(read_results(results))
    json_path, _ = save_surrogate(model, out / "surrogate", source=results)
    print(model.report())
    figures = []
    for vs, fixed in (("diameter_mm", {"friction": 0.0}), ("friction", {"diameter_mm": 23.0})):
        path = out / f"surrogate_vs_{vs}.png"
        save_figure(prediction_figure(model, "rsj", vs, fixed), path)
        figures.append(path)
    print(f"model: {json_path} (+ .npz); figures: {', '.join(str(f) for f in figures)}")
    return model, json_path, figures


def recommend_step(model, out: Path, target):
    from colonsim.files import write_json
    from colonsim.surrogate.patients import describe_patient, patient_inputs
    from colonsim.surrogate.recommend import format_recommendation, recommend

    _section("5/5 which scope deforms the colon least? two contrasting patients (RSJ)")
    recs = []
    for p in PATIENTS:
        inputs = patient_inputs("rsj", age=p["age"], region=p["region"])
        rec = recommend(model, "rsj", inputs, target=target)
        rec["patient"] = {"label": p["label"], "age": p["age"], "region": p["region"],
                          "mapping": describe_patient("rsj", age=p["age"], region=p["region"])}
        recs.append(rec)
        print(f"{p['label']} ({rec['patient']['mapping']}):")
        print(format_recommendation(rec))
    write_json(out / "recommendations.json", recs)
    return recs


def _cell(v) -> str:
    return f"{v:.3g}" if isinstance(v, float) else str(v)


def write_report(out: Path, calibration, insertions, sweep, model, recs, seconds: dict, size: dict):
    """``report.md``: what the demo ran, its main numbers and where each file is."""
    from colonsim.files import atomic_path
    from colonsim.markdown import frame_table
    from colonsim.insertion.case.results import comparison_table
    from colonsim.surrogate.recommend import format_recommendation

    from colonsim.workflows import run_folder

    sd = dict(zip(calibration.names, calibration.uncertainty.std))
    animated = run_folder(insertions[-1])  # the run step 2 animates
    speed = (f", pushed at {size['push_speed']:g} m/s (not the model's quasi-static default: faster and cheaper, "
             "its numbers ring)" if "push_speed" in size else "")
    lines = ["# colonsim demo", "",
             "Generated by `colonsim demo`. Calibration on the bundled SYNTHETIC tensile curves with a reduced "
             f"budget; insertions on a {size['element_size_mm']:g} mm wall mesh with scope nodes every "
             f"{size['scope_spacing_mm']:g} mm{speed}. "
             "Run times on this machine: "
             + ", ".join(f"{k} {v:.0f} s" for k, v in seconds.items()) + ".", "",
             "## 1. Calibration (`calibration/`)", ""]
    lines += [f"- {n} = {v:.1f} +- {sd[n]:.1f} Pa (1 sd)" for n, v in calibration.parameter_dict.items()]
    lines += ["- C10 and C01 are strongly anti-correlated: uniaxial tension pins their sum, not the split (README)"]
    lines += ["- fit, sensitivity and objective figures: `calibration/fit.png`, `calibration/sensitivity.png`, "
              "`calibration/objective.png`; parameters and uncertainty: `calibration/material.json`", "",
              "## 2. RSJ insertions, D = 36 mm, mu = 0 (`insertion/`)", "",
              frame_table(comparison_table(insertions), _cell), "",
              "![RSJ insertions](insertion/comparison.png)", "",
              f"The {insertions[-1].summary['scope']['name']} run as a movie (`insertion/{animated}/insertion.gif`) "
              "and where it stretched the wall, unrolled (`stretch_map.png` in every run's folder; "
              "docs/visualisation.md):", "",
              f"![the {insertions[-1].summary['scope']['name']} insertion](insertion/{animated}/insertion.gif)", "",
              f"![wall-stretch map](insertion/{animated}/stretch_map.png)", "",
              "## 3. Sweep (`sweep/`)", "",
              f"{sweep.total} runs, {int((sweep.table['status'] == 'ok').sum())} ok. "
              "Table: `sweep/results.parquet`; time series: `sweep/runs/<key>/`; four of its cases on a finer mesh, "
              "whose scatter is the surrogate's noise floor: `replicates/results.parquet`.", "",
              frame_table(sweep.table.sort_values(["diameter_mm", "friction", "scope_diameter_mm"])[
                  ["scope", "diameter_mm", "friction", "point_A_cm", "point_C_cm", "max_deformation_cm",
                   "final_deformation_cm", "peak_contact_force_N"]], _cell), "",
              "## 4. Surrogate (`surrogate.json` + `surrogate.npz`)", "", "```", model.report(), "```", "",
              "![surrogate vs colon diameter](surrogate_vs_diameter_mm.png)", "",
              "## 5. Recommendations (`recommendations.json`)", ""]
    for rec in recs:
        lines += [f"**{rec['patient']['label']}** ({rec['patient']['mapping']})", "", "```",
                  format_recommendation(rec), "```", ""]
    lines += [f"These numbers come from a {sweep.total}-run sweep: the surrogate's cross-validation above says how far to "
              "trust them. `colonsim sweep --preset thesis` runs the source's 39 insertions."]
    with atomic_path(out / "report.md") as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return out / "report.md"


def print_summary(calibration, insertions, model, recs, target=PAIN_PROXY):
    """The demo's findings in a few lines, by ``target`` (default the pain proxy)."""
    from colonsim.laws import get_law

    _section("summary")
    mu0 = get_law(calibration.model["law"]).initial_shear_modulus(calibration.parameters)
    print(f"calibration: small-strain shear modulus mu0 = {mu0 / 1e3:.1f} kPa "
          f"({', '.join(f'{n} {v / 1e3:.1f} kPa' for n, v in calibration.parameter_dict.items())})")
    what = "largest colon deformation over the run" if target == PAIN_PROXY else target
    print(f"RSJ D = 36 mm, mu = 0, {what}: " + ", ".join(
        f"{r.summary['scope']['name']} {r.summary[target]:.2f} cm" for r in insertions))
    cv = model.cv_["rsj"][target]
    unknown = model.error_unknown("rsj", target)
    print(f"surrogate of the {what}: rests on {cv['n']} runs; leave-one-out RMSE {cv['rmse']:.2f} cm"
          + (f"; {unknown}, so no interval or probability below" if unknown else
             f", 95 % interval coverage {100 * cv['coverage_95']:.0f} %"))
    for rec in recs:
        scopes = "  ".join(f"{s['scope'].upper()} {s['mean']:.2f} cm" + ("" if s["low95"] is None else
                           f" [95 % {s['low95']:.2f}, {s['high95']:.2f}]") for s in rec["scopes"])
        order = " < ".join(s.upper() for s in rec["ranking"])
        sure = ("" if rec["p_ranking"] is None else
                f" (probability {100 * rec['p_ranking']:.0f} %; {100 * rec['p_ranking_with_cv_error']:.0f} % "
                "allowing the cross-validated error)")
        print(f"{rec['patient']['label']}: {scopes}\n  {order}{sure}")


@dataclass(frozen=True)
class DemoOptions:
    """Where the demo writes, its wall mesh and scope node spacing (mm; None: the model's default),
    its push speed (m/s; None: the model's default), sweep processes (None: up to 2 cores), bars,
    and the deformation the summary and the recommendations rank by."""

    out: Path = Path("colonsim_demo")
    element_size_mm: float = 3.0
    scope_spacing_mm: float | None = None
    push_speed: float | None = None
    workers: int | None = None
    show_progress: bool = True
    target: str = PAIN_PROXY


def run_demo(options: DemoOptions):
    """Run the five steps into ``options.out`` and print the summary."""
    out = Path(options.out)
    show = options.show_progress
    workers = options.workers or min(2, available_cores())
    scope_spacing = options.scope_spacing_mm
    if scope_spacing is None:
        from colonsim.insertion.case.insertion_case import InsertionCase

        scope_spacing = InsertionCase.scope_spacing_mm  # the model's default
    size = run_size(options.element_size_mm, scope_spacing, options.push_speed)
    seconds = {}
    t0 = time.perf_counter()
    calibration = calibrate_step(out / "calibration", show)
    seconds["calibration"] = time.perf_counter() - t0
    material = out / "calibration" / "material.json"
    t = time.perf_counter()
    insertions = insertion_step(material, size, out / "insertion", show)
    seconds["insertions"] = time.perf_counter() - t
    t = time.perf_counter()
    sweep = sweep_step(material, size, out / "sweep", workers, show, insertions)
    seconds["sweep"] = time.perf_counter() - t
    t = time.perf_counter()
    model, _, _ = surrogate_step(out / "sweep" / "results.parquet", out / "replicates" / "results.parquet", out)
    recs = recommend_step(model, out, options.target)
    seconds["surrogate and recommendations"] = time.perf_counter() - t
    report = write_report(out, calibration, insertions, sweep, model, recs, seconds, size)
    print_summary(calibration, insertions, model, recs, options.target)
    print(f"\ndemo finished in {time.perf_counter() - t0:.0f} s; report: {report}; every file in {out}/")
    print("Next: `colonsim sweep --preset thesis` runs the source's 39 insertions; `colonsim surrogate fit` and "
          "`colonsim recommend` work on its results.parquet the same way.")
