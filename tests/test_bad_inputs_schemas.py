"""Files the program wrote, edited by hand, are refused before any run, with nothing written
(colonsim.schemas): a sweep's results table, its sweep.json, its run folders; and the good ones
resume. No simulation runs: the rows are failed runs (and one finished run whose folder is made
by hand), which a resume does not run again."""

import hashlib
import json

import pandas as pd
import pytest

from colonsim.errors import ColonsimError
from colonsim.insertion.case.results import RUN_SUMMARY
from colonsim.insertion.study.sweep import TABLE, SweepStore, read_results, result_row, run_sweep
from colonsim.insertion.study.sweep_spec import parse_sweep
from colonsim.schemas import check_material_document, check_sweep_document

SPEC = parse_sweep('[sweep]\nname = "s"\n[[grid]]\nsegment = "straight"\nscope = ["utc", "sdc"]\nfriction = [0.1]\n')
FAILED = {"status": "failed", "error": "x", "wall_time_s": 1.0, "finished_at": "2026-01-01T00:00:00+00:00"}


def never_runs(case):  # pragma: no cover - a resume of finished runs never calls it
    raise AssertionError("a run started")


def sweep_folder(tmp_path):
    """A sweep folder as the sweep leaves it: one failed run, one finished run with its folder."""
    out = tmp_path / "sweep"
    failed, done = SPEC.cases
    with SweepStore(out) as store:
        store.record(failed, {**FAILED, "key": failed.key()})
        row = result_row(done, {"status": "ok", "wall_time_s": 2.0, "finished_at": FAILED["finished_at"],
                                "summary": {"final_deformation_cm": 1.0}}, f"runs/{done.key()}/timeseries.csv")
        (out / "runs" / done.key()).mkdir(parents=True)
        (out / "runs" / done.key() / RUN_SUMMARY).write_text("{}")
        store.rows[row["key"]] = row
        store.write()
    (out / "sweep.json").write_text(json.dumps(SPEC.document()))
    return out


def digest(folder):
    return {p.relative_to(folder).as_posix(): hashlib.md5(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def edit(out, change):
    table = pd.read_parquet(out / TABLE)
    changed = change(table)
    (table if changed is None else changed).to_parquet(out / TABLE, index=False)


def refused(out, match):
    before = digest(out)
    with pytest.raises(ColonsimError, match=match) as info:
        run_sweep(SPEC.cases, out, workers=1, runner=never_runs, spec=SPEC, progress=False)
    assert "\n" not in str(info.value)
    assert digest(out) == before  # nothing written, nothing removed (the lock came and went)


def test_the_table_the_sweep_wrote_resumes_without_a_run(tmp_path):
    out = sweep_folder(tmp_path)
    before = digest(out)
    report = run_sweep(SPEC.cases, out, workers=1, runner=never_runs, spec=SPEC, progress=False)
    assert (report.skipped, report.ran) == (2, 0)
    assert digest(out)[TABLE] == before[TABLE]
    assert len(read_results(out)) == 2


def test_an_older_table_without_a_later_column_still_resumes(tmp_path):
    """A column the catalog added later (here the contact surface and the centerline) is optional."""
    out = sweep_folder(tmp_path)
    edit(out, lambda t: t.drop(columns=["contact_surface", "contact_face_subdivision", "centerline", "ended_by"]))
    assert run_sweep(SPEC.cases, out, workers=1, runner=never_runs, spec=SPEC, progress=False).ran == 0


@pytest.mark.parametrize("change, match", [
    (lambda t: t.rename(columns={"friction": "frictoin"}), r"column 'frictoin' is not one the sweep "
                                                                        r"writes and friction is missing"),
    (lambda t: t.__setitem__("friction", t["friction"].astype(str)), r"column friction holds str values \('0.1'\) "
                                                                     r"where the sweep writes numbers"),
    (lambda t: t.drop(columns=["friction"]), r"the key of run \w+ is not the hash of its inputs \(input column\(s\) "
                                              r"friction missing, read as their defaults\)"),
    (lambda t: t.__setitem__("diameter_mm", [30.0, 36.0]), r"the key of run \w+ is not the hash of its inputs"),
    (lambda t: t.__setitem__("friction", [float("nan"), 0.1]), r"\(empty input\(s\) friction\)"),
    (lambda t: t.__setitem__("key", ["0123456789ab", t["key"][1]]), r"key of run 0123456789ab is not the hash"),
    (lambda t: t.__setitem__("key", [t["key"][1], t["key"][1]]), r"key \w+ is on 2 rows \(a run recorded twice\)"),
    (lambda t: t.__setitem__("status", ["OK", "ok"]), r"status 'OK' in run \w+ is neither ok nor failed"),
    (lambda t: t.__setitem__("wall_time_s", [float("inf"), 1.0]), r"column wall_time_s is infinite in run \w+"),
    (lambda t: t.drop(columns=["status"]), r"lacks the column\(s\) status, which identify its runs"),
])
def test_a_hand_edited_table_is_refused_before_any_run(tmp_path, change, match):
    out = sweep_folder(tmp_path)
    edit(out, change)
    refused(out, match + r".*restore the table as the sweep wrote it, or run the sweep into a new --out")


def test_a_finished_run_without_its_folder_is_refused(tmp_path):
    out = sweep_folder(tmp_path)
    (out / "runs" / SPEC.cases[1].key() / RUN_SUMMARY).unlink()
    refused(out, r"recorded as finished but runs/<key>/summary.json is missing")


def test_an_edited_sweep_document_is_refused(tmp_path):
    out = sweep_folder(tmp_path)
    doc = json.loads((out / "sweep.json").read_text())
    (out / "sweep.json").write_text(json.dumps({**doc, "keys": "all", "toml": None}))
    refused(out, r"sweep.json: field keys is not a list of run keys")
    with pytest.raises(ColonsimError, match=r"field runs \(3\) is not the number of keys \(2\)"):
        check_sweep_document({**doc, "runs": 3}, "sweep.json")
    assert check_sweep_document(doc, "sweep.json") is doc


def test_a_reused_folder_is_checked_too(tmp_path):
    other = sweep_folder(tmp_path)
    edit(other, lambda t: t.__setitem__("diameter_mm", [30.0, 36.0]))
    out = tmp_path / "new"
    with pytest.raises(ColonsimError, match=r"results.parquet: the key of run \w+ is not the hash of its inputs"):
        run_sweep(SPEC.cases, out, workers=1, runner=never_runs, spec=SPEC, progress=False, reuse=[other])
    assert not out.exists() or not any(out.iterdir())


def test_a_material_document_with_nan_or_a_missing_parameter_is_refused():
    good = {"law": "mooney_rivlin_3", "units": "Pa", "parameters": {"C10": 1e4, "C01": 2e3, "C11": 5e3}}
    assert check_material_document(good, "m.json", ("C10", "C01", "C11")) == good["parameters"]
    for params, match in (({"C10": float("nan"), "C01": 2e3, "C11": 5e3}, "parameter C10 is nan, not a finite number"),
                          ({"C10": 1e4, "C01": "2e3", "C11": 5e3}, "parameter C01 is '2e3', not a finite number"),
                          ({"C10": 1e4, "C01": 2e3}, "parameter C11 is None")):
        with pytest.raises(ColonsimError, match=match):
            check_material_document({**good, "parameters": params}, "m.json", ("C10", "C01", "C11"))


def test_material_export_refuses_a_material_file_with_nan_and_writes_nothing(tmp_path, capsys):
    from colonsim.cli import main
    from colonsim.data import REFERENCE_MATERIAL_PATH

    doc = json.loads(REFERENCE_MATERIAL_PATH.read_text())
    name = next(iter(doc["parameters"]))
    edited = tmp_path / "material.json"
    edited.write_text(json.dumps({**doc, "parameters": {**doc["parameters"], name: float("nan")}}))
    before = digest(tmp_path)
    assert main(["material", "export", str(edited), "--format", "lsdyna"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"parameter {name} is nan, not a finite number" in err[0]
    assert digest(tmp_path) == before
    edited.write_text(json.dumps(doc))
    assert main(["material", "export", str(edited), "--format", "lsdyna"]) == 0
