"""``colonsim demo`` end to end on a coarse wall mesh: every step runs and writes what the README promises.

The full demo uses the 3 mm mesh (a few minutes on 2 cores); the smoke size (a 5 mm wall mesh,
scope nodes every 10 mm, pushed at 0.6 m/s: colonsim.catalog) keeps this check near four minutes
on a slow machine. Its numbers are not physics (too coarse, too fast), so only their consistency
is checked.
"""

import json

import pandas as pd
import pytest

from colonsim.catalog import SMOKE_ELEMENT_MM, SMOKE_PUSH_SPEED, SMOKE_SCOPE_SPACING_MM
from colonsim.cli import main
from colonsim.demo import REPLICATE_MESH


@pytest.mark.slow
def test_demo_runs_every_workflow_and_writes_one_folder(tmp_path, capsys):
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), "--element-size", str(SMOKE_ELEMENT_MM),
                 "--scope-spacing", str(SMOKE_SCOPE_SPACING_MM), "--push-speed", str(SMOKE_PUSH_SPEED),
                 "--no-progress"]) in (None, 0)
    text = capsys.readouterr().out
    for step in ("1/5", "2/5", "3/5", "4/5", "5/5", "summary"):
        assert f"== {step}" in text
    material = json.loads((out / "calibration" / "material.json").read_text())
    assert material["parameters"]["C11"] > 0
    for scope in ("UTC", "PDC", "SDC"):
        assert (out / "insertion" / f"rsj_{scope}" / "timeseries.csv").is_file()
    table = pd.read_parquet(out / "sweep" / "results.parquet")
    assert len(table) == 12 and (table["status"] == "ok").all()
    # step 2's runs are cases of the sweep: recorded there with their own numbers, not run again
    assert "3 of its cases are the runs of step 2" in text
    for scope in ("UTC", "PDC", "SDC"):
        run = json.loads((out / "insertion" / f"rsj_{scope}" / "summary.json").read_text())
        row = table[table["key"] == run["key"]]
        assert len(row) == 1 and row["max_deformation_cm"].item() == run["max_deformation_cm"]
    assert set(table["diameter_mm"]) == {23.0, 36.0} and set(table["friction"]) == {0.0, 0.1}
    replicates = pd.read_parquet(out / "replicates" / "results.parquet")
    assert len(replicates) == 4 and set(replicates["element_size_mm"]) == {round(REPLICATE_MESH * SMOKE_ELEMENT_MM, 3)}
    assert (out / "surrogate.json").is_file() and (out / "surrogate.npz").is_file()
    doc = json.loads((out / "surrogate.json").read_text())
    assert doc["segments"]["rsj"]["models"]["max_deformation_cm"]["scatter"]["pairs"] == 4
    recs = json.loads((out / "recommendations.json").read_text())
    assert [r["patient"]["region"] for r in recs] == ["african", "european"]
    summary = text.split("== summary")[1]
    assert "largest colon deformation over the run" in summary and "rests on 12 runs" in summary
    for rec in recs:
        assert rec["target"] == "max_deformation_cm" and rec["n_runs"] == 12
        # a number where the model vouches for its error, else the reason instead of one
        assert (rec["error_unknown"] is None) == (rec["p_ranking"] is not None)
        assert rec["p_ranking"] is None or 0.0 <= rec["p_ranking"] <= 1.0
        assert sorted(rec["ranking"]) == ["pdc", "sdc", "utc"]
        means = [s["mean"] for s in rec["scopes"]]
        assert means == sorted(means)  # the ranking is by predicted deformation
    report = (out / "report.md").read_text()
    assert (f"{SMOKE_ELEMENT_MM:g} mm wall mesh with scope nodes every {SMOKE_SCOPE_SPACING_MM:g} mm, pushed at "
            f"{SMOKE_PUSH_SPEED:g} m/s") in report
    assert set(table["push_speed"]) == set(replicates["push_speed"]) == {SMOKE_PUSH_SPEED}
    assert "![RSJ insertions](insertion/comparison.png)" in report
    for figure in ("insertion/comparison.png", "surrogate_vs_diameter_mm.png", "surrogate_vs_friction.png",
                   "insertion/rsj_SDC/insertion.gif", "insertion/rsj_SDC/stretch_map.png"):
        assert (out / figure).stat().st_size > 10_000
    # the SDC run is the one animated, every run has its stretch map, the sweep its stretched area
    assert "![the SDC insertion](insertion/rsj_SDC/insertion.gif)" in report
    assert not (out / "insertion" / "rsj_UTC" / "insertion.gif").exists()
    assert (out / "insertion" / "rsj_UTC" / "stretch_map.npz").is_file()
    assert (table["wall_area_stretched_cm2"] > 0).all()
