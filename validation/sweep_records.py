"""Sweep records: what the validation report reads of a sweep, small enough to commit.

The report's sweeps take about an hour and a half of two cores and the predictor's many more, a
machine here gives about two and a half hours a sitting, and a sweep folder does not outlive its
machine (one RSF run's folder is 3.8 MB, most of it the time series' 22 columns). A record keeps
of each finished run what the report reads and nothing else, so a sweep can be run over several
sittings and machines, each landing what it finished:

- the sweep's table (``results.parquet``: every row as it is, with its code version) and its
  ``sweep.json`` (the cases it defines);
- per run its ``summary.json`` as it is;
- the time series' columns the report reads (:data:`SERIES_COLUMNS`), each number rounded to
  :data:`SERIES_QUANTUM` (0.1 um of depth, deformation and tip position, 0.1 mN of push force:
  below every digit the report prints) and stored as the differences of successive samples;
- the final shape (wall and scope nodes) rounded to :data:`SHAPE_QUANTUM` (0.1 um), likewise;
- ``packed.json``: when each pack was made, by which code, from which folder (the rows' own code
  versions are in the table).

Measured on the `thesis` preset: 51 kB an RSJ run, 81 kB an RSF run, 86 kB a THF run (3.0 MB
for the 39), against 1.4 / 3.8 MB for an RSJ / RSF run folder.

Use::

    python -m validation.sweep_records pack SWEEP_DIR RECORD_DIR     # add SWEEP_DIR's finished runs
    python -m validation.sweep_records pack --no-series SWEEP_DIR RECORD_DIR    # their table and summaries
    python -m validation.sweep_records unpack RECORD_DIR SWEEP_DIR   # a sweep folder again
    python -m validation.sweep_records status [RECORDS_DIR]          # what each record holds

``pack`` adds the finished runs of a sweep folder to a record (a new record, or one of the same
sweep: the same ``sweep.json``), keeping the runs the record has that the folder lacks. ``unpack``
writes a sweep folder that ``colonsim sweep`` resumes (the cases in the record are not run
again) and that ``python -m validation.report`` reads as it reads the folder the runs were made in; its
time series hold :data:`SERIES_COLUMNS` only. So the report's sweeps go: unpack, run the sweep on
(resuming), pack, commit the record; once a sweep is complete the report is made from its
unpacked folder.
"""

from __future__ import annotations

import argparse
import datetime
import json
import shutil
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from colonsim.errors import ColonsimError
from colonsim.files import atomic_path, output_set, write_json
from colonsim.insertion.case.results import RUN_SERIES, RUN_SHAPE, RUN_SUMMARY, read_final_shape
from colonsim.provenance import code_version
from colonsim.insertion.study.sweep import SWEEP_DOCUMENT, TABLE, read_results

# the committed records (one folder per sweep)
RECORDS = Path(__file__).resolve().parents[1] / "benchmarks" / "records"
# the time-series columns the validation report reads (tests/test_sweep_records.py checks that
# every column the report's modules ask a sweep for is here)
SERIES_COLUMNS = ("phase", "depth_cm", "deformation_cm", "tip_arc_cm", "push_force_N", "contact_nodes")
SERIES_QUANTUM = {"depth_cm": 1e-5, "deformation_cm": 1e-5, "tip_arc_cm": 1e-5, "push_force_N": 1e-4}
SHAPE_QUANTUM = 1e-7  # m
SERIES = "series.parquet"
SHAPE = "shape.npz"
LOG = "packed.json"  # one entry per pack: when, by which code, from which folder, how many runs


def _to_steps(values, quantum: float) -> np.ndarray:
    """Values rounded to ``quantum``, as the differences of successive ones along the first axis
    (int32: exact to add up again; a record's largest value, 1 m in steps of 0.1 um, is 1e7)."""
    counts = np.round(np.asarray(values, dtype=np.float64) / quantum).astype(np.int64)
    steps = np.diff(counts, axis=0, prepend=np.zeros_like(counts[:1]))
    if np.abs(steps).max(initial=0) >= 2**31:
        raise ColonsimError(f"a value of {np.abs(values).max():g} is too large for a record in steps of {quantum:g}")
    return steps.astype(np.int32)


def _from_steps(steps, quantum: float) -> np.ndarray:
    return np.cumsum(np.asarray(steps, dtype=np.int64), axis=0) * quantum


def pack_series(frame: pd.DataFrame) -> pd.DataFrame:
    """The record of a run's time series: :data:`SERIES_COLUMNS`, the rounded ones as steps (a
    column with a non-finite value is kept as it is)."""
    missing = [c for c in SERIES_COLUMNS if c not in frame]
    if missing:
        raise ColonsimError(f"the time series lacks the columns {missing}; pack a sweep written by `colonsim sweep`")
    out = {}
    for col in SERIES_COLUMNS:
        values = frame[col].to_numpy()
        if col in SERIES_QUANTUM and np.isfinite(values.astype(np.float64)).all():
            out[col] = _to_steps(values, SERIES_QUANTUM[col])
        else:
            out[col] = values
    return pd.DataFrame(out)


def unpack_series(record: pd.DataFrame) -> pd.DataFrame:
    """The time series of a record (:data:`SERIES_COLUMNS`, in user units as in ``timeseries.csv``)."""
    out = {}
    for col in SERIES_COLUMNS:
        values = record[col].to_numpy()
        out[col] = _from_steps(values, SERIES_QUANTUM[col]) if col in SERIES_QUANTUM and values.dtype == np.int32 \
            else values
    return pd.DataFrame(out)


def pack_shape(shape: dict) -> dict:
    """The record of a final shape: each (n, 3) array of node positions (m) rounded to
    :data:`SHAPE_QUANTUM`, each coordinate as steps from node to node (neighbouring nodes of a
    mesh lie close, so the steps are small numbers)."""
    return {name: _to_steps(x, SHAPE_QUANTUM) for name, x in shape.items()}


def unpack_shape(record: dict) -> dict:
    return {name: _from_steps(s, SHAPE_QUANTUM) for name, s in record.items()}


def _sweep_document(folder: Path):
    path = folder / SWEEP_DOCUMENT
    return json.loads(path.read_text(encoding="utf-8")) if path.is_file() else None


def _check_same(source: Path, target: Path):
    mine, theirs = _sweep_document(source), _sweep_document(target)
    if mine is not None and theirs is not None and set(mine.get("keys", ())) != set(theirs.get("keys", ())):
        raise ColonsimError(f"{target} holds another sweep ({theirs.get('name')!r}) than {source} "
                            f"({mine.get('name')!r}); give another folder")


def _folders(source, target, needs):
    """(source, target, source table, target table or an empty one) of a pack or unpack, checked."""
    source, target = Path(source), Path(target)
    if not (source / TABLE).is_file():
        raise ColonsimError(f"no {TABLE} in {source}; give {needs}")
    if target.exists() and not target.is_dir():
        raise ColonsimError(f"{target} is a file; give a folder")
    _check_same(source, target)
    table = read_results(source)
    return source, target, table, read_results(target) if (target / TABLE).is_file() else table.iloc[0:0]


def _merge(source, target, have, rows) -> int:
    """Write ``target``'s table: its rows ``have`` with ``rows`` in place of theirs (by key); the
    sweep document of ``source`` beside it. Returns the number of rows."""
    fresh = {r["key"] for r in rows}
    merged = pd.concat([have[~have["key"].isin(fresh)], pd.DataFrame(rows)], ignore_index=True) if rows else have
    with atomic_path(target / TABLE) as tmp:
        merged.to_parquet(tmp, index=False, compression="zstd")
    document = _sweep_document(source)
    if document is not None:
        write_json(target / SWEEP_DOCUMENT, document)
    return len(merged)


def pack(sweep_dir, record_dir, series=True) -> dict:
    """Add the finished runs of the sweep folder ``sweep_dir`` to the record ``record_dir``.

    A run is packed when its row says ok or failed; an ok run also needs its summary, time series
    and final shape in its run folder (else it is left out and named). A run the record holds
    already (the same key, finished at the same time) is left as it is, so that packing again
    rewrites no file of it. ``series`` False keeps of each run its summary alone (``--no-series``:
    what a surrogate and a resumed sweep read, about 13 kB a run; the report's figures need the
    series and shapes). Returns the counts."""
    sweep, record, table, kept = _folders(sweep_dir, record_dir, "the folder of a sweep (its --out)")
    held = {r["key"]: r.get("finished_at") for r in kept.to_dict("records")}
    rows, incomplete = [], []
    with output_set(record / "runs") as stage:
        for row in table.to_dict("records"):
            key = row["key"]
            if key in held and held[key] == row.get("finished_at") and (row["status"] != "ok"
                                                                         or (record / "runs" / key).is_dir()):
                continue
            run = sweep / Path(str(row["timeseries_path"])).parent if row.get("timeseries_path") else None
            if row["status"] == "ok":
                files = ([run / RUN_SUMMARY] + ([run / RUN_SERIES, run / RUN_SHAPE] if series else [])) if run else []
                if not files or not all(f.is_file() for f in files):
                    incomplete.append(key)
                    continue
                target = stage / key
                target.mkdir()
                shutil.copyfile(files[0], target / RUN_SUMMARY)
                if series:
                    frame = pd.read_csv(files[1], usecols=list(SERIES_COLUMNS))
                    pack_series(frame).to_parquet(target / SERIES, index=False, compression="zstd")
                    np.savez_compressed(target / SHAPE, **pack_shape(read_final_shape(run)))
            rows.append(row)
    total = _merge(sweep, record, kept, rows)
    log = json.loads((record / LOG).read_text(encoding="utf-8")) if (record / LOG).is_file() else []
    log.append({"date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
                "packed_by": code_version().get("git_commit"), "from": str(sweep), "runs": len(rows),
                "left_out": incomplete, "rows_after": total, "series": bool(series)})
    write_json(record / LOG, log)
    return {"packed": len(rows), "incomplete": incomplete, "rows": total}


def unpack(record_dir, sweep_dir) -> dict:
    """Write the record ``record_dir`` as a sweep folder ``sweep_dir`` (new, or one of the same
    sweep: its rows and run folders of the record's runs are replaced). Returns the counts."""
    record, sweep, table, have = _folders(record_dir, sweep_dir, "a record folder written by `python -m validation.sweep_records pack`")
    rows = []
    with output_set(sweep / "runs") as stage:
        for row in table.to_dict("records"):
            source = record / "runs" / row["key"]
            if row["status"] == "ok":
                target = stage / row["key"]
                target.mkdir()
                shutil.copyfile(source / RUN_SUMMARY, target / RUN_SUMMARY)
                if (source / SERIES).is_file():  # a run packed --no-series has its summary alone
                    unpack_series(pd.read_parquet(source / SERIES)).to_csv(target / RUN_SERIES, index=False)
                    with np.load(source / SHAPE, allow_pickle=False) as data:
                        np.savez_compressed(target / RUN_SHAPE, **unpack_shape({n: data[n] for n in data.files}))
                row = {**row, "timeseries_path": f"runs/{row['key']}/{RUN_SERIES}"}
            rows.append(row)
    _merge(record, sweep, have, rows)
    return {"unpacked": len(rows)}


def status(record_dir) -> dict:
    """What a record holds: its sweep's name, the runs it defines, the rows recorded (ok / failed)
    and the commits that made them."""
    record = Path(record_dir)
    if not (record / TABLE).is_file():
        raise ColonsimError(f"no {TABLE} in {record}; give a record folder written by `python -m validation.sweep_records pack`")
    table, document = read_results(record), _sweep_document(record) or {}
    return {"record": record.name, "sweep": document.get("name"), "defined": len(document.get("keys", ())) or None,
            "ok": int((table["status"] == "ok").sum()), "failed": int((table["status"] != "ok").sum()),
            "code": {str(k)[:12]: int(v) for k, v in table.get("git_commit", pd.Series(dtype=str)).value_counts().items()}}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("pack", help="add a sweep folder's finished runs to a record")
    p.add_argument("sweep")
    p.add_argument("record")
    p.add_argument("--no-series", action="store_true",
                   help="keep of each run its summary alone, not its time series and final shape (what a surrogate "
                        "and a resumed sweep read)")
    u = sub.add_parser("unpack", help="write a record as a sweep folder")
    u.add_argument("record")
    u.add_argument("sweep")
    st = sub.add_parser("status", help="what the records in a folder hold")
    st.add_argument("records", nargs="?", default=str(RECORDS))
    args = parser.parse_args(argv)
    try:
        if args.command == "status":
            for folder in sorted(p for p in Path(args.records).iterdir() if (p / TABLE).is_file()):
                s = status(folder)
                code = ", ".join(f"{c}: {n}" for c, n in s["code"].items())
                print(f"{s['record']}: sweep {s['sweep']!r}, {s['ok']} ok + {s['failed']} failed of "
                      f"{s['defined'] or '?'} defined; rows' code {code}")
        elif args.command == "pack":
            done = pack(args.sweep, args.record, series=not args.no_series)
            print(f"packed {done['packed']} runs into {args.record} ({done['rows']} in the record)"
                  + (f"; left out, their run folders incomplete: {', '.join(done['incomplete'])}"
                     if done["incomplete"] else ""))
        else:
            done = unpack(args.record, args.sweep)
            print(f"unpacked {done['unpacked']} runs into {args.sweep}")
    except ColonsimError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
