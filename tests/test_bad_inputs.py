"""The bad-input corpus: every command refuses bad input with one line, exit code 2, no traceback,
and leaves what was already written byte-identical.

All cases share one workspace holding earlier good results (a fitted surrogate, a prediction, a
recommendation, a sweep folder, insertion and calibration folders) and the bad inputs; each case
checks that no file or folder of the workspace changed, appeared or vanished. The CLI runs
in-process (``colonsim.cli.main``), so a case costs milliseconds unless it must build a model.
"""

import json
import os
from pathlib import Path

import numpy as np
import pytest

from colonsim.data import TENSILE_DIR
from colonsim.cli import main
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH
from colonsim.insertion.study.sweep import SweepStore
from colonsim.insertion.study.sweep_spec import parse_sweep
from colonsim.surrogate.synthetic import synthetic_sweep

CURVE = str(TENSILE_DIR / "specimen_01.csv")
GEOMETRY = ["--length", "100", "--width", "25", "--thickness", "2"]
SWEEP_A = '[sweep]\nname = "a"\n[[grid]]\nsegment = "straight"\nscope = ["utc", "sdc"]\n'
UNWRITABLE = "/proc/colonsim-test/out"  # nobody, root included, creates files in /proc
linux_only = pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs /proc")


def _material(path, scale=None, parameters=None):
    doc = json.loads(REFERENCE_MATERIAL_PATH.read_text())
    if scale is not None:
        doc["parameters"] = {k: v * scale for k, v in doc["parameters"].items()}
    if parameters is not None:
        doc["parameters"] = parameters
    path.write_text(json.dumps(doc))


@pytest.fixture(scope="module")
def ws(tmp_path_factory):
    """The workspace: earlier good results and the bad inputs the cases use."""
    ws = tmp_path_factory.mktemp("corpus")
    table = synthetic_sweep(design="grid", noise_cm=0.02, seed=1)
    table.to_parquet(ws / "results.parquet")
    table.to_csv(ws / "results.csv", index=False)
    assert main(["surrogate", "fit", str(ws / "results.parquet"), "-o", str(ws / "model"), "--restarts", "0",
                 "--targets", "max_deformation_cm"]) == 0
    table.drop(columns=["diameter_mm"]).to_csv(ws / "nodiam.csv", index=False)
    assert main(["surrogate", "fit", str(ws / "nodiam.csv"), "-o", str(ws / "nodiam"), "--restarts", "0",
                 "--targets", "max_deformation_cm"]) == 0
    (ws / "good").mkdir()
    assert main(["predict", str(ws / "model"), "--segment", "rsj", "--diameter", "30", "--friction", "0",
                 "-o", str(ws / "good" / "pred.json")]) == 0
    assert main(["recommend", str(ws / "model"), "--segment", "rsj", "--diameter", "30", "--friction", "0",
                 "-o", str(ws / "good" / "rec.json")]) == 0

    def variant(name, edit):
        t = table.copy()
        edit(t)
        t.to_csv(ws / name, index=False)

    variant("blank_segment.csv", lambda t: t.__setitem__("segment", t["segment"].where(t.index != 3, None)))
    variant("huge_output.csv", lambda t: t.__setitem__("final_deformation_cm",
                                                       np.where(t.index == 3, 1e300, t["final_deformation_cm"])))
    variant("text_output.csv", lambda t: t.__setitem__("final_deformation_cm",
                                                       t["final_deformation_cm"].astype(object).where(t.index != 5, "about 3")))
    variant("no_ok_run.csv", lambda t: t.__setitem__("status", "failed"))
    (ws / "q_text.csv").write_text("segment,scope,diameter_mm,friction\nrsj,sdc,wide,0\n")
    (ws / "q_inf.csv").write_text("segment,scope,diameter_mm,friction\nrsj,sdc,30,inf\n")

    # earlier results of the other commands (contents stand for any earlier output)
    for folder, name in (("good_insert", "comparison.csv"), ("good_cal", "material.json"), ("good_demo", "report.md")):
        (ws / folder).mkdir()
        (ws / folder / name).write_text("earlier results\n")
    spec = parse_sweep(SWEEP_A)
    with SweepStore(ws / "sweep_a") as store:  # an earlier sweep: one run recorded (as failed: no simulation needed)
        case = spec.cases[0]
        store.record(case, {"key": case.key(), "status": "failed", "error": "RuntimeError: x", "wall_time_s": 1.0,
                            "finished_at": "2026-01-01T00:00:00+00:00"})
    (ws / "sweep_a" / "sweep.json").write_text(json.dumps(spec.document()))

    (ws / "a_file").write_text("a regular file\n")
    (ws / "a_dir.json").mkdir()
    (ws / "model_as_dir.json").mkdir()
    (ws / "nanrow.csv").write_text("displacement [mm],force [N]\n1,1\n2,nan\n3,3\n")
    (ws / "not_json.json").write_text("{C10: 1")
    _material(ws / "stiff.json", scale=1e10)
    toml = {
        "sweep_b.toml": '[sweep]\nname = "b"\n[[grid]]\nsegment = "straight"\nscope = ["pdc"]\n',
        "huge_lhs.toml": "[lhs]\nsamples = 100000000\nfriction = [0, 0.1]\n",
        "huge_grid.toml": "[[grid]]\n" + "\n".join(f"{k} = {list(range(1, 12))}" for k in
                                                   ("diameter_mm", "angle_deg", "wall_thickness_mm", "push_speed", "ramp_s")),
        "fixed_only.toml": "[fixed]\nfriction = 0.1\n",
        "empty_grid.toml": "[grid]\n",
        "inf_value.toml": "[[grid]]\nangle_deg = [0, inf]\n",
        "inf_range.toml": "[lhs]\nsamples = 4\nangle_deg = [0, inf]\n",
        "nan_value.toml": "[[grid]]\nfriction = nan\n",
        "not_toml.toml": "[grid\n",
        "typo.toml": '[grid]\nsegmnt = "rsj"\n',
        "estimate.toml": '[[grid]]\ntime_step_estimate = "fast"\n',
        "surface.toml": '[[grid]]\ncontact_surface = "edges"\n',
        "subdivision.toml": '[[grid]]\ncontact_surface = "faces"\ncontact_face_subdivision = 0\n',
        "stiff.toml": f'[fixed]\nmaterial = "{(ws / "stiff.json").as_posix()}"\n[[grid]]\nscope = ["utc", "sdc"]\n',
    }
    for name, text in toml.items():
        (ws / name).write_text(text)
    return ws


def _snapshot(root: Path) -> dict:
    """Every file's bytes and every folder, under ``root``."""
    return {p.relative_to(root).as_posix(): (p.read_bytes() if p.is_file() else None)
            for p in sorted(root.rglob("*"))}


# (command line with {ws} for the workspace, words the one-line error must contain)
CASES = [
    # calibrate: one-line errors it already gave (its other checks are tested with the calibration)
    (["calibrate", "--curve", "{ws}/missing.csv", *GEOMETRY, "--out", "{ws}/good_cal"], "not found"),
    (["calibrate", "--curve", CURVE, *GEOMETRY, "--displacement-unit", "furlong", "--out", "{ws}/good_cal"], "furlong"),
    (["calibrate", "--curve", CURVE, *GEOMETRY, "--force-unit", "stone", "--out", "{ws}/good_cal"], "stone"),
    (["calibrate", "--curve", "{ws}/nanrow.csv", *GEOMETRY, "--out", "{ws}/good_cal"], "NaN or infinite value at data row 2"),
    (["calibrate", "--curve", CURVE, "--length", "100", "--width", "25", "--out", "{ws}/good_cal"], "thickness is missing"),
    (["calibrate", "--law", "ogden", "--out", "{ws}/good_cal"], "unknown hyperelastic law 'ogden'"),
    (["calibrate", "--points", "2", "--out", "{ws}/good_cal"], "--points: 2 is outside 5-200"),
    (["calibrate", "--curve", CURVE, "--manifest", str(TENSILE_DIR / "manifest.csv"), "--out", "{ws}/good_cal"], "not both"),
    # insert
    (["insert", "--segment", "rsx", "--out", "{ws}/good_insert"], "unknown colon segment 'rsx'"),
    (["insert", "--scope", "huge", "--out", "{ws}/good_insert"], "unknown scope 'huge'"),
    (["insert", "--diameter", "5", "--out", "{ws}/good_insert"], "diameter_mm = 5 is outside"),
    (["insert", "--friction", "inf", "--out", "{ws}/good_insert"], "'inf' is not a finite number"),
    (["insert", "--angle", "nan", "--out", "{ws}/good_insert"], "'nan' is not a finite number"),
    (["insert", "--friction", "-1", "--out", "{ws}/good_insert"], "friction = -1 is outside [0, 1]"),
    (["insert", "--wall-thickness", "abc", "--out", "{ws}/good_insert"], "'abc' is not a number"),
    (["insert", "--material", "{ws}/missing.json", "--out", "{ws}/good_insert"], "not found"),
    (["insert", "--material", "{ws}/not_json.json", "--out", "{ws}/good_insert"], "not valid JSON"),
    (["insert", "--material", "{ws}/stiff.json", "--out", "{ws}/good_insert"], "1e+10 times stiffer"),
    (["insert", "--max-steps", "0", "--out", "{ws}/good_insert"], "must be at least 1"),
    (["insert", "--out", "{ws}/a_file"], "a_file is an existing file, not a folder"),
    (["insert", "--out", "{ws}/a_file/run"], "a_file is a file, not a folder"),
    pytest.param(["insert", "--out", UNWRITABLE], "cannot write in /proc", marks=linux_only),
    # sweep
    (["sweep", "{ws}/missing.toml", "--out", "{ws}/sweep_a"], "not found"),
    (["sweep", "{ws}/not_toml.toml", "--out", "{ws}/sweep_a"], "not valid TOML"),
    (["sweep", "{ws}/typo.toml", "--out", "{ws}/sweep_a"], "did you mean 'segment'?"),
    (["sweep", "{ws}/estimate.toml", "--out", "{ws}/sweep_a"],
     "time_step_estimate = 'fast' is not one of bounds, global; give \"global\" (the default) or \"bounds\""),
    (["insert", "--time-step-estimate", "fast", "--out", "{ws}/ins"], "invalid choice: 'fast'"),
    (["sweep", "{ws}/surface.toml", "--out", "{ws}/sweep_a"],
     "contact_surface = 'edges' is not one of nodes, faces; give \"nodes\" or \"faces\""),
    (["sweep", "{ws}/subdivision.toml", "--out", "{ws}/sweep_a"],
     "contact_face_subdivision = 0 is not a whole number from 1 to 8"),
    (["insert", "--contact-surface", "edges", "--out", "{ws}/ins"], "invalid choice: 'edges'"),
    (["sweep", "{ws}/fixed_only.toml", "--out", "{ws}/sweep_a"], "only [fixed] values"),
    (["sweep", "{ws}/empty_grid.toml", "--out", "{ws}/sweep_a"], "[grid] is empty"),
    (["sweep", "{ws}/inf_value.toml", "--out", "{ws}/sweep_a"], "angle_deg = inf; give a finite number"),
    (["sweep", "{ws}/inf_range.toml", "--out", "{ws}/sweep_a"], "angle_deg = inf; give a finite number"),
    (["sweep", "{ws}/nan_value.toml", "--out", "{ws}/sweep_a"], "friction = nan; give a finite number"),
    (["sweep", "{ws}/huge_lhs.toml", "--dry-run", "--out", "{ws}/sweep_a"], "asks for 100,000,000 runs"),
    (["sweep", "{ws}/huge_grid.toml", "--dry-run", "--out", "{ws}/sweep_a"], "asks for 161,051 runs"),
    (["sweep", "{ws}/stiff.toml", "--dry-run", "--out", "{ws}/sweep_a"], "1e+10 times stiffer"),
    (["sweep", "{ws}/sweep_b.toml", "--out", "{ws}/sweep_a"], "holds another sweep ('a')"),
    (["sweep", "{ws}/sweep_b.toml", "--dry-run", "--out", "{ws}/sweep_a"], "holds another sweep ('a')"),
    (["sweep", "--preset", "smoke", "--dry-run", "--out", "{ws}/a_file"], "a_file is an existing file"),
    (["sweep", "--preset", "smoke", "--workers", "-3", "--out", "{ws}/sweep_a"], "must be at least 1"),
    pytest.param(["sweep", "--preset", "smoke", "--out", UNWRITABLE], "cannot write in /proc", marks=linux_only),
    # surrogate fit / info / plot
    (["surrogate", "fit", "{ws}/missing.parquet", "-o", "{ws}/model"], "not found"),
    (["surrogate", "fit", "{ws}/blank_segment.csv", "-o", "{ws}/model"], "1 row(s) have no segment (run rsj-0003)"),
    (["surrogate", "fit", "{ws}/huge_output.csv", "-o", "{ws}/model", "--targets", "final_deformation_cm"],
     "the fit is not finite"),
    (["surrogate", "fit", "{ws}/text_output.csv", "-o", "{ws}/model"], "holds 'about 3', not a number"),
    (["surrogate", "fit", "{ws}/no_ok_run.csv", "-o", "{ws}/model"], "no run with status 'ok'"),
    (["surrogate", "fit", "{ws}/results.csv", "-o", "{ws}/model", "--targets", "pain"], "no column pain"),
    (["surrogate", "fit", "{ws}/results.csv", "-o", "{ws}/model_as_dir"], "model_as_dir.json is a folder"),
    (["surrogate", "fit", "{ws}/results.csv", "-o", "{ws}/a_file/model"], "a_file is a file, not a folder"),
    (["surrogate", "fit", "{ws}/results.csv", "-o", "{ws}/model", "--restarts", "-1"], "--restarts: -1 is outside 0-50"),
    (["surrogate", "info", "{ws}/not_json.json"], "not valid JSON"),
    (["surrogate", "plot", "{ws}/model", "--segment", "rsj", "--vs", "diameter", "--friction", "0",
      "-o", "{ws}/good/plot.txt"], "give a file ending in .png, .pdf, .svg"),
    (["surrogate", "plot", "{ws}/model", "--segment", "rsj", "--vs", "colour", "--friction", "0",
      "-o", "{ws}/good/plot.png"], "does not depend on colour"),
    # predict
    (["predict", "{ws}/model", "--segment", "rsj", "--diameter", "30", "--friction", "inf"], "'inf' is not a finite number"),
    (["predict", "{ws}/model", "--segment", "rsj", "--diameter", "30", "--friction", "1e308"],
     "friction = 1e+308 is outside [0, 1]"),
    (["predict", "{ws}/model", "--csv", "{ws}/q_text.csv"], "query 1 has diameter_mm = 'wide'; give a number"),
    (["predict", "{ws}/model", "--csv", "{ws}/q_inf.csv"], "query 1 has friction = inf; give a finite number"),
    (["predict", "{ws}/model", "--csv", "{ws}/missing.csv"], "not found"),
    (["predict", "{ws}/nodiam", "--segment", "rsj", "--diameter", "23", "--friction", "0"],
     "fitted on a table without diameter_mm"),
    (["predict", "{ws}/nodiam", "--segment", "rsj", "--region", "african", "--friction", "0"],
     "fitted on a table without diameter_mm"),
    (["predict", "{ws}/model", "--segment", "rsj", "--diameter", "30", "--friction", "0", "-o", "{ws}/a_dir.json"],
     "a_dir.json is a folder"),
    (["predict", "{ws}/model", "--segment", "rsj", "--diameter", "30", "--friction", "0", "-o", "{ws}/good/pred.txt"],
     "give a file ending in .csv, .json"),
    (["predict", "{ws}/model", "--segment", "rsj", "--diameter", "30", "--friction", "0",
      "-o", "{ws}/a_file/pred.json"], "a_file is a file, not a folder"),
    pytest.param(["predict", "{ws}/model", "--segment", "rsj", "--diameter", "30", "--friction", "0",
                  "-o", UNWRITABLE + ".json"], "cannot write in /proc", marks=linux_only),
    (["predict", "{ws}/missing.json", "--segment", "rsj"], "not found"),
    # recommend
    (["recommend", "{ws}/model", "--segment", "rsj", "--diameter", "30", "--friction", "nan"], "'nan' is not a finite number"),
    (["recommend", "{ws}/model", "--segment", "rsj", "--diameter", "30", "--friction", "1e308"],
     "friction = 1e+308 is outside [0, 1]"),
    (["recommend", "{ws}/model", "--segment", "rsj", "--diameter", "30", "--friction", "0", "-o", "{ws}/good"],
     "good is a folder"),
    (["recommend", "{ws}/model", "--segment", "rsj", "--diameter", "30", "--friction", "0",
      "-o", "{ws}/a_file/rec.json"], "a_file is a file, not a folder"),
    (["recommend", "{ws}/model", "--segment", "rsj", "--diameter", "30", "--friction", "0", "--scope", "utc"],
     "at least two different scopes"),
    # demo, and the command line itself
    (["demo", "--out", "{ws}/a_file"], "a_file is an existing file"),
    (["demo", "--workers", "0", "--out", "{ws}/good_demo"], "must be at least 1"),
    (["demo", "--element-size", "inf", "--out", "{ws}/good_demo"], "'inf' is not a finite number"),
    (["demo", "--push-speed", "0", "--out", "{ws}/good_demo"], "push_speed = 0.0 is outside [0.001, 5]"),
    (["simulate"], "invalid choice: 'simulate'"),
    ([], "the following arguments are required: command"),
]


def _case_id(case):
    argv = case.values[0] if hasattr(case, "values") else case[0]
    return " ".join(a.replace("{ws}/", "") for a in argv[:6]) or "(no command)"


@pytest.mark.parametrize("argv,message", CASES, ids=[_case_id(c) for c in CASES])
def test_bad_input_is_one_line_exit_2_and_nothing_written(ws, argv, message, capsys):
    before = _snapshot(ws)
    cwd = os.getcwd()
    os.chdir(ws)  # default output folders would land in the workspace
    try:
        code = main([a.replace("{ws}", str(ws)) for a in argv])
    finally:
        os.chdir(cwd)
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert code == 2, captured.err
    assert len(lines) == 1 and lines[0].startswith("colonsim: error: "), captured.err
    assert message in lines[0], lines[0]
    assert "Traceback" not in captured.err + captured.out
    assert _snapshot(ws) == before


def test_the_corpus_covers_every_command_and_is_large():
    commands = {c[0][0] if c[0] else "" for c in (case.values if hasattr(case, "values") else case for case in CASES)}
    assert {"calibrate", "insert", "sweep", "surrogate", "predict", "recommend", "demo"} <= commands
    assert len(CASES) >= 40
