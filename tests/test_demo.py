"""``colonsim demo`` end to end on a coarse wall mesh: every step runs and writes what the README promises.

The full demo uses the 3 mm mesh (a few minutes on 2 cores); the smoke size (a 5 mm wall mesh,
scope nodes every 10 mm, pushed at 0.6 m/s: colonsim.catalog) keeps this check near four minutes
on a slow machine, ``--sweep`` included. Its numbers are not physics (too coarse, too fast), so
only their consistency is checked. The predictor it asks is a tiny one fitted on a SYNTHETIC table
(tests/predictor_fixture.py), put in the shipped one's place by ``COLONSIM_PREDICTOR``; the demo
without any predictor is checked on the same runs.
"""

import json
import math
from types import SimpleNamespace

import pandas as pd
import pytest

from colonsim.catalog import SMOKE_ELEMENT_MM, SMOKE_PUSH_SPEED, SMOKE_SCOPE_SPACING_MM
from colonsim.demo import DemoOptions, Sections, run_demo
from colonsim.demo_predictor import NO_PREDICTOR, comparison, comparison_line, predictor_step
from colonsim.demo_report import write_report
from colonsim.demo_sweep import REPLICATE_MESH
from colonsim.identification.search import Budget
from colonsim.insertion.case.insertion_case import InsertionCase
from colonsim.surrogate import predictor

from predictor_fixture import synthetic_patient_table

# the calibration at a third of --quick's evaluations (the demo's own budget took 24 of its 80 s here):
# its material only has to be a calibrated one, as the smoke mesh's runs only have to run
CALIBRATION = Budget(designs=12, cma_popsize=6, cma_max_evaluations=36, nm_max_evaluations=60)


def tiny_rsj_predictor(folder):
    """A predictor of RSJ fitted on a SYNTHETIC table whose friction reaches both ends of its range
    (the two patients' 0 and 0.1)."""
    from colonsim.surrogate.predictor_fit import fit_predictor, save_predictor

    table = synthetic_patient_table(n=60, segment="rsj", ranges={"angle_deg": (0.0, 0.0), "diameter_mm": (20.0, 40.0)})
    table.loc[:1, "friction"] = [0.0, 0.1]
    model = fit_predictor({"patient_space_rsj": table}, targets=("max_deformation_cm", "final_deformation_cm"),
                          n_restarts=0, hyperparameter_draws=0)
    return save_predictor(model, folder / "patient_space")[0]


@pytest.mark.slow
def test_demo_runs_every_workflow_and_writes_one_folder(tmp_path, capsys, monkeypatch):
    out = tmp_path / "demo"
    monkeypatch.setattr(predictor, "SHIPPED", tmp_path / "none")  # no predictor ships: said in one line
    monkeypatch.delenv(predictor.OVERRIDE, raising=False)
    made = run_demo(DemoOptions(out=out, element_size_mm=SMOKE_ELEMENT_MM, scope_spacing_mm=SMOKE_SCOPE_SPACING_MM,
                                push_speed=SMOKE_PUSH_SPEED, sweep=True, show_progress=False,
                                calibration_budget=CALIBRATION))
    text = capsys.readouterr().out
    for step in (1, 2, 3, 5, 6, 7):
        assert f"== {step}/7 " in text
    # no predictor: one line, and no comparison with the live run (its section is not printed)
    assert "== 4/7" not in text and text.count("no predictions: this colonsim ships no fitted") == 1
    material = json.loads((out / "calibration" / "material.json").read_text())
    assert material["parameters"]["C11"] > 0
    run = json.loads((out / "insertion" / "rsj_SDC" / "summary.json").read_text())
    assert (out / "insertion" / "rsj_SDC" / "timeseries.csv").is_file() and not (out / "predictions.json").exists()
    table = pd.read_parquet(out / "sweep" / "results.parquet")
    assert len(table) == 12 and (table["status"] == "ok").all()
    # the live run is a case of the sweep: recorded there with its own numbers, not run again
    assert "1 of its cases is the live run" in text
    row = table[table["key"] == run["key"]]
    assert len(row) == 1 and row["max_deformation_cm"].item() == run["max_deformation_cm"]
    assert set(table["diameter_mm"]) == {23.0, 36.0} and set(table["friction"]) == {0.0, 0.1}
    replicates = pd.read_parquet(out / "replicates" / "results.parquet")
    assert len(replicates) == 4 and set(replicates["element_size_mm"]) == {round(REPLICATE_MESH * SMOKE_ELEMENT_MM, 3)}
    doc = json.loads((out / "surrogate.json").read_text())
    assert doc["segments"]["rsj"]["models"]["max_deformation_cm"]["scatter"]["pairs"] == 4
    recs = json.loads((out / "surrogate_recommendations.json").read_text())
    assert [r["patient"]["region"] for r in recs] == ["african", "european"]
    summary = text.split("== summary")[1]
    assert f"predictor: no predictions ({NO_PREDICTOR})" in summary and "rests on 12 runs" in summary
    for rec in recs:
        assert rec["target"] == "max_deformation_cm" and rec["n_runs"] == 12
        # a number where the model vouches for its error, else the reason instead of one
        assert (rec["error_unknown"] is None) == (rec["p_ranking"] is not None)
        assert sorted(rec["ranking"]) == ["pdc", "sdc", "utc"]
        means = [s["mean"] for s in rec["scopes"]]
        assert means == sorted(means)  # the ranking is by predicted deformation
    report = (out / "report.md").read_text()
    assert f"No predictions: {NO_PREDICTOR}." in report and "## 7. Its recommendations" in report
    assert (f"{SMOKE_ELEMENT_MM:g} mm wall mesh with scope nodes every {SMOKE_SCOPE_SPACING_MM:g} mm, pushed at "
            f"{SMOKE_PUSH_SPEED:g} m/s") in report
    assert set(table["push_speed"]) == set(replicates["push_speed"]) == {SMOKE_PUSH_SPEED}
    for figure in ("insertion/comparison.png", "surrogate_vs_diameter_mm.png", "surrogate_vs_friction.png",
                   "insertion/rsj_SDC/insertion.gif", "insertion/rsj_SDC/stretch_map.png"):
        assert (out / figure).stat().st_size > 10_000
    assert "![the SDC insertion](insertion/rsj_SDC/insertion.gif)" in report
    assert (table["wall_area_stretched_cm2"] > 0).all()

    # the same live run asked of a predictor (a SYNTHETIC one in the shipped one's place)
    monkeypatch.setenv(predictor.OVERRIDE, str(tiny_rsj_predictor(tmp_path)))
    predicted = predictor_step(out / "calibration" / "material.json", made["live"], "max_deformation_cm", Sections(4))
    text = capsys.readouterr().out
    assert "== 1/4 the predictor shipped" in text and "== 2/4 the live run beside" in text
    assert "material.json maps to tissue stiffness" in text
    assert predicted["sweeps"] == ["patient_space_rsj"] and 0.6 < predicted["stiffness_factor"] < 1.6
    for rec in predicted["recommendations"]:
        assert sorted(rec["ranking"]) == ["pdc", "sdc", "utc"] and rec["tissue"]["draws"] > 1
        assert all(s["low95"] < s["mean"] < s["high95"] for s in rec["scopes"])
    assert "distal resistance 5 N" in predicted["recommendations"][0]["patient"]["mapping"]
    assert [r["output"] for r in predicted["comparison"]] == ["max_deformation_cm", "final_deformation_cm"]
    assert predicted["comparison"][0]["live"] == run["max_deformation_cm"]
    for line in (comparison_line(r) for r in predicted["comparison"]):
        assert ("inside the interval" in line) != ("OUTSIDE the interval" in line) and line in text
    # the smoke run is not at the predictor's settings, and the demo says so rather than score it
    assert any(s.startswith("element_size_mm 5 (the predictor's runs: 3)") for s in predicted["settings_apart"])
    assert "not the predictor's error" in text
    write_report(out, made["calibration"], made["live"], predicted, {}, made["size"], made["swept"])
    report = (out / "report.md").read_text()
    assert "## 4. The live run beside the predictor" in report and NO_PREDICTOR not in report
    assert "**older European patient (diverticular disease)**" in report


def test_the_live_value_is_said_inside_or_outside_the_interval_both_ways():
    predicted = pd.Series({"max_deformation_cm": 2.0, "max_deformation_cm_low95": 1.8, "max_deformation_cm_high95": 2.2,
                           "final_deformation_cm": 1.5, "final_deformation_cm_low95": math.nan,
                           "final_deformation_cm_high95": math.nan})
    inside, unknown = comparison({"max_deformation_cm": 2.1, "final_deformation_cm": 1.4}, predicted)
    assert inside["inside"] is True and "inside the interval" in comparison_line(inside)
    assert unknown["inside"] is None and "states no interval" in comparison_line(unknown)
    outside = comparison({"max_deformation_cm": 2.3}, predicted, targets=("max_deformation_cm",))[0]
    assert outside["inside"] is False and "OUTSIDE the interval" in comparison_line(outside)


def test_without_a_predictor_the_demo_says_so_in_one_line_and_predicts_nothing(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(predictor, "SHIPPED", tmp_path / "none")
    monkeypatch.delenv(predictor.OVERRIDE, raising=False)
    assert predictor_step(tmp_path / "material.json", None, "max_deformation_cm", Sections(4)) == \
        {"no_predictions": NO_PREDICTOR}
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[0] == "== 1/4 the predictor shipped with colonsim: the calibrated material's patients, the scopes ranked"
    assert len(lines) == 2 and lines[1].startswith("no predictions: this colonsim ships no fitted predictor (")


def test_a_material_outside_the_predictors_domain_gets_no_predictions_and_one_line(tmp_path, capsys, monkeypatch):
    """A calibrated wall three times the reference's: the predictor refuses it, and the demo says why."""
    from colonsim.data import REFERENCE_MATERIAL_PATH

    doc = json.loads(REFERENCE_MATERIAL_PATH.read_text())
    doc["parameters"] = {k: 3 * v for k, v in doc["parameters"].items()}
    doc.pop("covariance_Pa2", None)
    (tmp_path / "stiff.json").write_text(json.dumps(doc))
    monkeypatch.setenv(predictor.OVERRIDE, str(tiny_rsj_predictor(tmp_path)))
    live = SimpleNamespace(case=InsertionCase(), summary={})  # the refusal comes before any live number is read
    why = predictor_step(tmp_path / "stiff.json", live, "max_deformation_cm", Sections(4))["no_predictions"]
    assert "does not answer for this material" in why and "tissue stiffness 3 outside" in why
    out = capsys.readouterr().out
    assert "no predictions for this material:" in out and "tissue stiffness 3 outside" in out
