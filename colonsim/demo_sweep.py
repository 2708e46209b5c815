"""``colonsim demo --sweep``: a small sweep of the demo's own, a surrogate fitted on it and its
recommendation for the demo's two patients, for who wants to see a sweep and a fit happen.

The sweep: RSJ x UTC/PDC/SDC x D 23/36 mm x mu 0/0.1 (12 runs on local processes, one of which is
the demo's live run, recorded rather than run again), and 4 of its cases again on a finer mesh (the
simulation's scatter, the surrogate's noise floor). The surrogate's leave-one-out cross-validation
says how far 12 runs carry.
"""

from __future__ import annotations

from pathlib import Path

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

# points A and C: the largest deformation is modelled as the larger of the two (colonsim.surrogate.larger)
SURROGATE_TARGETS = ("max_deformation_cm", "final_deformation_cm", "point_A_cm", "point_C_cm", "peak_contact_force_N",
                     "max_wall_stretch")


def _toml(size: dict) -> str:
    """The run size (:func:`run_size`) as lines of a sweep's ``[fixed]`` table."""
    return "\n".join(f"{name} = {value!r}" for name, value in size.items())


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


def sweep_step(material: Path, size: dict, out: Path, workers: int, show: bool, section, insertions=()):
    from colonsim.insertion.study.sweep import run_sweep
    from colonsim.insertion.study.sweep_spec import parse_sweep

    text = DEMO_SWEEP.format(material=material.resolve().as_posix(), size=_toml(size))
    spec = parse_sweep(text, origin="demo sweep")
    section(f"sweep: {spec.description.split(': ', 1)[1]} on {workers} local process"
            f"{'es' if workers > 1 else ''}")
    reused = record_step_runs(spec, insertions, out)
    if reused:
        print(f"{reused} of its cases {'is the live run' if reused == 1 else 'are the live runs'} (recorded, not run "
              "again)")
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


def surrogate_step(results: Path, replicates: Path, out: Path, section):
    from colonsim.files import save_figure
    from colonsim.surrogate.model import SweepSurrogate
    from colonsim.surrogate.plot import prediction_figure
    from colonsim.surrogate.store import save_surrogate
    from colonsim.surrogate.table import read_results

    section("Gaussian-process surrogate of the sweep (leave-one-out cross-validation)")
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


def recommend_step(model, out: Path, target, section):
    from colonsim.demo_predictor import patient_recommendations
    from colonsim.files import write_json

    section("which scope deforms the colon least? the same two patients, asked of the sweep's surrogate")
    recs = patient_recommendations(model, "rsj", target)
    write_json(out / "surrogate_recommendations.json", recs)
    return recs
