"""Fault corpus, writes: a file-size limit, a full disk, a read-only folder, a folder where a results
file goes. Every case: exit code 2 (or a ColonsimError), one line naming the cause and the fix, no
traceback, the earlier set of results byte-identical, no staging folder left behind.

The file-size limit is set on a child process only (``resource.setrlimit`` before it starts, the
``ulimit -f`` of a shell); the full disk and the read-only folder are a small tmpfs mounted in a
private mount namespace of the child (``unshare -m``), so nothing outside the child sees them and
they vanish with it; without the privilege those cases are skipped.
"""

import hashlib
import resource
import shutil
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pandas as pd
import pytest

from colonsim.errors import ColonsimError
from colonsim.files import STAGING_PREFIX, output_set, write_json
from colonsim.insertion.case.scenario import InsertionCase
from colonsim.insertion.study.sweep import LOCK, TABLE, SweepStore

EARLIER = {"material.json": b'{"law": "earlier"}\n', "fit.csv": b"earlier,fit\n", "history.csv": b"a,b\n1,2\n",
           "fit.png": b"\x89PNG earlier", "sensitivity.csv": b"earlier\n"}


def digest(folder: Path) -> dict:
    """{relative path: sha256} of every file under ``folder`` (hidden ones included)."""
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def earlier_set(folder: Path) -> dict:
    folder.mkdir(parents=True, exist_ok=True)
    for name, data in EARLIER.items():
        (folder / name).write_bytes(data)
    (folder / "laws").mkdir(exist_ok=True)
    (folder / "laws" / "note.txt").write_text("earlier law folder\n")
    return digest(folder)


def limited(max_kib):
    """preexec_fn: a file-size limit of ``max_kib`` KiB (``ulimit -f``) in the child only."""
    def apply():
        resource.setrlimit(resource.RLIMIT_FSIZE, (max_kib * 1024, max_kib * 1024))
    return apply


def run(argv, preexec=None, timeout=60, cwd=None):
    return subprocess.run(argv, capture_output=True, text=True, timeout=timeout, preexec_fn=preexec, cwd=cwd)


def one_line_error(proc, *words):
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2, proc.stderr
    assert len(lines) == 1 and lines[0].startswith("colonsim: error: "), proc.stderr
    assert "Traceback" not in proc.stderr
    for w in words:
        assert w in lines[0], lines[0]
    return lines[0]


def no_staging(folder: Path):
    assert not list(folder.rglob(f"{STAGING_PREFIX}*")), list(folder.rglob(f"{STAGING_PREFIX}*"))


# -- the output set, in-process ------------------------------------------------------------------

def test_output_set_swaps_the_whole_set_in(tmp_path):
    out = tmp_path / "out"
    earlier_set(out)
    (out / "keep.txt").write_text("not part of the set\n")
    with output_set(out) as stage:
        write_json(stage / "material.json", {"law": "new"})
        (stage / "laws").mkdir()
        (stage / "laws" / "mooney.txt").write_text("new\n")
        assert not (out / "laws" / "mooney.txt").exists()  # nothing visible before the end
    assert (out / "material.json").read_text().strip().startswith("{")
    assert '"new"' in (out / "material.json").read_text()
    assert sorted(p.name for p in (out / "laws").iterdir()) == ["mooney.txt"]  # the folder replaced as a whole
    assert (out / "fit.csv").read_bytes() == EARLIER["fit.csv"]  # not in the set: untouched
    assert (out / "keep.txt").exists()
    no_staging(out)


def test_output_set_failing_midway_leaves_the_earlier_set_byte_identical(tmp_path):
    out = tmp_path / "out"
    before = earlier_set(out)
    with pytest.raises(RuntimeError):
        with output_set(out) as stage:
            write_json(stage / "material.json", {"law": "new"})
            (stage / "laws").mkdir()
            raise RuntimeError("the work failed after some files were written")
    assert digest(out) == before
    no_staging(out)


def test_output_set_into_a_new_folder_leaves_nothing_on_failure(tmp_path):
    with pytest.raises(RuntimeError):
        with output_set(tmp_path / "new" / "out") as stage:
            (stage / "a.txt").write_text("x")
            raise RuntimeError
    assert not (tmp_path / "new" / "out").exists()


def test_a_folder_where_a_results_file_goes_is_refused_before_any_work(tmp_path):
    out = tmp_path / "out"
    before = earlier_set(out)
    (out / "comparison.csv").mkdir()
    ran = []
    with pytest.raises(ColonsimError, match=r"a folder stands where the results file goes; move it away"):
        with output_set(out, files=("comparison.csv",)) as stage:
            ran.append(stage)
    assert not ran
    assert digest(out) == before


def test_a_file_where_a_results_folder_goes_is_refused_at_the_swap_without_damage(tmp_path):
    out = tmp_path / "out"
    (out).mkdir()
    (out / "rsj_SDC").write_text("a user's file\n")
    (out / "comparison.csv").write_text("earlier\n")
    with pytest.raises(ColonsimError, match="a file stands where the results folder goes"):
        with output_set(out) as stage:
            (stage / "rsj_SDC").mkdir()
            (stage / "comparison.csv").write_text("new\n")
    assert (out / "comparison.csv").read_text() == "earlier\n"
    assert (out / "rsj_SDC").read_text() == "a user's file\n"
    no_staging(out)


def test_cli_calibrate_into_a_folder_whose_material_json_is_a_folder(tmp_path, capsys):
    from colonsim.cli import main

    out = tmp_path / "cal"
    earlier_set(out)
    (out / "material.json").unlink()
    (out / "material.json").mkdir()
    before = digest(out)
    t0 = time.monotonic()
    code = main(["calibrate", "--analytic", "--quick", "--points", "5", "--no-progress", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert "material.json: a folder stands where the results file goes" in err[0]
    assert time.monotonic() - t0 < 5  # refused before the fit
    assert digest(out) == before


# -- a file-size limit (ulimit -f) ---------------------------------------------------------------

SCRIPT_SET = textwrap.dedent("""
    import sys
    from colonsim.files import output_set
    from colonsim.errors import ColonsimError
    try:
        with output_set(sys.argv[1]) as stage:
            (stage / "material.json").write_text("new")
            (stage / "fit.csv").write_bytes(b"x" * 200_000)
    except ColonsimError as exc:
        print(exc, file=sys.stderr)
        sys.exit(2)
""")


def test_output_set_under_a_file_size_limit(tmp_path):
    out = tmp_path / "out"
    before = earlier_set(out)
    proc = run([sys.executable, "-c", SCRIPT_SET, str(out)], preexec=limited(50), timeout=30)
    assert proc.returncode == 2, proc.stderr
    assert "file-size limit (ulimit -f)" in proc.stderr and "earlier results there are unchanged" in proc.stderr
    assert f"cannot write {out}:" in proc.stderr and STAGING_PREFIX not in proc.stderr  # the final name
    assert digest(out) == before
    no_staging(out)


def test_calibrate_under_a_file_size_limit_keeps_the_earlier_calibration(tmp_path):
    """The audit's case: ``colonsim calibrate`` into an earlier calibration's folder under
    ``ulimit -f 50`` changed material.json, fit.csv, history.csv and the rest."""
    out = tmp_path / "cal"
    before = earlier_set(out)
    proc = run([sys.executable, "-m", "colonsim.cli", "calibrate", "--analytic", "--quick", "--points", "5",
                "--no-progress", "--out", str(out)], preexec=limited(50), timeout=60)
    line = one_line_error(proc, "file-size limit", "ulimit -f unlimited", "earlier results there are unchanged")
    assert STAGING_PREFIX not in line
    assert digest(out) == before
    no_staging(out)


SCRIPT_INSERT = textwrap.dedent("""
    import sys
    import numpy as np
    import pandas as pd
    import colonsim.insertion.case.scenario as scenario
    from colonsim.cli import main

    COLUMNS = ["time_s", "depth_m", "deformation_m", "max_stretch", "tip_displacement_m", "tip_arc_m",
               "tip_past_end_m", "lag_m", "tip_heading_deg", "distal_force_N", "contact_force_N", "push_force_N", "contact_nodes",
               "kinetic_colon_J", "internal_colon_J", "kinetic_scope_J", "kinetic_scope_sliding_J", "internal_scope_J",
               "contact_energy_J", "dt_s", "step"]

    def standin(case, progress=None, snapshot_interval=None):
        # SYNTHETIC run: no simulation, a result of the recorder's shape whose time series
        # (about 1 MB of CSV) exceeds the file-size limit the test sets
        ts = pd.DataFrame({c: np.linspace(0.0, 1.0, 4000) for c in COLUMNS}).assign(phase="push")
        summary = {"scope": {"name": case.scope.upper(), "diameter_mm": 11.0}, "final_deformation_cm": 1.0,
                   "max_deformation_cm": 2.0, "points_cm": {}, "peak_contact_force_N": 1.0,
                   "peak_push_force_N": 2.0, "max_wall_stretch": 1.1, "max_lag_cm": 0.0, "final_lag_cm": 0.0,
                   "distal_resistance": {"resistance_N": 0.0, "acting": False, "final_force_N": 0.0},
                   "quasi_static": {"ringing_ratio": 0.05, "holds": True}, "ended_by": "far_end",
                   "end": {"reason": "far end", "depth_cm": 20.0}, "steps": 10, "wall_time_s": 0.1}
        return scenario.InsertionResult(case, ts, summary, snapshots=[], model=None,
                                        final_shape={"colon_m": np.zeros((4, 3)), "scope_m": np.zeros((2, 3))})

    scenario.run_insertion = standin
    sys.exit(main(sys.argv[1:]))
""")


def test_insert_under_a_file_size_limit_keeps_the_earlier_run(tmp_path):
    """The audit's case: ``colonsim insert`` into an earlier run's folder under ``ulimit -f 200``
    changed its summary.json. The simulation is a stand-in (the writes are what is tested)."""
    out = tmp_path / "ins"
    argv = [sys.executable, "-c", SCRIPT_INSERT, "insert", "--segment", "straight", "--scope", "utc",
            "--no-progress", "--out", str(out)]
    earlier_set(out / "straight_UTC")
    (out / "comparison.csv").write_text("earlier\n")
    before = digest(out)
    proc = run(argv, preexec=limited(200), timeout=60)
    one_line_error(proc, "file-size limit", "earlier results there are unchanged")
    assert digest(out) == before
    no_staging(out)


SCRIPT_TABLE = textwrap.dedent("""
    import sys
    from colonsim.insertion.study.sweep import SweepStore
    from colonsim.errors import ColonsimError
    store = SweepStore(sys.argv[1])
    try:
        with store:
            for i in range(4000):
                store.rows[f"k{i}"] = {"key": f"k{i}", "status": "ok", "error": "x" * 40, "quasi_static": True,
                                       "kinetic_energy_check": True, "ended_by": "far_end"}
            store.write()
    except ColonsimError as exc:
        print(exc, file=sys.stderr)
        sys.exit(2)
""")


def test_sweep_table_and_lock_survive_a_failed_table_write(tmp_path):
    out = tmp_path / "sweep"
    store = SweepStore(out)
    case = InsertionCase(segment="straight", scope="utc")
    with store:  # a finished run's row as the sweep records it (a resume checks its key against its inputs)
        store.record(case, {"status": "failed", "error": "x", "wall_time_s": 1.0, "finished_at": "2026-01-01T00:00:00"})
    before = (out / TABLE).read_bytes()
    proc = run([sys.executable, "-c", SCRIPT_TABLE, str(out)], preexec=limited(24), timeout=30)
    assert proc.returncode == 2 and "file-size limit" in proc.stderr, proc.stderr
    assert (out / TABLE).read_bytes() == before  # the finished run's row is still there
    assert not (out / LOCK).exists()  # released, so the next resume is not told another sweep runs
    assert list(pd.read_parquet(out / TABLE)["key"]) == [case.key()]
    assert sorted(p.name for p in out.iterdir()) == [TABLE]


# -- a full disk and a read-only folder (tmpfs in a private mount namespace) ----------------------

def _namespace_available():
    if not sys.platform.startswith("linux") or shutil.which("unshare") is None:
        return False
    probe = subprocess.run(["unshare", "-m", "--propagation", "private", "sh", "-c",
                            "d=$(mktemp -d) && mount -t tmpfs -o size=64k tmpfs $d && umount $d && rmdir $d"],
                           capture_output=True, timeout=10)
    return probe.returncode == 0


needs_mounts = pytest.mark.skipif(not _namespace_available(),
                                  reason="needs unshare -m and mount (root or CAP_SYS_ADMIN)")

SCRIPT_DISK = textwrap.dedent("""
    import hashlib, subprocess, sys
    from pathlib import Path
    disk, mode = Path(sys.argv[1]), sys.argv[2]
    subprocess.run(["mount", "-t", "tmpfs", "-o", "size=400k", "tmpfs", str(disk)], check=True)
    out = disk / "cal"
    out.mkdir()
    for name, data in {"material.json": b"earlier", "fit.csv": b"earlier,fit", "history.csv": b"a,b"}.items():
        (out / name).write_bytes(data)
    digest = lambda: {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(out.rglob("*"))}
    before = digest()
    if mode == "full":
        (disk / "filler").write_bytes(b"0" * 300_000)  # ~100 kB left: less than the calibration's files
    else:
        subprocess.run(["mount", "-o", "remount,ro", str(disk)], check=True)
    proc = subprocess.run([sys.executable, "-m", "colonsim.cli", "calibrate", "--analytic", "--quick", "--points",
                           "5", "--no-progress", "--out", str(out)], capture_output=True, text=True, timeout=60)
    print(proc.returncode)
    print(digest() == before)
    print(sorted(p.name for p in out.iterdir()))
    sys.stderr.write(proc.stderr)
""")


@needs_mounts
@pytest.mark.parametrize("mode,words", [("full", ("the disk is full", "free some space", "unchanged")),
                                        ("readonly", ("Read-only file system", "choose a folder you may write to"))])
def test_calibrate_on_a_full_or_read_only_disk(tmp_path, mode, words):
    disk = tmp_path / "disk"
    disk.mkdir()
    proc = subprocess.run(["unshare", "-m", "--propagation", "private", sys.executable, "-c", SCRIPT_DISK, str(disk),
                           mode], capture_output=True, text=True, timeout=90)
    code, same, names = proc.stdout.strip().splitlines()
    lines = proc.stderr.strip().splitlines()
    assert code == "2", proc.stderr
    assert len(lines) == 1 and lines[0].startswith("colonsim: error: ") and "Traceback" not in proc.stderr, proc.stderr
    assert all(w in lines[0] for w in words), lines[0]
    assert same == "True"
    assert names == "['fit.csv', 'history.csv', 'material.json']"  # no staging folder left
    assert not any(disk.iterdir())  # the tmpfs lived in the child's namespace only


@pytest.mark.parametrize("entry,kind", [(TABLE, "folder"), ("runs", "file")])
def test_a_sweep_whose_table_is_a_folder_is_refused_before_any_run(tmp_path, entry, kind, capsys):
    from colonsim.cli import main

    out = tmp_path / "sweep"
    out.mkdir()
    (out / entry).mkdir() if kind == "folder" else (out / entry).write_text("a user's file\n")
    before = digest(out)
    t0 = time.monotonic()
    code = main(["sweep", "--preset", "smoke", "--workers", "1", "--no-progress", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert f"{entry}: a {kind} stands where the results" in err[0], err[0]
    assert time.monotonic() - t0 < 10  # no run started
    assert digest(out) == before and sorted(p.name for p in out.iterdir()) == [entry]


def test_surrogate_fit_under_a_file_size_limit_keeps_the_earlier_model(tmp_path):
    """A model is a pair (JSON + arrays): both replaced together or neither."""
    from colonsim.cli import main
    from colonsim.surrogate.synthetic import synthetic_sweep

    synthetic_sweep(design="grid", noise_cm=0.02, seed=1).to_parquet(tmp_path / "results.parquet")
    argv = ["surrogate", "fit", str(tmp_path / "results.parquet"), "-o", str(tmp_path / "model"), "--restarts", "0",
            "--targets", "final_deformation_cm"]
    assert main(argv) == 0
    before = digest(tmp_path)
    assert (tmp_path / "model.npz").stat().st_size > 8 * 1024  # so the limit below bites
    proc = run([sys.executable, "-m", "colonsim.cli", *argv, "--seed", "7"], preexec=limited(8), timeout=60)
    one_line_error(proc, "model.npz", "file-size limit", "earlier results there are unchanged")
    assert digest(tmp_path) == before


def test_an_oserror_no_writer_caught_is_still_one_line(monkeypatch, capsys):
    """The command line's last resort: an OSError from anywhere is one line (exit 2), the staging
    folder's name hidden, the cause and the fix named."""
    import errno

    from colonsim import cli

    def failing(args):
        raise OSError(errno.ENOSPC, "No space left on device", f"/data/out/{STAGING_PREFIX}abc/fit.csv")

    monkeypatch.setattr(cli, "cmd_calibrate", failing)
    assert cli.main(["calibrate"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["colonsim: error: cannot write /data/out/fit.csv: the disk is full; free some space or choose "
                   "--out on another disk"]
