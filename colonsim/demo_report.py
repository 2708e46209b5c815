"""What ``colonsim demo`` leaves behind: ``report.md`` (what ran, its numbers, where each file is)
and the summary it prints last."""

from __future__ import annotations

from pathlib import Path

from colonsim.catalog import PAIN_PROXY

def _cell(v) -> str:
    return f"{v:.3g}" if isinstance(v, float) else str(v)


def ranking_line(rec) -> str:
    """A patient's scopes with their intervals, and their order with its probability."""
    scopes = "  ".join(f"{s['scope'].upper()} {s['mean']:.2f} cm" + ("" if s["low95"] is None else
                       f" [95 % {s['low95']:.2f}, {s['high95']:.2f}]") for s in rec["scopes"])
    order = " < ".join(s.upper() for s in rec["ranking"])
    sure = ("" if rec["p_ranking"] is None else
            f" (probability {100 * rec['p_ranking']:.0f} %; {100 * rec['p_ranking_with_cv_error']:.0f} % "
            "allowing the cross-validated error)")
    return f"{rec['patient']['label']}: {scopes}\n  {order}{sure}"


def _run_section(live, size) -> list:
    from colonsim.insertion.case.results import comparison_table
    from colonsim.markdown import frame_table
    from colonsim.workflows import run_folder

    folder, case = run_folder(live), live.case
    return [f"## 2. The live insertion: {case.scope.upper()} through {case.segment.upper()} (`insertion/`)", "",
            f"D = {case.diameter_mm:g} mm, mu = {case.friction:g}, distal resistance {case.distal_resistance_N:g} N "
            "(colonsim insert's defaults), the calibrated material.", "",
            frame_table(comparison_table([live]), _cell), "",
            f"![the {case.scope.upper()} insertion](insertion/{folder}/insertion.gif)", "",
            "Where it stretched the wall, unrolled (docs/visualisation.md):", "",
            f"![wall-stretch map](insertion/{folder}/stretch_map.png)", ""]


def _predictor_section(predicted) -> list:
    from colonsim.demo_predictor import comparison_line
    from colonsim.surrogate.recommend import format_recommendation

    lines = ["## 3. The shipped predictor (`predictions.json`)", ""]
    if "no_predictions" in predicted:
        return lines + [f"No predictions: {predicted['no_predictions']}.", "",
                        "## 4. The live run beside the predictor", "", "Nothing to compare with.", ""]
    lines += [f"Fitted on {', '.join(predicted['sweeps']) or 'unnamed sweeps'} by the engine of "
              f"{', '.join(c[:10] for c in predicted['engine_commits']) or 'unknown commits'}. Tissue: "
              f"{predicted['tissue_note']}.", ""]
    for rec in predicted["recommendations"]:
        lines += [f"**{rec['patient']['label']}** ({rec['patient']['mapping']})", "", "```",
                  format_recommendation(rec), "```", ""]
    lines += ["## 4. The live run beside the predictor", "",
              f"The same case asked of the predictor at the material's stiffness factor "
              f"{predicted['stiffness_factor']:.3g}:", ""]
    lines += [f"- {comparison_line(row)}" for row in predicted["comparison"]]
    if predicted["settings_apart"]:
        lines += ["", "The live run is not at the predictor's settings (" + "; ".join(predicted["settings_apart"])
                  + "): the difference shows what those settings change, not the predictor's error."]
    return lines + [""]


def _sweep_section(sweep, model, recs) -> list:
    from colonsim.markdown import frame_table
    from colonsim.surrogate.recommend import format_recommendation

    lines = ["## 5. Sweep (`sweep/`)", "",
             f"{sweep.total} runs, {int((sweep.table['status'] == 'ok').sum())} ok. "
             "Table: `sweep/results.parquet`; time series: `sweep/runs/<key>/`; four of its cases on a finer mesh, "
             "whose scatter is the surrogate's noise floor: `replicates/results.parquet`.", "",
             frame_table(sweep.table.sort_values(["diameter_mm", "friction", "scope_diameter_mm"])[
                 ["scope", "diameter_mm", "friction", "point_A_cm", "point_C_cm", "max_deformation_cm",
                  "final_deformation_cm", "peak_contact_force_N"]], _cell), "",
             "## 6. Surrogate of the sweep (`surrogate.json` + `surrogate.npz`)", "", "```", model.report(), "```", "",
             "![surrogate vs colon diameter](surrogate_vs_diameter_mm.png)", "",
             "## 7. Its recommendations (`surrogate_recommendations.json`)", ""]
    for rec in recs:
        lines += [f"**{rec['patient']['label']}** ({rec['patient']['mapping']})", "", "```",
                  format_recommendation(rec), "```", ""]
    return lines + [f"These come from a {sweep.total}-run sweep: the cross-validation above says how far to trust them."]


def write_report(out: Path, calibration, live, predicted, seconds: dict, size: dict, swept=None):
    """``report.md``: what the demo ran, its main numbers and where each file is; ``swept``: the
    sweep, its surrogate and recommendations of ``--sweep``, or None."""
    from colonsim.files import atomic_path

    sd = dict(zip(calibration.names, calibration.uncertainty.std))
    speed = (f", pushed at {size['push_speed']:g} m/s (not the model's quasi-static default: faster and cheaper, "
             "its numbers ring)" if "push_speed" in size else "")
    lines = ["# colonsim demo", "",
             "Generated by `colonsim demo`. Calibration on the bundled SYNTHETIC tensile curves with a reduced "
             f"budget; the insertion on a {size['element_size_mm']:g} mm wall mesh with scope nodes every "
             f"{size['scope_spacing_mm']:g} mm{speed}. "
             "Run times on this machine: " + ", ".join(f"{k} {v:.0f} s" for k, v in seconds.items()) + ".", "",
             "## 1. Calibration (`calibration/`)", ""]
    lines += [f"- {n} = {v:.1f} +- {sd[n]:.1f} Pa (1 sd)" for n, v in calibration.parameter_dict.items()]
    lines += ["- C10 and C01 are strongly anti-correlated: uniaxial tension pins their sum, not the split (README)",
              "- fit, sensitivity and objective figures: `calibration/fit.png`, `calibration/sensitivity.png`, "
              "`calibration/objective.png`; parameters and uncertainty: `calibration/material.json`", ""]
    lines += _run_section(live, size) + _predictor_section(predicted)
    if swept is not None:
        lines += _sweep_section(*swept)
    lines += ["", "`colonsim sweep --preset thesis` runs the source's 39 insertions; `colonsim predict` and "
              "`colonsim recommend` ask the predictor about any patient in its domain."]
    with atomic_path(out / "report.md") as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return out / "report.md"


def print_summary(calibration, live, predicted, target=PAIN_PROXY, swept=None):
    """The demo's findings in a few lines, by ``target`` (default the pain proxy)."""
    from colonsim.demo_predictor import comparison_line
    from colonsim.laws import get_law

    print("\n== summary", flush=True)
    mu0 = get_law(calibration.model["law"]).initial_shear_modulus(calibration.parameters)
    answered = "no_predictions" not in predicted
    factor = f"; tissue stiffness factor {predicted['stiffness_factor']:.3g}" if answered else ""
    print(f"calibration: small-strain shear modulus mu0 = {mu0 / 1e3:.1f} kPa "
          f"({', '.join(f'{n} {v / 1e3:.1f} kPa' for n, v in calibration.parameter_dict.items())}){factor}")
    what = "largest colon deformation over the run" if target == PAIN_PROXY else target
    case = live.case
    print(f"live run, {case.segment.upper()} {case.scope.upper()} D = {case.diameter_mm:g} mm, mu = {case.friction:g}: "
          f"{what} {live.summary[target]:.2f} cm")
    if not answered:
        print(f"predictor: no predictions ({predicted['no_predictions']})")
    else:
        print(f"predictor, {what}, the calibrated material:")
        for rec in predicted["recommendations"]:
            print(ranking_line(rec))
        print("the live run against the predictor's answer for the same case:")
        for row in predicted["comparison"]:
            print(f"  {comparison_line(row)}")
    if swept is not None:
        sweep, model, recs = swept
        cv = model.cv_["rsj"][target]
        unknown = model.error_unknown("rsj", target)
        print(f"surrogate of the demo sweep, {what}: rests on {cv['n']} runs; leave-one-out RMSE {cv['rmse']:.2f} cm"
              + (f"; {unknown}, so no interval or probability below" if unknown else
                 f", 95 % interval coverage {100 * cv['coverage_95']:.0f} %"))
        for rec in recs:
            print(ranking_line(rec))
