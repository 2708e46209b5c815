"""Sweeps that run: a real Dask LocalCluster on loopback, resume after a killed sweep, failed runs.

The smoke preset (3 runs of a few seconds on a coarse wall mesh) keeps this file near 40 s on 2 cores.
"""

import dataclasses
import math
import os
import signal
import subprocess
import sys
import time
import types
from pathlib import Path

import pandas as pd
import pytest

from colonsim.insertion.case.scenario import InsertionCase, run_insertion
from colonsim.insertion.study.sweep import IDENTITY, OUTPUTS, TABLE, SweepStore, describe_cases, result_row, run_sweep
from colonsim.insertion.study.sweep_outcomes import DIED, LocalPool, local_outcomes
from colonsim.insertion.study.sweep_spec import load_sweep

ROOT = Path(__file__).resolve().parents[1]
SMOKE = load_sweep(preset="smoke").cases
# The columns the surrogate reads (its contract with the sweep).
CONTRACT = ["key", "status", "error", "wall_time_s", "timeseries_path", "finished_at", "segment", "scope",
            "diameter_mm", "angle_deg", "friction", "wall_thickness_mm", "material", "scope_diameter_mm",
            "final_deformation_cm", "max_deformation_cm", "point_A_cm", "point_B_cm", "point_C_cm",
            "peak_contact_force_N", "peak_push_force_N", "max_wall_stretch", "quasi_static", "simulated_time_s"]


def failing_runner(case):
    """Runs the real simulation, except: straight -> an error; RSJ UTC -> the worker process dies."""
    if case.segment == "straight":
        raise RuntimeError("injected failure\nsecond line")
    if case.scope == "utc":
        os._exit(3)
    return run_insertion(case)


def pid_runner(case):
    """SYNTHETIC run: no simulation, the worker process's id as its outcome; RSJ UTC -> the worker dies."""
    if case.scope == "utc":
        os._exit(3)
    return types.SimpleNamespace(summary={"pid": os.getpid()}, timeseries=None)


def check_ok_rows(folder, table):
    ok = table[table["status"] == "ok"]
    for _, row in ok.iterrows():
        ts = pd.read_csv(folder / row["timeseries_path"])
        assert len(ts) > 10 and (folder / "runs" / row["key"] / "summary.json").is_file()
        assert row["error"] == "" and row["wall_time_s"] > 0 and math.isfinite(row["final_deformation_cm"])
    rsj = ok[ok["segment"] == "rsj"]
    assert (rsj["max_deformation_cm"] > 0).all() and (rsj["peak_contact_force_N"] > 0).all()


def _task_threads():
    from colonsim.insertion.study import sweep_worker

    sweep_worker._one_thread()
    return __import__("numba").get_num_threads()


def test_smoke_sweep_on_a_dask_local_cluster(tmp_path):
    distributed = pytest.importorskip("distributed")
    out = tmp_path / "smoke"
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        report = run_sweep(SMOKE, out, scheduler=cluster.scheduler_address, progress=False)
        assert (report.ran, report.ok, report.failed, report.skipped) == (3, 3, 0, 0)
        # a task thread on every worker runs one Numba thread once the sweep's worker set-up ran
        # (Numba may already be imported in a Dask worker, so the pool size itself can stay 2;
        # the per-thread setting is what the runs use)
        with distributed.Client(cluster) as client:
            workers = list(client.scheduler_info()["workers"])
            threads = client.gather([client.submit(_task_threads, workers=[w], pure=False) for w in workers])
        assert set(threads) == {1}
    table = pd.read_parquet(out / TABLE)
    assert len(table) == 3 and set(table["key"]) == {c.key() for c in SMOKE}
    assert set(CONTRACT) <= set(table.columns)
    assert list(table.columns) == [*IDENTITY, *(f.name for f in dataclasses.fields(InsertionCase)),
                                   "scope_diameter_mm", "wall_mu0_kPa", "wall_C11_kPa", "tissue_stiffness", *OUTPUTS]
    assert table["quasi_static"].dtype == bool and sorted(table["scope_diameter_mm"]) == [9.2, 11.3, 12.8]
    check_ok_rows(out, table)
    # nothing left to do: the same sweep is skipped entirely, without a cluster
    again = run_sweep(SMOKE, out, progress=False)
    assert (again.ran, again.skipped) == (0, 3)


def _children(pid):
    """Processes whose parent is ``pid`` (Linux /proc)."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:  # exited meanwhile
            continue
        if int(fields[1]) == pid:
            found.append(int(stat.parent.name))
    return found


def _running(pid):
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.skipif(not Path("/proc/self/stat").is_file(), reason="reads the process table from /proc")
def test_a_killed_sweep_resumes_where_it_stopped(tmp_path):
    """SIGKILL the sweep's main process (what the out-of-memory killer does) after its first
    recorded run: its workers exit within seconds; a rerun skips the runs already done."""
    out = tmp_path / "killed"
    env = {**os.environ, "NUMBA_NUM_THREADS": "1", "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.Popen([sys.executable, "-m", "colonsim.cli", "sweep", "--preset", "smoke", "--workers", "1",
                             "--out", str(out), "--no-progress"], cwd=ROOT, env=env, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 240
        while not (out / TABLE).is_file():
            assert proc.poll() is None, proc.stderr.read().decode()
            assert time.monotonic() < deadline, "the sweep recorded no run in 240 s"
            time.sleep(0.05)
        workers = _children(proc.pid)
        assert workers
        proc.kill()  # the main process only
        proc.wait()
        deadline = time.monotonic() + 10
        while any(_running(w) for w in workers) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not [w for w in workers if _running(w)], "worker processes outlived their sweep"
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)  # whatever is left (nothing, if the test passed)
        except ProcessLookupError:
            pass
        proc.wait()
    before = pd.read_parquet(out / TABLE)
    assert 1 <= len(before) < 3 and (before["status"] == "ok").all()
    assert (out / ".sweep.lock").is_file()  # left by the killed sweep; the rerun takes it over

    report = run_sweep(SMOKE, out, workers=1, progress=False)
    assert report.skipped == len(before) and report.ran == 3 - len(before) and report.ok == report.ran
    table = pd.read_parquet(out / TABLE)
    assert len(table) == 3 and set(table["key"]) == {c.key() for c in SMOKE}
    # rows of the first sweep are kept as they were, not rerun
    kept = table.set_index("key").loc[before["key"], "finished_at"]
    assert kept.tolist() == before["finished_at"].tolist()
    assert not (out / ".sweep.lock").exists() and not list(out.glob(f".{TABLE}.*"))
    check_ok_rows(out, table)


def test_failed_runs_are_recorded_and_do_not_stop_the_others(tmp_path):
    out = tmp_path / "failing"
    report = run_sweep(SMOKE, out, workers=1, runner=failing_runner, progress=False)
    assert (report.ran, report.ok, report.failed) == (3, 1, 2)
    rows = {(r["segment"], r["scope"]): r for r in pd.read_parquet(out / TABLE).to_dict("records")}
    error = rows[("straight", "pdc")]["error"]
    assert error == "RuntimeError: injected failure second line"
    assert rows[("rsj", "utc")]["error"] == DIED  # the pool was replaced and the sweep went on
    ok = rows[("rsj", "sdc")]
    assert ok["status"] == "ok" and ok["final_deformation_cm"] > 0
    for key in (("straight", "pdc"), ("rsj", "utc")):
        r = rows[key]
        assert r["status"] == "failed" and r["timeseries_path"] == "" and math.isnan(r["final_deformation_cm"])
        assert not (out / "runs" / r["key"]).exists()
    # failed runs count as finished unless asked to retry them (the store test checks the retry set)
    assert run_sweep(SMOKE, out, workers=1, progress=False).ran == 0


def test_a_local_pool_serves_several_sweeps_and_replaces_a_broken_one():
    """The rounds of an adaptive sweep share their worker processes; a worker that dies costs its
    run, and the next sweep gets fresh processes."""
    dies = next(c for c in SMOKE if c.scope == "utc")
    others = [c for c in SMOKE if c.scope != "utc"]

    def pids(cases, pool):
        outcomes = [o for _, o in local_outcomes(cases, 2, pid_runner, pool)]
        return {o["summary"]["pid"] if o["status"] == "ok" else o["error"] for o in outcomes}

    with LocalPool(2, warm_up=False) as pool:
        first = pids(others, pool)
        alive = set(pool.executor()._processes)
        assert first <= alive and pids(others, pool) <= alive  # the same processes, not new ones
        assert pids([dies], pool) == {DIED}
        after = pids(others[:1], pool)
        assert len(after) == 1 and not after & alive  # a fresh pool
    assert pool._executor is None  # closed on leaving the block


def test_store_rows_follow_the_contract_and_the_table_is_replaced_atomically(tmp_path):
    case = InsertionCase(segment="rsj", scope="10.5", diameter_mm=30.0)
    outcome = {"key": case.key(), "status": "failed", "error": "ColonsimError: diverged", "wall_time_s": 1.5,
               "finished_at": "2026-01-01T00:00:00+00:00"}
    row = result_row(case, outcome)
    assert row["material"] == "" and row["scope"] == "10.5" and row["scope_diameter_mm"] == pytest.approx(10.5)
    # a failed run has no outputs: NaN numbers, False checks, no ending
    assert row["quasi_static"] is False and row["kinetic_energy_check"] is False and math.isnan(row["ringing_ratio"]) and row["ended_by"] == ""
    assert row["came_to_rest"] is False
    assert all(math.isnan(row[k]) for k in OUTPUTS
               if k not in ("quasi_static", "kinetic_energy_check", "came_to_rest", "ended_by"))
    with SweepStore(tmp_path) as store:
        store.record(case, outcome)
        assert store.finished() == {case.key()} and store.finished(retry_failed=True) == set()
    assert sorted(p.name for p in tmp_path.iterdir()) == [TABLE]  # no temporary file, lock released
    with SweepStore(tmp_path) as store:
        assert set(store.rows) == {case.key()}
        assert list(store.table().columns[:len(IDENTITY)]) == list(IDENTITY)


def test_a_folder_holds_one_sweep(tmp_path):
    """Resuming the same sweep is allowed (same cases, or the same TOML text after the case fields
    changed); another sweep is refused, also into a folder without sweep.json."""
    from colonsim.errors import ColonsimError
    from colonsim.insertion.study.sweep_spec import parse_sweep

    a = parse_sweep('[sweep]\nname = "a"\n[[grid]]\nsegment = "straight"\nscope = ["utc", "sdc"]\n')
    b = parse_sweep('[sweep]\nname = "b"\n[[grid]]\nsegment = "straight"\nscope = ["pdc"]\n')
    outcome = {"status": "failed", "error": "x", "wall_time_s": 1.0, "finished_at": "2026-01-01T00:00:00+00:00"}
    with SweepStore(tmp_path) as store:
        store.record(a.cases[0], {**outcome, "key": a.cases[0].key()})
        store.check_same_sweep([c.key() for c in a.cases])  # no sweep.json: the rows are of this sweep
        with pytest.raises(ColonsimError, match="holds another sweep of 1 runs"):
            store.check_same_sweep([c.key() for c in b.cases])
    (tmp_path / "sweep.json").write_text(__import__("json").dumps(a.document()))
    with SweepStore(tmp_path) as store:
        store.check_same_sweep([c.key() for c in a.cases], a.source)
        store.check_same_sweep(["other keys"], a.source)  # same TOML, keys of a newer InsertionCase
        with pytest.raises(ColonsimError, match=r"holds another sweep \('a'\) of 2 runs \(1 recorded, 0 in common"):
            store.check_same_sweep([c.key() for c in b.cases], b.source)
        with pytest.raises(ColonsimError, match="another sweep"):
            store.check_same_sweep([a.cases[0].key()])  # a part of it is another sweep too


def test_a_longer_sweep_extends_the_one_a_folder_holds(tmp_path):
    """A sweep that holds every case of the folder's sweep and more resumes there, and says so;
    not if the folder has a row that is not one of its cases."""
    from colonsim.errors import ColonsimError
    from colonsim.insertion.study.sweep_spec import parse_sweep

    a = parse_sweep('[sweep]\nname = "a"\n[[grid]]\nsegment = "straight"\nscope = ["utc", "sdc"]\n')
    longer = parse_sweep('[sweep]\nname = "longer"\n[[grid]]\nsegment = "straight"\nscope = ["utc", "pdc", "sdc"]\n')
    other = parse_sweep('[sweep]\nname = "other"\n[[grid]]\nsegment = "straight"\nscope = ["pdc", "sdc"]\n')
    outcome = {"status": "failed", "error": "x", "wall_time_s": 1.0, "finished_at": "2026-01-01T00:00:00+00:00"}
    (tmp_path / "sweep.json").write_text(__import__("json").dumps(a.document()))
    with SweepStore(tmp_path) as store:
        store.record(a.cases[0], {**outcome, "key": a.cases[0].key()})
        said = store.check_same_sweep([c.key() for c in longer.cases], longer.source)
        assert said == (f"this sweep of 3 runs extends the one {tmp_path} held ('a'), whose 2 runs are all cases "
                        "of it (1 recorded, kept)")
        assert store.check_same_sweep([c.key() for c in a.cases], a.source) is None  # the same sweep
        with pytest.raises(ColonsimError, match=r"holds another sweep \('a'\) of 2 runs \(1 recorded, 1 in common"):
            store.check_same_sweep([c.key() for c in other.cases], other.source)  # not every case of 'a'
        store.record(longer.cases[1], {**outcome, "key": longer.cases[1].key()})  # a row 'a' does not have
        with pytest.raises(ColonsimError, match="another sweep"):
            store.check_same_sweep([c.key() for c in a.cases] + ["a third key"])  # longer, but without that row


def test_an_unreachable_scheduler_fails_before_anything_is_written(tmp_path):
    pytest.importorskip("distributed")  # the cluster extra
    import socket

    from colonsim.errors import ColonsimError
    from colonsim.insertion.study.sweep_spec import parse_sweep

    with socket.socket() as s:  # a loopback port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    spec = parse_sweep('[sweep]\nname = "x"\n[[grid]]\nsegment = "rsj"\nscope = "utc"\n')
    out = tmp_path / "sweep"
    with pytest.raises(ColonsimError, match=r"Dask scheduler tcp://127\.0\.0\.1:\d+: cannot connect"):
        run_sweep(spec.cases, out, scheduler=f"tcp://127.0.0.1:{port}", spec=spec, progress=False)
    assert not (out / "sweep.json").exists() and not (out / TABLE).exists()


def test_result_files_get_the_mode_of_a_plain_open(tmp_path):
    from colonsim.files import write_json

    mask = os.umask(0o022)
    try:
        write_json(tmp_path / "a.json", {"x": 1})
        (tmp_path / "b.json").write_text("{}")
    finally:
        os.umask(mask)
    assert (tmp_path / "a.json").stat().st_mode & 0o777 == (tmp_path / "b.json").stat().st_mode & 0o777 == 0o644


def test_the_case_listing_shows_an_input_set_in_some_cases_and_unset_in_others():
    """A material given in one case and not in the other varies (None is a value of its own)."""
    cases = [types.SimpleNamespace(to_dict=lambda m=m: {"segment": "rsj", "material": m}, key=lambda m=m: f"k-{m}")
             for m in (None, "tissue/material.json")]
    header = describe_cases(cases).splitlines()[0].split()
    assert header == ["key", "material"]
