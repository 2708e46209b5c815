"""Run a sweep of insertions: a resumable results store and two ways to run the cases.

Output folder::

    results.parquet     one row per run (columns: :data:`IDENTITY`, every InsertionCase field,
                        ``scope_diameter_mm``, :data:`OUTPUTS`); rewritten atomically after each run
    sweep.json          the sweep this folder holds (name, seed, keys, TOML text)
    runs/<key>/         timeseries.csv, summary.json, insertion.png, final_shape.npz of each successful run

A run is identified by :meth:`InsertionCase.key` (a hash of every input). Rerunning a sweep into
the same folder skips the keys already in the table, so a killed sweep loses at most the runs
that were in flight; failed runs are recorded with their error (rerun them with
``retry_failed=True``) and never stop the others. ``reuse`` takes the finished runs of the same
cases (the same key: every input equal) from other sweep folders instead of running them again;
their rows keep the code version that made them. A folder holds one sweep: another sweep (other
cases) written into it is refused, so that one table never mixes two sweeps. A table, a
``sweep.json`` or a finished run's folder that is not as the sweep wrote it (a column renamed,
dropped or turned into text, a key or an input edited, a run folder deleted) is refused before
any run starts, with nothing written (:mod:`colonsim.schemas`,
:mod:`colonsim.insertion.study.sweep_table`); so is a folder named by ``reuse`` whose table is.

Runs go to a local process pool or an existing Dask distributed cluster
(:mod:`colonsim.insertion.study.sweep_outcomes`); both yield outcomes as runs finish, and only this process writes files:
Dask workers need the package, and the material and centerline files the cases name at their paths.
"""

from __future__ import annotations

import math
import os
import shutil
import time
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from colonsim.errors import ColonsimError
from colonsim.files import atomic_path, check_entries, check_output_folder, output_set, write_json
from colonsim.provenance import code_version
from colonsim.schemas import check_run_folders, check_sweep_document
from colonsim.insertion.case.results import RUN_SUMMARY
from colonsim.insertion.case.run_budget import DEFAULT_MAX_STEPS, check_sweep_budget
from colonsim.insertion.case.scenario import InsertionResult
from colonsim.insertion.study.sweep_animation import AnimatedRuns
from colonsim.insertion.study.sweep_outcomes import dask_distributed, dask_outcomes, local_outcomes
from colonsim.insertion.study.sweep_rows import IDENTITY, OUTPUTS, input_columns, input_row, result_row
from colonsim.insertion.study.sweep_table import read_table

TABLE = "results.parquet"
SWEEP_DOCUMENT = "sweep.json"
LOCK = ".sweep.lock"
class SweepStore:
    """The results of a sweep folder: read at start, one row added (atomically) per finished run.

    Holds a lock file while open so that two sweeps never write the same table.
    """

    def __init__(self, folder):
        self.folder = Path(folder)
        self.table_path = self.folder / TABLE
        self.rows = {}
        self._lock = None

    def load(self):
        """Read the rows already in the table (no lock needed: the table is replaced atomically),
        refused as a whole if it is not as the sweep wrote it (:mod:`colonsim.schemas`)."""
        if self.table_path.is_file():
            table = read_table(self.table_path)
            check_run_folders(self.folder, table, RUN_SUMMARY)
            self.rows = {row["key"]: row for row in table.to_dict("records")}

    def __enter__(self):
        self.folder.mkdir(parents=True, exist_ok=True)
        lock = self.folder / LOCK
        for _ in range(2):
            try:
                fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
            except FileExistsError:
                if _alive(lock):
                    raise ColonsimError(f"another sweep (pid {lock.read_text().strip()}) is writing to {self.folder}; "
                                        "wait for it or use another --out") from None
                lock.unlink(missing_ok=True)  # left by a killed sweep
                continue
            os.write(fd, str(os.getpid()).encode())
            os.close(fd)
            self._lock = lock
            for stale in self.folder.glob(f".{TABLE}.*"):  # temporary copy of a sweep killed mid-write
                stale.unlink(missing_ok=True)
            try:
                self.load()
            except BaseException:
                self.__exit__()
                raise
            return self
        raise ColonsimError(f"cannot take the lock {lock}; remove it if no sweep is running")

    def __exit__(self, *exc):
        if self._lock is not None:
            self._lock.unlink(missing_ok=True)
            self._lock = None

    def check_same_sweep(self, keys, source=None):
        """Refuse to resume here a sweep other than the one this folder holds; return None, or a
        line saying that this sweep extends the one held.

        The same sweep: the same cases (keys), or the same TOML text (its keys change when the
        case fields change with the code). An extension: every case of the sweep held is a case of
        this one (a longer list, the finished runs kept); ``sweep.json`` then names this sweep.
        A folder without ``sweep.json`` holds the rows of its table: every one must be a case of
        this sweep."""
        keys = set(keys)
        path = self.folder / SWEEP_DOCUMENT
        if path.is_file():
            import json

            try:
                held = json.loads(path.read_text(encoding="utf-8"))
            except ValueError as exc:
                raise ColonsimError(f"cannot read {path} ({type(exc).__name__}); it should name the sweep this folder "
                                    "holds: use another --out") from None
            check_sweep_document(held, path)
            held_keys, held_source = set(held["keys"]), held.get("toml")
            if held_keys == keys or (source and held_source == source):
                return None
            name = held.get("name")
            if held_keys < keys and set(self.rows) <= keys:
                return (f"this sweep of {len(keys)} runs extends the one {self.folder} held"
                        f"{f' ({name!r})' if name else ''}, whose {len(held_keys)} runs are all cases of it "
                        f"({len(self.rows)} recorded, kept)")
        else:
            held_keys, name = set(self.rows), None
            if held_keys <= keys:
                return None
        common = len(held_keys & keys)
        raise ColonsimError(f"{self.folder} holds another sweep{f' ({name!r})' if name else ''} of {len(held_keys)} "
                            f"runs ({len(self.rows)} recorded, {common} in common with this one of {len(keys)}); "
                            "resume that one with its own file, or give this sweep another --out")

    def finished(self, retry_failed=False) -> set:
        """Keys that need no new run: ok runs, and failed ones unless ``retry_failed``."""
        return {k for k, r in self.rows.items() if r["status"] == "ok" or (r["status"] == "failed" and not retry_failed)}

    def other_code(self, keys) -> dict:
        """Commit -> number of the rows ``keys`` that another version of the code produced (rows
        without a recorded commit, or runs outside a git checkout, are not counted)."""
        mine = code_version()["git_commit"]
        counts = {}
        for k in keys:
            commit = self.rows[k].get("git_commit")
            if mine and isinstance(commit, str) and commit and commit != mine:
                counts[commit] = counts.get(commit, 0) + 1
        return counts

    def record(self, case, outcome) -> dict:
        """Write the run folder (ok runs), then the table with the run's row; return the row."""
        path = ""
        if outcome["status"] == "ok":
            from colonsim.insertion.case.results import write_insertion

            folder = Path("runs") / case.key()
            result = InsertionResult(case, outcome["timeseries"], outcome["summary"], snapshots=[], model=None,
                                     final_shape=outcome.get("final_shape"))
            with output_set(self.folder / "runs") as stage:  # the run's folder whole, or its earlier one kept
                written = write_insertion(result, stage / case.key(), visuals=outcome.get("visuals"))
            path = (folder / written["timeseries"].name).as_posix()
        row = result_row(case, outcome, path)
        self.rows[row["key"]] = row
        self.write()
        return row

    def adopt(self, source, row) -> None:
        """Take the finished run ``row`` of the sweep folder ``source``: its run folder copied
        whole (or not at all), then its row, as it is (its code version included)."""
        key = row["key"]
        with output_set(self.folder / "runs") as stage:
            shutil.copytree(Path(source) / "runs" / key, stage / key)
        self.rows[key] = dict(row)
        self.write()

    def table(self) -> pd.DataFrame:
        """All rows, contract columns first (older rows may add columns of removed inputs)."""
        frame = pd.DataFrame(list(self.rows.values()))
        first = [*IDENTITY, *input_columns(), *OUTPUTS]
        if frame.empty:
            return pd.DataFrame(columns=first)
        for col in first:
            if col not in frame:
                frame[col] = math.nan  # a field added to InsertionCase after older rows were written
        frame = frame[first + [c for c in frame.columns if c not in first]]
        frame["quasi_static"] = frame["quasi_static"].fillna(False).astype(bool)
        # rows written before these columns existed: unknown (<NA> / ""), not "failed"
        frame["kinetic_energy_check"] = frame["kinetic_energy_check"].astype("boolean")
        frame["ended_by"] = frame["ended_by"].astype(object).where(frame["ended_by"].notna(), "").astype(str)
        return frame.reset_index(drop=True)

    def write(self):
        with atomic_path(self.table_path) as tmp:
            self.table().to_parquet(tmp, index=False)


def _alive(lock: Path) -> bool:
    try:
        pid = int(lock.read_text().strip())
        os.kill(pid, 0)
    except (ValueError, OSError):
        return False
    return pid != os.getpid()


@dataclass
class SweepReport:
    """What a call to :func:`run_sweep` did."""

    folder: Path
    total: int
    skipped: int
    ran: int
    ok: int
    failed: int
    wall_time_s: float
    table: pd.DataFrame

    @property
    def runs_per_hour(self) -> float:
        return 3600.0 * self.ran / self.wall_time_s if self.ran and self.wall_time_s > 0 else math.nan


def reusable_runs(folders, keys, out=None) -> dict:
    """{key: (folder, row)} of the ok runs among ``keys`` in the sweep folders ``folders`` whose
    run folder is there (the first folder that has a key gives it); ``out``, the sweep's own
    folder, may not be one of them."""
    found = {}
    for folder in folders:
        folder = Path(folder)
        if out is not None and folder.resolve() == Path(out).resolve():
            raise ColonsimError(f"--reuse {folder} is this sweep's own folder; name other sweep folders")
        if not (folder / TABLE).is_file():
            raise ColonsimError(f"--reuse {folder}: no {TABLE} there; name the folder of a sweep (its --out)")
        for row in read_results(folder).to_dict("records"):
            key = row["key"]
            if (key in keys and key not in found and row["status"] == "ok"
                    and (folder / "runs" / key / RUN_SUMMARY).is_file()):
                found[key] = (folder, row)
    return found


def run_sweep(cases, out, workers=2, scheduler=None, runner=None, retry_failed=False, spec=None,
              progress=True, log=print, max_steps=DEFAULT_MAX_STEPS, pool=None, reuse=()) -> SweepReport:
    """Run every case of a sweep not yet finished in ``out``; record each run as it finishes.

    Parameters
    ----------
    cases : list of InsertionCase
        Validated cases (:func:`colonsim.insertion.study.sweep_spec.load_sweep`).
    out : path
        The sweep folder (created; reused to resume).
    workers : int
        Local worker processes (ignored with ``scheduler``).
    scheduler : str or None
        Address of a Dask distributed scheduler, e.g. ``tcp://10.0.0.5:8786``.
    runner : callable(case) -> result, or None
        The simulation (default :func:`colonsim.insertion.case.scenario.run_insertion`); must be importable
        by the workers.
    retry_failed : bool
        Run again the cases recorded as failed.
    spec : SweepSpec or None
        Written to ``sweep.json``: it names the sweep the folder holds.
    max_steps : int
        Refuse the sweep if a run of one of its materials needs more time steps
        (:func:`colonsim.insertion.case.run_budget.check_sweep_budget`).
    pool : LocalPool or None
        Local worker processes to run on and leave open (several sweeps in a row); None: the
        sweep starts its own.
    reuse : paths
        Other sweep folders whose finished runs of the same cases are copied in, not run again
        (:func:`reusable_runs`).
    """
    if workers < 1:
        raise ColonsimError(f"workers = {workers}; give at least 1 worker process")
    for case in cases:
        case.validate()
    if scheduler:
        dask_distributed()  # a missing dask fails before anything is written
    out = check_output_folder(out)
    check_entries(out, {TABLE: "file", SWEEP_DOCUMENT: "file", "runs": "folder"})  # before any run, not after
    check_sweep_budget(cases, max_steps)
    if runner is None and spec is not None and spec.animated:  # the chosen runs with snapshots and their movie
        runner = AnimatedRuns(spec.animated)
    t0 = time.perf_counter()
    with SweepStore(out) as store:
        extends = store.check_same_sweep([c.key() for c in cases], spec.source if spec is not None else None)
        if extends:
            log(extends)
        done = store.finished(retry_failed)
        todo = [c for c in cases if c.key() not in done]
        if reuse:
            taken = reusable_runs(reuse, {c.key() for c in todo}, out)
            for folder, row in taken.values():
                store.adopt(folder, row)
            todo = [c for c in todo if c.key() not in taken]
            if taken:
                commits = sorted({str(row.get("git_commit") or "?")[:12] for _, row in taken.values()})
                log(f"{len(taken)} run(s) of the same cases taken from {', '.join(str(f) for f in reuse)}, not run "
                    f"again (made by code {', '.join(commits)})")
        skipped = len(cases) - len(todo)
        other = store.other_code({c.key() for c in cases} & done)
        if other:
            log(f"note: {sum(other.values())} finished run(s) in {out} were made by other code "
                f"({', '.join(c[:12] for c in other)}) and are kept; rerun into a new --out to redo them with this code")
        ok = failed = 0
        outcomes = None
        if todo:  # a Dask client connects here: an unreachable scheduler fails before sweep.json is written
            outcomes = (dask_outcomes(todo, scheduler, runner, log) if scheduler
                        else local_outcomes(todo, min(workers, len(todo)), runner, pool))
        write_json(out / SWEEP_DOCUMENT, spec.document() if spec is not None else
                   {"name": None, "runs": len(cases), "keys": [c.key() for c in cases]})
        if outcomes is not None:
            from tqdm import tqdm

            bar = tqdm(total=len(todo), unit="run", disable=None if progress else True, dynamic_ncols=True,
                       leave=False, mininterval=0.5)
            try:
                for case, outcome in outcomes:
                    row = store.record(case, outcome)
                    ok += row["status"] == "ok"
                    failed += row["status"] == "failed"
                    bar.set_postfix_str(f"ok {ok}, failed {failed}")
                    bar.update(1)
            finally:
                bar.close()
                outcomes.close()
        table = store.table()
    wanted = {c.key() for c in cases}
    table = table[table["key"].isin(wanted)].reset_index(drop=True)
    return SweepReport(out, len(cases), skipped, ok + failed, ok, failed, time.perf_counter() - t0, table)


def read_results(folder) -> pd.DataFrame:
    """The results table of a sweep folder, checked (:func:`colonsim.insertion.study.sweep_table.read_table`)."""
    path = Path(folder) / TABLE
    if not path.is_file():
        raise ColonsimError(f"no {TABLE} in {folder}; run `colonsim sweep ... --out {folder}` first")
    return read_table(path)


def describe_cases(cases) -> str:
    """The cases as an aligned text table (inputs that vary, plus the key)."""
    frame = pd.DataFrame([{**c.to_dict(), "key": c.key()} for c in cases])
    # map(str), not astype(str): pandas 3 keeps None missing through astype(str), and nunique skips it
    varying = [c for c in frame.columns if c != "key" and frame[c].map(str).nunique() > 1]
    return frame[["key", *varying]].to_string(index=False)


__all__ = ["SweepStore", "SweepReport", "run_sweep", "reusable_runs", "read_results",
           "result_row", "input_row", "describe_cases", "IDENTITY", "OUTPUTS", "TABLE"]
