"""Sweep records (validation/sweep_records.py): a sweep folder packed and unpacked again gives the
report the same table, summaries, time series (to the record's quantum) and final shapes; a record
grows run by run; the report never asks a sweep for a column a record leaves out; bad folders are
one line."""

import json
import re
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the validation package (a tool folder)

from validation import sweep_records as records  # noqa: E402
from validation.sweeps import Sweep  # noqa: E402

from colonsim.errors import ColonsimError  # noqa: E402
from colonsim.insertion.case.insertion_case import InsertionCase  # noqa: E402
from colonsim.insertion.case.results import read_final_shape  # noqa: E402
from colonsim.insertion.study.sweep_rows import input_row  # noqa: E402


# the runs' cases: real inputs whose keys the table's schema can check (colonsim.schemas)
CASES = {f"k{i}": InsertionCase(diameter_mm=20.0 + i) for i in range(1, 10)}
K = {name: case.key() for name, case in CASES.items()}
INPUTS = {case.key(): input_row(case) for case in CASES.values()}


def _run_folder(folder, key, seed, n=400):
    """A run folder as `colonsim sweep` writes it: every series column plus one the record drops."""
    rng = np.random.default_rng(seed)
    run = folder / "runs" / key
    run.mkdir(parents=True)
    depth = np.cumsum(rng.uniform(0.0, 0.02, n))
    series = pd.DataFrame({
        "time_s": np.arange(n) * 1e-3, "phase": np.where(np.arange(n) < n // 2, "push", "settle"),
        "depth_cm": depth, "deformation_cm": np.abs(np.sin(depth)) * rng.uniform(0.5, 2.0),
        "tip_arc_cm": depth - 0.1 * np.sin(depth), "push_force_N": rng.normal(4.0, 0.7, n),
        "contact_nodes": rng.integers(0, 40, n), "kinetic_colon_J": rng.uniform(0, 1e-3, n)})
    series.to_csv(run / "timeseries.csv", index=False)
    (run / "summary.json").write_text(json.dumps({"key": key, "points_cm": {"A": {"depth_cm": 1.0}}}), encoding="utf-8")
    shape = {"colon_m": rng.normal(0.0, 0.05, (300, 3)), "scope_m": rng.normal(0.0, 0.2, (60, 3))}
    np.savez_compressed(run / "final_shape.npz", **shape)
    return {**INPUTS[key], "key": key, "status": "ok", "timeseries_path": f"runs/{key}/timeseries.csv",
            "final_deformation_cm": float(series["deformation_cm"].iloc[-1]), "git_commit": "abc",
            "finished_at": f"2026-12-01T00:00:{seed:02d}"}, series, shape


def _sweep(folder, keys, failed=(), seed=0, name="demo", defined=None):
    folder.mkdir(parents=True, exist_ok=True)
    rows, made = [], {}
    for i, key in enumerate(keys):
        row, series, shape = _run_folder(folder, key, seed + i)
        rows.append(row)
        made[key] = (series, shape)
    rows += [{**INPUTS[k], "key": k, "status": "failed", "timeseries_path": "", "final_deformation_cm": np.nan,
              "git_commit": "abc", "finished_at": "2026-12-01T01:00:00"} for k in failed]
    pd.DataFrame(rows).to_parquet(folder / "results.parquet", index=False)
    all_keys = list(defined or (list(keys) + list(failed)))  # the cases the sweep defines, finished or not
    (folder / "sweep.json").write_text(json.dumps({"name": name, "keys": all_keys, "toml": "x"}), encoding="utf-8")
    return made


def test_pack_then_unpack_gives_the_report_the_same_run(tmp_path):
    made = _sweep(tmp_path / "sweep", [K["k1"], K["k2"]], failed=[K["k3"]])
    done = records.pack(tmp_path / "sweep", tmp_path / "record")
    assert done == {"packed": 3, "incomplete": [], "rows": 3}
    records.unpack(tmp_path / "record", tmp_path / "again")
    before = pd.read_parquet(tmp_path / "sweep" / "results.parquet")
    after = pd.read_parquet(tmp_path / "again" / "results.parquet")
    pd.testing.assert_frame_equal(before.sort_values("key").reset_index(drop=True),
                                  after.sort_values("key").reset_index(drop=True))
    assert json.loads((tmp_path / "again" / "sweep.json").read_text()) == json.loads(
        (tmp_path / "sweep" / "sweep.json").read_text())
    for key, (series, shape) in made.items():
        run = tmp_path / "again" / "runs" / key
        assert (run / "summary.json").read_bytes() == (tmp_path / "sweep" / "runs" / key / "summary.json").read_bytes()
        back = pd.read_csv(run / "timeseries.csv")
        assert list(back.columns) == list(records.SERIES_COLUMNS)
        for col in records.SERIES_COLUMNS:
            if col in records.SERIES_QUANTUM:  # rounded to the quantum, never further: the steps add up exactly
                np.testing.assert_allclose(back[col], series[col], rtol=0, atol=0.5 * records.SERIES_QUANTUM[col] * 1.001)
            else:
                assert (back[col] == series[col]).all()
        shape_back = read_final_shape(run)
        for name, x in shape.items():
            np.testing.assert_allclose(shape_back[name], x, rtol=0, atol=0.5 * records.SHAPE_QUANTUM * 1.001)
    assert not (tmp_path / "again" / "runs" / K["k3"]).exists()


def test_the_report_reads_an_unpacked_record_as_the_sweep(tmp_path):
    _sweep(tmp_path / "sweep", [K["k1"], K["k2"]])
    records.pack(tmp_path / "sweep", tmp_path / "record")
    records.unpack(tmp_path / "record", tmp_path / "again")
    table = pd.read_parquet(tmp_path / "sweep" / "results.parquet")
    original = Sweep("main", tmp_path / "sweep", [], table, True)
    unpacked = Sweep("main", tmp_path / "again", [], pd.read_parquet(tmp_path / "again" / "results.parquet"), True)
    for _, row in table.iterrows():
        assert unpacked.summary(row) == original.summary(row)
        a = original.timeseries(row, ["phase", "depth_cm", "push_force_N"])
        b = unpacked.timeseries(row, ["phase", "depth_cm", "push_force_N"])
        assert (a["phase"] == b["phase"]).all()
        assert np.abs(a["depth_cm"] - b["depth_cm"]).max() <= 0.5e-5 * 1.001


def test_a_record_grows_over_sittings_and_keeps_what_a_later_folder_lacks(tmp_path):
    _sweep(tmp_path / "first", [K["k1"]], seed=1, defined=[K["k1"], K["k2"]])
    records.pack(tmp_path / "first", tmp_path / "record")
    # the next sitting: the record unpacked, one more run added by the resumed sweep
    records.unpack(tmp_path / "record", tmp_path / "second")
    row, _, _ = _run_folder(tmp_path / "second", K["k2"], 7)
    table = pd.concat([pd.read_parquet(tmp_path / "second" / "results.parquet"), pd.DataFrame([row])])
    table.to_parquet(tmp_path / "second" / "results.parquet", index=False)
    first = {p.name: p.read_bytes() for p in (tmp_path / "record" / "runs" / K["k1"]).iterdir()}
    done = records.pack(tmp_path / "second", tmp_path / "record")
    assert done["rows"] == 2 and done["packed"] == 1  # k1, held already, is not packed again
    assert {p.name: p.read_bytes() for p in (tmp_path / "record" / "runs" / K["k1"]).iterdir()} == first
    # a folder holding only one of them, a later run of k2, replaces k2 and keeps k1
    made = _sweep(tmp_path / "third", [K["k2"]], seed=8, defined=[K["k1"], K["k2"]])
    assert records.pack(tmp_path / "third", tmp_path / "record") == {"packed": 1, "incomplete": [], "rows": 2}
    np.testing.assert_allclose(records.unpack_series(pd.read_parquet(tmp_path / "record" / "runs" / K["k2"] / "series.parquet"))
                               ["depth_cm"], made[K["k2"]][0]["depth_cm"], rtol=0, atol=1e-5)
    assert sorted(pd.read_parquet(tmp_path / "record" / "results.parquet")["key"]) == [K["k1"], K["k2"]]


def test_status_says_what_a_record_holds(tmp_path, capsys):
    _sweep(tmp_path / "sweep", [K["k1"], K["k2"]], failed=[K["k3"]], defined=[K["k1"], K["k2"], K["k3"], K["k4"]], name="thesis")
    records.pack(tmp_path / "sweep", tmp_path / "records" / "thesis")
    assert records.status(tmp_path / "records" / "thesis") == {
        "record": "thesis", "sweep": "thesis", "defined": 4, "ok": 2, "failed": 1, "code": {"abc": 3}}
    assert records.main(["status", str(tmp_path / "records")]) == 0
    assert "thesis: sweep 'thesis', 2 ok + 1 failed of 4 defined; rows' code abc: 3" in capsys.readouterr().out


def test_a_run_folder_that_is_not_complete_is_left_out_and_named(tmp_path):
    _sweep(tmp_path / "sweep", [K["k1"], K["k2"]])
    (tmp_path / "sweep" / "runs" / K["k2"] / "final_shape.npz").unlink()
    done = records.pack(tmp_path / "sweep", tmp_path / "record")
    assert done["incomplete"] == [K["k2"]] and done["rows"] == 1


def test_bad_folders_are_one_line(tmp_path, capsys):
    assert records.main(["pack", str(tmp_path / "nothing"), str(tmp_path / "record")]) == 2
    assert "no results.parquet" in capsys.readouterr().err
    _sweep(tmp_path / "a", [K["k1"]], name="a")
    _sweep(tmp_path / "b", [K["k9"]], name="b")
    records.pack(tmp_path / "a", tmp_path / "record")
    with pytest.raises(ColonsimError, match="holds another sweep"):
        records.pack(tmp_path / "b", tmp_path / "record")
    assert records.main(["unpack", str(tmp_path / "a"), str(tmp_path / "b")]) == 2
    assert "another sweep" in capsys.readouterr().err


def test_every_column_the_report_reads_is_recorded():
    asked = set()
    for path in (ROOT / "validation").glob("*.py"):
        for call in re.findall(r"\.timeseries\(\s*row\s*,\s*\[([^\]]*)\]", path.read_text(encoding="utf-8")):
            asked |= set(re.findall(r"\"([^\"]+)\"", call))
    assert asked, "the report's modules ask a sweep for time-series columns"
    assert asked <= set(records.SERIES_COLUMNS), asked - set(records.SERIES_COLUMNS)


SMOOTHNESS = ROOT / "benchmarks" / "sweeps" / "smoothness.toml"


def _smoothness_folder(folder) -> list:
    """A sweep folder of three of the smoothness sweep's ten cases (its real sweep.json); their keys."""
    from colonsim.insertion.study.sweep_spec import load_sweep

    spec = load_sweep(SMOOTHNESS)
    keys = [c.key() for c in spec.cases]
    INPUTS.update({c.key(): input_row(c) for c in spec.cases[:3]})
    _sweep(folder, keys[:3])
    (folder / "sweep.json").write_text(json.dumps(spec.document()), encoding="utf-8")
    return keys


def test_colonsim_sweep_resumes_in_an_unpacked_record(tmp_path, capsys):
    """A record of three of the smoothness sweep's ten cases, unpacked: `colonsim sweep` counts them
    done and would run the other seven (a dry run: nothing is simulated)."""
    from colonsim.cli import main

    toml = SMOOTHNESS
    _smoothness_folder(tmp_path / "sweep")
    records.pack(tmp_path / "sweep", tmp_path / "record")
    records.unpack(tmp_path / "record", tmp_path / "again")
    capsys.readouterr()
    assert main(["sweep", str(toml), "--dry-run", "--out", str(tmp_path / "again")]) == 0
    assert f"10 runs, 3 already in {tmp_path / 'again'}/" in capsys.readouterr().out


def test_a_record_without_series_keeps_the_table_and_summaries_and_a_sweep_resumes_in_it(tmp_path, capsys):
    """``pack --no-series`` (the patient-space sweeps, which the predictor reads by their tables):
    each run's summary alone; packed again, nothing is rewritten; unpacked, the table and summaries
    are back and `colonsim sweep` counts those runs done."""
    from colonsim.cli import main

    toml = SMOOTHNESS
    keys = _smoothness_folder(tmp_path / "sweep")
    assert records.main(["pack", "--no-series", str(tmp_path / "sweep"), str(tmp_path / "record")]) == 0
    assert sorted(p.name for p in (tmp_path / "record" / "runs" / keys[0]).iterdir()) == ["summary.json"]
    assert json.loads((tmp_path / "record" / "packed.json").read_text())[-1]["series"] is False
    assert records.pack(tmp_path / "sweep", tmp_path / "record", series=False)["packed"] == 0  # held already
    records.unpack(tmp_path / "record", tmp_path / "again")
    pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / "again" / "results.parquet"),
                                  pd.read_parquet(tmp_path / "sweep" / "results.parquet"))
    assert not (tmp_path / "again" / "runs" / keys[1] / "timeseries.csv").exists()
    capsys.readouterr()
    assert main(["sweep", str(toml), "--dry-run", "--out", str(tmp_path / "again")]) == 0
    assert f"10 runs, 3 already in {tmp_path / 'again'}/" in capsys.readouterr().out
